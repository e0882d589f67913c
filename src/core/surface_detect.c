/* Free-surface particles layer by layer (Barecasco, Terissa & Naa 2013; PF Fig. 9). See
 * src/pfsph/surface_detect.h and docs/film.md. */
#include "pfsph/surface_detect.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/hits.h"
#include "core/stage.h"
#include "pfsph/dist.h"

/* The targets a peel walks for particle i: every target of the grid ranges rg (j == NULL), or
 * the ones a float SIMD filter kept from them (j[0..n), in walk order): all within a radius
 * 1e-3 above the peel's in float, a superset of every target that the double tests below can
 * accept (|x_i - x_j| < R for the direction sum; within rc of a test point at rc from x_i,
 * hence within R plus round-off, for the cover). Each candidate is tested with the same double
 * expressions either way, so the layers are the same; the filter drops ~85 % of the ~200
 * candidates of a reach-1 walk before the scalar double code (docs/interactive.md).
 * The kept targets of the ranges rg of (x, y, z) into H (skip: i, or UINT32_MAX); 0 when they
 * do not fit (then the caller walks the ranges) */
static int peel_filter(pfsph_hits_fn hits, pfsph_hits *H, const pfsph_ranges *rg, const pfsph_particles *ps,
                       pfsph_real x, pfsph_real y, pfsph_real z, pfsph_real r2f, uint32_t skip)
{
    H->n = 0;
    for (int q = 0; q < rg->n; q++) {
        if ((size_t)H->n + (rg->e[q] - rg->b[q]) > PFSPH_HITS_CAP) return 0;
        hits(H, ps->x, ps->y, ps->z, rg->b[q], rg->e[q], x, y, z, r2f, skip);
    }
    return 1;
}

/* One peel: for each particle still in (layer[i] == 0, or every particle on the first pass)
 * out[i] = 1 when its sphere has an uncovered point. Neighbours already peeled do not cover. */
