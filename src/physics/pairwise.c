/* Pairwise interaction forces of PF-SPH (Yang et al.): cosine pair force over k*h (Eqs. 3, 5, 6),
 * the anisotropic filter T_i (Eqs. 7-12), and the parameters: lambda of Eq. 13 for the cosine
 * force, surface tension and contact angle targets (Eqs. 13-16, 21), the `pfsph check` report.
 * Derivations: docs/pairwise.md. */
#include "pfsph/pairwise.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/dist.h"
#include "core/hits.h"
#include "core/nlist.h"
#include "pfsph/eigen.h"
#include "pfsph/film.h"
#include "physics/pair_terms.h"
#include "physics/solver.h"
#include "physics/stages.h"

static const double PI = 3.14159265358979323846;

struct pfsph_pairwise {
    int dim;
    double R;                 /* k h */
    pfsph_real *sx, *sy, *sz; /* shifting scratch */
    size_t cap;
    double shift_max; /* largest shift of the last step [m] */
    double amax;      /* largest pair-force acceleration of the last apply [m/s^2] */
};

void pfsph_pairwise_filter_matrix(int dim, const double C[3][3], double eta, double eps_min, double T[3][3])
{
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) T[a][b] = a == b ? 1.0 : 0.0;
    if (!(eta > 0)) return;
    double w[3] = {0, 0, 0}, v[3][3] = {{0}};
    double floor_ = eps_min > 1e-12 ? eps_min : 1e-12;
    if (dim == 3) {
        /* No eigenvalue clamped (w_min / w_max >= eps_min, the bulk): e_min / e_k = w_min / w_k,
         * so G / |G| = sum_k (w_min / w_k) v_k v_k^T = w_min C^-1 (Eqs. 8-11), and C^-1 from its
         * adjugate (C is then no worse conditioned than 1 / eps_min): no eigenvectors needed. */
        pfsph_eigen_sym3_values(C, w);
        if (w[0] > 0 && w[2] >= floor_ * w[0]) {
            const double A00 = C[1][1] * C[2][2] - C[1][2] * C[1][2], A01 = C[0][2] * C[1][2] - C[0][1] * C[2][2],
                         A02 = C[0][1] * C[1][2] - C[0][2] * C[1][1], A11 = C[0][0] * C[2][2] - C[0][2] * C[0][2],
                         A12 = C[0][1] * C[0][2] - C[0][0] * C[1][2], A22 = C[0][0] * C[1][1] - C[0][1] * C[0][1];
            const double det = C[0][0] * A00 + C[0][1] * A01 + C[0][2] * A02;
            if (det > 0) {
                const double f = eta * w[2] / det;
                const double adj[3][3] = {{A00, A01, A02}, {A01, A11, A12}, {A02, A12, A22}};
                for (int a = 0; a < 3; a++)
                    for (int b = 0; b < 3; b++) T[a][b] = (a == b ? 1.0 - eta : 0.0) + f * adj[a][b];
                return;
            }
        }
    }
    if (dim == 2) {
        const double c2[2][2] = {{C[0][0], C[0][1]}, {C[0][1], C[1][1]}};
        double w2[2], v2[2][2];
        pfsph_eigen_sym2(c2, w2, v2);
        w[0] = w2[0];
        w[1] = w2[1];
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2; b++) v[a][b] = v2[a][b];
    } else {
        /* closed form: T is wanted to float precision, and Jacobi to 1e-15 was 12 % of a
         * pair-force step (docs/benchmarks.md) */
        pfsph_eigen_sym3_fast(C, w, v);
    }
    if (!(w[0] > 0)) return; /* no neighbours: nothing to be anisotropic about */
    /* Eqs. 8-9: eigenvalues normalised by the largest (NOTES item 4), clamped below. */
    double e[3];
    for (int k = 0; k < dim; k++) {
        double t = w[k] / w[0];
        e[k] = t > floor_ ? t : floor_;
    }
    /* Eqs. 10-11: G = R diag(1/e) R^T; its spectral norm is 1/e_min, so G/|G| has eigenvalues
     * e_min/e_k in (0, 1] and is the identity for an isotropic C (NOTES item 3). */
    double emin = e[dim - 1];
    for (int k = 0; k < dim; k++)
        if (e[k] < emin) emin = e[k];
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) {
            double g = 0;
            for (int k = 0; k < dim; k++) g += v[a][k] * v[b][k] * (emin / e[k]);
            T[a][b] = (a == b ? 1.0 - eta : 0.0) + eta * g;
        }
}

int pfsph_pairwise_create(pfsph_pairwise **out, const pfsph_ctx *ctx, pfsph_error *err)
{
    *out = NULL;
    const pfsph_pairwise_params *pp = ctx->pairwise;
    double R = pp->k * (double)ctx->h;
    if (ctx->grid && (double)ctx->grid->cell * ctx->grid->reach_far < R * (1.0 - 1e-6))
        return pfsph_fail(err, PFSPH_EINPUT,
                          "pairwise: grid cell %g m is smaller than the pair force radius k*h = "
                          "%g m (size cells with pfsph_pairwise_radius)",
                          (double)ctx->grid->cell * ctx->grid->reach_far, R);
    pfsph_pairwise *pw = calloc(1, sizeof(*pw));
    if (!pw) return pfsph_fail(err, PFSPH_ENOMEM, "pairwise: out of memory");
    pw->dim = ctx->dim;
    pw->R = R;
    *out = pw;
    return PFSPH_OK;
}

