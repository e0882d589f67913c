/* Divergence-free SPH (Bender & Koschier 2015, 2017) in the number-density form of PF Eq. 23:
 * a divergence solve on the velocities at the start of the step and a density solve on the
 * predicted velocities, both Jacobi iterations on a clamped pressure (p >= 0) with the DFSPH
 * factor of each particle; time steps limited by the CFL condition only (no sound speed).
 * Derivation and choices: docs/solvers.md, "DFSPH". */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/reduce.h"
#include "physics/density.h"
#include "physics/pressure.h"
#include "physics/solver.h"

#define OMEGA 0.5
/* a_np dt^2 / d per step. On the 2D tank at tolerance 0.001: 0.004 settles to vmax 0.004 m/s
 * in 2 s (40 sweeps a step at rest); 0.001 to 0.010 m/s (10 sweeps, half the step). At 0.004
 * the 7k dam break's steps are limited by the CFL condition after the first 0.1 s. */
#define EPS_STEP 0.004

enum { FAC, VX, VY, VZ, RATE, ERR, PV, AX, AY, AZ, NSCR };

typedef struct dfsph {
    double tol, div_tol, cfl, c;
    int min_iter, max_iter, div_max_iter;
    double full; /* neighbours (fluid + boundary) of a particle inside the fluid */
} dfsph;

static int create(void **state, const pfsph_ctx *ctx, const pfsph_solver_config *cfg, pfsph_error *err)
{
    dfsph *D = calloc(1, sizeof *D);
    if (!D) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    D->tol = cfg->tolerance;
    D->min_iter = cfg->min_iter;
    D->max_iter = cfg->max_iter;
    D->div_tol = cfg->div_tolerance;
    D->div_max_iter = cfg->div_max_iter;
    D->cfl = cfg->cfl;
    D->c = cfg->sound_speed;
    const double q = (double)ctx->h / (double)ctx->spacing;
    D->full = ctx->dim == 2 ? 3.14159265358979 * q * q : 4.18879020478639 * q * q * q;
    *state = D;
    return PFSPH_OK;
}

static void destroy(void *state) { free(state); }

/* DFSPH factor 1 / A_i with A_i = |g_i|^2 / m_i + sum_j |grad W_ij|^2 / m_j, g_i = sum_j grad
 * W_ij + (1/V0) sum_b V_b grad W_ib: how much one unit of p_i / delta_i^2 on i (and its
 * reaction on the neighbours) changes delta_i per dt^2 (Bender & Koschier 2017, Eq. 9 for
 * number densities). A particle with fewer than 60 % of a full neighbourhood gets factor 0 in
 * the divergence solve only, through the sign of fac (SPlisHSPlasH's 20 of 33 in 3D): its
 * velocity divergence at a free surface is not a compression. */
static void factors(const dfsph *D, const pfsph_ctx *ctx, pfsph_real *fac)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const double few = 0.6 * D->full;
    const size_t n = f->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        pfsph_ranges r;
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        double gx = 0, gy = 0, gz = 0, s2 = 0;
        int nn = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2 || j == i) continue;
                double w = pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                double ax = w * dx, ay = w * dy, az = w * dz;
                gx += ax;
                gy += ay;
                gz += az;
                s2 += (ax * ax + ay * ay + az * az) / (double)ctx->mass[f->phase[j]];
                nn++;
            }
        if (b->n) {
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2) continue;
                    double w = (double)(b->aux[j] * inv_v0) * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                    gx += w * dx;
                    gy += w * dy;
                    gz += w * dz;
                    nn++;
                }
        }
        double A = (gx * gx + gy * gy + gz * gz) / (double)ctx->mass[f->phase[i]] + s2;
        double fi = A > 1e-30 * s2 && A > 0 ? 1.0 / A : 0.0;
        fac[i] = (pfsph_real)(nn + 1 < few ? -fi : fi);
    }
}

/* v_out = v + dt (a_extra + a_p(p)) for the pressure-like field p (PF Eq. 4 form). */
static void corrected_velocity(const pfsph_ctx *c, const pfsph_real *p, const pfsph_real *ex,
                               const pfsph_real *ey, const pfsph_real *ez, pfsph_real *const a[3],
                               pfsph_real *vx, pfsph_real *vy, pfsph_real *vz)
{
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    const pfsph_real dt = (pfsph_real)c->dt;
    pfsph__pressure_accel(c, f->x, f->y, f->z, c->nd, p, a[0], a[1], a[2]);
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        vx[i] = f->vx[i] + dt * ((ex ? ex[i] : 0) + a[0][i]);
        vy[i] = f->vy[i] + dt * ((ey ? ey[i] : 0) + a[1][i]);
        vz[i] = f->vz[i] + dt * ((ez ? ez[i] : 0) + a[2][i]);
    }
}

/* One Jacobi update of the clamped pressure p from the residual: density mode (res = predicted
 * delta - delta0, over dt^2) or divergence mode (res = D delta / Dt, over dt). Returns the mean
 * compression the residual stands for, relative to delta0 and over one step. */
