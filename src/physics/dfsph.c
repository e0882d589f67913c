/* Divergence-free SPH (Bender & Koschier 2015, 2017) in the number-density form of PF Eq. 23:
 * a divergence solve on the velocities at the start of the step and a density solve on the
 * predicted velocities, both Jacobi iterations on a clamped pressure (p >= 0) with the DFSPH
 * factor of each particle; time steps limited by the CFL condition and the non-pressure
 * forces other than viscosity (no sound speed). The passes walk the step's neighbour lists
 * (src/core/nlist.h) or, without them, the grid (physics/neighbours.h: the same bits).
 * Derivation and choices: docs/solvers.md, "DFSPH". */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/dist.h"
#include "core/reduce.h"
#include "physics/neighbours.h"
#include "physics/solver.h"

#define OMEGA 0.5
/* a_np dt^2 / d per step. On the 2D tank at tolerance 0.001: 0.004 settles to vmax 0.004 m/s
 * in 2 s (40 sweeps a step at rest); 0.001 to 0.010 m/s (10 sweeps, half the step). 0.01 made
 * the 7k dam break 19 % faster but the density-ratio-10 bubble of test_pf_rising_bubble rose
 * unsteadily (0.246 then 0.304 m/s, gas compressed 4.4 %); at 0.004: 0.309, 0.307 m/s, 1.4 %. */
#define EPS_STEP 0.004

/* scratch: PV the wall pressure for bodies (after the solve) doubles as ERR (each particle's
 * compression, during the solves); XQ and V4 packed, 4 values per
 * particle (solver.h, nscratch4): XQ = (x, y, z, p / delta^2), V4 = the corrected (vx, vy, vz).
 * A list entry then loads one 16-byte vector per neighbour and array instead of three or four
 * scalars (4 loads a pair instead of 8 in the rate pass), and the three sums run as the lanes
 * of one vector: lane by lane the scalar expressions in the same order, the same bits. */
enum { FAC, RATE, PV, BX, BY, BZ, BC, XQ, V4, NSCR };
#define ERR PV
#define NSCR4 2

/* Without neighbour lists (grid walks; issue 28: 100 B per particle at 2e7) the scratch is one
 * array, FAC, kept from pre_forces to solve in the stages' shared scratch (solver.h,
 * walk_nscratch; after solve it holds the wall pressure), and a call borrows what holds nothing
 * while it runs:
 * - fluid->rho (m delta, written by the density stage; put back by the same expression, the
 *   same bits, before the call returns) holds Q = p / delta^2 during the acceleration pass, then
 *   each particle's RATE (a particle reads its own rate before it writes its Q);
 * - the pressure accelerations' arrays hold the wall sums until they are compacted, then in the
 *   divergence solve the corrected velocities (a_p is not kept there);
 * the density solve keeps a_np + a_p (the integrator then gets it whole, with a_np set to -0:
 * -0 + a = a exactly) and recomputes v_j + dt (a_np,j + a_p,j) from it (the
 * expression that stored it, the same bits) instead of keeping the velocities; the positions come
 * from the grid walk's x_ij; the wall sums are kept only for the particles with a wall neighbour
 * (compact, in the solver's state); the mean residual is summed during the rate pass in
 * pfsph__sum's blocks and order. The same terms in the same order as with lists: the same bits. */
enum { W_FAC, W_NSCR };

typedef pfsph_real v4r __attribute__((vector_size(4 * sizeof(pfsph_real))));
/* a load of 4 values at any alignment of pfsph_real (GCC's idiom of __m128_u); a macro, not a
 * function: a double build's 32-byte vector returned by value would change the ABI */
typedef pfsph_real v4r_u __attribute__((vector_size(4 * sizeof(pfsph_real)), aligned(sizeof(pfsph_real)), may_alias));
#define ld4(p) (*(const v4r_u *)(p))

/* its scene keys under $.solver, in the order of the scene's solver_settings. A tighter default
 * tolerance than PCISPH's: at 0.005 its 2D tank at rest kept vmax ~0.2 m/s (docs/solvers.md,
 * "DFSPH"); one minimum correction: its warm start is often within tolerance already (the 7k dam
 * break to 1 s: 13.4 s wall with 1, 15.5 s with 2, 19.1 s with PCISPH's 3). */
enum { K_TOL, K_MIN, K_MAX, K_DIV_TOL, K_DIV_MAX, K_LISTS, NKEYS };
static const pfsph_solver_key keys[NKEYS] = {
    {"tolerance", 0.001, 1e-5, 0.1, 0, "mean relative density error the density solve stops at"},
    {"min_iterations", 1, 1, 1000, 1, "density corrections per step at least"},
    {"max_iterations", 50, 1, 10000, 1, "density corrections per step at most"},
    {"divergence_tolerance", 0.001, 1e-6, 0.1, 0, "mean |D delta / Dt| dt / delta0 the divergence solve stops at"},
    {"divergence_max_iterations", 100, 0, 10000, 1, "divergence corrections per step at most; 0: none"},
    {"neighbour_lists", 0, -1, 1, PFSPH_KEY_AUTO_BOOL,
     "true: neighbour lists (~300 B per particle in 3D), false: grid walks (the same bits), "
     "\"auto\": lists while they fit a quarter of the memory"},
};