void pfsph_pairwise_destroy(pfsph_pairwise *pw)
{
    if (!pw) return;
    free(pw->sx);
    free(pw->sy);
    free(pw->sz);
    free(pw);
}

void pfsph_pairwise_shift(pfsph_pairwise *pw, const pfsph_ctx *ctx)
{
    const pfsph_pairwise_params *pp = ctx->pairwise;
    if (!pw || !pp->enabled || !(pp->shift.D > 0 || pp->shift.A > 0) || !(ctx->dt > 0)) return;
    const size_t n = ctx->fluid->n;
    if (n > pw->cap) {
        pfsph_real *a = realloc(pw->sx, n * sizeof(pfsph_real));
        if (a) pw->sx = a;
        pfsph_real *b = realloc(pw->sy, n * sizeof(pfsph_real));
        if (b) pw->sy = b;
        pfsph_real *c = realloc(pw->sz, n * sizeof(pfsph_real));
        if (c) pw->sz = c;
        if (!a || !b || !c) return; /* out of memory: skip shifting this step */
        pw->cap = n;
    }
    pfsph_shift_params sp = pp->shift;
    /* neighbour searches within h stay exact if nothing moves more than cell - h */
    double room = ((double)ctx->grid->cell * ctx->grid->reach - (double)ctx->h) / (double)ctx->spacing;
    if (sp.max_frac > room) sp.max_frac = room > 0 ? room : 0;
    pw->shift_max = pfsph_shift_apply(ctx, &sp, ctx->dt, pw->R, pw->sx, pw->sy, pw->sz);
}

/* Constants of one apply call, shared by all particles. */
typedef struct pw_job {
    const pfsph_ctx *ctx;
    double coef[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES]; /* c[a][b] m_b: acceleration per unit f */
    bool two_phase;                                  /* bubbles in air: film fractions enter through Eq. 24 */
    const double (*c)[PFSPH_MAX_PHASES];             /* the raw matrix, for Eq. 24 */
    const int *film;                                 /* film phase of each gas phase */
    double mass[PFSPH_MAX_PHASES];
    pfsph_real R, R2;
    double U_R;        /* 3 pi / (2 R) */
    pfsph_kernel kk;   /* cubic spline with support k h, for Eq. 7 (NOTES item 2) */
    pfsph_real inv_v0; /* 1 / V0: the walls' density term, as density.c scales it */
    bool filter;
    double eta, eps_min;
    int center;
    bool trim; /* walk only the cells the k h ball touches (positions as sorted) */
    pfsph_hits_fn hits;
    /* the interactive list walk's pair pass in the particles' precision (pfsph__sums_pair_r) */
    pfsph_real coef_r[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES], U_Rr;
} pw_job;

static void job_init(pw_job *J, const pfsph_ctx *ctx, bool sorted)
{
    const pfsph_pairwise_params *pp = ctx->pairwise;
    J->ctx = ctx;
    for (int a = 0; a < PFSPH_MAX_PHASES; a++)
        for (int b = 0; b < PFSPH_MAX_PHASES; b++) J->coef[a][b] = pp->c[a][b] * (double)ctx->mass[b];
    for (int b = 0; b < PFSPH_MAX_PHASES; b++) J->mass[b] = (double)ctx->mass[b];
    J->two_phase = ctx->film && ctx->film->nbubbles > 0;
    J->c = (const double(*)[PFSPH_MAX_PHASES])pp->c;
    J->film = ctx->film ? ctx->film->film : NULL;
    double R = pp->k * (double)ctx->h;
    J->R = (pfsph_real)R;
    J->R2 = (pfsph_real)(R * R);
    J->U_R = 1.5 * PI / R;
    J->U_Rr = (pfsph_real)J->U_R;
    for (int a = 0; a < PFSPH_MAX_PHASES; a++)
        for (int b = 0; b < PFSPH_MAX_PHASES; b++) J->coef_r[a][b] = (pfsph_real)J->coef[a][b];
    pfsph_kernel_init(&J->kk, ctx->dim, (pfsph_real)R);
    J->inv_v0 = (pfsph_real)1 / ctx->V0;
    J->filter = pp->filter && pp->eta > 0;
    J->eta = pp->eta;
    J->eps_min = pp->eps_min;
    J->center = pp->center;
    /* shifting moves the fluid after the sort: then the whole reach, whose slack covers it */
    J->trim = sorted && !(pp->shift.D > 0 || pp->shift.A > 0);
    J->hits = pfsph_hits_select();
}

/* Where a walk also lists its pairs within h (the interactive PCISPH's lists, pcisph_lists.h):
 * idx and dw entries from pos while they fit before re; pos counts on past re. */
typedef struct pw_sink {
    uint32_t *idx;
    pfsph_real *dw;
    size_t pos, re;
} pw_sink;

