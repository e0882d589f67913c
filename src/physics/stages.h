/* Internal: the SPH stages the time step is built from. Each is a function over arrays with
 * an explicit context, testable alone. Fluid arrays must be in the order of ctx->grid. */
#ifndef PFSPH_STAGES_H
#define PFSPH_STAGES_H

#include "pfsph/sim.h"

/* Akinci et al. 2012 boundary particle volume V_b = 1 / sum_k W_bk over boundary particles,
 * written into b->aux for the particles whose aux is not already positive. */
void pfsph__boundary_volumes(pfsph_particles *b, const pfsph_grid *bg, const pfsph_kernel *k);

/* Number density delta_i = sum_j W_ij + (1/V0) sum_b V_b W_ib (PF Eq. 23 with Akinci 2012
 * boundaries), at positions (x, y, z) of the fluid (the current or the predicted ones). */
void pfsph__number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                           const pfsph_real *z, pfsph_real *nd);

/* ctx->ax.. = gravity + viscosity (fluid-fluid and fluid-boundary). */
void pfsph__nonpressure(const pfsph_ctx *ctx);

/* Pressure acceleration in the number-density form of Solenthaler & Pajarola 2008:
 * a_i = -(1/m_i) [sum_j (p_i/d_i^2 + p_j/d_j^2) grad W_ij + sum_b (V_b/V0) p_i/d_i^2 grad W_ib]. */
void pfsph__pressure_accel(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                           const pfsph_real *z, const pfsph_real *nd, const pfsph_real *p,
                           pfsph_real *apx, pfsph_real *apy, pfsph_real *apz);

/* Tait equation (DF Eq. 3 with NOTES item 12), negative pressures clamped to zero. */
void pfsph__tait(const pfsph_ctx *ctx, const pfsph_real *nd, double B, double gamma,
                 double rho_common, pfsph_real *p);

/* Deterministic sum (fixed blocks, serial combination): same bits for any thread count. */
double pfsph__sum(const pfsph_real *a, size_t n);

/* PCISPH scaling: |sum grad W|^2 + sum |grad W|^2 over a full lattice neighbourhood. */
double pfsph__pcisph_prototype(const pfsph_kernel *k, int dim, pfsph_real spacing);

#endif