static int check(const double *v, const char **key, char *msg, size_t len)
{
    return pfsph__check_iterations(v[K_MIN], v[K_MAX], key, msg, len);
}

typedef struct dfsph {
    double tol, div_tol, cfl, c;
    int min_iter, max_iter, div_max_iter;
    double full; /* neighbours (fluid + boundary) of a particle inside the fluid */
    int walk;    /* no lists: the layout of W_NSCR */
    /* walk: the wall sums (bx, by, bz, bc) of the particles with a wall neighbour, ascending */
    uint32_t *near;
    pfsph_real *nearb; /* 4 per entry of near */
    size_t nnear, near_cap;
    double *part; /* the mean residual's sum per block of PFSPH_SUM_BLOCK particles */
    size_t part_cap;
    /* a distributed run without lists (core/dist.h): each particle's compression, for the global
     * sum of the mean residual */
    pfsph_real *dbuf;
    size_t dbuf_cap;
} dfsph;

static int create(void **state, const pfsph_ctx *ctx, const pfsph_solver_config *cfg, pfsph_error *err)
{
    dfsph *D = calloc(1, sizeof *D);
    if (!D) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    D->tol = cfg->settings[K_TOL];
    D->min_iter = (int)cfg->settings[K_MIN];
    D->max_iter = (int)cfg->settings[K_MAX];
    D->div_tol = cfg->settings[K_DIV_TOL];
    D->div_max_iter = (int)cfg->settings[K_DIV_MAX];
    D->cfl = cfg->cfl;
    D->c = cfg->sound_speed;
    const double q = (double)ctx->h / (double)ctx->spacing;
    D->full = ctx->dim == 2 ? 3.14159265358979 * q * q : 4.18879020478639 * q * q * q;
    D->walk = !cfg->lists;
    *state = D;
    return PFSPH_OK;
}

static void destroy(void *state)
{
    dfsph *D = state;
    if (!D) return;
    free(D->near);
    free(D->nearb);
    free(D->part);
    free(D->dbuf);
    free(D);
}

/* DFSPH factor 1 / A_i with A_i = |g_i|^2 / m_i + sum_j |grad W_ij|^2 / m_j, g_i = sum_j grad
 * W_ij + (1/V0) sum_b V_b grad W_ib: how much one unit of p_i / delta_i^2 on i (and its
 * reaction on the neighbours) changes delta_i per dt^2 (Bender & Koschier 2017, Eq. 9 for
 * number densities). A particle with fewer than 60 % of a full neighbourhood gets factor 0 in
 * the divergence solve only, through the sign of fac (SPlisHSPlasH's 20 of 33 in 3D): its
 * velocity divergence at a free surface is not a compression.
 * The same walk stores the boundary sums that stay fixed during the step (walls and bodies do
 * not move until the integration), so that the solver's passes need no boundary walk:
 * B_i = sum_b V_b grad W_ib (bx, by, bz) and C_i = sum_b V_b v_b . grad W_ib (bc). */
static void factors(const dfsph *D, const pfsph_ctx *ctx, pfsph_real *fac, pfsph_real *const bsum[4], pfsph_real *xq)
{
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_nlist *nl = ctx->nlist, *bl = ctx->nlist_b;
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0, h2 = k->h * k->h;
    const double few = 0.6 * D->full;
    const size_t n = f->n;
    const pfsph_hits_fn hits = pfsph_hits_select();
#pragma omp parallel
    {
        pfsph_hits H; /* grid walks (no lists) */
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
            if (xq) { /* the positions stay put until the integration */
                xq[4 * i] = xi;
                xq[4 * i + 1] = yi;
                xq[4 * i + 2] = zi;
            }
            double gx = 0, gy = 0, gz = 0, s2 = 0;
            int nn = 0;
            PFSPH_FOR_NEIGHBOURS(nl, ctx->grid, hits, &H, k, f->x, f->y, f->z, i, xi, yi, zi, h2, (uint32_t)i, j, dwj, {
                pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                double w = dwj;
                double ax = w * dx, ay = w * dy, az = w * dz;
                gx += ax;
                gy += ay;
                gz += az;
                s2 += (ax * ax + ay * ay + az * az) / (double)ctx->mass[f->phase[j]];
                nn++;
            });
            pfsph_real bx = 0, by = 0, bz = 0, bc = 0;
            if (b->n)
                PFSPH_FOR_NEIGHBOURS(bl, ctx->bgrid, hits, &H, k, b->x, b->y, b->z, i, xi, yi, zi, h2, UINT32_MAX, j,
                                     dw, {
                                         pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                                         double w = (double)(b->aux[j] * inv_v0) * dw;
                                         gx += w * dx;
                                         gy += w * dy;
                                         gz += w * dz;
                                         nn++;
                                         /* the order and rounding of pressure.c's wall term, so that a_p keeps
                                          * its bits */
                                         pfsph_real sb = b->aux[j] * dw;
                                         bx += sb * dx;
                                         by += sb * dy;
                                         bz += sb * dz;
                                         bc += sb * (b->vx[j] * dx + b->vy[j] * dy + b->vz[j] * dz);
                                     });
            bsum[0][i] = bx;
            bsum[1][i] = by;
            bsum[2][i] = bz;
            bsum[3][i] = bc;
            double A = (gx * gx + gy * gy + gz * gz) / (double)ctx->mass[f->phase[i]] + s2;
            double fi = A > 1e-30 * s2 && A > 0 ? 1.0 / A : 0.0;
            fac[i] = (pfsph_real)(nn + 1 < few ? -fi : fi);
        }
    }
}