/* One thread's buffers: the hits of a walk, their cos(U_R r) / r and their pair scalars. */
typedef struct pw_scratch {
    pfsph_hits H;
    double cr[PFSPH_HITS_CAP + PFSPH_HITS_PAD], sc[PFSPH_HITS_CAP + PFSPH_HITS_PAD];
    int sp[PFSPH_HITS_CAP + PFSPH_HITS_PAD]; /* hits that take Eq. 24 (sum_hits) */
    pfsph_real cfr[PFSPH_HITS_CAP + PFSPH_HITS_PAD], scr[PFSPH_HITS_CAP + PFSPH_HITS_PAD]; /* rp */
} pw_scratch;

/* Adds the pairs in W->H (targets in ps) to P's four-lane sums (pair_terms.h): sc = c m_j f(r) / r
 * (Eq. 3 divided by m_i, times x_ij) and, if J->filter, the kernel w of Eq. 7 (NOTES item 2).
 * rp (a constant at each call, so that the compiler makes two versions): sc and the sums in the
 * particles' precision and eight lanes, into PR (the interactive list walk, docs/interactive.md,
 * "The fifth pass"). */
static inline void sum_hits(const pw_job *J, const pfsph_particles *ps, pw_scratch *W, int pa, double ai, int bi,
                            bool want_vir, pfsph_pair_sums *P, pfsph_real *ds, pw_sink *sk, const bool rp,
                            pfsph_pair_sums_r *PR)
{
    pfsph_hits *H = &W->H;
    const double *coef = J->coef[pa];
    const int n = H->n;
    /* the per-pair cosine and kernel in vector code (pair_terms.c), over whole vectors */
    const int n16 = pfsph_hits_pad16(H);
    if (!ds) {
        if (J->filter) pfsph__terms_w(&J->kk, n16, H->r2, H->t0);
    } else { /* Eq. 23's sum (density.c) from the hits within h: W_h is 0 beyond h, and adds nothing */
        /* Eq. 7's kernel, W_h and (lists) dW_h / r from one sqrt */
        pfsph__terms_w_dwr(&J->kk, &J->ctx->kern, n16, H->r2, J->filter ? H->t0 : NULL, H->t1, sk ? H->t2 : NULL);
        pfsph_real s = *ds;
        if (ps == J->ctx->fluid && rp) s += pfsph__lanes_sum(n, H->t1); /* eight lanes (the arrays are padded) */
        else if (ps == J->ctx->fluid)
            for (int e = 0; e < n; e++) s += H->t1[e];
        else
            for (int e = 0; e < n; e++) s += ps->aux[H->j[e]] * H->t1[e];
        *ds = s;
        if (sk) { /* the pairs within h, as density.c lists them (dW/r of each) */
            const pfsph_real h2 = J->ctx->kern.h * J->ctx->kern.h;
            size_t pos = sk->pos;
            if (pos + (size_t)n <= sk->re) {
                /* room for all: branch-free (each entry written, kept only within h), as about
                 * a third of the k h hits lie within h and the branch mispredicted */
                uint32_t *restrict idx = sk->idx + pos;
                pfsph_real *restrict dw = sk->dw + pos;
                size_t m = 0;
                for (int e = 0; e < n; e++) {
                    idx[m] = H->j[e];
                    dw[m] = H->t2[e];
                    m += H->r2[e] < h2;
                }
                pos += m;
            } else
                for (int e = 0; e < n; e++)
                    if (H->r2[e] < h2) {
                        if (pos < sk->re) {
                            sk->idx[pos] = H->j[e];
                            sk->dw[pos] = H->t2[e];
                        }
                        pos++;
                    }
            sk->pos = pos;
        }
    }
    if (!J->two_phase && rp)
        pfsph__terms_pair_sc_r(J->U_Rr, J->coef_r[pa], ps->phase, n16, H->j, H->r2, W->cfr, W->scr,
                               J->filter ? H->t0 : NULL);
    else if (!J->two_phase) {
        /* Eq. 3 with NOTES item 1: +c m_i m_j f(r) r_ij / r on i (repulsive f > 0); r = 0: no
         * direction, no force, and not in Eq. 7's sum. The cosine in float (pfsph__cos_pair,
         * error < 2e-7): the force is summed in double, its shape needs 1e-7. */
        pfsph__terms_pair_sc(J->U_R, coef, ps->phase, n16, H->j, H->r2, W->cr, W->sc, J->filter ? H->t0 : NULL);
    } else if (!(ai > 0)) {
        /* i has no film: coef[pb] for every hit but those with a film or in another bubble,
         * which take Eq. 24 (pfsph_film_pair_c) in a second loop; then the cosine and sc in
         * vector code. The same cf and sc per hit as the loop below. */
        double *cf = W->cr; /* the hits' coefficients (the loop below keeps cos / r there) */
        int *sp = W->sp, ns = 0;
        for (int e = 0; e < n16; e++) {
            const uint32_t j = H->j[e];
            const int bj = ps->bubble[j];
            cf[e] = coef[ps->phase[j]];
            sp[ns] = e;
            ns += e < n && (ps->film[j] > 0 || (bi && bj && bi != bj));
        }
        for (int q = 0; q < ns; q++) {
            const int e = sp[q];
            const uint32_t j = H->j[e];
            const int pb = ps->phase[j];
            const int bj = ps->bubble[j];
            const bool apart = bi && bj && bi != bj;
            cf[e] = pfsph_film_pair_c(J->c, J->film, pa, ai, pb, (double)ps->film[j], apart) * J->mass[pb];
        }
        pfsph__terms_pair_sc_cf(J->U_R, n16, cf, H->r2, W->sc, J->filter ? H->t0 : NULL);
    } else {
        pfsph__terms_pair_cos(J->U_R, n, H->r2, W->cr);
        for (int e = 0; e < n; e++) {
            const uint32_t j = H->j[e];
            /* Eq. 24 where a film particle takes part */
            const int pb = ps->phase[j];
            const double aj = (double)ps->film[j];
            const int bj = ps->bubble[j];
            const bool apart = bi && bj && bi != bj;
            const double cf = ai > 0 || aj > 0 || apart
                ? pfsph_film_pair_c(J->c, J->film, pa, ai, pb, aj, apart) * J->mass[pb]
                : coef[pb];
            /* as pfsph__terms_pair_sc */
            const bool live = H->r2[e] > 0;
            W->sc[e] = live && cf != 0.0 ? cf * W->cr[e] : 0.0;
            if (!live) H->t0[e] = 0;
        }
    }
    if (rp) {
        if (J->two_phase) /* Eq. 24's coefficients in double, as above */
            for (int e = 0; e < n; e++) W->scr[e] = (pfsph_real)W->sc[e];
        const int m = (n + 7) & ~7; /* padding entries add zeros */
        for (int e = n; e < m; e++) W->scr[e] = H->t0[e] = H->dx[e] = H->dy[e] = H->dz[e] = 0;
        pfsph__sums_pair_r(m, H->dx, H->dy, H->dz, W->scr, H->t0, J->filter, PR);
        return;
    }
    const int m = (n + 3) & ~3; /* padding entries add zeros */
    for (int e = n; e < m; e++) {
        W->sc[e] = 0;
        H->t0[e] = H->dx[e] = H->dy[e] = H->dz[e] = 0;
    }
    pfsph__sums_pair(m, H->dx, H->dy, H->dz, W->sc, H->t0, J->filter, want_vir, P);
}

