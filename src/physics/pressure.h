/* Pressure force, number-density form (PF Eq. 4 with Eq. 23; NOTES item 8). */
#ifndef PFSPH_PRESSURE_H
#define PFSPH_PRESSURE_H

#include "pfsph/ctx.h"

/* Pressure acceleration in the number-density form of Solenthaler & Pajarola 2008:
 * a_i = -(1/m_i) [sum_j (p_i/d_i^2 + p_j/d_j^2) grad W_ij + sum_b (V_b/V0) p_i/d_i^2 grad W_ib]. */
void pfsph__pressure_accel(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y, const pfsph_real *z,
                           const pfsph_real *nd, const pfsph_real *p, pfsph_real *apx, pfsph_real *apy,
                           pfsph_real *apz);

#endif