/* The residual of particle i: density mode (predicted delta - delta0) or divergence mode
 * (dt D delta / Dt, none for a deficient neighbourhood), a compression over the step [1/m^d],
 * and the factor that turns it into a pressure update. */
static inline double residual_of(const pfsph_ctx *c, int divergence, const pfsph_real *rate, const pfsph_real *fac,
                                 size_t i, double *fi)
{
    const double f = fac[i];
    if (divergence) {
        *fi = f > 0 ? f : 0;
        return f > 0 ? c->dt * (double)rate[i] : 0;
    }
    *fi = fabs(f);
    return (double)c->nd[i] + c->dt * (double)rate[i] - (double)c->nd0;
}

/* One Jacobi update of the clamped pressure p_i: p_i / delta_i^2 grows by omega res / (dt^2 A_i)
 * (Bender & Koschier 2017, Eqs. 9, 12; the divergence residual already carries one dt). A_i
 * counts only particle i's own pressure; in a Jacobi sweep the neighbours push too, and
 * omega = 1 overshot: a 2D tank at rest diverged at step 3. omega = 0.5, as IISPH and our PCISPH
 * relax. */
static inline pfsph_real updated(const pfsph_ctx *c, int divergence, const pfsph_real *rate, const pfsph_real *fac,
                                 const pfsph_real *p, size_t i)
{
    const double dt2 = c->dt * c->dt;
    double fi, res = residual_of(c, divergence, rate, fac, i, &fi);
    double nd = c->nd[i];
    double pn = (double)p[i] + OMEGA * nd * nd * res * fi / dt2;
    return (pfsph_real)(pn > 0 ? pn : 0);
}

/* A distributed run: the Jacobi update (with upd) of every particle, then the halo copies of p
 * from their owners (a halo particle's own residual misses the neighbours beyond the halo), so
 * that the pass after it reads each neighbour's p as the serial run has it. That is the one
 * refresh an iteration needs: the halo holds every cell within a walk's reach + 1 of the owned
 * ones (src/mpi/decomp.c), so the corrected velocity of a neighbour of an owned particle is made
 * of the refreshed p within its reach and its own a_np, both as in the serial run; the rates of
 * the owned particles, all the mean residual sums, follow. (Without it, tests/data/mpi/
 * dam_2d_dfsph.json differs from the serial run at its second frame.) Returns the upd the pass
 * after it still has to do: none here, upd in a serial run (one parallel region, as before). */
static int halo_updated(const pfsph_ctx *c, int upd, int divergence, const pfsph_real *rate, const pfsph_real *fac,
                        pfsph_real *p)
{
    if (!c->dist) return upd;
    if (upd) {
        const size_t n = c->fluid->n;
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) p[i] = updated(c, divergence, rate, fac, p, i);
    }
    pfsph_real *const a[1] = {p};
    pfsph__halo(c, a, 1);
    return 0;
}

/* With upd, first the Jacobi update of p from the last residual (rate, fac); then a = a_p(p)
 * (PF Eq. 4 in the number-density form with the Akinci wall term, as pfsph__pressure_accel
 * computes it, over the lists, with p_j / delta_j^2 computed once per particle into lane 3 of
 * xq) and v4 = v + dt (a_extra + a). One parallel region: a barrier fewer per iteration matters on
 * a loaded machine. */