/* lanes 0 + 1 + 2 + 3 in a fixed order */
static inline double lanes(const double l[4]) { return (l[0] + l[1]) + (l[2] + l[3]); }

/* Sums over one particle set for fluid particle i at (xi, yi, zi) of phase pa: the pairs within
 * k h of a grid walk, filtered in SIMD (core/hits.h), in the walk's order. */
static inline void sum_set(const pw_job *J, const pfsph_particles *ps, const pfsph_grid *g, size_t self, pfsph_real xi,
                           pfsph_real yi, pfsph_real zi, int pa, double ai, int bi, bool want_vir, pfsph_pair_sums *P,
                           pw_scratch *W, pfsph_real *ds, pw_sink *sk, const bool rp, pfsph_pair_sums_r *PR)
{
    pfsph_ranges rg;
    if (J->trim) pfsph_grid_ranges_radius(g, xi, yi, zi, J->R, &rg);
    else pfsph_grid_ranges_far(g, xi, yi, zi, &rg);
    PFSPH_HITS_WALK(J->hits, &W->H, rg, ps->x, ps->y, ps->z, xi, yi, zi, J->R2, (uint32_t)self,
                    sum_hits(J, ps, W, pa, ai, bi, want_vir, P, ds, sk, rp, PR));
}

/* Everything for fluid particle i: the acceleration (T_i applied), optionally the virial,
 * T_i itself and (nd not NULL) the number density delta_i of Eq. 23 into nd[i]. rp (a
 * constant): the pair sums in the particles' precision (sum_hits; no virial). */
