/* Static contact angles at temperature in 3D, the wetting and non-wetting ends: targets 30 and
 * 150 degrees (issue 31: 30-150 in 2D and 3D), the drops, measurement and criteria of
 * test_pf_contact_angle_3d.c (its header; the code is pfm_contact_angles, tests/pf_measure.c):
 * 216-particle cubes on 26 x 26 d plates, the angle averaged over 1-2 s, within 10 degrees of
 * the target. A 30-degree cap of this volume is about 16 d across, so it fits its plate.
 * Measured: see docs/validation.md. Label validation; under AddressSanitizer it runs 0.04 s and
 * checks the code paths only. */
#include <omp.h>

#include "pf_measure.h"
#include "testutil.h"

static void test_contact_angles_3d_ends(void **state)
{
    (void)state;
    const double target[] = {30, 150};
    pfm_contact_angles(3, target, 2);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_contact_angles_3d_ends)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
