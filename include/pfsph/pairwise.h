/* Pairwise interaction forces (Yang et al., PF-SPH, Sections 3-4): cosine pair force over an
 * enlarged radius k*h (Eqs. 3, 5, 6), anisotropic filtering (Eqs. 7-12), coefficients from
 * surface tension and contact angle targets (Eqs. 13-21). Derivations and choices:
 * docs/pairwise.md. */
#ifndef PFSPH_PAIRWISE_H
#define PFSPH_PAIRWISE_H

#include <stdbool.h>
#include <stdio.h>

#include "pfsph/shifting.h"
#include "pfsph/types.h"

/* scene.h includes this header, so the scene and the context are only forward-declared. */
struct pfsph_ctx;
struct pfsph_scene;

/* Where the covariance of Eq. 7 is centred. */
enum pfsph_pw_center {
    PFSPH_PW_CENTER_PARTICLE = 0, /* x_i, Eq. 7 as written (default). At k h ~ 2.8 d a particle
                                     on a flat surface sees C_n/C_t ~ 0.66 (square lattice): the
                                     surface row counts in C_t only; in the continuum limit the
                                     moments about x_i are even in the normal and the edge
                                     particle would look isotropic */
    PFSPH_PW_CENTER_MEAN = 1,     /* kernel-weighted mean of the neighbourhood (Yu & Turk 2013):
                                     a stronger, resolution-independent signal at surfaces */
};

typedef struct pfsph_pairwise_params {
    bool enabled;
    double k;         /* radius enlargement, default (80/30)^(1/3) (Eq. 5) */
    bool filter;      /* anisotropic filter on (Eq. 12) */
    double eta;       /* Eq. 11, default 0.2 */
    double eps_min;   /* Eq. 8 clamp on eigenvalues normalised by the largest one, default 0.5 */
    int center;       /* enum pfsph_pw_center */
    pfsph_shift_params shift; /* particle shifting stage (off unless the scene asks) */
    /* Coefficient matrix c[a][b] over scene phases (solids included), symmetric, >= 0.
     * Pair force c m_i m_j f(r): c in N/kg^2 in 3D; in 2D masses are per metre of depth. */
    double c[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Which entries the scene stated (c directly, sigma, or contact angle). */
    bool c_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Targets as written in the scene; resolved into c by pfsph_pairwise_resolve. */
    bool sigma_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    double sigma[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];   /* N/m (2D: N/m per metre of depth) */
    bool angle_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    double angle_deg[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Filled by pfsph_pairwise_resolve (for the report). */
    bool resolved;
    double radius;    /* k*h [m] */
    double lambda;    /* Eq. 13 constant for the cosine force [m^(dim+2)] */
} pfsph_pairwise_params;

void pfsph_pairwise_defaults(pfsph_pairwise_params *p);

/* The pair force shape of Eq. 6: cos(3 pi r / (2 R)) for r <= R, 0 beyond (R = k h). Positive
 * (repulsive) below R/3, negative (attractive) between R/3 and R. */
double pfsph_pairwise_shape(double r, double R);

/* lambda of Eq. 13 for the cosine force over radius R, from the Kirkwood-Buff integral for a
 * step density profile (docs/pairwise.md): sigma = lambda * c * n^2 m^2 = lambda c rho^2.
 * 3D: (pi/8) R^5 (U^4 - 12 U^2 + 24) / U^5; 2D: (1/3) R^4 (U^3 - 6 U - 6) / U^4; U = 3 pi / 2. */
double pfsph_pairwise_lambda(int dim, double R);

/* Radius the pair forces need: k*h if enabled, else 0. The core sizes grid cells to
 * max(h, this). */
pfsph_real pfsph_pairwise_radius(const struct pfsph_scene *s, pfsph_real h);

/* Turn sigma and contact-angle targets into c[a][b] (Eqs. 13-16, 21) for particles at the given
 * spacing [m] and SPH support h [m]; fills s->pairwise.resolved/radius/lambda. Idempotent.
 * Returns PFSPH_EINPUT with a message for impossible targets (a cross surface tension larger
 * than the cohesions allow, a contact angle on a fluid without cohesion, ...). */
int pfsph_pairwise_resolve(struct pfsph_scene *s, pfsph_real spacing, pfsph_real h,
                           pfsph_error *err);

/* Print the coefficient matrix, each target with the coefficient it produced, and the surface
 * tensions and contact angles the final matrix predicts (for `pfsph check`). */
void pfsph_pairwise_report(const struct pfsph_scene *s, FILE *out);

/* Anisotropic filter T (Eqs. 8-11) from a symmetric dim x dim covariance C (Eq. 7), row-major
 * 3x3 storage (2D uses the upper-left 2x2; T[2][2] = 1). Eigenvalues are normalised by the
 * largest one before the eps_min clamp; the spectral norm is used in Eq. 11, so an isotropic C
 * gives T = I. A zero C (no neighbours) gives T = I. */
void pfsph_pairwise_filter_matrix(int dim, const double C[3][3], double eta, double eps_min,
                                  double T[3][3]);

typedef struct pfsph_pairwise pfsph_pairwise;

/* Per-run state (scratch) for ctx's particle counts; ctx->scene->pairwise must be resolved. */
int pfsph_pairwise_create(pfsph_pairwise **out, const struct pfsph_ctx *ctx, pfsph_error *err);
void pfsph_pairwise_destroy(pfsph_pairwise *pw); /* NULL is a no-op */

/* ADD F_i^int / m_i to ctx->ax, ay, az for every fluid particle: fluid-fluid pairs within k*h
 * found through ctx->grid, fluid-solid pairs through ctx->boundary/ctx->bgrid (boundary
 * particles are static and receive nothing). Eq. 3 with the sign of NOTES item 1, then Eq. 12
 * when the filter is on and eta > 0. Grid cells must be >= k*h; fluid arrays in grid order.
 * Deterministic for any thread count. This is also the function the benchmark times. */
void pfsph_pairwise_apply(pfsph_pairwise *pw, const struct pfsph_ctx *ctx);

/* Particle shifting (include/pfsph/shifting.h) with the scene's "shifting" parameters, for a
 * step of ctx->dt: called right after the grid sort, before the density. No-op when off. The
 * shift per step is capped at min(max_frac d, cell - h) so that neighbour searches stay exact. */
void pfsph_pairwise_shift(pfsph_pairwise *pw, const struct pfsph_ctx *ctx);

/* Diagnostics for tests and measurements, same neighbour loops as apply. For each fluid
 * particle i: vir[i] = sum_j r_ij . F_ji [J] (F_ji the filtered force on i from j, fluid and
 * solid neighbours); T (if not NULL) receives the 9 entries of T_i row-major at T + 9 i. */
void pfsph_pairwise_diagnose(pfsph_pairwise *pw, const struct pfsph_ctx *ctx, double *vir,
                             double *T);

/* As pfsph_pairwise_diagnose, and (if W is not NULL) the virial tensor of each fluid particle,
 * W_i = sum_j F_ji (x) r_ij [J], 9 entries row-major at W + 9 i (its trace is vir[i]); for the
 * stress-anisotropy route to the Laplace pressure (docs/pairwise.md). */
void pfsph_pairwise_diagnose_tensor(pfsph_pairwise *pw, const struct pfsph_ctx *ctx,
                                    double *vir, double *T, double *W);

#endif