static double update(const pfsph_ctx *c, int divergence, const pfsph_real *rate, const pfsph_real *fac,
                     pfsph_real *p, pfsph_real *err)
{
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    const double dt = c->dt, nd0 = c->nd0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        double fi = fac[i];
        double res; /* compression over the step [1/m^d] */
        if (divergence) {
            res = fi > 0 ? dt * (double)rate[i] : 0; /* deficient neighbourhoods: no constraint */
            if (fi < 0) fi = 0;
        } else {
            res = (double)c->nd[i] + dt * (double)rate[i] - nd0;
            fi = fabs(fi);
        }
        /* p_i / delta_i^2 grows by omega res / (dt^2 A_i) (Bender & Koschier 2017, Eqs. 9,
         * 12). A_i counts only particle i's own pressure; in a Jacobi sweep the neighbours push
         * too, and omega = 1 overshot: a 2D tank at rest diverged at step 3. omega = 0.5, as
         * IISPH and our PCISPH relax. */
        double nd = c->nd[i];
        double pn = (double)p[i] + OMEGA * nd * nd * res * fi / (dt * dt);
        p[i] = (pfsph_real)(pn > 0 ? pn : 0);
        err[i] = (pfsph_real)(res > 0 ? res / nd0 : 0);
    }
    return n ? pfsph__sum(err, n) / (double)n : 0;
}

/* Divergence solve: make D delta / Dt = 0 where the fluid compresses, correcting v in place.
 * The divergence pressure is kept in fluid->aux between steps (it follows the particles through
 * the grid sort and into checkpoints); half of it warm-starts the next step. */
static void pre_forces(void *state, const pfsph_ctx *c, pfsph_real *const *scr, pfsph_solve_stats *out)
{
    const dfsph *D = state;
    pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    factors(D, c, scr[FAC]);
    out->div_iterations = 0;
    if (D->div_max_iter <= 0 || !n) return;
    pfsph_real *pv = f->aux;
    pfsph_real *const a[3] = {scr[AX], scr[AY], scr[AZ]};
    for (size_t i = 0; i < n; i++) pv[i] *= (pfsph_real)0.5;
    int it = 0;
    for (;;) {
        corrected_velocity(c, pv, NULL, NULL, NULL, a, scr[VX], scr[VY], scr[VZ]);
        if (it >= D->div_max_iter) break;
        pfsph__number_density_rate(c, scr[VX], scr[VY], scr[VZ], scr[RATE]);
        double avg = update(c, 1, scr[RATE], scr[FAC], pv, scr[ERR]);
        it++;
        if (avg <= D->div_tol) {
            /* the velocities and the kept pressure must agree: apply the last update */
            corrected_velocity(c, pv, NULL, NULL, NULL, a, scr[VX], scr[VY], scr[VZ]);
            break;
        }
    }
    memcpy(f->vx, scr[VX], n * sizeof(pfsph_real));
    memcpy(f->vy, scr[VY], n * sizeof(pfsph_real));
    memcpy(f->vz, scr[VZ], n * sizeof(pfsph_real));
    out->div_iterations = it;
}

/* Density solve: the predicted number density delta_i + dt D delta_i / Dt(v*) reaches delta0,
 * v* = v + dt (a_nonpressure + a_p). Warm start: half of last step's pressure, which is
 * physical and so needs no rescaling when dt changes. */
static void solve(void *state, const pfsph_ctx *c, pfsph_real *const ap[3], pfsph_real *const *scr,
                  pfsph_solve_stats *out)
{
    const dfsph *D = state;
    pfsph_particles *f = c->fluid;
    int it = 0;
    double avg = 0;
    /* Half the last pressure, not all of it: a full warm start let pressure modes that move
     * no density (the near-null space of div grad) pile up from step to step; on the 2D tank
     * at rest they drove vmax to 0.5-2 m/s (docs/solvers.md, "DFSPH"). */
    for (size_t i = 0; i < f->n; i++) f->p[i] *= (pfsph_real)0.5;
    for (;;) {
        corrected_velocity(c, f->p, c->ax, c->ay, c->az, ap, scr[VX], scr[VY], scr[VZ]);
        if (it >= D->max_iter) break;
        pfsph__number_density_rate(c, scr[VX], scr[VY], scr[VZ], scr[RATE]);
        avg = update(c, 0, scr[RATE], scr[FAC], f->p, scr[ERR]);
        it++;
        if (it >= D->min_iter && avg <= D->tol) {
            /* the last update is already within tolerance: its accelerations are the ones */
            corrected_velocity(c, f->p, c->ax, c->ay, c->az, ap, scr[VX], scr[VY], scr[VZ]);
            break;
        }
    }
    out->iterations = it;
    out->density_err_avg = avg;
}

/* The wall felt both solves' pressures this step: their sum is what a body must feel back. */
static const pfsph_real *wall_pressure(void *state, const pfsph_ctx *c, pfsph_real *const *scr)
{
    (void)state;
    const pfsph_particles *f = c->fluid;
    pfsph_real *pw = scr[PV];
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < f->n; i++) pw[i] = f->p[i] + f->aux[i];
    return pw;
}

/* CFL on the flow speed, and the displacement the non-pressure forces cause in one step held
 * at a_np dt^2 <= EPS_STEP d: the Jacobi solve has to undo it within the step. No acoustic
 * limit. (This replaces the force criterion 0.25 sqrt(d / a), which it always undercuts.) */
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

const pfsph_solver_ops pfsph_solver_dfsph = {
    .name = "dfsph",
    .nscratch = NSCR,
    .create = create,
    .destroy = destroy,
    .pre_forces = pre_forces,
    .solve = solve,
    .wall_pressure = wall_pressure,
    .dt_limit = dt_limit,
    .speed_bound = speed_bound,
    .hint = hint,
};
