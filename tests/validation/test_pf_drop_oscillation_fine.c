/* The oscillating drop (docs/validation_drop.md), the cases beyond the 2D physics test
 * (tests/physics/test_pf_drop_oscillation.c): the same 2D drop (R = 0.12 m) at the finer
 * spacing d = 6 mm (20 spacings), and a 3D ball of R = 0.06 m at d = 1 cm and 6.67 mm (6 and 9
 * spacings). Each rings with Rayleigh's period (2D omega^2 = 6 sigma / (rho R^3), 3D
 * 8 sigma / (rho R^3)) within 15 % and decays at Lamb's rate (2D 4 nu / R^2, 3D 5 nu / R^2)
 * within a factor 1.5, with the scene's viscosity and no opt-in keys. Knobs as in the physics
 * test (PF_NU, PF_SIGMA, PF_EPS, PF_PERIODS, PF_SEED); PF_CASES picks cases by number (e.g. "13"). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pf_drop.h"
#include "testutil.h"

/* 2D runs at theta 0.04, not the 2D default 0.01: at 0.01 the 2D liquid is a shear-thinning soft
 * glass and the drop rings at about 4x Lamb's damping (docs/viscosity.md); the default stays
 * 0.01 until the 2D bubble and shape tests are re-derived for 0.04. */
#define THETA_2D "\"thermostat\": {\"reduced_temperature\": 0.04},"

static void run_case(int dim, double R, double d, const char *tag)
{
    const char *sel = tu_env("PF_CASES", "");
    char num[2] = {tag[0], 0};
    if (*sel && !strstr(sel, num)) {
        tu_skip("not among the cases PF_CASES picks");
        return;
    }
    const pfm_osc cfg = {dim,
                         R,
                         d,
                         tu_env_num("PF_SIGMA", 4),
                         tu_env_num("PF_NU", dim == 2 ? 2e-3 : 3e-3),
                         tu_env_num("PF_EPS", 0.1),
                         tu_env_num("PF_PERIODS", 3),
                         tu_env_num("PF_MELT", 0.3),
                         (int)tu_env_num("PF_SEED", 1),
                         (int)tu_env_num("PF_SEEDS", dim == 2 ? 3 : 1),
                         dim == 2 ? THETA_2D : NULL};
    pfm_osc_result r;
    const int rc = pfm_oscillation(&cfg, &r);
    pfm_osc_report(&cfg, &r, tag + 2);
    const double pt = r.T / r.T0, pg = r.gamma / r.gamma_lamb;
    pfm_osc_free(&r);
    assert_int_equal(rc, 0);
    assert_true(fabs(pt - 1) <= 0.15);
    assert_true(pg >= 1 / 1.5 && pg <= 1.5);
}

static void drop_2d_fine(void **state)
{
    (void)state;
    tu_release_only();
    run_case(2, 0.12, 0.006, "1 2d_fine");
}

static void drop_3d_coarse(void **state)
{
    (void)state;
    tu_release_only();
    run_case(3, 0.06, 0.01, "2 3d_coarse");
}

static void drop_3d_fine(void **state)
{
    (void)state;
    tu_release_only();
    run_case(3, 0.06, 0.02 / 3, "3 3d_fine");
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(drop_2d_fine), cmocka_unit_test(drop_3d_coarse),
                                       cmocka_unit_test(drop_3d_fine)};
    return tu_run_group(tests, NULL, NULL);
}
