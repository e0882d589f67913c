/* Emitters (emitter.h; docs/emitters.md): nozzles on the scene lattice that add particles
 * layer by layer. Runs as the last stage of a step, after the particles moved, so that the
 * spacing to the layer emitted before is the distance the jet travelled; the next step's grid
 * sort takes the new particles in. */
#include "pfsph/emitter.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/dist.h"
#include "physics/stages.h"

/* Closer than this to a particle already there, a site is skipped for the layer: the issue's
 * bound on entry spacing, with the lattice's own d between sites of one layer and between
 * consecutive layers of a free jet. */
#define EMIT_MIN_GAP 0.8

typedef struct nozzle {
    pfsph_emitter_params p;
    pfsph_emitter_info info;
    double step[3];      /* displacement per unit of layer travelled: d direction / |direction[axis]| */
    double *site;        /* 3 per site: the exit plane's lattice sites */
    double lo[3], hi[3]; /* bounding box of the sites */
    pfsph_emitter_state st;
} nozzle;

struct pfsph_emitters {
    int n;
    nozzle *z;
    uint32_t *near; /* indices of particles near a nozzle: grown geometrically, kept */
    size_t near_cap;
    uint8_t *blocked; /* per site of the step's layers: a particle stands in the way */
    size_t blocked_cap;
};

static double lat(double d, long k) { return ((double)k + 0.5) * d; }

/* Sites of the opening, in lattice order (first transverse axis fastest), into out (3 per site;
 * NULL: count only). */
static size_t sample(const pfsph_emitter_params *p, int dim, double d, const double *dmin, const double *dmax,
                     const double *stepv, pfsph_site_filter keep, void *user, double *out)
{
    int t[2] = {-1, -1}, nt = 0;
    for (int a = 0; a < dim; a++)
        if (a != p->axis) t[nt++] = a;
    double half[2] = {0, 0};
    if (p->shape == PFSPH_NOZZLE_DISC) half[0] = half[1] = p->radius;
    else half[0] = 0.5 * p->size[0], half[1] = 0.5 * p->size[1];
    long k0[2] = {0, 0}, k1[2] = {0, 0};
    for (int j = 0; j < nt; j++) {
        k0[j] = (long)floor((p->center[t[j]] - half[j]) / d - 0.5) - 1;
        k1[j] = (long)ceil((p->center[t[j]] + half[j]) / d - 0.5) + 1;
    }
    const double tiny = 1e-9 * d;
    size_t n = 0;
    for (long b = k0[1]; b <= k1[1]; b++)
        for (long a = k0[0]; a <= k1[0]; a++) {
            double x[3] = {p->center[0], p->center[1], dim == 3 ? p->center[2] : 0};
            x[t[0]] = lat(d, a);
            if (nt == 2) x[t[1]] = lat(d, b);
            else if (b != k0[1]) continue; /* 2D: one row */
            double u = x[t[0]] - p->center[t[0]], w = nt == 2 ? x[t[1]] - p->center[t[1]] : 0;
            bool in;
            if (p->shape == PFSPH_NOZZLE_DISC) in = u * u + w * w <= p->radius * p->radius + tiny * p->radius;
            else /* [c - s/2, c + s/2), as a box block takes its sites */
                in = u >= -half[0] - tiny && u < half[0] - tiny &&
                    (nt < 2 || (w >= -half[1] - tiny && w < half[1] - tiny));
            /* the site and a layer's travel from it inside the domain (the grid removes what
             * leaves it) */
            for (int c = 0; c < dim && in; c++)
                in = x[c] >= dmin[c] && x[c] <= dmax[c] && x[c] + stepv[c] >= dmin[c] && x[c] + stepv[c] <= dmax[c];
            if (!in || (keep && !keep(x, user))) continue;
            if (out) memcpy(out + 3 * n, x, sizeof x);
            n++;
        }
    return n;
}