static void peel(const pfsph_ctx *ctx, const pfsph_surface_opts *o, double radius, int reach, bool first,
                 const uint8_t *layer, uint8_t *out)
{
    const pfsph_particles *f = ctx->fluid;
    const pfsph_particles *b = o->boundary && ctx->boundary && ctx->bgrid ? ctx->boundary : NULL;
    const size_t n = f->n;
    const double R2 = radius * radius, rc = 0.5 * radius, rc2 = rc * rc;
    const uint8_t *grp = o->group;
    /* the SIMD prefilter's radius in float: 1e-3 above R^2 covers float round-off (1e-6) */
    const pfsph_hits_fn hits = pfsph_hits_select();
    const pfsph_real r2f = (pfsph_real)(R2 * 1.001);
#pragma omp parallel
    {
        pfsph_hits Hf, Hb;
#pragma omp for schedule(dynamic, 256)
        for (size_t i = 0; i < n; i++) {
            if (!first && layer[i]) {
                out[i] = 0;
                continue;
            }
            const double xi = f->x[i], yi = f->y[i], zi = f->z[i];
            const uint8_t gi = grp ? grp[i] : 0;
            double s[3] = {0, 0, 0};
            int nn = 0;
            pfsph_ranges rg;
            /* the unit vectors from the neighbours to i: their sum points to the least covered
         * side of i's sphere */
            pfsph_grid_ranges_reach(ctx->grid, f->x[i], f->y[i], f->z[i], reach, &rg);
            /* the filtered targets (Hf, Hb), or the ranges' (jf, jb NULL) */
            const uint32_t *jf =
                hits && peel_filter(hits, &Hf, &rg, f, f->x[i], f->y[i], f->z[i], r2f, (uint32_t)i) ? Hf.j : NULL;
            const int nf = jf ? Hf.n : 0;
#define PEEL_FLUID(J, ...)                                       \
    do {                                                         \
        if (jf) {                                                \
            for (int e_ = 0; e_ < nf; e_++) {                    \
                const uint32_t J = jf[e_];                       \
                __VA_ARGS__                                      \
            }                                                    \
        } else                                                   \
            for (int q_ = 0; q_ < rg.n; q_++)                    \
                for (uint32_t J = rg.b[q_]; J < rg.e[q_]; J++) { \
                    __VA_ARGS__                                  \
                }                                                \
    } while (0)
            PEEL_FLUID(j, {
                if (j == i || (grp && grp[j] != gi) || (!first && layer[j])) continue;
                const double dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                const double r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= R2 || r2 <= 0) continue;
                const double inv = 1.0 / sqrt(r2);
                s[0] += dx * inv;
                s[1] += dy * inv;
                s[2] += dz * inv;
                nn++;
            });
            pfsph_ranges rb;
            rb.n = 0;
            const uint32_t *jb = NULL;
            int nb = 0;
            if (b) {
                pfsph_grid_ranges_reach(ctx->bgrid, f->x[i], f->y[i], f->z[i], reach, &rb);
                jb = hits && peel_filter(hits, &Hb, &rb, b, f->x[i], f->y[i], f->z[i], r2f, UINT32_MAX) ? Hb.j : NULL;
                nb = jb ? Hb.n : 0;
            }
#define PEEL_WALL(J, ...)                                        \
    do {                                                         \
        if (jb) {                                                \
            for (int e_ = 0; e_ < nb; e_++) {                    \
                const uint32_t J = jb[e_];                       \
                __VA_ARGS__                                      \
            }                                                    \
        } else                                                   \
            for (int q_ = 0; q_ < rb.n; q_++)                    \
                for (uint32_t J = rb.b[q_]; J < rb.e[q_]; J++) { \
                    __VA_ARGS__                                  \
                }                                                \
    } while (0)
            if (b)
                PEEL_WALL(j, {
                    const double dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    const double r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= R2 || r2 <= 0) continue;
                    const double inv = 1.0 / sqrt(r2);
                    s[0] += dx * inv;
                    s[1] += dy * inv;
                    s[2] += dz * inv;
                    nn++;
                });
            if (!nn) { /* alone: all of its sphere is uncovered */
                out[i] = 1;
                continue;
            }
            const double sn = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            /* a balanced neighbourhood (a lattice's interior: |s| is round-off) */
            if (!(sn > 1e-6 * nn)) {
                out[i] = 0;
                continue;
            }
            /* the test points on i's sphere: where the neighbours are fewest (Barecasco et al.),
         * then a ring 30 degrees off it (ours: a particle in a one-site notch of a lattice
         * surface has an uncovered arc of 30 degrees that the sum's direction can miss) */
            const double u[3] = {s[0] / sn, s[1] / sn, s[2] / sn};
            double e1[3], e2[3] = {0, 0, 0};
            if (ctx->dim == 2) {
                e1[0] = -u[1], e1[1] = u[0], e1[2] = 0;
            } else { /* an orthonormal pair perpendicular to u */
                const double t[3] = {fabs(u[0]) < 0.9 ? 1.0 : 0.0, fabs(u[0]) < 0.9 ? 0.0 : 1.0, 0};
                e1[0] = u[1] * t[2] - u[2] * t[1], e1[1] = u[2] * t[0] - u[0] * t[2], e1[2] = u[0] * t[1] - u[1] * t[0];
                const double l = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
                for (int a = 0; a < 3; a++) e1[a] /= l;
                e2[0] = u[1] * e1[2] - u[2] * e1[1], e2[1] = u[2] * e1[0] - u[0] * e1[2],
                e2[2] = u[0] * e1[1] - u[1] * e1[0];
            }
            const double C = 0.86602540378443865, Sn = 0.5; /* cos, sin of 30 degrees */
            const int npts = ctx->dim == 2 ? 3 : 5;
            const double ring[5][2] = {{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
            bool covered = true;
            for (int t = 0; t < npts && covered; t++) {
                const double cu = t ? C : 1.0, se = t ? Sn : 0.0;
                double dir[3];
                for (int a = 0; a < 3; a++) dir[a] = cu * u[a] + se * (ring[t][0] * e1[a] + ring[t][1] * e2[a]);
                const double px = xi + rc * dir[0], py = yi + rc * dir[1], pz = zi + rc * dir[2];
                /* covered: any target within rc of the point (the order of the tests is free) */
                covered = false;
                PEEL_FLUID(j, {
                    if (covered) break;
                    if (j == i || (grp && grp[j] != gi) || (!first && layer[j])) continue;
                    const double dx = px - f->x[j], dy = py - f->y[j], dz = pz - f->z[j];
                    if (dx * dx + dy * dy + dz * dz < rc2) covered = true;
                });
                if (b && !covered)
                    PEEL_WALL(j, {
                        if (covered) break;
                        const double dx = px - b->x[j], dy = py - b->y[j], dz = pz - b->z[j];
                        if (dx * dx + dy * dy + dz * dz < rc2) covered = true;
                    });
            }
            out[i] = covered ? 0 : 1;
        }
    }
#undef PEEL_FLUID
#undef PEEL_WALL
}