static inline void particle(const pw_job *J, size_t i, double acc[3], bool want_vir, double *vir, double Tout[9],
                            double Wout[9], pw_scratch *W, pfsph_real *nd, pw_sink *sk, pw_sink *skb, const bool rp)
{
    const pfsph_ctx *ctx = J->ctx;
    const pfsph_particles *f = ctx->fluid;
    pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
    int pa = f->phase[i];
    pfsph_pair_sums P;
    pfsph_pair_sums_r PR;
    if (rp) memset(&PR, 0, sizeof PR);
    else memset(&P, 0, sizeof P);
    const double ai = J->two_phase ? (double)f->film[i] : 0.0;
    const int bi = J->two_phase ? f->bubble[i] : 0;
    /* the density as density.c sums it, self term first, walls apart and scaled by 1 / V0 */
    pfsph_real s = nd ? pfsph_kernel_w0(&ctx->kern) : 0, sb = 0;
    sum_set(J, f, ctx->grid, i, xi, yi, zi, pa, ai, bi, want_vir, &P, W, nd ? &s : NULL, sk, rp, &PR);
    /* most of a liquid has no wall within k h: its empty walk (rows, flush) cost ~5 % of the pass;
     * the flags cover k h >= h, so the density's wall term is 0 where they skip */
    if (ctx->boundary && ctx->bgrid && ctx->boundary->n > 0 && pfsph_grid_near_far(ctx->bgrid, xi, yi, zi))
        sum_set(J, ctx->boundary, ctx->bgrid, (size_t)UINT32_MAX, xi, yi, zi, pa, ai, bi, want_vir, &P, W,
                nd ? &sb : NULL, skb, rp, &PR);
    if (nd) nd[i] = s + sb * J->inv_v0;
    /* the lanes' totals; the filter's d = x_j - x_i = -x_ij */
    double S[6] = {0, 0, 0, 0, 0, 0}, sx[3], sxx[6], sw;
    if (rp) {
        for (int a = 0; a < 3; a++) {
            acc[a] = (double)pfsph__lanes8(PR.acc[a]);
            sx[a] = -(double)pfsph__lanes8(PR.sx[a]);
        }
        for (int a = 0; a < 6; a++) sxx[a] = (double)pfsph__lanes8(PR.sxx[a]);
        sw = (double)pfsph_kernel_w0(&J->kk) + (double)pfsph__lanes8(PR.sw);
    } else {
        for (int a = 0; a < 3; a++) {
            acc[a] = lanes(P.acc[a]);
            sx[a] = -lanes(P.sx[a]);
        }
        for (int a = 0; a < 6; a++) {
            S[a] = lanes(P.S[a]);
            sxx[a] = lanes(P.sxx[a]);
        }
        /* the sum of Eq. 7 includes j = i */
        sw = (double)pfsph_kernel_w0(&J->kk) + lanes(P.sw);
    }
    double T[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    if (J->filter) {
        double inv = 1.0 / sw;
        double C[3][3] = {{sxx[0] * inv, sxx[1] * inv, sxx[2] * inv},
                          {sxx[1] * inv, sxx[3] * inv, sxx[4] * inv},
                          {sxx[2] * inv, sxx[4] * inv, sxx[5] * inv}};
        if (J->center == PFSPH_PW_CENTER_MEAN) {
            double mu[3] = {sx[0] * inv, sx[1] * inv, sx[2] * inv};
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) C[a][b] -= mu[a] * mu[b];
        }
        pfsph_pairwise_filter_matrix(ctx->dim, C, J->eta, J->eps_min, T);
        double a0 = T[0][0] * acc[0] + T[0][1] * acc[1] + T[0][2] * acc[2];
        double a1 = T[1][0] * acc[0] + T[1][1] * acc[1] + T[1][2] * acc[2];
        double a2 = T[2][0] * acc[0] + T[2][1] * acc[1] + T[2][2] * acc[2];
        acc[0] = a0; /* Eq. 12 */
        acc[1] = a1;
        acc[2] = a2;
    }
    if (want_vir) {
        /* sum_j r_ij . (T f_ji) = m_i tr(T S), S = sum_j s_j r_ij r_ij^T (symmetric). */
        const double Sm[3][3] = {{S[0], S[1], S[2]}, {S[1], S[3], S[4]}, {S[2], S[4], S[5]}};
        double tr = 0;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) tr += T[a][b] * Sm[b][a];
        *vir = (double)ctx->mass[pa] * tr;
        if (Wout) /* sum_j (T f_ji) (x) r_ij = m_i T S */
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) {
                    double t = 0;
                    for (int q = 0; q < 3; q++) t += T[a][q] * Sm[q][b];
                    Wout[3 * a + b] = (double)ctx->mass[pa] * t;
                }
    }
    if (Tout)
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) Tout[3 * a + b] = T[a][b];
}

/* The pair accelerations added to (add) or written to out[0..2], and nd if not NULL. */
static void apply(pfsph_pairwise *pw, const pfsph_ctx *ctx, pfsph_real *nd, pfsph_real *const out[3], bool add)
{
    pw->amax = 0;
    pw_job J;
    job_init(&J, ctx, true);
    if (!ctx->pairwise->enabled) /* the density alone: forces of zero, walked as the pairs are */
        for (int a = 0; a < PFSPH_MAX_PHASES; a++)
            for (int b = 0; b < PFSPH_MAX_PHASES; b++) J.coef[a][b] = 0;
    const size_t n = ctx->fluid->n;
    pfsph_real *ax = out[0], *ay = out[1], *az = out[2];
    double a2max = 0; /* a max is the same for any thread count and order */
#pragma omp parallel
    {
        pw_scratch W;
#pragma omp for schedule(dynamic, 256) reduction(max : a2max)
        for (size_t i = 0; i < n; i++) {
            double acc[3];
            particle(&J, i, acc, false, NULL, NULL, NULL, &W, nd, NULL, NULL, false);
            if (add) {
                ax[i] += (pfsph_real)acc[0];
                ay[i] += (pfsph_real)acc[1];
                az[i] += (pfsph_real)acc[2];
            } else {
                ax[i] = (pfsph_real)acc[0];
                ay[i] = (pfsph_real)acc[1];
                az[i] = (pfsph_real)acc[2];
            }
            const double a2 = acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2];
            if (a2 > a2max) a2max = a2;
        }
    }
    pw->amax = sqrt(a2max);
}

void pfsph_pairwise_apply(pfsph_pairwise *pw, const pfsph_ctx *ctx)
{
    pw->amax = 0;
    if (!ctx->pairwise->enabled) return;
    pfsph_real *const a[3] = {ctx->ax, ctx->ay, ctx->az};
    apply(pw, ctx, NULL, a, true);
}