static void corrected_velocity(const pfsph_ctx *c, int upd, int divergence, const pfsph_real *rate,
                               const pfsph_real *fac, pfsph_real *p, const pfsph_real *ex, const pfsph_real *ey,
                               const pfsph_real *ez, pfsph_real *const bsum[4], pfsph_real *xq, pfsph_real *const *a,
                               pfsph_real *v4)
{
    const pfsph_particles *f = c->fluid;
    const pfsph_nlist *nl = c->nlist;
    const size_t n = f->n;
    const pfsph_real dt = (pfsph_real)c->dt;
    const pfsph_real inv_v0 = (pfsph_real)1 / c->V0;
    const pfsph_real *nd = c->nd;
    const pfsph_kernel *k = &c->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_hits_fn hits = pfsph_hits_select();
    upd = halo_updated(c, upd, divergence, rate, fac, p);
#pragma omp parallel
    {
        pfsph_hits H; /* grid walks (no lists) */
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            if (upd) p[i] = updated(c, divergence, rate, fac, p, i);
            xq[4 * i + 3] = p[i] / (nd[i] * nd[i]);
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const v4r Xi = ld4(xq + 4 * i);
            const pfsph_real pi = Xi[3];
            v4r A = {0, 0, 0, 0};
            PFSPH_FOR_NEIGHBOURS(nl, c->grid, hits, &H, k, f->x, f->y, f->z, i, Xi[0], Xi[1], Xi[2], h2, (uint32_t)i, j,
                                 dw, {
                                     const v4r Xj = ld4(xq + 4 * (size_t)j);
                                     const pfsph_real s = (pi + Xj[3]) * dw;
                                     A += s * (Xi - Xj); /* lanes 0-2: a += s x_ij (lane 3 unused) */
                                 });
            pfsph_real ax = A[0], ay = A[1], az = A[2];
            if (pi > 0) { /* Akinci 2012: the wall pushes with p_i alone (pressure.c) */
                const pfsph_real wb = pi * inv_v0;
                ax += wb * bsum[0][i];
                ay += wb * bsum[1][i];
                az += wb * bsum[2][i];
            }
            const pfsph_real inv_m = -(pfsph_real)1 / c->mass[f->phase[i]];
            const pfsph_real a0 = inv_m * ax, a1 = inv_m * ay, a2 = inv_m * az;
            if (a) { /* the divergence solve keeps only the velocities */
                a[0][i] = a0;
                a[1][i] = a1;
                a[2][i] = a2;
            }
            v4[4 * i] = f->vx[i] + dt * ((ex ? ex[i] : 0) + a0);
            v4[4 * i + 1] = f->vy[i] + dt * ((ey ? ey[i] : 0) + a1);
            v4[4 * i + 2] = f->vz[i] + dt * ((ez ? ez[i] : 0) + a2);
        }
    }
}

/* D delta_i / Dt for the velocities v (PF Eq. 23 differentiated): sum_j (v_i - v_j) . grad
 * W_ij over the lists, plus the wall's (1/V0) (v_i . B_i - C_i) from the sums of factors();
 * and err_i, the relative compression over the step that the residual stands for. */
static void density_rate(const pfsph_ctx *c, const pfsph_real *xq, const pfsph_real *v4, pfsph_real *const bsum[4],
                         pfsph_real *rate, int divergence, const pfsph_real *fac, pfsph_real *err)
{
    const double nd0 = c->nd0;
    const pfsph_particles *f = c->fluid;
    const pfsph_nlist *nl = c->nlist;
    const size_t n = f->n;
    const pfsph_real inv_v0 = (pfsph_real)1 / c->V0;
    const pfsph_kernel *k = &c->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_hits_fn hits = pfsph_hits_select();
#pragma omp parallel
    {
        pfsph_hits H; /* grid walks (no lists) */
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const v4r Xi = ld4(xq + 4 * i), Vi = ld4(v4 + 4 * i);
            const pfsph_real vxi = Vi[0], vyi = Vi[1], vzi = Vi[2];
            pfsph_real s = 0;
            PFSPH_FOR_NEIGHBOURS(nl, c->grid, hits, &H, k, f->x, f->y, f->z, i, Xi[0], Xi[1], Xi[2], h2, (uint32_t)i, j,
                                 dw, {
                                     const size_t j4 = 4 * (size_t)j;
                                     /* (v_i - v_j) . x_ij, summed x + y, then + z as the scalar expression */
                                     const v4r P = (Vi - ld4(v4 + j4)) * (Xi - ld4(xq + j4));
                                     const pfsph_real vd = P[0] + P[1] + P[2];
                                     s += vd * dw;
                                 });
            const pfsph_real sb = vxi * bsum[0][i] + vyi * bsum[1][i] + vzi * bsum[2][i] - bsum[3][i];
            rate[i] = s + sb * inv_v0;
            /* the compression it stands for (residual()), in the same pass */
            double fi, res = residual_of(c, divergence, rate, fac, i, &fi);
            err[i] = (pfsph_real)(res > 0 ? res / nd0 : 0);
        }
    }
}

/* ---- without lists: the grid-walk layout (W_NSCR above) ---- */

/* a wall sum that is not +0: the particle had a wall neighbour (one whose sums are all +0 adds
 * the same +0 whether kept or not) */
static inline int nonzero(pfsph_real v) { return v != 0 || signbit(v); }

/* Keeps the wall sums t[0..3] of the particles where one is not +0, ascending (fixed chunks,
 * so the order does not depend on the threads). */
