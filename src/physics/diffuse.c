/* Diffuse material of Liu et al. 2018 (DF Sections 4-5, Algorithm 1 lines 12-26): generation
 * from the diffusion entropy (Eqs. 9-16), emission in a cylinder (Eqs. 17-22), one-way coupling
 * through the fluid velocity field (Eqs. 23-28) and lifetime (Eq. 29). Typos resolved as in
 * NOTES items 13-19; the choices are written down in docs/diffuse.md. */
#include "pfsph/diffuse.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dist.h"
#include "pfsph/rng.h"
#include "physics/stages.h"

#define TWO_PI 6.283185307179586

/* rng streams: stream 0 decides the count of an emitter (stochastic rounding, NOTES 15);
 * stream 1 + k gives the four uniforms of its k-th particle. */
#define STREAM_COUNT 0u
#define STREAM_EMIT 1u

struct pfsph_diffuse {
    pfsph_diffuse_params p;
    int foam_min, foam_max;        /* resolved thresholds (NOTES 18) */
    bool liquid[PFSPH_MAX_PHASES]; /* fluid phases that emit and couple (gas phases do not) */
    bool all_liquid;               /* no gas phase: the per-neighbour phase test can go */
    pfsph_particles ps;
    /* [0, nold): the particles of the last step's sort that stayed; [nold, n): the step's new
     * ones, in id order. Only a distributed run reads it (the global order, docs/cluster.md). */
    size_t nold;
    uint64_t created, refused;
    uint32_t *emit; /* per fluid particle: count, then exclusive prefix (scratch) */
    size_t emit_cap;
    /* The step's arrays lent for one pfsph_diffuse_step_in (NULL otherwise): start-of-step
     * positions and emit counts in the simulation's per-particle scratch instead of 16 B per
     * fluid particle of the module's own (issue 28) */
    pfsph_real *lent_old[3];
    uint32_t *lent_emit;
    uint8_t *keep; /* per diffuse particle (scratch) */
    size_t keep_cap;
    pfsph_real *ox, *oy, *oz;             /* per fluid particle: start-of-step positions (own or lent) */
    pfsph_real *own_ox, *own_oy, *own_oz; /* the module's own, when nothing is lent */
    size_t old_cap;
    uint32_t *perm, *key, *perm2, *key2; /* per diffuse particle: spatial sort (scratch) */
    size_t perm_cap;
    void *tmp; /* permutation scratch, 4 bytes per diffuse particle */
    size_t tmp_cap;
    uint32_t *mkey; /* per diffuse particle: its cell, for a distributed run's exchange */
    size_t mkey_cap;
};

int pfsph_diffuse_create(pfsph_diffuse **out, const pfsph_ctx *ctx, pfsph_error *err)
{
    *out = NULL;
    if (!ctx || !ctx->diffuse) return pfsph_fail(err, PFSPH_EINPUT, "diffuse: no scene in the context");
    pfsph_diffuse *d = calloc(1, sizeof(*d));
    if (!d) return pfsph_fail(err, PFSPH_ENOMEM, "diffuse: out of memory");
    d->p = *ctx->diffuse;
    if (d->p.max_particles < 0) d->p.max_particles = 0;
    pfsph_diffuse_thresholds(&d->p, ctx->dim, (double)ctx->h, (double)ctx->spacing, &d->foam_min, &d->foam_max);
    for (int k = 0; k < PFSPH_MAX_PHASES; k++)
        d->liquid[k] = k >= ctx->nphases || ctx->phases[k].kind != PFSPH_PHASE_GAS;
    d->all_liquid = true;
    for (int k = 0; k < PFSPH_MAX_PHASES; k++) d->all_liquid = d->all_liquid && d->liquid[k];
    size_t cap = (size_t)d->p.max_particles < 4096 ? (size_t)d->p.max_particles : 4096;
    if (pfsph_particles_init(&d->ps, cap) != PFSPH_OK) {
        free(d);
        return pfsph_fail(err, PFSPH_ENOMEM, "diffuse: out of memory");
    }
    *out = d;
    return PFSPH_OK;
}

void pfsph_diffuse_destroy(pfsph_diffuse *d)
{
    if (!d) return;
    pfsph_particles_free(&d->ps);
    free(d->emit);
    free(d->keep);
    free(d->own_ox);
    free(d->own_oy);
    free(d->own_oz);
    free(d->perm);
    free(d->key);
    free(d->perm2);
    free(d->key2);
    free(d->tmp);
    free(d->mkey);
    free(d);
}

const pfsph_particles *pfsph_diffuse_particles(const pfsph_diffuse *d) { return &d->ps; }