/* A distributed run (docs/cluster.md): a peel reads its neighbours' layers, and a halo copy's
 * layer is right only where its owner computed it (its neighbourhood may leave the halo), so the
 * halo copies take their owners' layers before the next peel. Out of memory ends the process (the
 * other ranks wait in the refresh: mpirun then stops them), as in the diffuse stage's paths. */
static void halo_layers(const pfsph_ctx *ctx, uint8_t *layer)
{
    const size_t n = ctx->fluid->n;
    pfsph_real *a = malloc((n ? n : 1) * sizeof *a);
    if (!a) abort();
    for (size_t i = 0; i < n; i++) a[i] = (pfsph_real)layer[i];
    pfsph_real *const arr[1] = {a};
    ctx->dist->halo(ctx->dist, arr, 1);
    for (size_t i = 0; i < n; i++) layer[i] = (uint8_t)a[i];
    free(a);
}

void pfsph_surface_detect(const pfsph_ctx *ctx, const pfsph_surface_opts *o, uint8_t *layer, uint8_t *work)
{
    const size_t n = ctx->fluid->n;
    if (!n) return;
    double radius = o->radius;
    if (!(radius > 0)) radius = fmin(2.0 * (double)ctx->spacing, (double)ctx->h);
    int reach = o->reach > 0 ? o->reach : ctx->grid->reach;
    if (reach > 3) reach = 3;
    int layers = o->layers < 1 ? 1 : o->layers > PFSPH_SURFACE_MAX_LAYERS ? PFSPH_SURFACE_MAX_LAYERS : o->layers;
    peel(ctx, o, radius, reach, true, layer, layer);
    for (int L = 2; L <= layers; L++) {
        if (ctx->dist && !ctx->dist->fluid_whole) halo_layers(ctx, layer);
        peel(ctx, o, radius, reach, false, layer, work);
        for (size_t i = 0; i < n; i++)
            if (work[i]) layer[i] = (uint8_t)L;
    }
}

/* Output: the outer two layers of surface particles of every fluid frame (docs/film.md). The
 * particles moved since the step's sort by at most a step's travel: one cell more each way keeps
 * every neighbour within the radius in the ranges walked. With bubbles each bubble on its own. */
int pfsph__surface_layers(const pfsph_ctx *c, bool bubbles, int layers, uint8_t *out)
{
    const size_t n = c->fluid->n;
    uint8_t *work = layers > 1 ? malloc(n ? n : 1) : NULL;
    if (layers > 1 && !work) return PFSPH_ENOMEM;
    int reach = c->grid->reach + 1;
    pfsph_surface_opts o = {.radius = 0,
                            .layers = layers,
                            .group = bubbles ? c->fluid->bubble : NULL,
                            .boundary = true,
                            .reach = reach > 3 ? 3 : reach};
    pfsph_surface_detect(c, &o, out, work);
    free(work);
    return PFSPH_OK;
}

static int surface_layers_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    if (pfsph__surface_layers(st->ctx, st->film != NULL, 2, st->out_layer))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory for the surface layers");
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_surface_layers = {.name = "surface_layers",
                                                    .slot = PFSPH_STAGE_OUTPUT,
                                                    .reads = PFSPH_D_POS | PFSPH_D_ORDER,
                                                    .writes = PFSPH_D_OUTPUT,
                                                    .run = surface_layers_run};