static int compact_walls(dfsph *D, size_t n, pfsph_real *const t[4])
{
    enum { CHUNKS = 64 };
    size_t off[CHUNKS + 1];
    off[0] = 0;
#pragma omp parallel for schedule(static)
    for (int c = 0; c < CHUNKS; c++) {
        size_t m = 0;
        for (size_t i = n * (size_t)c / CHUNKS; i < n * (size_t)(c + 1) / CHUNKS; i++)
            m += nonzero(t[0][i]) || nonzero(t[1][i]) || nonzero(t[2][i]) || nonzero(t[3][i]);
        off[c + 1] = m;
    }
    for (int c = 0; c < CHUNKS; c++) off[c + 1] += off[c];
    const size_t m = off[CHUNKS];
    if (m > D->near_cap) {
        const size_t cap = m + m / 4;
        uint32_t *idx = realloc(D->near, cap * sizeof *idx);
        if (idx) D->near = idx;
        pfsph_real *b = realloc(D->nearb, 4 * cap * sizeof *b);
        if (b) D->nearb = b;
        if (!idx || !b) return PFSPH_ENOMEM;
        D->near_cap = cap;
    }
    D->nnear = m;
#pragma omp parallel for schedule(static)
    for (int c = 0; c < CHUNKS; c++) {
        size_t k = off[c];
        for (size_t i = n * (size_t)c / CHUNKS; i < n * (size_t)(c + 1) / CHUNKS; i++)
            if (nonzero(t[0][i]) || nonzero(t[1][i]) || nonzero(t[2][i]) || nonzero(t[3][i])) {
                D->near[k] = (uint32_t)i;
                for (int a = 0; a < 4; a++) D->nearb[4 * k + a] = t[a][i];
                k++;
            }
    }
    return PFSPH_OK;
}

/* The wall sums of particle i, for a pass whose threads each visit their particles in
 * ascending order (static schedules): *k is the thread's place in the compact set, SIZE_MAX
 * before its first particle. NULL: none (all +0). */
static inline const pfsph_real *walls_of(const dfsph *D, size_t *k, size_t i)
{
    if (*k == SIZE_MAX) { /* the first entry at or after i */
        size_t lo = 0, hi = D->nnear;
        while (lo < hi) {
            const size_t mid = lo + (hi - lo) / 2;
            if (D->near[mid] < i) lo = mid + 1;
            else hi = mid;
        }
        *k = lo;
    }
    if (*k < D->nnear && D->near[*k] == i) return D->nearb + 4 * (*k)++;
    return NULL;
}

/* fluid->rho as the density stage wrote it (pfsph__density_check): m delta */
static void restore_rho(const pfsph_ctx *c)
{
    pfsph_particles *f = c->fluid;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->n; i++) f->rho[i] = c->mass[f->phase[i]] * c->nd[i];
}

/* corrected_velocity over grid walks: R holds the rates on entry (with upd) and Q on return; out
 * receives the corrected velocities (divergence) or a_p (density solve). */
static void corrected_walk(const dfsph *D, const pfsph_ctx *c, int upd, int divergence, const pfsph_real *fac,
                           pfsph_real *p, pfsph_real *R, const pfsph_real *ex, const pfsph_real *ey,
                           const pfsph_real *ez, pfsph_real *const out[3])
{
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    const pfsph_real dt = (pfsph_real)c->dt;
    const pfsph_real inv_v0 = (pfsph_real)1 / c->V0;
    const pfsph_real *nd = c->nd;
    const pfsph_kernel *k = &c->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_hits_fn hits = pfsph_hits_select();
    upd = halo_updated(c, upd, divergence, R, fac, p);
#pragma omp parallel
    {
        pfsph_hits H;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            if (upd) p[i] = updated(c, divergence, R, fac, p, i);
            R[i] = p[i] / (nd[i] * nd[i]);
        }
        size_t kb = SIZE_MAX;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i], pi = R[i];
            pfsph_real ax = 0, ay = 0, az = 0;
            PFSPH_FOR_HITS(c->grid, hits, &H, k, f->x, f->y, f->z, xi, yi, zi, h2, (uint32_t)i, j, dw, dx, dy, dz, {
                const pfsph_real s = (pi + R[j]) * dw;
                ax += s * dx;
                ay += s * dy;
                az += s * dz;
            });
            const pfsph_real *B = walls_of(D, &kb, i);
            if (pi > 0) {
                const pfsph_real wb = pi * inv_v0;
                ax += wb * (B ? B[0] : 0);
                ay += wb * (B ? B[1] : 0);
                az += wb * (B ? B[2] : 0);
            }
            const pfsph_real inv_m = -(pfsph_real)1 / c->mass[f->phase[i]];
            const pfsph_real a0 = inv_m * ax, a1 = inv_m * ay, a2 = inv_m * az;
            if (divergence) {
                out[0][i] = f->vx[i] + dt * ((ex ? ex[i] : 0) + a0);
                out[1][i] = f->vy[i] + dt * ((ey ? ey[i] : 0) + a1);
                out[2][i] = f->vz[i] + dt * ((ez ? ez[i] : 0) + a2);
            } else { /* a_np + a_p: the integrator gets it whole (solve) */
                out[0][i] = ex[i] + a0;
                out[1][i] = ey[i] + a1;
                out[2][i] = ez[i] + a2;
            }
        }
    }
}