void pfsph_diffuse_counts(const pfsph_diffuse *d, size_t counts[3])
{
    counts[0] = counts[1] = counts[2] = 0;
    for (size_t i = 0; i < d->ps.n; i++)
        if (d->ps.phase[i] < PFSPH_DIFFUSE_NTYPES) counts[d->ps.phase[i]]++;
}

void pfsph_diffuse_totals(const pfsph_diffuse *d, uint64_t *created, uint64_t *refused)
{
    if (created) *created = d->created;
    if (refused) *refused = d->refused;
}

long pfsph_diffuse_add(pfsph_diffuse *d, const pfsph_real x[3], const pfsph_real v[3], int type, pfsph_real lifetime)
{
    if ((long)d->ps.n >= d->p.max_particles || type < 0 || type >= PFSPH_DIFFUSE_NTYPES) return -1;
    long i = pfsph_particles_push(&d->ps, x, v, (uint8_t)type);
    if (i < 0) return -1;
    d->ps.aux[i] = lifetime;
    d->created++;
    return i;
}

static inline int classify(const pfsph_diffuse *d, int count)
{
    if (count < d->foam_min) return PFSPH_DIFFUSE_SPRAY;
    if (count > d->foam_max) return PFSPH_DIFFUSE_BUBBLE;
    return PFSPH_DIFFUSE_FOAM;
}

/* Fluid positions at the start of the step: the integrator moved x by dt v (symplectic Euler),
 * so x(t) = x(t+dt) - dt v(t+dt), the positions the grid was built from (NOTES 19). Stored once
 * per step in d->ox.. (pfsph_diffuse_step); `old` false selects the current positions. */
static inline void fluid_pos(const pfsph_diffuse *d, const pfsph_particles *f, bool old, const pfsph_real **x,
                             const pfsph_real **y, const pfsph_real **z)
{
    *x = old ? d->ox : f->x;
    *y = old ? d->oy : f->y;
    *z = old ? d->oz : f->z;
}

/* Eq. 13 with lambda = 1 - vhat_ij . xhat_ij (NOTES 13) and W^D of Eq. 11, over liquid
 * neighbours at the start-of-step positions; stops early once the sum reaches `stop` (phi of
 * Eq. 14 saturates there, so the result of Eq. 15 is unchanged). */
static double velocity_difference(const pfsph_diffuse *d, const pfsph_ctx *ctx, size_t i, double stop)
{
    const pfsph_particles *f = ctx->fluid;
    const pfsph_real *X, *Y, *Z;
    fluid_pos(d, f, true, &X, &Y, &Z);
    const pfsph_real h = ctx->h, h2 = h * h, inv_h = 1 / h;
    const pfsph_real xi = X[i], yi = Y[i], zi = Z[i];
    const pfsph_real vxi = f->vx[i], vyi = f->vy[i], vzi = f->vz[i];
    pfsph_ranges rg;
    pfsph_grid_ranges(ctx->grid, xi, yi, zi, &rg);
    double sum = 0.0;
    for (int r = 0; r < rg.n; r++) {
        uint32_t e = rg.e[r] < f->n ? rg.e[r] : (uint32_t)f->n;
        pfsph_real part = 0;
        for (uint32_t j = rg.b[r]; j < e; j++) {
            pfsph_real dx = xi - X[j], dy = yi - Y[j], dz = zi - Z[j];
            pfsph_real r2 = dx * dx + dy * dy + dz * dz;
            if (r2 >= h2 || r2 <= 0 || j == i || !d->liquid[f->phase[j]]) continue;
            pfsph_real ux = vxi - f->vx[j], uy = vyi - f->vy[j], uz = vzi - f->vz[j];
            pfsph_real u2 = ux * ux + uy * uy + uz * uz;
            if (u2 <= 0) continue;
            pfsph_real rr = sqrt(r2), inv_r = 1 / rr;
            /* |v_ij| lambda = |v_ij| - v_ij . xhat_ij */
            part += (sqrt(u2) - (ux * dx + uy * dy + uz * dz) * inv_r) * (1 - rr * inv_h);
        }
        sum += (double)part;
        if (sum >= stop) break;
    }
    return sum;
}

static inline double kinetic_energy(const pfsph_diffuse *d, const pfsph_ctx *ctx, size_t i)
{
    const pfsph_particles *f = ctx->fluid;
    double m = d->p.energy_mass > 0 ? d->p.energy_mass : (double)ctx->mass[f->phase[i]];
    double v2 = (double)f->vx[i] * f->vx[i] + (double)f->vy[i] * f->vy[i] + (double)f->vz[i] * f->vz[i];
    return 0.5 * m * v2; /* Eq. 9 */
}

static int prepare_old(pfsph_diffuse *d, const pfsph_ctx *ctx);
static void distribute(pfsph_diffuse *d, const pfsph_ctx *ctx, size_t from);