int pfsph_emitters_create(pfsph_emitters **out, const pfsph_emitter_params *p, int n, const pfsph_ctx *ctx,
                          pfsph_site_filter keep, void *user, const char *source, pfsph_error *err)
{
    *out = NULL;
    if (n <= 0) return PFSPH_OK;
    pfsph_emitters *em = calloc(1, sizeof *em);
    if (!em || !(em->z = calloc((size_t)n, sizeof *em->z))) {
        free(em);
        return pfsph_fail(err, PFSPH_ENOMEM, "emitters: out of memory");
    }
    em->n = n;
    const double d = (double)ctx->spacing, V0 = (double)ctx->V0;
    for (int i = 0; i < n; i++) {
        nozzle *z = &em->z[i];
        z->p = p[i];
        const double dn = fabs(z->p.direction[z->p.axis]);
        for (int a = 0; a < 3; a++) z->step[a] = d * z->p.direction[a] / dn;
        size_t ns = sample(&z->p, ctx->dim, d, ctx->domain_min, ctx->domain_max, z->step, keep, user, NULL);
        if (!ns) {
            pfsph_emitters_destroy(em);
            return pfsph_fail(err, PFSPH_EINPUT,
                              "%s: $.emitters[%d]: the nozzle holds no lattice site inside the "
                              "domain and at least 0.4 d from the solids (sites lie at (k + 1/2) d, d = %g m; widen "
                              "the opening or move it)",
                              source, i, d);
        }
        z->site = malloc(3 * ns * sizeof(double));
        if (!z->site) {
            pfsph_emitters_destroy(em);
            return pfsph_fail(err, PFSPH_ENOMEM, "emitters: out of memory");
        }
        sample(&z->p, ctx->dim, d, ctx->domain_min, ctx->domain_max, z->step, keep, user, z->site);
        z->info.sites = ns;
        const double layer_v = (double)ns * V0;
        /* the rate is exact on the lattice: a layer of ns sites every d of normal travel */
        if (z->p.rate > 0) {
            double vn = z->p.rate * d / layer_v;
            z->info.speed = vn / dn;
        } else {
            z->info.speed = z->p.speed;
        }
        if (!(z->info.speed <= 1e3)) {
            double sp = z->info.speed;
            pfsph_emitters_destroy(em);
            return pfsph_fail(err, PFSPH_EINPUT,
                              "%s: $.emitters[%d].rate: %g through %zu sites needs an entry speed "
                              "of %g m/s, above 1000 m/s; widen the opening or lower the rate",
                              source, i, p[i].rate, ns, sp);
        }
        z->info.layer_rate = z->info.speed * dn / d;
        z->info.rate = z->info.layer_rate * layer_v;
        for (int a = 0; a < 3; a++) {
            z->lo[a] = HUGE_VAL;
            z->hi[a] = -HUGE_VAL;
        }
        for (size_t s = 0; s < ns; s++)
            for (int a = 0; a < 3; a++) {
                z->lo[a] = fmin(z->lo[a], z->site[3 * s + a]);
                z->hi[a] = fmax(z->hi[a], z->site[3 * s + a]);
            }
    }
    *out = em;
    return PFSPH_OK;
}

void pfsph_emitters_destroy(pfsph_emitters *em)
{
    if (!em) return;
    for (int i = 0; i < em->n && em->z; i++) free(em->z[i].site);
    free(em->z);
    free(em->near);
    free(em->blocked);
    free(em);
}

int pfsph_emitters_count(const pfsph_emitters *em) { return em ? em->n : 0; }

void pfsph_emitters_info(const pfsph_emitters *em, int i, pfsph_emitter_info *info) { *info = em->z[i].info; }

/* Seconds of [t0, t1] during which nozzle z is open. */
static double open_for(const nozzle *z, double t0, double t1)
{
    double a = fmax(t0, z->p.start), b = fmin(t1, z->p.stop);
    return b > a ? b - a : 0;
}