void pfsph_pairwise_apply_density(pfsph_pairwise *pw, const pfsph_ctx *ctx, pfsph_real *nd, pfsph_real *const acc[3])
{
    apply(pw, ctx, nd, acc, false);
}

/* One thread's particles [i0, i1) of pfsph_pairwise_apply_density_lists. */
static double apply_lists_block(const pw_job *J, pw_scratch *W, size_t i0, size_t i1, pfsph_real *nd,
                                pfsph_real *const out[3], pfsph_nlist *l, pfsph_nlist *lb, pw_sink *sk, pw_sink *skb)
{
    uint32_t *cnt = l->start + 1, *bcnt = lb->start + 1;
    double a2max = 0;
    for (size_t i = i0; i < i1; i++) {
        double acc[3];
        const size_t p0 = sk->pos, b0 = skb->pos;
        /* the interactive mode's list walk (sim.c schedules it for the interactive PCISPH only):
         * the pair sums in the particles' precision, eight lanes */
        particle(J, i, acc, false, NULL, NULL, NULL, W, nd, sk, skb, true);
        cnt[i] = (uint32_t)(sk->pos - p0);
        bcnt[i] = (uint32_t)(skb->pos - b0);
        out[0][i] = (pfsph_real)acc[0];
        out[1][i] = (pfsph_real)acc[1];
        out[2][i] = (pfsph_real)acc[2];
        const double a2 = acc[0] * acc[0] + acc[1] * acc[1] + acc[2] * acc[2];
        if (a2 > a2max) a2max = a2;
    }
    return a2max;
}

int pfsph_pairwise_apply_density_lists(pfsph_pairwise *pw, const pfsph_ctx *ctx, pfsph_real *nd,
                                       pfsph_real *const acc[3], pfsph_nlist *l, pfsph_nlist *lb, double guess)
{
    pw->amax = 0;
    pw_job J;
    job_init(&J, ctx, true);
    if (!ctx->pairwise->enabled)
        for (int a = 0; a < PFSPH_MAX_PHASES; a++)
            for (int b = 0; b < PFSPH_MAX_PHASES; b++) J.coef[a][b] = 0;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = ctx->kern.h * ctx->kern.h;
    const size_t n = f->n;
    int T = omp_get_max_threads();
    if (T > PFSPH_NLIST_MAX_THREADS) T = PFSPH_NLIST_MAX_THREADS;
    int rc = pfsph_nlist_plan(l, n, T, guess), rcb = pfsph_nlist_plan(lb, n, T, guess / 4);
    if (rc == PFSPH_ENOMEM || rcb == PFSPH_ENOMEM) return PFSPH_ENOMEM;
    int over = rc != PFSPH_OK, bover = rcb != PFSPH_OK;
    double a2max = 0;
    /* contiguous blocks in order, one per thread, as the lists' plan has them (density.c) */
#pragma omp parallel num_threads(T) reduction(| : over, bover) reduction(max : a2max)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const size_t i0 = n * (size_t)t / (size_t)nt, i1 = n * (size_t)(t + 1) / (size_t)nt;
        const size_t rb = l->rbeg[t], re = nt == T ? l->rbeg[t + 1] : rb;
        const size_t brb = lb->rbeg[t], bre = nt == T ? lb->rbeg[t + 1] : brb;
        pw_sink sk = {l->idx, l->dw, rb, re}, skb = {lb->idx, lb->dw, brb, bre};
        pw_scratch W;
        a2max = apply_lists_block(&J, &W, i0, i1, nd, acc, l, lb, &sk, &skb);
        if (nt != T || sk.pos > re) over = 1;
        else l->used[t] = sk.pos - rb;
        if (nt != T || skb.pos > bre) bover = 1;
        else lb->used[t] = skb.pos - brb;
    }
    pw->amax = sqrt(a2max);
    const pfsph_nlist_sets S = {ctx->grid, f->x, f->y, f->z, f->x, f->y, f->z, n, 1, h2, &ctx->kern};
    const pfsph_nlist_sets SB = {ctx->bgrid, b->x, b->y, b->z, f->x, f->y, f->z, n, 0, h2, &ctx->kern};
    rc = pfsph_nlist_finish(l, over, &S);
    return rc ? rc : pfsph_nlist_finish(lb, bover, &SB);
}

double pfsph_pairwise_amax(const pfsph_pairwise *pw) { return pw ? pw->amax : 0; }

void pfsph_pairwise_diagnose(pfsph_pairwise *pw, const pfsph_ctx *ctx, double *vir, double *T)
{
    pfsph_pairwise_diagnose_tensor(pw, ctx, vir, T, NULL);
}

