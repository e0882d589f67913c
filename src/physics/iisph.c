/* Implicit incompressible SPH (Ihmsen, Cornelis, Solenthaler, Horvath, Teschner 2014, IEEE TVCG
 * 20(3)) in the number-density form of PF Eq. 23: relaxed Jacobi on the pressure Poisson
 * equation of the advection-predicted density, with Akinci boundary particles. Derivation and
 * measurements: docs/solvers.md, "IISPH". The passes walk the step's neighbour lists or, without
 * them, the grid (physics/neighbours.h: the same bits). */
#include <math.h>
#include <stdlib.h>

#include "core/dist.h"
#include "core/reduce.h"
#include "physics/neighbours.h"
#include "physics/solver.h"

/* Relaxed Jacobi, omega = 0.5 as the paper recommends (Sec. 3.3): a_ii counts only particle i's
 * own pressure, while in a Jacobi sweep its neighbours push at the same time. */
#define OMEGA 0.5
/* a_np dt^2 <= EPS_STEP d: the compression one step of non-pressure forces causes, which the
 * solve must undo within the step. DFSPH's value (its density solve is this operator);
 * measured for IISPH in docs/solvers.md, "IISPH". */
#define EPS_STEP 0.004

/* Scratch: AII the diagonal, DADV the advection-predicted number density, B* the wall sums
 * B_i = sum_b V_b grad W_ib (fixed within the step: walls and bodies move after the
 * integration), ERR each particle's compression, PN the next Jacobi iterate; XQ and W4 hold 4 values per particle
 * (nscratch4): XQ = (x, y, z, p / delta^2), W4 = v_adv during the prediction, then the pressure
 * acceleration (one 16-byte load per neighbour). */
enum { AII, DADV, BX, BY, BZ, ERR, PN, XQ, W4, NSCR };
#define NSCR4 2

typedef pfsph_real v4r __attribute__((vector_size(4 * sizeof(pfsph_real))));
/* a load of 4 values at any alignment of pfsph_real (as in dfsph.c) */
typedef pfsph_real v4r_u __attribute__((vector_size(4 * sizeof(pfsph_real)), aligned(sizeof(pfsph_real)), may_alias));
#define ld4(p) (*(const v4r_u *)(p))

/* its scene keys under $.solver, in the order of the scene's solver_settings (PCISPH's defaults) */
enum { K_TOL, K_MIN, K_MAX, K_LISTS, NKEYS };
static const pfsph_solver_key keys[NKEYS] = {
    {"tolerance", 0.005, 1e-5, 0.1, 0, "mean relative density error the Jacobi iteration stops at"},
    {"min_iterations", 3, 1, 1000, 1, "Jacobi iterations per step at least"},
    {"max_iterations", 50, 1, 10000, 1, "Jacobi iterations per step at most"},
    {"neighbour_lists", 0, -1, 1, PFSPH_KEY_AUTO_BOOL,
     "true: neighbour lists (~300 B per particle in 3D), false: grid walks (the same bits), "
     "\"auto\": lists while they fit a quarter of the memory"},
};

static int check(const double *v, const char **key, char *msg, size_t len)
{
    return pfsph__check_iterations(v[K_MIN], v[K_MAX], key, msg, len);
}

typedef struct iisph {
    double tol, cfl, c;
    int min_iter, max_iter;
} iisph;

static int create(void **state, const pfsph_ctx *ctx, const pfsph_solver_config *cfg, pfsph_error *err)
{
    (void)ctx;
    iisph *S = calloc(1, sizeof *S);
    if (!S) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    S->tol = cfg->settings[K_TOL];
    S->min_iter = (int)cfg->settings[K_MIN];
    S->max_iter = (int)cfg->settings[K_MAX];
    S->cfl = cfg->cfl;
    S->c = cfg->sound_speed;
    *state = S;
    return PFSPH_OK;
}

static void destroy(void *state) { free(state); }

