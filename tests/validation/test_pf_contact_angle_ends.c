/* Static contact angles at temperature, the wetting and non-wetting ends: targets 30 and 150
 * degrees, the drops and criteria of tests/physics/test_pf_contact_angle.c (its header says how
 * the angle is measured; the code is pfm_contact_angles, tests/pf_measure.c). Label
 * validation: about 45 s on one core. */
#include <omp.h>

#include "pf_measure.h"
#include "testutil.h"

static void test_contact_angles(void **state)
{
    (void)state;
    const double target[] = {30, 150};
    pfm_contact_angles(2, target, 2);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_contact_angles)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