/* pfsph_pairwise_diagnose_tensor for the particles [lo, hi) */
static void diagnose_range(const pfsph_ctx *ctx, size_t lo, size_t hi, double *vir, double *T, double *W)
{
    pw_job J;
    /* called between steps too, on positions moved since the sort: the whole reach */
    job_init(&J, ctx, false);
    if (!ctx->pairwise->enabled)
        for (int a = 0; a < PFSPH_MAX_PHASES; a++)
            for (int b = 0; b < PFSPH_MAX_PHASES; b++) J.coef[a][b] = 0;
#pragma omp parallel
    {
        pw_scratch Ws;
#pragma omp for schedule(dynamic, 256)
        for (size_t i = lo; i < hi; i++) {
            double acc[3], v = 0;
            particle(&J, i, acc, true, &v, T ? T + 9 * i : NULL, W ? W + 9 * i : NULL, &Ws, NULL, NULL, NULL, false);
            if (vir) vir[i] = v;
        }
    }
}

void pfsph_pairwise_diagnose_tensor(pfsph_pairwise *pw, const pfsph_ctx *ctx, double *vir, double *T, double *W)
{
    (void)pw;
    diagnose_range(ctx, 0, ctx->fluid->n, vir, T, W);
}

void pfsph_pairwise_mechanical_pressure(pfsph_pairwise *pw, const pfsph_ctx *ctx, const pfsph_real *p, double *vir,
                                        pfsph_real *out)
{
    const pfsph_particles *f = ctx->fluid;
    if (!p) p = f->p;
    (void)pw;
    /* a distributed run: the owned particles (out and vir hold nothing for the halo) */
    size_t lo, hi;
    pfsph__owned(ctx, &lo, &hi);
    const int dim = ctx->dim;
    diagnose_range(ctx, lo, hi, vir, NULL, NULL);
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
#pragma omp parallel for schedule(static)
    for (size_t i = lo; i < hi; i++) {
        /* peculiar velocity against the kernel-weighted mean of the neighbours (self excluded);
         * for uncorrelated thermal velocities E|u|^2 = <v'^2> (1 + sum w^2 / (sum w)^2) */
        double sw = 0, sw2 = 0, m[3] = {0, 0, 0}, pv = 0;
        const double pi = (double)p[i] / ((double)ctx->nd[i] * (double)ctx->nd[i]);
        pfsph_ranges r;
        pfsph_grid_ranges(ctx->grid, f->x[i], f->y[i], f->z[i], &r);
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                if (j == i) continue;
                pfsph_real dx = f->x[i] - f->x[j], dy = f->y[i] - f->y[j], dz = f->z[i] - f->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2) continue;
                pfsph_real rr = pfsph_sqrt(r2);
                double w = (double)pfsph_kernel_w(k, rr);
                /* r_ij . F_ij of the pressure force (pressure.c) */
                pv -= (pi + (double)p[j] / ((double)ctx->nd[j] * (double)ctx->nd[j])) * (double)r2 *
                    (double)pfsph_kernel_dw_r(k, rr);
                sw += w;
                sw2 += w * w;
                m[0] += w * f->vx[j];
                m[1] += w * f->vy[j];
                m[2] += w * f->vz[j];
            }
        double kin = 0;
        if (sw > 0) {
            double ux = f->vx[i] - m[0] / sw, uy = f->vy[i] - m[1] / sw, uz = f->vz[i] - m[2] / sw;
            kin = (double)ctx->mass[f->phase[i]] * (ux * ux + uy * uy + (dim == 3 ? uz * uz : 0)) /
                (1.0 + sw2 / (sw * sw));
        }
        const pfsph_particles *b = ctx->boundary;
        if (b && b->n && pi > 0) { /* the Akinci wall term of the pressure force */
            pfsph_grid_ranges(ctx->bgrid, f->x[i], f->y[i], f->z[i], &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = f->x[i] - b->x[j], dy = f->y[i] - b->y[j], dz = f->z[i] - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2) continue;
                    pv -= (double)b->aux[j] / (double)ctx->V0 * pi * (double)r2 *
                        (double)pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                }
        }
        /* virial pressure of particle i's volume 1 / n_i: (m u^2 + 1/2 sum_j r_ij . F_ij) / (dim V_i),
         * F_ij the pressure and pair forces. The pressure force's virial, not p_i itself: they
         * agree on a lattice (sum_j V_j x_ij (x) grad W_ij = -I), not in a disordered liquid. */
        out[i] = (pfsph_real)((double)ctx->nd[i] / dim * (kin + 0.5 * (vir[i] + pv)));
    }
}

/* ---- the stages this module owns ---- */

/* particle shifting, if the scene asks (docs/pairwise.md); uses last step's ctx->dt */
static int shift_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    pfsph_pairwise_shift(st->pw, st->ctx);
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_shift = {.name = "shift",
                                           .slot = PFSPH_STAGE_PAIRWISE,
                                           .reads = PFSPH_D_POS | PFSPH_D_ORDER,
                                           .writes = PFSPH_D_POS,
                                           .run = shift_run};

/* With pair forces and a solver without neighbour lists or pre_forces (WCSPH, PCISPH): the
 * density in the pair forces' walk, whose k h neighbourhood holds the h one (one walk instead of
 * two: the density pass was ~7 % of a pair-force step). The pair accelerations go to pair_a for
 * the pairwise stage (explicitly handed over: PFSPH_D_PAIR_ACC). */
static int pair_density_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)err;
    pfsph_ctx *c = st->ctx;
    c->nlist = c->nlist_b = NULL;
    pfsph_pairwise_apply_density(st->pw, c, c->nd, st->pair_a);
    return pfsph__density_check(st, bad);
}

