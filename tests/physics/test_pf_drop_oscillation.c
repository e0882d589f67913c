/* The oscillating drop in 2D (docs/validation_drop.md): a free disc of pair-force liquid given
 * the l = 2 potential flow rings with Rayleigh's period, 2 pi / sqrt(6 sigma / (rho R^3)), within
 * 15 % and decays at Lamb's rate, 4 nu / R^2 (2D), within a factor 1.5, with the scene's
 * viscosity and no opt-in keys. R = 0.12 m at d = 1 cm (12 spacings, 450 particles). The finer
 * 2D drop and the 3D drops: tests/validation/test_pf_drop_oscillation_fine.c. Knobs for studies:
 * PF_DIM, PF_R, PF_D, PF_SIGMA, PF_NU, PF_EPS, PF_PERIODS, PF_SEED. */
#include <math.h>
#include <stdio.h>

#include "pf_drop.h"
#include "testutil.h"

/* 2D runs at theta 0.04, not the 2D default 0.01: at 0.01 the 2D liquid is a shear-thinning soft
 * glass and the drop rings at about 4x Lamb's damping (docs/viscosity.md); the default stays
 * 0.01 until the 2D bubble and shape tests are re-derived for 0.04. */
#define THETA_2D "\"thermostat\": {\"reduced_temperature\": 0.04},"

static void drop_2d(void **state)
{
    (void)state;
    tu_release_only();
    const pfm_osc cfg = {(int)tu_env_num("PF_DIM", 2),
                         tu_env_num("PF_R", 0.12),
                         tu_env_num("PF_D", 0.01),
                         tu_env_num("PF_SIGMA", 4),
                         tu_env_num("PF_NU", 2e-3),
                         tu_env_num("PF_EPS", 0.1),
                         tu_env_num("PF_PERIODS", 3),
                         tu_env_num("PF_MELT", 0.3),
                         (int)tu_env_num("PF_SEED", 1),
                         (int)tu_env_num("PF_SEEDS", 3),
                         THETA_2D};
    pfm_osc_result r;
    const int rc = pfm_oscillation(&cfg, &r);
    pfm_osc_report(&cfg, &r, "2d_coarse");
    const double pt = r.T / r.T0, pg = r.gamma / r.gamma_lamb;
    pfm_osc_free(&r);
    assert_int_equal(rc, 0);
    assert_true(fabs(pt - 1) <= 0.15);
    assert_true(pg >= 1 / 1.5 && pg <= 1.5);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(drop_2d)};
    return tu_run_group(tests, NULL, NULL);
}