size_t pfsph_emitters_max(const pfsph_emitters *em, double t)
{
    size_t total = 0;
    for (int i = 0; em && i < em->n; i++) {
        const nozzle *z = &em->z[i];
        /* an upper bound, so a product a rounding error short of a whole number of layers
         * counts that layer: float and double builds then give the same bound */
        double layers = floor(z->info.layer_rate * open_for(z, 0, t) * (1 + 1e-6)) + 1;
        total += (size_t)layers * z->info.sites;
    }
    return total;
}

/* Whole layers owed after the step: what _step emits (the same arithmetic, in the same order). */
static double owed(const nozzle *z, double t0, double dt)
{
    return z->st.debt + z->info.layer_rate * open_for(z, t0, t0 + dt);
}

size_t pfsph_emitters_due(const pfsph_emitters *em, double t0, double dt)
{
    size_t total = 0;
    for (int i = 0; em && i < em->n; i++) {
        const nozzle *z = &em->z[i];
        total += (size_t)floor(owed(z, t0, dt)) * z->info.sites;
    }
    return total;
}

/* Indices of the particles in the box [lo - r, hi + r], into em->near (grown when needed). */
static size_t gather(pfsph_emitters *em, const pfsph_particles *f, int dim, const double *lo, const double *hi,
                     double r, size_t j0, size_t j1)
{
    size_t m = 0;
    for (size_t j = j0; j < j1; j++) {
        const double x[3] = {f->x[j], f->y[j], f->z[j]};
        int in = 1;
        for (int a = 0; a < dim && in; a++) in = x[a] >= lo[a] - r && x[a] <= hi[a] + r;
        if (!in) continue;
        if (m == em->near_cap) {
            size_t cap = em->near_cap ? 2 * em->near_cap : 256;
            uint32_t *q = realloc(em->near, cap * sizeof *q);
            if (!q) return SIZE_MAX;
            em->near = q;
            em->near_cap = cap;
        }
        em->near[m++] = (uint32_t)j;
    }
    return m;
}

/* The nozzle is a velocity inlet: a particle in the slab from half a spacing behind the exit
 * plane to one spacing in front of it, over the opening, that moves out slower than the jet is
 * given the jet's velocity. Without it a
 * particle standing in front of the nozzle (a pool risen to it, gas in a tube that a bubble is
 * blown from) would block its sites for good; with it the inlet pushes the way clear, as the
 * pressure behind a real nozzle does. Returns the particles set. */
static size_t push_inlet(const nozzle *z, pfsph_particles *f, int dim, double d, const pfsph_real *v, size_t j0,
                         size_t j1)
{
    const int a = z->p.axis;
    const double sgn = z->p.direction[a] > 0 ? 1 : -1, vn = (double)v[a] * sgn;
    int t[2] = {-1, -1}, nt = 0;
    for (int k = 0; k < dim; k++)
        if (k != a) t[nt++] = k;
    const double half0 = z->p.shape == PFSPH_NOZZLE_DISC ? z->p.radius : 0.5 * z->p.size[0];
    const double half1 = z->p.shape == PFSPH_NOZZLE_DISC ? z->p.radius : 0.5 * z->p.size[1];
    const double m = 0.5 * d;
    size_t set = 0;
    for (size_t j = j0; j < j1; j++) {
        const double x[3] = {f->x[j], f->y[j], f->z[j]};
        double along = (x[a] - z->p.center[a]) * sgn;
        if (!(along >= -0.5 * d && along < d)) continue;
        /* back to the exit plane along the jet, then inside the opening (half a spacing more) */
        double u = x[t[0]] - z->p.center[t[0]] - along * z->step[t[0]] / d;
        double w = nt == 2 ? x[t[1]] - z->p.center[t[1]] - along * z->step[t[1]] / d : 0;
        bool in = z->p.shape == PFSPH_NOZZLE_DISC ? u * u + w * w <= (half0 + m) * (half0 + m)
                                                  : fabs(u) <= half0 + m && (nt < 2 || fabs(w) <= half1 + m);
        const pfsph_real *fv[3] = {f->vx, f->vy, f->vz};
        if (!in || (double)fv[a][j] * sgn >= vn) continue;
        f->vx[j] = v[0];
        f->vy[j] = v[1];
        f->vz[j] = v[2];
        set++;
    }
    return set;
}