/* Predict advection (the paper's Algorithm 2, first part). v_adv = v + dt a_np; then, in one
 * walk of the lists:
 * - delta_adv = delta_i + dt [sum_j (v_adv_i - v_adv_j) . grad W_ij
 *                            + (1/V0) sum_b V_b (v_adv_i - v_b) . grad W_ib];
 * - a_ii, the change of delta_i by p_i alone. The pressure acceleration (pressure.c) is
 *   a_i = -(1/m_i) [sum_j (p_i/delta_i^2 + p_j/delta_j^2) grad W_ij + (1/V0) sum_b V_b p_i/delta_i^2 grad W_ib]
 *   and the density change it causes over the step dt^2 [sum_j (a_i - a_j) . grad W_ij + (1/V0) a_i . B_i].
 *   p_i enters a_i with -(p_i / (m_i delta_i^2)) g_i, g_i = sum_j grad W_ij + (1/V0) B_i (the
 *   paper's d_ii, the boundary included), and each a_j with +(p_i / (m_j delta_i^2)) grad W_ij
 *   (the paper's d_ji); so a_ii = -(dt^2 / delta_i^2) (|g_i|^2 / m_i + sum_j |grad W_ij|^2 / m_j).
 *   The wall does not move back, so it adds no d_ji term (SPlisHSPlasH's Akinci branch adds one
 *   as if it did). Negative: pressure lowers the density. 0 for a particle without neighbours.
 * The wall sums B_i are kept for the iterations. Fills XQ's positions (they stay put). */
static void predict_advection(const pfsph_ctx *c, const pfsph_real *p, pfsph_real *const *scr)
{
    const pfsph_particles *f = c->fluid, *b = c->boundary;
    const pfsph_nlist *nl = c->nlist, *bl = c->nlist_b;
    const size_t n = f->n;
    const double dt = c->dt;
    const pfsph_real fdt = (pfsph_real)dt, inv_v0 = (pfsph_real)1 / c->V0;
    pfsph_real *xq = scr[XQ], *va = scr[W4], *aii = scr[AII], *dadv = scr[DADV];
    pfsph_real *bx_ = scr[BX], *by_ = scr[BY], *bz_ = scr[BZ];
    const pfsph_kernel *k = &c->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_hits_fn hits = pfsph_hits_select();
#pragma omp parallel
    {
        pfsph_hits H; /* grid walks (no lists) */
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            xq[4 * i] = f->x[i];
            xq[4 * i + 1] = f->y[i];
            xq[4 * i + 2] = f->z[i];
            xq[4 * i + 3] = p[i] / (c->nd[i] * c->nd[i]);
            va[4 * i] = f->vx[i] + fdt * c->ax[i];
            va[4 * i + 1] = f->vy[i] + fdt * c->ay[i];
            va[4 * i + 2] = f->vz[i] + fdt * c->az[i];
            va[4 * i + 3] = 0;
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const v4r Xi = ld4(xq + 4 * i), Vi = ld4(va + 4 * i);
            double gx = 0, gy = 0, gz = 0, s2 = 0;
            pfsph_real rate = 0;
            PFSPH_FOR_NEIGHBOURS(
                nl, c->grid, hits, &H, k, f->x, f->y, f->z, i, Xi[0], Xi[1], Xi[2], h2, (uint32_t)i, j, w, {
                    const size_t j4 = 4 * (size_t)j;
                    const v4r X = Xi - ld4(xq + j4), P = (Vi - ld4(va + j4)) * X;
                    rate += (P[0] + P[1] + P[2]) * w;
                    const double ax = (double)(w * X[0]), ay = (double)(w * X[1]), az = (double)(w * X[2]);
                    gx += ax;
                    gy += ay;
                    gz += az;
                    s2 += (ax * ax + ay * ay + az * az) / (double)c->mass[f->phase[j]];
                });
            pfsph_real bx = 0, by = 0, bz = 0, bc = 0;
            if (b->n)
                PFSPH_FOR_NEIGHBOURS(
                    bl, c->bgrid, hits, &H, k, b->x, b->y, b->z, i, Xi[0], Xi[1], Xi[2], h2, UINT32_MAX, j, dw, {
                        const pfsph_real dx = Xi[0] - b->x[j], dy = Xi[1] - b->y[j], dz = Xi[2] - b->z[j];
                        const pfsph_real s = b->aux[j] * dw;
                        bx += s * dx;
                        by += s * dy;
                        bz += s * dz;
                        bc += s * (b->vx[j] * dx + b->vy[j] * dy + b->vz[j] * dz);
                    });
            bx_[i] = bx;
            by_[i] = by;
            bz_[i] = bz;
            rate += (Vi[0] * bx + Vi[1] * by + Vi[2] * bz - bc) * inv_v0;
            dadv[i] = c->nd[i] + fdt * rate;
            gx += (double)(bx * inv_v0);
            gy += (double)(by * inv_v0);
            gz += (double)(bz * inv_v0);
            const double A = (gx * gx + gy * gy + gz * gz) / (double)c->mass[f->phase[i]] + s2;
            const double nd = c->nd[i];
            aii[i] = (pfsph_real)(A > 0 ? -dt * dt * A / (nd * nd) : 0);
        }
    }
}

/* The pressure acceleration of the pressures in XQ's lane 3 (p / delta^2), over the lists with
 * the Akinci wall term from the stored sums: into ap and W4's lanes 0-2. */