void pfsph_diffuse_potentials(pfsph_diffuse *d, const pfsph_ctx *ctx, size_t i, double *v_diff, double *energy,
                              double *rate)
{
    if (prepare_old(d, ctx) != PFSPH_OK) {
        *v_diff = *energy = *rate = 0;
        return;
    }
    double e = kinetic_energy(d, ctx, i);
    double v = d->liquid[ctx->fluid->phase[i]] ? velocity_difference(d, ctx, i, INFINITY) : 0;
    if (v_diff) *v_diff = v;
    if (energy) *energy = e;
    if (rate)
        *rate = d->liquid[ctx->fluid->phase[i]] ? pfsph_diffuse_phi(v, d->p.phi_v_min, d->p.phi_v_max) *
                pfsph_diffuse_phi(e, d->p.phi_e_min, d->p.phi_e_max)
                                                : 0.0; /* Eq. 15 */
}

/* Number of particles fluid particle i emits this step: Eq. 16 with stochastic rounding. */
static uint32_t emit_count(const pfsph_diffuse *d, const pfsph_ctx *ctx, size_t i)
{
    const pfsph_particles *f = ctx->fluid;
    if (!d->liquid[f->phase[i]]) return 0;
    double pe = pfsph_diffuse_phi(kinetic_energy(d, ctx, i), d->p.phi_e_min, d->p.phi_e_max);
    if (pe <= 0.0) return 0; /* skips the neighbour loop for most particles */
    /* The Bernoulli trial's uniform first (counter-based: drawing it early changes nothing).
     * phi_v <= 1, so n_d <= pe k_max dt =: nmax (the same products, rounded monotonically).
     * When nmax < 1, floor(n_d) = 0 and the trial u < n_d fails for any u >= nmax whatever
     * v_diff is: the neighbour loop of Eqs. 10-13 is skipped and the count (0) is the same bit
     * for bit. With k_max dt ~ 0.01-0.1 this skips the loop for 90-99% of the candidates. */
    uint32_t u[4];
    pfsph_rng_u32x4(ctx->seed, f->id[i], ctx->step, STREAM_COUNT, u);
    const double un = pfsph_rng_to_unit(u[0]);
    const double nmax = pe * d->p.sampling_rate * ctx->dt;
    if (nmax < 1.0 && un >= nmax) return 0;
    double v = velocity_difference(d, ctx, i, d->p.phi_v_max);
    double rate = pe * pfsph_diffuse_phi(v, d->p.phi_v_min, d->p.phi_v_max);
    double nd = rate * d->p.sampling_rate * ctx->dt;
    if (nd <= 0.0) return 0;
    if (nd > 1e6) nd = 1e6;
    double fl = floor(nd);
    return (uint32_t)fl + (un < nd - fl ? 1u : 0u);
}