/* The corrected velocity of particle j: kept (divergence), or v + dt (a_np + a_p) as
 * corrected_walk computes it, from the sum it keeps (density solve). */
static inline void velocity_of(const pfsph_particles *f, int kept, pfsph_real dt, const pfsph_real *const in[3],
                               size_t j, pfsph_real *vx, pfsph_real *vy, pfsph_real *vz)
{
    if (kept) {
        *vx = in[0][j];
        *vy = in[1][j];
        *vz = in[2][j];
    } else {
        *vx = f->vx[j] + dt * in[0][j];
        *vy = f->vy[j] + dt * in[1][j];
        *vz = f->vz[j] + dt * in[2][j];
    }
}

/* density_rate over grid walks, for particles [i0, i1): the rates into R; returns the sum of the
 * compressions as pfsph__sum adds them within one block. */
static inline double rate_block(const dfsph *D, const pfsph_ctx *c, int divergence, const pfsph_real *const in[3],
                                const pfsph_real *fac, pfsph_real *R, pfsph_real *E, pfsph_hits *H, pfsph_hits_fn hits,
                                size_t *kb, size_t i0, size_t i1)
{
    const pfsph_particles *f = c->fluid;
    const pfsph_real dt = (pfsph_real)c->dt;
    const pfsph_real inv_v0 = (pfsph_real)1 / c->V0;
    const pfsph_kernel *k = &c->kern;
    const pfsph_real h2 = k->h * k->h;
    const double nd0 = c->nd0;
    double sum = 0;
    for (size_t i = i0; i < i1; i++) {
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        pfsph_real vxi, vyi, vzi;
        velocity_of(f, divergence, dt, in, i, &vxi, &vyi, &vzi);
        pfsph_real s = 0;
        PFSPH_FOR_HITS(c->grid, hits, H, k, f->x, f->y, f->z, xi, yi, zi, h2, (uint32_t)i, j, dw, dx, dy, dz, {
            pfsph_real vxj, vyj, vzj;
            velocity_of(f, divergence, dt, in, j, &vxj, &vyj, &vzj);
            /* (v_i - v_j) . x_ij, summed x + y, then + z */
            const pfsph_real vd = (vxi - vxj) * dx + (vyi - vyj) * dy + (vzi - vzj) * dz;
            s += vd * dw;
        });
        const pfsph_real *B = walls_of(D, kb, i);
        const pfsph_real bx = B ? B[0] : 0, by = B ? B[1] : 0, bz = B ? B[2] : 0, bc = B ? B[3] : 0;
        const pfsph_real sb = vxi * bx + vyi * by + vzi * bz - bc;
        R[i] = s + sb * inv_v0;
        double fi, res = residual_of(c, divergence, R, fac, i, &fi);
        const pfsph_real e = (pfsph_real)(res > 0 ? res / nd0 : 0);
        if (E) E[i] = e;
        sum += (double)e;
    }
    return sum;
}

/* All particles' rates; returns the sum of their compressions with pfsph__sum's bits (a
 * distributed run: of the whole run's, from each particle's in D->dbuf). */
static double rate_walk(const dfsph *D, const pfsph_ctx *c, int divergence, const pfsph_real *const in[3],
                        const pfsph_real *fac, pfsph_real *R)
{
    const size_t n = c->fluid->n, nb = (n + PFSPH_SUM_BLOCK - 1) / PFSPH_SUM_BLOCK;
    const pfsph_hits_fn hits = pfsph_hits_select();
    double *part = D->part;
    pfsph_real *E = c->dist ? D->dbuf : NULL;
#pragma omp parallel
    {
        pfsph_hits H;
        size_t kb = SIZE_MAX;
#pragma omp for schedule(static)
        for (size_t b = 0; b < nb; b++) {
            const size_t i0 = b * PFSPH_SUM_BLOCK, i1 = i0 + PFSPH_SUM_BLOCK < n ? i0 + PFSPH_SUM_BLOCK : n;
            /* the two modes as their own loops: the kept velocities or their expression */
            part[b] = divergence ? rate_block(D, c, 1, in, fac, R, E, &H, hits, &kb, i0, i1)
                                 : rate_block(D, c, 0, in, fac, R, E, &H, hits, &kb, i0, i1);
        }
    }
    if (E) return pfsph__fluid_sum(c, E);
    double total = 0;
    for (size_t b = 0; b < nb; b++) total += part[b];
    return total;
}