static void pressure_accel(const pfsph_ctx *c, pfsph_real *const *scr, pfsph_real *const ap[3])
{
    const pfsph_particles *f = c->fluid;
    const pfsph_nlist *nl = c->nlist;
    const size_t n = f->n;
    const pfsph_real inv_v0 = (pfsph_real)1 / c->V0;
    const pfsph_real *xq = scr[XQ], *bx = scr[BX], *by = scr[BY], *bz = scr[BZ];
    pfsph_real *a4 = scr[W4];
    const pfsph_kernel *k = &c->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_hits_fn hits = pfsph_hits_select();
    pfsph_hits H; /* grid walks (no lists); this thread's: called inside the parallel region */
#pragma omp for schedule(static)
    for (size_t i = 0; i < n; i++) {
        const v4r Xi = ld4(xq + 4 * i);
        const pfsph_real pi = Xi[3];
        v4r A = {0, 0, 0, 0};
        PFSPH_FOR_NEIGHBOURS(nl, c->grid, hits, &H, k, f->x, f->y, f->z, i, Xi[0], Xi[1], Xi[2], h2, (uint32_t)i, j, dw,
                             {
                                 const v4r Xj = ld4(xq + 4 * (size_t)j);
                                 A += ((pi + Xj[3]) * dw) * (Xi - Xj);
                             });
        pfsph_real ax = A[0], ay = A[1], az = A[2];
        if (pi > 0) { /* Akinci 2012: the wall pushes with p_i alone (pressure.c) */
            const pfsph_real wb = pi * inv_v0;
            ax += wb * bx[i];
            ay += wb * by[i];
            az += wb * bz[i];
        }
        const pfsph_real inv_m = -(pfsph_real)1 / c->mass[f->phase[i]];
        a4[4 * i] = ap[0][i] = inv_m * ax;
        a4[4 * i + 1] = ap[1][i] = inv_m * ay;
        a4[4 * i + 2] = ap[2][i] = inv_m * az;
        a4[4 * i + 3] = 0;
    }
}

/* The paper's Algorithm 2, second part: the Jacobi iteration
 *   p_i <- max(0, p_i + omega (delta0 - delta_adv_i - (A p)_i) / a_ii),
 * with (A p)_i = dt^2 [sum_j (a_i - a_j) . grad W_ij + (1/V0) a_i . B_i], the density change of
 * the pressure accelerations a = a_p(p). This is the paper's sum_j d_ij p_j form (Eqs. 12-14)
 * regrouped: the same update in exact arithmetic, computed through the accelerations (two walks
 * an iteration, as the paper's d_ij p_j and pressure passes). Each pass evaluates the residual
 * of the pressure as it stands, so that on return ap belongs to the final p and the error
 * reported is that of the accelerations applied; then it stops or updates. The error is the
 * project's: the mean over all particles of the predicted compression max(delta* - delta0, 0) /
 * delta0 (as PCISPH and DFSPH report it), where the paper averages the signed error of the
 * particles under pressure. Returns the updates made, *avg the last mean error. */