/* Distributed (docs/cluster.md): each rank pushes and looks for particles in the way among
 * those it owns (the last rank: and those it took this step), the sites' flags are or-ed over
 * the ranks, and the last rank alone appends the new particles: in the global order they follow
 * every other, as serially they follow the whole array. Every rank counts the same. */
size_t pfsph_emitters_step(pfsph_emitters *em, pfsph_particles *f, const pfsph_ctx *ctx, double t0, double dt,
                           double *vmax_in)
{
    *vmax_in = 0;
    if (!em) return 0;
    pfsph_dist *D = ctx->dist;
    const bool takes = !D || D->rank == D->nranks - 1;
    const size_t j0 = D ? D->own_lo : 0;
    const int dim = ctx->dim;
    const double d = (double)ctx->spacing, gap2 = EMIT_MIN_GAP * EMIT_MIN_GAP * d * d;
    size_t added = 0;
    for (int i = 0; i < em->n; i++) {
        nozzle *z = &em->z[i];
        const size_t j1 = takes ? f->n : D->own_hi;
        const pfsph_real v[3] = {(pfsph_real)(z->info.speed * z->p.direction[0]),
                                 (pfsph_real)(z->info.speed * z->p.direction[1]),
                                 (pfsph_real)(z->info.speed * z->p.direction[2])};
        if (open_for(z, t0, t0 + dt) > 0) {
            uint64_t set = push_inlet(z, f, dim, d, v, j0, j1), before;
            if (D) D->scan(D, &(uint64_t){set}, 1, &before, &set);
            z->st.pushed += set;
        }
        double debt = owed(z, t0, dt);
        if (debt < 1) {
            z->st.debt = debt;
            continue;
        }
        const long layers = (long)floor(debt);
        /* the particles that may stand in the way: near the sites and the layers' travel */
        double lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            double far = z->step[a] * (double)layers;
            lo[a] = z->lo[a] + fmin(0, far);
            hi[a] = z->hi[a] + fmax(0, far);
        }
        size_t m = gather(em, f, dim, lo, hi, EMIT_MIN_GAP * d, j0, j1);
        if (m == SIZE_MAX) m = 0; /* out of memory for the list: nothing blocks (rare) */
        const size_t ns = z->info.sites, nflag = (size_t)layers * ns;
        if (nflag > em->blocked_cap) {
            uint8_t *q = realloc(em->blocked, nflag);
            if (!q) abort(); /* a few bytes a site: nothing sensible is left */
            em->blocked = q;
            em->blocked_cap = nflag;
        }
        /* the sites in the way first (the list holds no particle of this nozzle's step) */
        double deb = debt;
        for (long l = 0; l < layers; l++) {
            deb -= 1;
            /* this layer crossed the exit plane `deb` layers of travel ago */
            for (size_t s = 0; s < ns; s++) {
                pfsph_real xr[3];
                for (int a = 0; a < 3; a++) xr[a] = (pfsph_real)(z->site[3 * s + a] + deb * z->step[a]);
                uint8_t blocked = 0;
                for (size_t q = 0; q < m && !blocked; q++) {
                    const uint32_t j = em->near[q];
                    double dx = (double)f->x[j] - (double)xr[0], dy = (double)f->y[j] - (double)xr[1],
                           dz = (double)f->z[j] - (double)xr[2];
                    blocked = dx * dx + dy * dy + dz * dz < gap2;
                }
                em->blocked[(size_t)l * ns + s] = blocked;
            }
        }
        if (D) D->any(D, em->blocked, nflag);
        const pfsph_real rho0 = ctx->rest_density[z->p.phase];
        for (long l = 0; l < layers; l++) {
            debt -= 1;
            const double off = debt;
            for (size_t s = 0; s < ns; s++) {
                pfsph_real xr[3];
                for (int a = 0; a < 3; a++) xr[a] = (pfsph_real)(z->site[3 * s + a] + off * z->step[a]);
                /* the caller reserved room: full means a bug, refuse */
                if (em->blocked[(size_t)l * ns + s] || (takes && f->n == f->cap)) {
                    z->st.refused++;
                    continue;
                }
                if (takes) {
                    long k = pfsph_particles_push(f, xr, v, (uint8_t)z->p.phase);
                    f->rho[k] = rho0;
                    /* blown gas joins its bubble: the next film stage counts it in the bubble's
                     * detection group, so the film spreads over the grown surface */
                    f->bubble[k] = (uint8_t)z->p.bubble;
                } else {
                    f->next_id++; /* the ids the last rank gives */
                }
                z->st.emitted++;
                added++;
            }
        }
        z->st.debt = debt;
        *vmax_in = fmax(*vmax_in, z->info.speed);
    }
    return added;
}