/* Eqs. 17-22 with NOTES 16: the k-th particle of emitter i at slot s of the diffuse set. */
static void emit_one(pfsph_diffuse *d, const pfsph_ctx *ctx, size_t i, uint32_t k, size_t s)
{
    const pfsph_particles *f = ctx->fluid;
    const double dt = ctx->dt;
    double u[4];
    pfsph_rng_uniform4(ctx->seed, f->id[i], ctx->step, STREAM_EMIT + k, u);
    const double xf[3] = {d->ox[i], d->oy[i], d->oz[i]};
    double vf[3] = {f->vx[i], f->vy[i], f->vz[i]};
    double sp = sqrt(vf[0] * vf[0] + vf[1] * vf[1] + vf[2] * vf[2]);
    double vh[3] = {0, 1, 0};
    if (sp > 0) vh[0] = vf[0] / sp, vh[1] = vf[1] / sp, vh[2] = vf[2] / sp;
    double r0 = d->p.emit_radius > 0 ? d->p.emit_radius : 0.5 * (double)ctx->spacing;
    double R = d->p.emit_radius_scale * r0;
    double H = d->p.emit_height_scale * sp * dt * u[2]; /* Eq. 17 */
    double off[3];
    if (ctx->dim == 2) {
        /* The cylinder's cross-section in the plane: a segment across the path. */
        double a = R * (2.0 * u[0] - 1.0);
        off[0] = -vh[1] * a;
        off[1] = vh[0] * a;
        off[2] = 0;
    } else {
        /* Orthonormal e1, e2 perpendicular to vhat (Eq. 20 rotates e1 by theta about vhat;
         * cos(theta) e1 + sin(theta) e2 is the same vector). */
        double ax[3] = {0, 0, 0};
        double m0 = fabs(vh[0]), m1 = fabs(vh[1]), m2 = fabs(vh[2]);
        ax[m0 <= m1 && m0 <= m2 ? 0 : (m1 <= m2 ? 1 : 2)] = 1.0;
        double e1[3] = {vh[1] * ax[2] - vh[2] * ax[1], vh[2] * ax[0] - vh[0] * ax[2], vh[0] * ax[1] - vh[1] * ax[0]};
        double n1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
        for (int a = 0; a < 3; a++) e1[a] /= n1;
        double e2[3] = {vh[1] * e1[2] - vh[2] * e1[1], vh[2] * e1[0] - vh[0] * e1[2], vh[0] * e1[1] - vh[1] * e1[0]};
        double ri = R * sqrt(u[0]); /* Eq. 19, sqrt: uniform over the disc */
        double th = TWO_PI * u[1];  /* Eq. 18 */
        double c = ri * cos(th), sn = ri * sin(th);
        for (int a = 0; a < 3; a++) off[a] = c * e1[a] + sn * e2[a];
    }
    pfsph_particles *ps = &d->ps;
    /* Eq. 21 from x_f(t) along the path; Eq. 22 with v_f (NOTES 16): the radial offset in m
     * reads as a spread velocity in m/s, as in Ihmsen et al. 2012. */
    ps->x[s] = (pfsph_real)(xf[0] + off[0] + H * vh[0]);
    ps->y[s] = (pfsph_real)(xf[1] + off[1] + H * vh[1]);
    ps->z[s] = (pfsph_real)(xf[2] + off[2] + H * vh[2]);
    ps->vx[s] = (pfsph_real)(off[0] + vf[0]);
    ps->vy[s] = (pfsph_real)(off[1] + vf[1]);
    ps->vz[s] = (pfsph_real)(off[2] + vf[2]);
    ps->rho[s] = 0;
    ps->p[s] = 0;
    ps->aux[s] = (pfsph_real)(d->p.lifetime_min + (d->p.lifetime_max - d->p.lifetime_min) * u[3]);
    ps->phase[s] = PFSPH_DIFFUSE_SPRAY;
}

#define SAMPLE_BLOCK 128

/* Liquid neighbours within h of (x, y, z) and the kernel sums of Eq. 23. `old` selects the
 * start-of-step fluid positions (exact for the grid) or the current ones. */
static int fluid_sample(const pfsph_diffuse *d, const pfsph_ctx *ctx, const pfsph_real xd[3], bool old, double *sw,
                        double sv[3])
{
    const pfsph_particles *f = ctx->fluid;
    const pfsph_real *X, *Y, *Z;
    fluid_pos(d, f, old, &X, &Y, &Z);
    const pfsph_real h2 = ctx->h * ctx->h;
    pfsph_ranges rg;
    pfsph_grid_ranges(ctx->grid, xd[0], xd[1], xd[2], &rg);
    int count = 0;
    double w = 0, s0 = 0, s1 = 0, s2 = 0;
    /* Per block of candidates: squared distances (vectorised), a branch-free compaction of the
     * indices within h (about 1 in 7 of the 27-cell candidates), their kernel weights
     * (vectorised), then the sums over those alone in the order a single loop would take them:
     * the same bits as that loop, without its mispredicted branch per candidate. */
    uint32_t nb[SAMPLE_BLOCK];
    pfsph_real r2b[SAMPLE_BLOCK], r2c[SAMPLE_BLOCK], wb[SAMPLE_BLOCK];
    const pfsph_real inv_h = ctx->kern.inv_h, sigma = ctx->kern.sigma;
    const bool all = d->all_liquid;
    const pfsph_real x0 = xd[0], y0 = xd[1], z0 = xd[2];
    for (int r = 0; r < rg.n; r++) {
        uint32_t e = rg.e[r] < f->n ? rg.e[r] : (uint32_t)f->n;
        pfsph_real pw = 0, p0 = 0, p1 = 0, p2 = 0;
        for (uint32_t b = rg.b[r]; b < e; b += SAMPLE_BLOCK) {
            const int mm = e - b < SAMPLE_BLOCK ? (int)(e - b) : SAMPLE_BLOCK;
            const pfsph_real *xb = X + b, *yb = Y + b, *zb = Z + b;
            for (int k = 0; k < mm; k++) { /* vectorises */
                pfsph_real dx = x0 - xb[k], dy = y0 - yb[k], dz = z0 - zb[k];
                r2b[k] = dx * dx + dy * dy + dz * dz;
            }
            int m = 0;
            for (int k = 0; k < mm; k++) {
                nb[m] = (uint32_t)k;
                r2c[m] = r2b[k];
                m += r2b[k] < h2;
            }
            /* pfsph_kernel_w(sqrt(r2)), branch-free; element-wise, so vectorising it changes no
             * bit */
#pragma omp simd
            for (int k = 0; k < m; k++) {
                pfsph_real q = pfsph_sqrt(r2c[k]) * inv_h, q2 = q * q, t = 1 - q;
                t = t > 0 ? t : 0; /* W = 0 for q >= 1 (r2 < h2 may round to q = 1) */
                pfsph_real wi = sigma * ((pfsph_real)6 * (q2 * q - q2) + (pfsph_real)1);
                pfsph_real wo = sigma * (pfsph_real)2 * t * t * t;
                wb[k] = q <= (pfsph_real)0.5 ? wi : wo;
            }
            for (int k = 0; k < m; k++) {
                const uint32_t j = b + nb[k];
                if (!all && !d->liquid[f->phase[j]]) continue;
                count++;
                const pfsph_real wj = wb[k];
                pw += wj;
                p0 += wj * f->vx[j];
                p1 += wj * f->vy[j];
                p2 += wj * f->vz[j];
            }
        }
        w += pw;
        s0 += p0;
        s1 += p1;
        s2 += p2;
    }
    *sw = w;
    sv[0] = s0;
    sv[1] = s1;
    sv[2] = s2;
    return count;
}

