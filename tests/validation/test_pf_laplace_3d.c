/* Laplace's law at temperature in 3D (issue 11; PF Eqs. 3, 6, 13; docs/thermostat.md, "Surface
 * tension at temperature", 3D, "Why 3D missed" and "What passes: balls of 6 to 10 d"). Lattice balls of radius
 * 6, 7, 8, 9 and 10 d (912-4,224 particles), no gravity, sigma target 4 N/m, k 1.7, h = 2 d,
 * nu 1e-3, DFSPH with tolerance 1e-4 (at its default 0.001 a 3D core stays 0.15 % compressed and
 * reads ~150 Pa low), seed 7, the thermostat at its default temperature, the target converted
 * with the shipped 3D factor 0.935. The pressure inside is the frames' mechanical pressure
 * (pfsph_sim_mechanical_pressure) averaged over the particles within R_e / 2 of the centroid,
 * sampled every 4 steps from 0.5 s to 5.5 s (the 5 s). The fit p = a + s x, x = 2 / R_e
 * (R_e = (3 N d^3 / (4 pi))^(1/3)), must give s within 15 % of sigma, |a| <= 0.25 sigma / R_max
 * and R^2 >= 0.9.
 * Why these radii: the mechanical pressure is a virial over the pair support (k h = 3.4 d), so
 * under the surface it overshoots for 1-2 d (+270 to +330 Pa) before the surface shell goes
 * negative; a ball needs R >= 6 d for a flat core within R_e / 2. Balls of 4 and 5 d have none
 * and read 13 % and 4 % high (slope 1.44 sigma, intercept -60 Pa: the reason this test was
 * pending).
 * Measured (seed 7): p_in / (2 sigma / R_e) = 0.964 +- 0.012, 0.964 +- 0.008, 1.001 +- 0.007,
 * 0.937 +- 0.007, 0.948 +- 0.012 (block errors); slope 0.993 sigma, intercept -2.9 Pa (bound
 * 9.97), R^2 0.989. Seeds 1 and 3: slopes 0.985 and 0.961, intercepts -3.5 and +0.4 Pa, R^2
 * 0.973 and 0.994. The five drops run in parallel, one per thread (each simulation
 * on one thread: 900-4,200 particles gain nothing from more); 5 s of all five cost about
 * 400 s of CPU (label validation). Under AddressSanitizer it skips (tu_release_only).
 * The code: pfm_laplace_run, tests/pf_measure.c.
 * Knobs for studies: PF_SOLVER (dfsph), PF_SOLVER_KEYS (solver keys appended, default
 * ', "tolerance": 0.0001'), PF_THETA, PF_SEED (7), PF_T0 (start of the average, 0.5 s), PF_T
 * (end, 5.5 s), PF_EVERY (steps between samples, 4), PF_RADII ("6,7,8,9,10" in spacings),
 * PF_PROFILE (radial profile in shells of 1 d, gyration radius, block means). */
#include <stdio.h>
#include <stdlib.h>

#include "pf_measure.h"
#include "testutil.h"

static void test_laplace(void **state)
{
    (void)state;
    tu_release_only();
    double radii[PFM_MAXR] = {6, 7, 8, 9, 10};
    int nr = 5;
    nr = tu_env_list("PF_RADII", radii, PFM_MAXR, nr);
    pfm_laplace cfg = {.dim = 3,
                       .solver = tu_env("PF_SOLVER", "dfsph"),
                       .solver_keys = tu_env("PF_SOLVER_KEYS", ", \"tolerance\": 0.0001"),
                       .dt_max = "0.002",
                       .every = (int)tu_env_num("PF_EVERY", 4),
                       .t0 = tu_env_num("PF_T0", 0.5),
                       .t_end = tu_env_num("PF_T", 5.5),
                       .profile = getenv("PF_PROFILE") != NULL,
                       .checks = 1};
    pfm_laplace_run(&cfg, radii, nr);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_laplace)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
