/* Static contact angles at temperature, the wetting and non-wetting ends: targets 30 and 150
 * degrees, the code and criteria of tests/physics/test_pf_contact_angle.c (its header says how the
 * angle is measured). Label validation: about 45 s on one core. */
#define PF_CA_ENDS 1
#include "physics/test_pf_contact_angle.c"