/* Grow a scratch buffer to hold n elements (geometric, so steady state never allocates). */
static void *ensure(void *buf, size_t *cap, size_t n, size_t elem, bool *ok)
{
    *ok = true;
    if (n <= *cap) return buf;
    size_t c = *cap ? *cap : 1024;
    while (c < n) c *= 2;
    void *q = realloc(buf, c * elem);
    if (!q) {
        *ok = false;
        return buf;
    }
    *cap = c;
    return q;
}

/* Algorithm 1 lines 18-26 (over diffuse particles, NOTES 17): classify by the fluid neighbour
 * count, Eq. 24 with the type's weights, Eq. 25, Eq. 29; mark the expired and the escaped. */
static void advect(pfsph_diffuse *d, const pfsph_ctx *ctx)
{
    pfsph_particles *ps = &d->ps;
    const double dt = ctx->dt;
    const double *g = ctx->gravity;
    const double *lo = ctx->domain_min, *hi = ctx->domain_max;
    const long n = (long)ps->n;
#pragma omp parallel for schedule(dynamic, 256)
    for (long i = 0; i < n; i++) {
        const pfsph_real xd[3] = {ps->x[i], ps->y[i], ps->z[i]};
        double sw, sv[3];
        int cnt = fluid_sample(d, ctx, xd, true, &sw, sv);
        int type = classify(d, cnt);
        const pfsph_diffuse_coupling *c = &d->p.type[type];
        double v[3] = {ps->vx[i], ps->vy[i], ps->vz[i]};
        double kg = (c->k_ext - c->k_b) * dt; /* Eq. 24: k_ext g dt - k_b g dt */
        for (int a = 0; a < 3; a++) {
            /* Eq. 23; without fluid neighbours there is no field to follow. */
            double vt = sw > 0 ? sv[a] / sw : v[a];
            v[a] = v[a] + kg * g[a] + c->k_cp * (vt - v[a]);
        }
        if (ctx->dim == 2) v[2] = 0;
        ps->vx[i] = (pfsph_real)v[0];
        ps->vy[i] = (pfsph_real)v[1];
        ps->vz[i] = (pfsph_real)v[2];
        ps->x[i] = (pfsph_real)((double)xd[0] + dt * (double)ps->vx[i]); /* Eq. 25 */
        ps->y[i] = (pfsph_real)((double)xd[1] + dt * (double)ps->vy[i]);
        ps->z[i] = (pfsph_real)((double)xd[2] + dt * (double)ps->vz[i]);
        ps->aux[i] = (pfsph_real)((double)ps->aux[i] - c->k_t * dt); /* Eq. 29 */
        ps->phase[i] = (uint8_t)type;
        double p[3] = {ps->x[i], ps->y[i], ps->z[i]};
        bool inside = true;
        for (int a = 0; a < ctx->dim; a++)
            if (!(p[a] >= lo[a] && p[a] <= hi[a])) inside = false;
        /* The paper has no collision term: foam and spray following the fluid's velocity leak
         * through walls (5.5-6.6% of live particles ended below the floor or outside the tank
         * in the dam-break previews). One that has entered a solid, closer than d/2 to one of
         * its particles (the wall's surface lies d/2 outside its first layer), is removed, as
         * one that leaves the domain. */
        if (inside && ctx->boundary && ctx->boundary->n && ctx->bgrid) {
            const pfsph_particles *b = ctx->boundary;
            const pfsph_real r2max = (pfsph_real)0.25 * ctx->spacing * ctx->spacing;
            pfsph_ranges rb;
            pfsph_grid_ranges(ctx->bgrid, ps->x[i], ps->y[i], ps->z[i], &rb);
            for (int q = 0; q < rb.n && inside; q++)
                for (uint32_t j = rb.b[q]; j < rb.e[q]; j++) {
                    pfsph_real dx = ps->x[i] - b->x[j], dy = ps->y[i] - b->y[j], dz = ps->z[i] - b->z[j];
                    if (dx * dx + dy * dy + dz * dz < r2max) {
                        inside = false;
                        break;
                    }
                }
        }
        d->keep[i] = ps->aux[i] > 0 && inside;
    }
}

