/* Number density of the fluid (PF Eq. 23) with Akinci boundary contributions. */
#ifndef PFSPH_DENSITY_H
#define PFSPH_DENSITY_H

#include "pfsph/ctx.h"

/* Number density delta_i = sum_j W_ij + (1/V0) sum_b V_b W_ib (PF Eq. 23 with Akinci 2012
 * boundaries), at positions (x, y, z) of the fluid (the current or the predicted ones). */
void pfsph__number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                           const pfsph_real *z, pfsph_real *nd);

#endif