void pfsph_emitters_get_state(const pfsph_emitters *em, int i, pfsph_emitter_state *st) { *st = em->z[i].st; }

int pfsph_emitters_check_state(const pfsph_emitters *em, int i, const pfsph_emitter_state *st, double t,
                               pfsph_error *err)
{
    const nozzle *z = &em->z[i];
    const uint64_t made = st->emitted + st->refused;
    /* every layer visits all sites; no more layers than the time allows */
    const double most = floor(z->info.layer_rate * open_for(z, 0, t) * (1 + 1e-9)) + 1;
    if (!(st->debt >= 0 && st->debt < 1) || made < st->emitted || made % z->info.sites != 0 ||
        (double)(made / z->info.sites) > most)
        return pfsph_fail(err, PFSPH_EINPUT,
                          "emitter %d: state (%g layers owed, %llu emitted, %llu refused) is not "
                          "one this nozzle of %zu sites reaches by t = %g s",
                          i, st->debt, (unsigned long long)st->emitted, (unsigned long long)st->refused, z->info.sites,
                          t);
    return PFSPH_OK;
}

int pfsph_emitters_set_state(pfsph_emitters *em, int i, const pfsph_emitter_state *st, double t, pfsph_error *err)
{
    int rc = pfsph_emitters_check_state(em, i, st, t, err);
    if (!rc) em->z[i].st = *st;
    return rc;
}

/* New particles at the nozzles, after everything moved. Their entry speed counts in the next
 * step's CFL condition through stats.vmax. The fluid's arrays are reserved for the scene's end
 * time; a longer run (--end) grows them by half at least (st->reserve). */
static int emit_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    pfsph_particles *f = st->ctx->fluid;
    size_t due = pfsph_emitters_due(st->em, st->time, st->ctx->dt);
    if (!due) {
        pfsph_emitters_step(st->em, f, st->ctx, st->time, st->ctx->dt, &(double){0}); /* keeps the debt */
        return PFSPH_OK;
    }
    int rc = st->reserve(st, f->n + due, err);
    if (rc) return rc;
    double vin = 0;
    const size_t added = pfsph_emitters_step(st->em, f, st->ctx, st->time, st->ctx->dt, &vin);
    if (vin > st->stats.vmax) st->stats.vmax = vin;
    pfsph_dist *D = st->ctx->dist;
    if (D) { /* the last rank owns the new particles (it holds no halo behind its own) */
        D->nglobal += added;
        if (D->rank == D->nranks - 1) D->own_hi = f->n;
    }
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_emit = {.name = "emit",
                                          .slot = PFSPH_STAGE_INTEGRATE,
                                          .reads = PFSPH_D_DT,
                                          .writes = PFSPH_D_ORDER | PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_STATS,
                                          .run = emit_run};