/* Stable in-place removal of the particles not kept (order, hence ids' order, preserved). */
static void compact(pfsph_diffuse *d)
{
    pfsph_particles *ps = &d->ps;
    size_t j = 0;
    for (size_t i = 0; i < ps->n; i++) {
        if (!d->keep[i]) continue;
        if (j != i) {
            for (int k = 0; k < PFSPH_NFIELDS; k++) ps->f[k][j] = ps->f[k][i];
            ps->phase[j] = ps->phase[i];
            ps->id[j] = ps->id[i];
        }
        j++;
    }
    ps->n = j;
}

/* Algorithm 1 lines 12-17. Counts per emitter in parallel, an exclusive prefix in fluid order
 * (deterministic: the grid order is), then each emitter writes its own slots. New ids follow
 * the slots. Beyond max_particles the rest is refused (later emitters in fluid order first).
 * Distributed: each rank's emitters are its owned fluid particles, a slice of the fluid order,
 * so the slots, ids and the cap follow from the counts' prefix over the ranks; every rank takes
 * the same branches (global counts), and the new particles go to the owners of their cells
 * before they are labelled (the labels read the fluid around them). */
static void generate(pfsph_diffuse *d, const pfsph_ctx *ctx)
{
    const pfsph_particles *f = ctx->fluid;
    pfsph_dist *D = ctx->dist;
    size_t lo, hi;
    pfsph__owned(ctx, &lo, &hi);
    const uint64_t nmine = d->ps.n;
    uint64_t nall = nmine, nbefore = 0; /* the live particles of all ranks */
    if (D) D->scan(D, &nmine, 1, &nbefore, &nall);
    size_t room = (uint64_t)d->p.max_particles > nall ? (size_t)((uint64_t)d->p.max_particles - nall) : 0;
    /* At the cap nothing can be created: skip the potentials (refusals are then not counted). */
    if (pfsph__fluid_count(ctx) == 0 || d->p.sampling_rate <= 0 || room == 0) return;
    bool ok;
    uint32_t *cnt = d->lent_emit;
    if (!cnt) {
        d->emit = ensure(d->emit, &d->emit_cap, f->n, sizeof(uint32_t), &ok);
        if (!ok) return;
        cnt = d->emit;
    }
#pragma omp parallel for schedule(dynamic, 512)
    for (long i = (long)lo; i < (long)hi; i++) cnt[i] = emit_count(d, ctx, (size_t)i);
    uint64_t total = 0;
    for (size_t i = lo; i < hi; i++) {
        uint32_t c = cnt[i];
        cnt[i] = (uint32_t)(total < UINT32_MAX ? total : UINT32_MAX);
        total += c;
    }
    uint64_t before = 0, all = total; /* this rank's emissions: [before, before + total) of all */
    if (D) D->scan(D, &total, 1, &before, &all);
    if (all == 0) return;
    const size_t addg = all < room ? (size_t)all : room;
    d->refused += all - addg;
    const size_t add = before >= addg ? 0 : (addg - before < total ? (size_t)(addg - before) : (size_t)total);
    size_t base = d->ps.n;
    if (base + add > d->ps.cap) {
        size_t c = d->ps.cap ? d->ps.cap : 1024;
        while (c < base + add) c *= 2;
        if (pfsph_particles_reserve(&d->ps, c) != PFSPH_OK) {
            if (D) abort(); /* the ids of the other ranks' would no longer follow */
            d->refused += add;
            return;
        }
    }
#pragma omp parallel for schedule(dynamic, 512)
    for (long i = (long)lo; i < (long)hi; i++) {
        uint32_t b = cnt[i], e = i + 1 < (long)hi ? cnt[i + 1] : (uint32_t)total;
        for (uint32_t k = 0; b + k < e && (size_t)(b + k) < add; k++) emit_one(d, ctx, (size_t)i, k, base + b + k);
    }
    pfsph_particles *ps = &d->ps;
    for (size_t s = 0; s < add; s++) ps->id[base + s] = ps->next_id + (uint32_t)(before + s);
    ps->next_id += (uint32_t)addg;
    ps->n = base + add;
    d->created += addg;
    d->nold = base;
    distribute(d, ctx, base);
    /* Label the new particles at their own position (current fluid positions; the next step
     * reclassifies with the exact start-of-step ones). */
    base = d->nold;
#pragma omp parallel for schedule(dynamic, 256)
    for (long q = (long)base; q < (long)ps->n; q++) {
        const pfsph_real xd[3] = {ps->x[q], ps->y[q], ps->z[q]};
        double sw, sv[3];
        ps->phase[q] = (uint8_t)classify(d, fluid_sample(d, ctx, xd, false, &sw, sv));
    }
}