/* iterate() over grid walks; io: the pressure accelerations' arrays (a_p, or the divergence
 * solve's velocities); R: fluid->rho. */
static int iterate_walk(const dfsph *D, const pfsph_ctx *c, int divergence, pfsph_real *p, pfsph_real *const io[3],
                        const pfsph_real *fac, pfsph_real *R, double tol, int min_it, int max_it, double *avg)
{
    const pfsph_real *ex = divergence ? NULL : c->ax, *ey = divergence ? NULL : c->ay, *ez = divergence ? NULL : c->az;
    const size_t n = pfsph__fluid_count(c);
    const pfsph_real *const in[3] = {io[0], io[1], io[2]};
    for (int it = 0;; it++) {
        corrected_walk(D, c, it > 0, divergence, fac, p, R, ex, ey, ez, io);
        const double sum = rate_walk(D, c, divergence, in, fac, R);
        *avg = n ? sum / (double)n : 0;
        if (it >= max_it || (it >= min_it && *avg <= tol)) return it;
    }
}

/* Jacobi iterations on p (density mode: velocities v + dt (a_np + a_p); divergence mode: v +
 * dt a_p) until the mean residual is within tol after at least min_it updates, or max_it
 * updates were made. On return ap (when not NULL) and v4 belong to the final p. Returns the updates
 * made; *avg the last mean residual. */
static int iterate(const pfsph_ctx *c, int divergence, pfsph_real *p, pfsph_real *const *ap, pfsph_real *const *scr,
                   double tol, int min_it, int max_it, double *avg)
{
    const pfsph_real *ex = divergence ? NULL : c->ax, *ey = divergence ? NULL : c->ay, *ez = divergence ? NULL : c->az;
    const size_t n = pfsph__fluid_count(c);
    pfsph_real *const bsum[4] = {scr[BX], scr[BY], scr[BZ], scr[BC]};
    for (int it = 0;; it++) {
        /* from the second pass on, the update of the last residual comes first */
        corrected_velocity(c, it > 0, divergence, scr[RATE], scr[FAC], p, ex, ey, ez, bsum, scr[XQ], ap, scr[V4]);
        density_rate(c, scr[XQ], scr[V4], bsum, scr[RATE], divergence, scr[FAC], scr[ERR]);
        *avg = n ? pfsph__fluid_sum(c, scr[ERR]) / (double)n : 0; /* the serial sum on any rank count */
        if (it >= max_it || (it >= min_it && *avg <= tol)) return it;
    }
}

/* Divergence solve: make D delta / Dt = 0 where the fluid compresses, correcting v in place.
 * The divergence pressure is kept in fluid->aux between steps (it follows the particles through
 * the grid sort and into checkpoints); half of it warm-starts the next step. */
static int pre_forces(void *state, const pfsph_ctx *c, pfsph_real *const ap[3], pfsph_real *const *scr,
                      pfsph_solve_stats *out)
{
    dfsph *D = state;
    pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    out->div_iterations = 0;
    if (c->dist && D->walk && n > D->dbuf_cap) { /* this step's room for rate_walk's compressions */
        pfsph_real *q = realloc(D->dbuf, n * sizeof *q);
        if (!q) return PFSPH_ENOMEM;
        D->dbuf = q;
        D->dbuf_cap = n;
    }
    if (D->walk) {
        pfsph_real *const tmp[4] = {ap[0], ap[1], ap[2], f->rho};
        factors(D, c, scr[W_FAC], tmp, NULL);
        int rc = compact_walls(D, n, tmp);
        const size_t nb = (n + PFSPH_SUM_BLOCK - 1) / PFSPH_SUM_BLOCK;
        if (!rc && nb > D->part_cap) {
            double *q = realloc(D->part, nb * sizeof *q);
            if (q) {
                D->part = q;
                D->part_cap = nb;
            } else rc = PFSPH_ENOMEM;
        }
        if (!rc && D->div_max_iter > 0 && n) {
            for (size_t i = 0; i < n; i++) f->aux[i] *= (pfsph_real)0.5;
            double avg;
            out->div_iterations =
                iterate_walk(D, c, 1, f->aux, ap, scr[W_FAC], f->rho, D->div_tol, 0, D->div_max_iter, &avg);
#pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++) {
                f->vx[i] = ap[0][i];
                f->vy[i] = ap[1][i];
                f->vz[i] = ap[2][i];
            }
        }
        restore_rho(c);
        return rc;
    }
    pfsph_real *const bsum[4] = {scr[BX], scr[BY], scr[BZ], scr[BC]};
    factors(D, c, scr[FAC], bsum, scr[XQ]);
    if (D->div_max_iter <= 0 || !n) return PFSPH_OK;
    pfsph_real *pv = f->aux;
    for (size_t i = 0; i < n; i++) pv[i] *= (pfsph_real)0.5;
    double avg;
    int it = iterate(c, 1, pv, NULL, scr, D->div_tol, 0, D->div_max_iter, &avg);
    const pfsph_real *v4 = scr[V4];
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        f->vx[i] = v4[4 * i];
        f->vy[i] = v4[4 * i + 1];
        f->vz[i] = v4[4 * i + 2];
    }
    out->div_iterations = it;
    return PFSPH_OK;
}