const pfsph_stage_ops pfsph_stage_pair_density = {.name = "density",
                                                  .slot = PFSPH_STAGE_PAIRWISE,
                                                  .reads = PFSPH_D_POS | PFSPH_D_ORDER | PFSPH_D_VEL | PFSPH_D_FILM,
                                                  .writes = PFSPH_D_DENSITY | PFSPH_D_PAIR_ACC,
                                                  .run = pair_density_run};

static int pairwise_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    pfsph_pairwise_apply(st->pw, st->ctx);
    return PFSPH_OK;
}

/* The same with neighbour lists (the interactive PCISPH, st->lists): the pairs within h of the
 * pair walk listed as the density stage lists them (pcisph_lists.h), one k h walk instead of an
 * h walk and a k h walk (docs/interactive.md, "Profile"). */
static int pair_density_lists_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    pfsph_ctx *c = st->ctx;
    c->nlist = c->nlist_b = NULL;
    const double q = (double)c->h / (double)c->spacing; /* as density.c guesses */
    const double guess = 1.25 * (c->dim == 2 ? 3.14159 * q * q : 4.18879 * q * q * q);
    int rc = pfsph_pairwise_apply_density_lists(st->pw, c, c->nd, st->pair_a, st->nlist, st->nlist_b, guess);
    if (rc)
        return pfsph_fail(err, rc, "cannot build the neighbour lists (%s)",
                          rc == PFSPH_ENOMEM ? "out of memory" : "internal error");
    c->nlist = st->nlist;
    c->nlist_b = st->nlist_b;
    return pfsph__density_check(st, bad);
}

const pfsph_stage_ops pfsph_stage_pair_density_lists = {.name = "density",
                                                        .slot = PFSPH_STAGE_PAIRWISE,
                                                        .reads =
                                                            PFSPH_D_POS | PFSPH_D_ORDER | PFSPH_D_VEL | PFSPH_D_FILM,
                                                        .writes = PFSPH_D_DENSITY | PFSPH_D_PAIR_ACC | PFSPH_D_NLIST,
                                                        .run = pair_density_lists_run};

const pfsph_stage_ops pfsph_stage_pairwise = {.name = "pairwise",
                                              .slot = PFSPH_STAGE_PAIRWISE,
                                              .reads = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_DENSITY | PFSPH_D_FILM,
                                              .writes = PFSPH_D_ACC,
                                              .run = pairwise_run};

/* the pair accelerations pair_density computed, added as pfsph_pairwise_apply adds them */
static int pairwise_add_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    pfsph_ctx *c = st->ctx;
    const pfsph_real *px = st->pair_a[0], *py = st->pair_a[1], *pz = st->pair_a[2];
    const size_t n = c->fluid->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        c->ax[i] += px[i];
        c->ay[i] += py[i];
        c->az[i] += pz[i];
    }
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_pairwise_add = {.name = "pairwise",
                                                  .slot = PFSPH_STAGE_PAIRWISE,
                                                  .reads = PFSPH_D_PAIR_ACC,
                                                  .writes = PFSPH_D_ACC,
                                                  .run = pairwise_add_run};

/* Output: the mechanical pressure, with the pressure the solver pushed with: DFSPH's divergence
 * solve pushes too (its wall_pressure); with its density pressure alone the interior of a 3D drop
 * read -15 Pa for +133 Pa. */
int pfsph__mechanical_pressure(const pfsph_step *st, pfsph_real *out)
{
    const pfsph_ctx *c = st->ctx;
    double *vir = malloc((c->fluid->n ? c->fluid->n : 1) * sizeof(double));
    if (!vir) return PFSPH_ENOMEM;
    const pfsph_real *p = st->solver->wall_pressure && c->fluid->n
        ? st->solver->wall_pressure(st->solver_state, c, st->solver_scratch)
        : NULL;
    /* a distributed run whose ranks each compute their slice: the step integrated the owned
     * particles only, and the walks read the neighbours' velocities, number densities, pressures
     * and film fractions: the halo copies get the owners' values, the serial ones (the positions
     * were refreshed before the frame's stages: src/mpi/frame_io.c) */
    if (c->dist && !c->dist->fluid_whole) {
        pfsph_particles *f = c->fluid;
        pfsph_real *const a[6] = {f->vx, f->vy, f->vz, c->nd, (pfsph_real *)(p ? p : f->p), f->film};
        c->dist->halo(c->dist, a, 6);
    }
    pfsph_pairwise_mechanical_pressure(st->pw, c, p, vir, out);
    free(vir);
    return PFSPH_OK;
}

static int mechanical_pressure_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    if (pfsph__mechanical_pressure(st, st->out_mech_p))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory for the mechanical pressure");
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_mechanical_pressure = {.name = "mechanical_pressure",
                                                         .slot = PFSPH_STAGE_OUTPUT,
                                                         .reads = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_DENSITY |
                                                             PFSPH_D_PRESSURE | PFSPH_D_SOLVER,
                                                         .writes = PFSPH_D_OUTPUT,
                                                         .run = mechanical_pressure_run};