static int prepare_old(pfsph_diffuse *d, const pfsph_ctx *ctx)
{
    const pfsph_particles *f = ctx->fluid;
    if (d->lent_old[0]) {
        d->ox = d->lent_old[0];
        d->oy = d->lent_old[1];
        d->oz = d->lent_old[2];
    } else {
        bool ok1, ok2, ok3;
        pfsph_real **own[3] = {&d->own_ox, &d->own_oy, &d->own_oz};
        size_t cap = d->old_cap;
        *own[0] = ensure(*own[0], &cap, f->n, sizeof(pfsph_real), &ok1);
        cap = d->old_cap;
        *own[1] = ensure(*own[1], &cap, f->n, sizeof(pfsph_real), &ok2);
        cap = d->old_cap;
        *own[2] = ensure(*own[2], &cap, f->n, sizeof(pfsph_real), &ok3);
        if (!ok1 || !ok2 || !ok3) return PFSPH_ENOMEM;
        d->old_cap = cap;
        d->ox = d->own_ox;
        d->oy = d->own_oy;
        d->oz = d->own_oz;
    }
    const pfsph_real dt = (pfsph_real)ctx->dt;
    const long n = (long)f->n;
#pragma omp parallel for schedule(static)
    for (long j = 0; j < n; j++) {
        d->ox[j] = f->x[j] - dt * f->vx[j];
        d->oy[j] = f->y[j] - dt * f->vy[j];
        d->oz[j] = f->z[j] - dt * f->vz[j];
    }
    return PFSPH_OK;
}

/* The fluid grid cell of diffuse particle i, clamped into the grid (the spatial sort's key, and
 * under MPI the cell whose owner takes the particle). */
static inline uint32_t cell_of(const pfsph_grid *g, const pfsph_particles *ps, size_t i)
{
    return pfsph_grid_cell_clamped(g, ps->x[i], ps->y[i], ps->z[i]);
}

/* A distributed run (docs/cluster.md): the particles [from, n) go to the rank that owns their
 * cell of the step's cut, those before `from` stay; the set then keeps the serial order's slice
 * (ps.n and nold change). Serial: nothing. */
static void distribute(pfsph_diffuse *d, const pfsph_ctx *ctx, size_t from)
{
    pfsph_dist *D = ctx->dist;
    if (!D) return;
    pfsph_particles *ps = &d->ps;
    bool ok;
    d->mkey = ensure(d->mkey, &d->mkey_cap, ps->n ? ps->n : 1, sizeof(uint32_t), &ok);
    if (!ok) abort(); /* the other ranks wait in the exchange: nothing sensible is left */
    for (size_t i = 0; i < ps->n; i++) d->mkey[i] = i < from ? UINT32_MAX : cell_of(ctx->grid, ps, i);
    D->migrate(D, ps, &d->nold, d->mkey);
}

/* Order the diffuse set by fluid grid cell (stable counting sort), so that neighbouring diffuse
 * particles read the same fluid cells: the coupling loop then walks memory nearly in order.
 * Deterministic; ids travel with their particles. */
static void sort_spatially(pfsph_diffuse *d, const pfsph_grid *g)
{
    pfsph_particles *ps = &d->ps;
    const size_t n = ps->n;
    if (n < 2) return;
    bool ok[5];
    size_t pc = d->perm_cap;
    uint32_t **arr[4] = {&d->perm, &d->key, &d->perm2, &d->key2};
    for (int k = 0; k < 4; k++) {
        pc = d->perm_cap;
        *arr[k] = ensure(*arr[k], &pc, n, sizeof(uint32_t), &ok[k]);
    }
    d->tmp = ensure(d->tmp, &d->tmp_cap, n, sizeof(pfsph_real) > 4 ? sizeof(pfsph_real) : 4, &ok[4]);
    if (!ok[0] || !ok[1] || !ok[2] || !ok[3] || !ok[4]) return; /* unsorted is still correct */
    d->perm_cap = pc;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < (long)n; i++) {
        d->key[i] = cell_of(g, ps, (size_t)i);
        d->perm[i] = (uint32_t)i;
    }
    /* A stable LSD radix sort, a byte of the cell key a pass: the order of a stable counting
     * sort over the cells without its array of a count per cell (4 B per fluid grid cell: 1.1 GB
     * for the 128 m cube of the diffuse paper's Table 1, issue 28) */
    uint32_t *key = d->key, *perm = d->perm, *key2 = d->key2, *perm2 = d->perm2;
    for (int shift = 0; shift < 32 && (g->ncells - 1) >> shift; shift += 8) {
        size_t cnt[257] = {0};
        for (size_t i = 0; i < n; i++) cnt[((key[i] >> shift) & 255u) + 1]++;
        for (int b = 0; b < 256; b++) cnt[b + 1] += cnt[b];
        for (size_t i = 0; i < n; i++) {
            const size_t at = cnt[(key[i] >> shift) & 255u]++;
            key2[at] = key[i];
            perm2[at] = perm[i];
        }
        uint32_t *t = key;
        key = key2;
        key2 = t;
        t = perm;
        perm = perm2;
        perm2 = t;
    }
    pfsph_particles_permute(ps, perm, n, d->tmp);
}