/* Density solve: the predicted number density delta_i + dt D delta_i / Dt(v*) reaches delta0,
 * v* = v + dt (a_nonpressure + a_p). Warm start: half of last step's pressure, which is
 * physical and so needs no rescaling when dt changes. */
static void solve(void *state, const pfsph_ctx *c, pfsph_real *const ap[3], pfsph_real *const *scr,
                  pfsph_solve_stats *out)
{
    const dfsph *D = state;
    pfsph_particles *f = c->fluid;
    /* Half the last pressure, not all of it: a full warm start let pressure modes that move
     * no density (the near-null space of div grad) pile up from step to step; on the 2D tank
     * at rest they drove vmax to 0.5-2 m/s (docs/solvers.md, "DFSPH"). */
    for (size_t i = 0; i < f->n; i++) f->p[i] *= (pfsph_real)0.5;
    double avg;
    if (D->walk) { /* pre_forces made the compact wall sums and the blocks' room for this step */
        out->iterations = iterate_walk(D, c, 0, f->p, ap, scr[W_FAC], f->rho, D->tol, D->min_iter, D->max_iter, &avg);
        restore_rho(c);
        /* ap holds a_np + a_p: a_np becomes -0, so that the integrator's a_np + a_p is it exactly */
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < f->n; i++) c->ax[i] = c->ay[i] = c->az[i] = -(pfsph_real)0;
    } else out->iterations = iterate(c, 0, f->p, ap, scr, D->tol, D->min_iter, D->max_iter, &avg);
    out->density_err_avg = avg;
}

/* The wall felt both solves' pressures this step: their sum is what a body must feel back. */
static const pfsph_real *wall_pressure(void *state, const pfsph_ctx *c, pfsph_real *const *scr)
{
    const pfsph_particles *f = c->fluid;
    /* without lists in FAC's array, which holds nothing after the solve */
    pfsph_real *pw = ((const dfsph *)state)->walk ? scr[W_FAC] : scr[PV];
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->n; i++) pw[i] = f->p[i] + f->aux[i];
    return pw;
}

/* CFL on the flow speed, and the displacement the non-pressure forces cause in one step held
 * at a_np dt^2 <= EPS_STEP d: the Jacobi solve has to undo it within the step. a_np is |g| +
 * the largest pair-force acceleration (np_cap_without_viscosity): viscosity compresses nothing
 * systematically, and with it the 7k dam break took 1,294 steps to 3 s instead of 701
 * (docs/solvers.md). No acoustic limit. (This replaces the force criterion 0.25 sqrt(d / a),
 * which it always undercuts.) */
static double dt_limit(const void *state, const pfsph_ctx *ctx, double vmax, double amax, double amax_np)
{
    (void)amax;
    const dfsph *D = state;
    const double d = ctx->spacing;
    double dt = INFINITY;
    if (vmax > 0) dt = D->cfl * d / vmax;
    if (amax_np > 0) dt = fmin(dt, sqrt(EPS_STEP * d / amax_np));
    return dt;
}

static double speed_bound(const void *state, const pfsph_ctx *ctx)
{
    (void)ctx;
    return 20 * ((const dfsph *)state)->c;
}

static const char *hint(const void *state, const pfsph_ctx *ctx)
{
    (void)state;
    (void)ctx;
    return "lower time.cfl or dt_max, or tighten solver.tolerance; check pairwise coefficients and viscosity";
}

static const char *ratio_advice(double ratio, int common_scale, char *buf, size_t len)
{
    (void)common_scale;
    (void)buf;
    (void)len;
    return ratio > 10.0 + 1e-9 ? "DFSPH is tested to 10 (test_pf_rising_bubble); higher ratios are untested, "
                                 "solver \"wcsph\" with \"pressure_scale\": \"common\" is tested to 1000"
                               : NULL;
}

const pfsph_solver_ops pfsph_solver_dfsph = {
    .name = "dfsph",
    .keys = keys,
    .nkeys = NKEYS,
    .check = check,
    .ratio_advice = ratio_advice,
    .nscratch = NSCR,
    .nscratch4 = NSCR4,
    .neighbour_lists = 1,
    .walk_nscratch = W_NSCR,
    .walk_near_bytes = sizeof(uint32_t) + 4 * sizeof(pfsph_real),
    .np_cap_without_viscosity = 1,
    .create = create,
    .destroy = destroy,
    .pre_forces = pre_forces,
    .solve = solve,
    .wall_pressure = wall_pressure,
    .dt_limit = dt_limit,
    .speed_bound = speed_bound,
    .hint = hint,
};
