/* Pairwise interaction forces (placeholder until the module lands). */
#include "pfsph/pairwise.h"

#include <math.h>
#include <string.h>

void pfsph_pairwise_defaults(pfsph_pairwise_params *p)
{
    memset(p, 0, sizeof(*p));
    p->k = cbrt(80.0 / 30.0);
    p->filter = true;
    p->eta = 0.2;
    p->eps_min = 0.5;
}