void pfsph_diffuse_step_in(pfsph_diffuse *d, const pfsph_ctx *ctx, pfsph_real *const old[3], uint32_t *emit)
{
    if (!d) return;
    for (int a = 0; a < 3; a++) d->lent_old[a] = old[a];
    d->lent_emit = emit;
    pfsph_diffuse_step(d, ctx);
    for (int a = 0; a < 3; a++) d->lent_old[a] = NULL;
    d->lent_emit = NULL;
    d->ox = d->oy = d->oz = NULL;
}

void pfsph_diffuse_step(pfsph_diffuse *d, const pfsph_ctx *ctx)
{
    if (!d || !ctx || !ctx->fluid || !ctx->grid || !(ctx->dt > 0)) return;
    bool ok;
    if (ctx->dist) {
        /* the integrator moved the owned particles only: the halo's positions and velocities
         * at t + dt, which the walks below read */
        pfsph_particles *f = ctx->fluid;
        pfsph_real *const a[6] = {f->x, f->y, f->z, f->vx, f->vy, f->vz};
        pfsph__halo(ctx, a, 6);
    }
    if (prepare_old(d, ctx) != PFSPH_OK) return;
    distribute(d, ctx, 0); /* each particle to the owner of its cell */
    d->keep = ensure(d->keep, &d->keep_cap, d->ps.n, 1, &ok);
    if (!ok) return;
    sort_spatially(d, ctx->grid);
    advect(d, ctx);
    compact(d);
    d->nold = d->ps.n;
    generate(d, ctx);
}

pfsph_particles *pfsph__diffuse_set(pfsph_diffuse *d, size_t **nold, uint64_t **created, uint64_t **refused)
{
    *nold = &d->nold;
    *created = &d->created;
    *refused = &d->refused;
    return &d->ps;
}

int pfsph_diffuse_import(pfsph_diffuse *d, const pfsph_particles *ps, uint64_t created, uint64_t refused)
{
    if ((long)ps->n > d->p.max_particles) return PFSPH_EINPUT;
    for (size_t i = 0; i < ps->n; i++)
        if (ps->phase[i] >= PFSPH_DIFFUSE_NTYPES) return PFSPH_EINPUT;
    if (ps->n > d->ps.cap && pfsph_particles_reserve(&d->ps, ps->n) != PFSPH_OK) return PFSPH_ENOMEM;
    for (int k = 0; k < PFSPH_NFIELDS; k++)
        if (ps->n) memcpy(d->ps.f[k], ps->f[k], ps->n * sizeof(pfsph_real));
    if (ps->n) {
        memcpy(d->ps.phase, ps->phase, ps->n);
        memcpy(d->ps.id, ps->id, ps->n * sizeof(uint32_t));
    }
    d->ps.n = ps->n;
    d->nold = ps->n;
    d->ps.next_id = ps->next_id;
    d->created = created;
    d->refused = refused;
    return PFSPH_OK;
}

static int diffuse_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    /* the accelerations' arrays hold nothing after the integrator (the next step writes them
     * before it reads them), nor does the stages' shared scratch between stages */
    pfsph_ctx *c = st->ctx;
    pfsph_real *const old[3] = {c->ax, c->ay, c->az};
    pfsph_diffuse_step_in(st->df, c, old, (uint32_t *)st->scratch[0]);
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_diffuse = {.name = "diffuse",
                                             .slot = PFSPH_STAGE_DIFFUSE,
                                             .reads = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_ORDER | PFSPH_D_DT,
                                             .writes = PFSPH_D_DIFFUSE | PFSPH_D_ACC, /* ACC: lent */
                                             .nscratch = 1,
                                             .run = diffuse_run};
