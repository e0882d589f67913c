/* Pairwise interaction forces (Yang et al., PF-SPH, Sections 3-4): cosine pair force over an
 * enlarged radius k*h (Eqs. 3, 5, 6), anisotropic filtering (Eqs. 7-12), coefficients from
 * surface tension and contact angle targets (Eqs. 13-21). Derivations and choices:
 * docs/pairwise.md. */
#ifndef PFSPH_PAIRWISE_H
#define PFSPH_PAIRWISE_H

#include <stdbool.h>
#include <stdio.h>

#include "pfsph/shifting.h"
#include "pfsph/ctx.h"

/* Anisotropic filter T (Eqs. 8-11) from a symmetric dim x dim covariance C (Eq. 7), row-major
 * 3x3 storage (2D uses the upper-left 2x2; T[2][2] = 1). Eigenvalues are normalised by the
 * largest one before the eps_min clamp; the spectral norm is used in Eq. 11, so an isotropic C
 * gives T = I. A zero C (no neighbours) gives T = I. */
void pfsph_pairwise_filter_matrix(int dim, const double C[3][3], double eta, double eps_min, double T[3][3]);

typedef struct pfsph_pairwise pfsph_pairwise;

/* Per-run state (scratch) for ctx's particle counts; ctx->scene->pairwise must be resolved. */
int pfsph_pairwise_create(pfsph_pairwise **out, const pfsph_ctx *ctx, pfsph_error *err);
void pfsph_pairwise_destroy(pfsph_pairwise *pw); /* NULL is a no-op */

/* ADD F_i^int / m_i to ctx->ax, ay, az for every fluid particle: fluid-fluid pairs within k*h
 * found through ctx->grid, fluid-solid pairs through ctx->boundary/ctx->bgrid (boundary
 * particles are static and receive nothing). Eq. 3 with the sign of NOTES item 1, then Eq. 12
 * when the filter is on and eta > 0. The grid's far reach (reach_far cells) must cover k*h;
 * fluid and boundary particles at the positions they were sorted at (the walk visits only the
 * cells the k h ball touches; with shifting configured it walks the whole reach). Deterministic
 * for any thread count and CPU. This is also the function the benchmark times. */
void pfsph_pairwise_apply(pfsph_pairwise *pw, const pfsph_ctx *ctx);
/* As pfsph_pairwise_apply, but the accelerations are WRITTEN to acc[0..2] (not added to ctx->ax),
 * and the same walk sums the number density delta_i of Eq. 23 into nd (fluid and wall terms as
 * pfsph__number_density, in this walk's order: equal to rounding): the density and pair stages
 * in one walk of the k h neighbourhood (sim.c). With pair forces disabled the accelerations are
 * 0 and nd is still computed. */
void pfsph_pairwise_apply_density(pfsph_pairwise *pw, const pfsph_ctx *ctx, pfsph_real *nd, pfsph_real *const acc[3]);
/* The same, and (the interactive PCISPH) the walk's pairs within h listed into l (fluid, j != i)
 * and lb (boundary) with their dW/r, as density.c's one-walk build lists them (guess: fluid
 * neighbours per particle for a first plan). PFSPH_OK or PFSPH_ENOMEM. */
int pfsph_pairwise_apply_density_lists(pfsph_pairwise *pw, const pfsph_ctx *ctx, pfsph_real *nd,
                                       pfsph_real *const acc[3], struct pfsph_nlist *l, struct pfsph_nlist *lb,
                                       double guess);
/* The largest pair-force acceleration |F_i^int / m_i| of the last apply [m/s^2] (0 for NULL). */
double pfsph_pairwise_amax(const pfsph_pairwise *pw);

/* Particle shifting (src/pfsph/shifting.h) with the scene's "shifting" parameters, for a
 * step of ctx->dt: called right after the grid sort, before the density. No-op when off. The
 * shift per step is capped at min(max_frac d, cell - h) so that neighbour searches stay exact. */
void pfsph_pairwise_shift(pfsph_pairwise *pw, const pfsph_ctx *ctx);

/* Diagnostics for tests and measurements, same neighbour loops as apply. For each fluid
 * particle i: vir[i] = sum_j r_ij . F_ji [J] (F_ji the filtered force on i from j, fluid and
 * solid neighbours); T (if not NULL) receives the 9 entries of T_i row-major at T + 9 i. */
void pfsph_pairwise_diagnose(pfsph_pairwise *pw, const pfsph_ctx *ctx, double *vir, double *T);

/* As pfsph_pairwise_diagnose, and (if W is not NULL) the virial tensor of each fluid particle,
 * W_i = sum_j F_ji (x) r_ij [J], 9 entries row-major at W + 9 i (its trace is vir[i]); for the
 * stress-anisotropy route to the Laplace pressure (docs/pairwise.md). */
void pfsph_pairwise_diagnose_tensor(pfsph_pairwise *pw, const pfsph_ctx *ctx, double *vir, double *T, double *W);

/* Mechanical (virial) pressure of each fluid particle [Pa; 2D: N/m]: the virial of the solver's
 * pressure force plus the pair-force virial n_i / (2 dim) sum_j r_ij . F_ji plus the kinetic part
 * n_i m_i |u_i|^2 / dim of its peculiar velocity u_i (docs/thermostat.md). p is the pressure the
 * solver pushed with this step (DFSPH: density plus divergence pressure); NULL: fluid->p. vir is
 * scratch of n doubles. Needs ctx->nd; the pair forces may be off (virial 0). */
void pfsph_pairwise_mechanical_pressure(pfsph_pairwise *pw, const pfsph_ctx *ctx, const pfsph_real *p, double *vir,
                                        pfsph_real *out);

#endif
