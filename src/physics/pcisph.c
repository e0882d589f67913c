/* Predictive-corrective incompressible SPH (Solenthaler & Pajarola 2009) in the number-density
 * form (PF Eq. 23, NOTES item 8), with the pair forces among the non-pressure forces before the
 * prediction loop (NOTES item 9). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dist.h"
#include "core/reduce.h"
#include "physics/density.h"
#include "physics/pcisph_lists.h"
#include "physics/pressure.h"
#include "physics/solver.h"

enum { XP, YP, ZP, NDP, ERR, NSCR };

#define PCISPH_OMEGA_INTERACTIVE 0.6 /* the interactive mode's relaxation (solve) */

/* its scene keys under $.solver, in the order of the scene's solver_settings */
enum { K_TOL, K_MIN, K_MAX, NKEYS };
static const pfsph_solver_key keys[NKEYS] = {
    {"tolerance", 0.005, 1e-5, 0.1, 0, "mean relative density error a step's corrections stop at"},
    {"min_iterations", 3, 1, 1000, 1, "corrections per step at least"},
    {"max_iterations", 50, 1, 10000, 1, "corrections per step at most"},
};

static int check(const double *v, const char **key, char *msg, size_t len)
{
    return pfsph__check_iterations(v[K_MIN], v[K_MAX], key, msg, len);
}

typedef struct pcisph {
    double proto; /* |sum grad W|^2 + sum |grad W|^2 of a full lattice neighbourhood */
    double tol, c, cfl;
    int min_iter, max_iter;
    /* the interactive mode's once-per-step neighbour lists (pcisph_lists.h) */
    pfsph_nlist l, lb;
    pfsph_pcisph_pairs cf, cb; /* and an iteration's pairs, density pass to pressure pass */
    pfsph_real *pn;            /* the pressure pass's p / delta^2 per particle */
    size_t pn_cap;
} pcisph;

/* PCISPH scaling: |sum grad W|^2 + sum |grad W|^2 over a full lattice neighbourhood. */
static double prototype(const pfsph_kernel *k, int dim, pfsph_real spacing);

static int create(void **state, const pfsph_ctx *ctx, const pfsph_solver_config *cfg, pfsph_error *err)
{
    pcisph *p = calloc(1, sizeof *p);
    if (!p) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    p->proto = prototype(&ctx->kern, ctx->dim, ctx->spacing);
    p->tol = cfg->settings[K_TOL];
    p->min_iter = (int)cfg->settings[K_MIN];
    p->max_iter = (int)cfg->settings[K_MAX];
    p->c = cfg->sound_speed;
    p->cfl = cfg->cfl;
    *state = p;
    return PFSPH_OK;
}

static void destroy(void *state)
{
    pcisph *p = state;
    if (!p) return;
    pfsph_nlist_free(&p->l);
    pfsph_nlist_free(&p->lb);
    pfsph__pcisph_pairs_free(&p->cf);
    pfsph__pcisph_pairs_free(&p->cb);
    free(p->pn);
    free(p);
}

/* room for n values in *a (capacity *cap): PFSPH_OK or PFSPH_ENOMEM (then as before) */
static int reserve(pfsph_real **a, size_t *cap, size_t n)
{
    if (n <= *cap) return PFSPH_OK;
    const size_t m = n + n / 8 + 64;
    pfsph_real *q = realloc(*a, m * sizeof(pfsph_real));
    if (!q) return PFSPH_ENOMEM;
    *a = q;
    *cap = m;
    return PFSPH_OK;
}

