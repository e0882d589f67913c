/* Weakly compressible SPH: pressure from the Tait equation (DF Eq. 3), one force evaluation
 * per step, time step limited by the sound speed (Monaghan 1994; Becker & Teschner 2007). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/dist.h"
#include "core/reduce.h"
#include "physics/eos.h"
#include "physics/pressure.h"
#include "physics/solver.h"

typedef struct wcsph {
    double B, gamma, rho_common; /* Tait: p = B rho0 ((rho/rho0)^gamma - 1), B = c^2 / gamma */
    double c, c_fast, cfl;
} wcsph;

static int create(void **state, const pfsph_ctx *ctx, const pfsph_solver_config *cfg, pfsph_error *err)
{
    (void)ctx;
    wcsph *w = calloc(1, sizeof *w);
    if (!w) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    w->c = cfg->sound_speed;
    w->gamma = cfg->gamma;
    w->B = cfg->sound_speed * cfg->sound_speed / cfg->gamma;
    w->rho_common = cfg->rho_common;
    w->c_fast = cfg->c_fast;
    w->cfl = cfg->cfl;
    *state = w;
    return PFSPH_OK;
}

static void destroy(void *state) { free(state); }

static void eos(void *state, const pfsph_ctx *c)
{
    const wcsph *w = state;
    pfsph__tait(c, c->nd, w->B, w->gamma, w->rho_common, c->fluid->p);
}

/* the mean compression of the step (stats.csv) */
static void report(void *state, const pfsph_ctx *c, pfsph_real *const *scr, pfsph_solve_stats *out)
{
    (void)state;
    const size_t n = c->fluid->n;
    pfsph_real *er = scr[0];
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        pfsph_real e = c->nd[i] / c->nd0 - 1;
        er[i] = e > 0 ? e : 0;
    }
    const size_t nall = pfsph__fluid_count(c); /* the serial sum on any rank count */
    out->density_err_avg = nall ? pfsph__fluid_sum(c, er) / (double)nall : 0;
    out->iterations = 0;
}

static void solve(void *state, const pfsph_ctx *c, pfsph_real *const ap[3], pfsph_real *const *scr,
                  pfsph_solve_stats *out)
{
    pfsph_particles *f = c->fluid;
    eos(state, c);
    pfsph__pressure_accel(c, f->x, f->y, f->z, c->nd, f->p, ap[0], ap[1], ap[2]);
    report(state, c, scr, out);
}

/* acoustic CFL with the fastest sound speed, and the force criterion on the total acceleration */
static double dt_limit(const void *state, const pfsph_ctx *ctx, double vmax, double amax, double amax_np)
{
    (void)amax_np;
    const wcsph *w = state;
    const double d = ctx->spacing;
    double dt = INFINITY, vsig = vmax + w->c_fast;
    if (vsig > 0) dt = w->cfl * d / vsig;
    return fmin(dt, pfsph__dt_force(d, amax));
}

static double speed_bound(const void *state, const pfsph_ctx *ctx)
{
    (void)ctx;
    return ((const wcsph *)state)->c;
}

static const char *hint(const void *state, const pfsph_ctx *ctx)
{
    (void)state;
    (void)ctx;
    return "the time step is too large for the stiffness: lower time.cfl or dt_max, or raise solver.sound_speed";
}

static const char *ratio_advice(double ratio, int common_scale, char *buf, size_t len)
{
    if (common_scale) {
        snprintf(buf, len,
                 "one pressure scale, the lightest phase's sound speed is %.3gx the solver's (the time step "
                 "shrinks by as much)",
                 sqrt(ratio));
        return buf;
    }
    if (ratio > 100.0 + 1e-9)
        return "per-phase pressure scales are tested to 100 and blew up at 1000 (docs/pairwise.md, \"Density "
               "ratios\"); use \"pressure_scale\": \"common\"";
    return NULL;
}

const pfsph_solver_ops pfsph_solver_wcsph = {
    .name = "wcsph",
    .ratio_advice = ratio_advice,
    .nscratch = 1,
    .scratch_per_call = 1, /* report's per-particle errors, summed at once */
    .eos = eos,
    .report = report,
    .create = create,
    .destroy = destroy,
    .solve = solve,
    .dt_limit = dt_limit,
    .speed_bound = speed_bound,
    .hint = hint,
};
