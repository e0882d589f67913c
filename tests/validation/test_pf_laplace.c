/* Laplace's law at temperature in 2D (issue 11; PF Eqs. 3, 6, 13; docs/thermostat.md, "Surface
 * tension at temperature", "The check"): lattice discs of radius 8, 10, 13, 16 and 20 d
 * (208-1,264 particles), no gravity, sigma target 4 N/m, k 1.7, nu 1e-3, PCISPH, the thermostat at its
 * default temperature. The pressure inside is the mechanical pressure the frames carry
 * (pfsph_sim_mechanical_pressure: solver pressure force virial + pair virial + kinetic part)
 * averaged over the particles within R/2 of the centroid, sampled every 2 steps from 1 s to
 * 6 s (5 s of averaging, as the issue asks). Sampled at frames instead (every 0.05 s) it is too
 * noisy: PCISPH's pressure answers each step's random kicks, about 45 Pa rms per sample
 * against a signal of 25-40 Pa, and those kicks decorrelate from one step to the next, so the
 * error of the mean falls as one over the square root of the samples taken (every 10 steps:
 * 1.1-1.3 Pa per drop, a slope known to 11 %; every 2 steps: about 0.5 Pa, 5 %).
 * The fit p = a + s / R_e (R_e = sqrt(N d^2 / pi), the drop's equivalent radius) must give
 * s within 15 % of the target sigma, |a| <= 0.25 sigma / R_max and R^2 >= 0.9. The target is
 * converted with the factor of the tension at temperature (pfsph_pairwise_sigma_factor),
 * calibrated once on discs of 15 d with WCSPH: these radii and this solver are a check of it.
 * Standard errors from 10 block averages are printed. Measured (seed 7): p_in / (sigma / R_e) =
 * 0.975, 0.912, 0.958, 0.936, 0.905 (+- 0.011-0.024); slope 0.992 sigma, intercept -1.64 Pa
 * (bound 4.99), R^2 0.994. Seeds 1 and 3: slopes 0.899 and 0.891, intercepts +0.75 and +0.51 Pa,
 * R^2 0.998 and 0.994. Five radii over 8-20 d, not three over 10-16 d: with three, a change of
 * rounding alone (the vectorised pair pass of issue 11) moved seed 7's slope from 0.988 to 0.861, because
 * each drop's mean scatters 3-4 % between realisations (several times its block error) and the
 * narrow range of 1 / R amplifies that into the slope. The five drops run in parallel, one per
 * thread, each simulation on one thread (independent, so the bits do not depend on the order): 131 s of CPU in all
 * (label validation). Under AddressSanitizer it skips (tu_release_only).
 * The code: pfm_laplace_run, tests/pf_measure.c.
 * Knobs for studies: PF_SOLVER, PF_TOL (the solver's density tolerance), PF_DTMAX (0.002 s),
 * PF_THETA, PF_SEED (7), PF_T (end [s]), PF_RADII ("8,10,13,16,20" in spacings). */
#include <stdio.h>
#include <stdlib.h>

#include "pf_measure.h"
#include "testutil.h"

static void test_laplace(void **state)
{
    (void)state;
    tu_release_only();
    double radii[PFM_MAXR] = {8, 10, 13, 16, 20};
    const int nr = tu_env_list("PF_RADII", radii, PFM_MAXR, 5);
    char tol[64] = "";
    if (getenv("PF_TOL")) snprintf(tol, sizeof tol, ", \"tolerance\": %s", getenv("PF_TOL"));
    pfm_laplace cfg = {.dim = 2,
                       .solver = tu_env("PF_SOLVER", "pcisph"),
                       .solver_keys = tol,
                       .dt_max = tu_env("PF_DTMAX", "0.002"),
                       .every = 2,
                       .t0 = 1.0,
                       .t_end = tu_env_num("PF_T", 6.0),
                       .checks = 1};
    pfm_laplace_run(&cfg, radii, nr);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_laplace)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