static void solve(void *state, const pfsph_ctx *c, pfsph_real *const ap[3], pfsph_real *const *scr,
                  pfsph_solve_stats *out)
{
    pcisph *P = state;
    pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    /* interactive: the neighbours once per step, as Solenthaler & Pajarola search them, instead
     * of two grid walks per correction (docs/interactive.md); grid walks when out of memory */
    const pfsph_nlist *L = c->nlist, *LB = c->nlist_b; /* the density stage's, when it built them */
    if (c->interactive && !(L && LB)) {
        L = &P->l;
        LB = &P->lb;
        if (pfsph__pcisph_lists(c, &P->l, &P->lb) != PFSPH_OK) L = LB = NULL;
    }
    const int lists = c->interactive && L && LB;
    /* the pairs kept from each density pass for its pressure pass; the list walks when out of memory */
    const int pairs = lists && pfsph__pcisph_pairs_reserve(&P->cf, L->start[n]) == PFSPH_OK &&
        pfsph__pcisph_pairs_reserve(&P->cb, LB->start[n]) == PFSPH_OK && reserve(&P->pn, &P->pn_cap, n) == PFSPH_OK;
    const double dt = c->dt;
    pfsph_real *apx = ap[0], *apy = ap[1], *apz = ap[2];
    pfsph_real *xp = scr[XP], *yp = scr[YP], *zp = scr[ZP], *ndp = scr[NDP], *er = scr[ERR];
    const pfsph_real nd0 = c->nd0;
    /* p += omega K (delta* - delta0) with K = m delta0^2 / (2 dt^2 (|sum gradW|^2 + sum |gradW|^2)):
     * Solenthaler & Pajarola 2009 rewritten for number densities, relaxed by omega = 0.5 as
     * IISPH relaxes its Jacobi iteration. The full K overshoots: a 2D tank at rest diverged
     * within 5 steps; with omega = 0.5 it settles (docs/solvers.md). The interactive mode
     * relaxes by 0.6: 13-16 % fewer iterations in its 3D scenes at the same contact angles
     * (0.7: 25 % fewer, the 150 degree drop 3 degrees further off; 0.9 took more steps;
     * docs/interactive.md). */
    const double omega = c->interactive ? PCISPH_OMEGA_INTERACTIVE : 0.5;
    const double kfac = omega * (double)nd0 * nd0 / (2 * dt * dt * P->proto);
    const pfsph_real fdt = (pfsph_real)dt, dt2 = (pfsph_real)(dt * dt);
    /* Pressure starts from zero every step. A warm start (last step's pressure) turns the
     * update into an integral controller across steps; measured on a 2D tank at rest it
     * kept ~1 J of sloshing energy instead of settling. */
    memset(apx, 0, n * sizeof(pfsph_real));
    memset(apy, 0, n * sizeof(pfsph_real));
    memset(apz, 0, n * sizeof(pfsph_real));
    memset(f->p, 0, n * sizeof(pfsph_real));
    int it = 0;
    double avg = 0, prev = INFINITY;
    while (it < P->max_iter) {
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) {
            xp[i] = f->x[i] + fdt * f->vx[i] + dt2 * (c->ax[i] + apx[i]);
            yp[i] = f->y[i] + fdt * f->vy[i] + dt2 * (c->ay[i] + apy[i]);
            zp[i] = f->z[i] + fdt * f->vz[i] + dt2 * (c->az[i] + apz[i]);
        }
        pfsph_real *const pred[3] = {xp, yp, zp};
        pfsph__halo(c, pred, 3); /* a distributed run: the owners' predictions of halo particles */
        if (pairs) pfsph__pcisph_density_pairs(c, L, LB, xp, yp, zp, ndp, &P->cf, &P->cb);
        else if (lists) pfsph__pcisph_density(c, L, LB, xp, yp, zp, ndp);
        else pfsph__number_density(c, xp, yp, zp, ndp);
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++) {
            pfsph_real e = ndp[i] - nd0;
            er[i] = e > 0 ? e / nd0 : 0;
            pfsph_real pn = f->p[i] + (pfsph_real)(kfac * (double)c->mass[f->phase[i]]) * e;
            f->p[i] = pn > 0 ? pn : 0;
        }
        pfsph_real *const dens[2] = {ndp, f->p};
        pfsph__halo(c, dens, 2);
        const size_t nall = pfsph__fluid_count(c);
        avg = nall ? pfsph__fluid_sum(c, er) / (double)nall : 0; /* the serial sum on any rank count */
        if (pairs) pfsph__pcisph_pressure_pairs(c, L, LB, ndp, f->p, &P->cf, &P->cb, P->pn, apx, apy, apz);
        else if (lists) pfsph__pcisph_pressure(c, L, LB, xp, yp, zp, ndp, f->p, apx, apy, apz);
        else pfsph__pressure_accel(c, xp, yp, zp, ndp, f->p, apx, apy, apz);
        it++;
        if (it >= P->min_iter && avg <= P->tol) break;
        /* interactive: an error that grows means the relaxed Jacobi diverges at this dt (a
         * wall's edge under a large step): more corrections would only add to it */
        if (lists && it >= P->min_iter && avg > prev) break;
        prev = avg;
    }
    out->iterations = it;
    out->density_err_avg = avg;
}

