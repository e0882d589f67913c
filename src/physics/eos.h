/* Equation of state: pressure from number density. */
#ifndef PFSPH_EOS_H
#define PFSPH_EOS_H

#include "pfsph/ctx.h"

/* Tait equation (DF Eq. 3 with NOTES item 12), negative pressures clamped to zero. */
void pfsph__tait(const pfsph_ctx *ctx, const pfsph_real *nd, double B, double gamma, double rho_common, pfsph_real *p);

#endif
