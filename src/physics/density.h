/* Number density of the fluid (PF Eq. 23) with Akinci boundary contributions. */
#ifndef PFSPH_DENSITY_H
#define PFSPH_DENSITY_H

#include "pfsph/ctx.h"

/* Number density delta_i = sum_j W_ij + (1/V0) sum_b V_b W_ib (PF Eq. 23 with Akinci 2012
 * boundaries), at positions (x, y, z) of the fluid (the current or the predicted ones). */
void pfsph__number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y, const pfsph_real *z,
                           pfsph_real *nd);

/* The same at the fluid's positions, and in the same walk each fluid particle's lists of
 * fluid neighbours (l: j != i within h) and boundary neighbours (lb: within h), with the
 * kernel derivatives (src/core/nlist.h, one-walk build; guess: fluid neighbours per particle
 * for a thread that had none). Returns PFSPH_OK, PFSPH_ENOMEM, or PFSPH_EINPUT when the lists
 * disagree with the walk (a bug). */
struct pfsph_nlist;
int pfsph__number_density_list(const pfsph_ctx *ctx, pfsph_real *nd, struct pfsph_nlist *l, struct pfsph_nlist *lb,
                               double guess);

#endif
