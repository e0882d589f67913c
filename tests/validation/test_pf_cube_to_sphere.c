/* Surface tension from pair forces alone (PF Fig. 1c, "configuration reached from a cube") at
 * the thermostat's default temperature: a 2:1:1 box of liquid (20 x 10 x 10 particles, 3D, no
 * gravity) becomes a sphere. A cube's second moments are isotropic from the start, hence the
 * elongated box (moment ratio 0.25 at the start).
 * Scene, and why: the paper's k (Eq. 5 was written for 3D); sigma 4 N/m and nu 3e-3 m^2/s as in
 * the 2D test (Ohnesorge number 0.17: an underdamped drop); theta 0.01, the default; lattice
 * start; DFSPH, the cheapest solver for a free drop (docs/thermostat.md).
 * Size: equipartition of the five l = 2 modes (<a_m^2> = theta d^2 / (4 R^2)) puts the mean
 * ratio at 0.964 for 1,024 particles and 0.971 for 2,000 (R = 7.82 d). At 1,024 (16 x 8 x 8)
 * the seeds read 0.951 / 0.933 / 0.955 over the same window: too close to 0.95.
 * Criteria (issue 11): Rayleigh's omega_l^2 = l (l - 1)(l + 2) sigma / (rho R^3) gives the l = 2
 * period T = 0.767 s. Each of three seeds runs to 6.2 s (8.1 T), sampled every 0.025 s; over the
 * last 4 T (the issue asks for at least two) the mean moment ratio must be >= 0.95 and the mean
 * fraction of kernel-neighbour pairs (r < h) closer than d/2 <= 0.1 % (clustering, PF Section
 * 3.2).
 * Why four periods: the mode's correlation time is about a period, so a two-period mean holds
 * few independent samples and scatters by about 0.007 here, while the drop sits 0.010-0.014
 * below its floor. With two periods (run to 3 s) seeds 1 / 2 / 3 read 0.9601 / 0.9591 / 0.9574,
 * then 0.9571 / 0.9450 / 0.9603 once the pair pass's rounding changed (2026-12-02, the same
 * physics): 0.95 was one deviation away. Over four periods (3.13-6.2 s) the same runs read
 * 0.9617 / 0.9591 / 0.9560 (bench/pf_shape gives the same bits); the last two periods alone
 * 0.9659 / 0.9606 / 0.9556. 0.016-0.025 % of the pairs closer than d/2; about 80 s of CPU per
 * seed. Before the 3D tension factor (Eq. 13 alone, 7 % stiffer), two periods: 0.9561 / 0.9614
 * / 0.9696; first round (ratio 0.9) at 0.53-0.57 s.
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "pfsph/sim.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

static void test_box_to_sphere(void **state)
{
    (void)state;
    tu_release_only();
    const int nl = 20, ns = 10;
    const double d = 0.01, sigma = 4, rho = 1000;
    const double R = cbrt(3.0 * nl * ns * ns * d * d * d / (4 * PI)); /* sphere of the same volume */
    /* Rayleigh (1879): omega_l^2 = l (l - 1) (l + 2) sigma / (rho R^3), l = 2 */
    const double T = 2 * PI / sqrt(8 * sigma / (rho * R * R * R));
    print_message("R = %.2f d, capillary period T = %.3f s\n", R / d, T);
    const double mean = tu_shape_relax_seeds(3, nl, ns, 6.2, 4 * T, 0.025, "four periods");
    print_message("three seeds: moment ratio %.4f (floor 0.971)\n", mean);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1); /* 2,000 particles: threads only add synchronisation */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_box_to_sphere)};
    return tu_run_group(tests, NULL, NULL);
}