static int iterate(const iisph *S, const pfsph_ctx *c, pfsph_real *p, pfsph_real *const ap[3], pfsph_real *const *scr,
                   double *avg)
{
    const pfsph_particles *f = c->fluid;
    const pfsph_nlist *nl = c->nlist;
    const size_t n = f->n;
    const double nd0 = c->nd0, dt2 = c->dt * c->dt;
    const pfsph_real inv_v0 = (pfsph_real)1 / c->V0;
    pfsph_real *xq = scr[XQ], *err = scr[ERR], *pn = scr[PN];
    const pfsph_real *a4 = scr[W4], *aii = scr[AII], *dadv = scr[DADV], *bx = scr[BX], *by = scr[BY], *bz = scr[BZ];
    const pfsph_kernel *k = &c->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_hits_fn hits = pfsph_hits_select();
    /* a distributed run: the halo copies of the updated p from their owners before lane 3 is made
     * of them (a halo particle's own update misses the neighbours beyond the halo); the one
     * refresh an iteration needs, as in DFSPH (docs/cluster.md, "DFSPH") */
    const int dist = c->dist != NULL;
    for (int it = 0;; it++) {
        if (it > 0 && dist) {
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++) p[i] = pn[i];
            pfsph_real *const a[1] = {p};
            pfsph__halo(c, a, 1);
        }
#pragma omp parallel
        {
            pfsph_hits H; /* grid walks (no lists) */
            if (it > 0) { /* the last pass's update (predict_advection filled lane 3 for the first) */
#pragma omp for schedule(static)
                for (size_t i = 0; i < n; i++) {
                    if (!dist) p[i] = pn[i];
                    xq[4 * i + 3] = p[i] / (c->nd[i] * c->nd[i]);
                }
            }
            pressure_accel(c, scr, ap);
#pragma omp for schedule(static)
            for (size_t i = 0; i < n; i++) {
                const v4r Ai = ld4(a4 + 4 * i), Xi = ld4(xq + 4 * i);
                pfsph_real s = 0;
                PFSPH_FOR_NEIGHBOURS(nl, c->grid, hits, &H, k, f->x, f->y, f->z, i, Xi[0], Xi[1], Xi[2], h2,
                                     (uint32_t)i, j, dw, {
                                         const size_t j4 = 4 * (size_t)j;
                                         /* lane 3: a's is 0 */
                                         const v4r P = (Ai - ld4(a4 + j4)) * (Xi - ld4(xq + j4));
                                         s += (P[0] + P[1] + P[2]) * dw;
                                     });
                s += (Ai[0] * bx[i] + Ai[1] * by[i] + Ai[2] * bz[i]) * inv_v0;
                /* the predicted density error delta_adv + (A p)_i - delta0 */
                const double res = (double)dadv[i] + dt2 * (double)s - nd0;
                err[i] = (pfsph_real)(res > 0 ? res / nd0 : 0);
                const double d = aii[i];
                const double q = d < 0 ? (double)p[i] - OMEGA * res / d : 0;
                pn[i] = (pfsph_real)(q > 0 ? q : 0);
            }
        }
        const size_t nall = pfsph__fluid_count(c);
        *avg = nall ? pfsph__fluid_sum(c, err) / (double)nall : 0; /* the serial sum on any rank count */
        if (it >= S->max_iter || (it >= S->min_iter && *avg <= S->tol)) return it;
    }
}

/* Warm start with half of last step's pressure (the paper's p_i^0 = 0.5 p_i(t - dt)): it lives
 * in fluid->p, so it follows the grid sort and goes into checkpoints. */
static void solve(void *state, const pfsph_ctx *c, pfsph_real *const ap[3], pfsph_real *const *scr,
                  pfsph_solve_stats *out)
{
    const iisph *S = state;
    pfsph_particles *f = c->fluid;
    for (size_t i = 0; i < f->n; i++) f->p[i] *= (pfsph_real)0.5;
    predict_advection(c, f->p, scr);
    double avg;
    out->iterations = iterate(S, c, f->p, ap, scr, &avg);
    out->density_err_avg = avg;
}

/* The paper's CFL rule on the flow speed (lambda = time.cfl, 0.4 by default) and the
 * displacement the non-pressure forces cause in one step held at a_np dt^2 <= EPS_STEP d: the
 * solve has to undo it within the step. a_np leaves viscosity out (np_cap_without_viscosity,
 * as DFSPH: it compresses nothing systematically). No acoustic limit. */
static double dt_limit(const void *state, const pfsph_ctx *ctx, double vmax, double amax, double amax_np)
{
    (void)amax;
    const iisph *S = state;
    const double d = ctx->spacing;
    double dt = INFINITY;
    if (vmax > 0) dt = S->cfl * d / vmax;
    if (amax_np > 0) dt = fmin(dt, sqrt(EPS_STEP * d / amax_np));
    return dt;
}

/* a blow-up only above 20 c and half a spacing in the step (pfsph__speed_bound_one_step) */
static double speed_bound(const void *state, const pfsph_ctx *ctx)
{
    return pfsph__speed_bound_one_step(((const iisph *)state)->c, ctx);
}

static const char *hint(const void *state, const pfsph_ctx *ctx)
{
    const iisph *S = state;
    if (ctx->dt > 0 && ctx->dt < S->cfl * (double)ctx->spacing / S->c)
        return "the time step is far below what IISPH needs (it removes density errors within one step, so "
               "speeds grow as 1/dt): raise time.dt_max and time.dt_min, do not lower them";
    return "lower time.cfl or dt_max, or tighten solver.tolerance; check pairwise coefficients and viscosity";
}

const pfsph_solver_ops pfsph_solver_iisph = {
    .name = "iisph",
    .keys = keys,
    .nkeys = NKEYS,
    .check = check,
    .nscratch = NSCR,
    .nscratch4 = NSCR4,
    .neighbour_lists = 1,
    .np_cap_without_viscosity = 1,
    .create = create,
    .destroy = destroy,
    .solve = solve,
    .dt_limit = dt_limit,
    .speed_bound = speed_bound,
    .hint = hint,
};