/* CFL on the flow speed alone; the force criterion on the non-pressure acceleration, because
 * PCISPH's pressure acceleration scales as 1/dt^2 and feeding it back would shrink dt step
 * after step; and the compression one step of acceleration causes (a dt^2 / d) held at 4% of
 * the tolerance, so that a few corrections suffice. With 10x that, a 2D tank at rest needed
 * dozens of iterations per step and diverged (docs/solvers.md). The interactive mode drops
 * that cap: it bound every step of the pair-force scenes, 15-20x below the force criterion,
 * and the iterations absorb it instead (docs/interactive.md). */
static double dt_limit(const void *state, const pfsph_ctx *ctx, double vmax, double amax, double amax_np)
{
    (void)amax;
    const pcisph *P = state;
    const double d = ctx->spacing;
    double dt = INFINITY;
    if (vmax > 0) dt = P->cfl * d / vmax;
    dt = fmin(dt, ctx->interactive ? pfsph__dt_force_interactive(d, amax_np) : pfsph__dt_force(d, amax_np));
    if (amax_np > 0 && !ctx->interactive) dt = fmin(dt, 0.2 * sqrt(P->tol * d / amax_np));
    return dt;
}

/* a blow-up only above 20 c and half a spacing in the step (pfsph__speed_bound_one_step) */
static double speed_bound(const void *state, const pfsph_ctx *ctx)
{
    return pfsph__speed_bound_one_step(((const pcisph *)state)->c, ctx);
}

/* below the acoustic step a smaller dt_max makes things worse */
static const char *hint(const void *state, const pfsph_ctx *ctx)
{
    const pcisph *P = state;
    if (ctx->dt > 0 && ctx->dt < P->cfl * (double)ctx->spacing / P->c)
        return "the time step is far below what PCISPH needs (it removes density errors within one step, so "
               "speeds grow as 1/dt): raise time.dt_max and time.dt_min, do not lower them";
    return "lower time.cfl or dt_max; check pairwise coefficients and viscosity";
}

static const char *ratio_advice(double ratio, int common_scale, char *buf, size_t len)
{
    (void)common_scale;
    (void)buf;
    (void)len;
    return ratio > 10.0 + 1e-9 ? "PCISPH is tested to 10 and diverged at 100 (docs/pairwise.md, \"Density "
                                 "ratios\"); use solver \"wcsph\" with \"pressure_scale\": \"common\""
                               : NULL;
}

const pfsph_solver_ops pfsph_solver_pcisph = {
    .name = "pcisph",
    .keys = keys,
    .nkeys = NKEYS,
    .check = check,
    .ratio_advice = ratio_advice,
    .nscratch = NSCR,
    .create = create,
    .destroy = destroy,
    .solve = solve,
    .dt_limit = dt_limit,
    .speed_bound = speed_bound,
    .hint = hint,
};

static double prototype(const pfsph_kernel *k, int dim, pfsph_real spacing)
{
    double gs[3] = {0, 0, 0}, gg = 0;
    int m = (int)(k->h / spacing) + 1;
    int mz = dim == 3 ? m : 0;
    for (int a = -m; a <= m; a++)
        for (int b = -m; b <= m; b++)
            for (int c = -mz; c <= mz; c++) {
                double dx = -a * (double)spacing, dy = -b * (double)spacing, dz = -c * (double)spacing;
                double r = sqrt(dx * dx + dy * dy + dz * dz);
                if (r <= 0 || r >= k->h) continue;
                double f = pfsph_kernel_dw_r(k, (pfsph_real)r);
                double g[3] = {f * dx, f * dy, f * dz};
                for (int t = 0; t < 3; t++) gs[t] += g[t];
                gg += g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
            }
    return gs[0] * gs[0] + gs[1] * gs[1] + gs[2] * gs[2] + gg;
}
