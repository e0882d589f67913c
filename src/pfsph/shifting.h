/* Particle shifting (Fickian, after Lind et al. 2012 and Skillen et al. 2013, with the
 * anti-clumping term of Monaghan 2000 / Sun et al. 2017 and the free-surface correction of Lind
 * et al.: no shift along the surface normal). Moves fluid particles down the gradient of the
 * particle concentration C_i = sum_j V_j W_ij, without changing their velocities, so that the
 * particle arrangement forgets its start lattice and stays free of clumps and voids. Used by
 * the pairwise-force model (docs/pairwise.md, "Particle shifting"), which otherwise gives the
 * arrangement a yield stress. */
#ifndef PFSPH_SHIFTING_H
#define PFSPH_SHIFTING_H

#include "pfsph/ctx.h"

/* Shift ctx->fluid positions in place for a step of length dt [s]. The fluid arrays must be in
 * the order of ctx->grid and its cells at least h + max_frac d (the shift is applied after the
 * sort, so every neighbour within h stays in the 3^dim cells searched). Boundary particles
 * count in C with their volumes (fluid is not shifted into walls). sx, sy, sz: scratch of
 * ctx->fluid->n entries each. normal_radius [m] (at least h, at most the grid cell): support
 * of the concentration gradient whose direction is the surface normal. Deterministic for any thread count. Returns the largest shift
 * [m]. */
double pfsph_shift_apply(const pfsph_ctx *ctx, const pfsph_shift_params *p, double dt, double normal_radius,
                         pfsph_real *sx, pfsph_real *sy, pfsph_real *sz);

/* Particle concentration C_i = V0 sum_j W_ij + sum_b V_b W_ib (self term included) of fluid
 * particle i, and its gradient (with the anti-clumping weight) in g[3]; for tests. */
double pfsph_shift_concentration(const pfsph_ctx *ctx, size_t i, double g[3]);

#endif
