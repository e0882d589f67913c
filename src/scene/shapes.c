/* Particle sampling of fluid blocks and solids. Fluid sits on a lattice of spacing d; solids
 * are sampled with the same spacing so that Akinci volumes come out close to d^dim. */
#include "shapes.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include "pfsph/rng.h"

static const double PI = 3.14159265358979323846;

static int emit(pfsph_particles *ps, long *count, double x, double y, double z, const double *v, int phase)
{
    (*count)++;
    if (!ps) return 0;
    pfsph_real p[3] = {(pfsph_real)x, (pfsph_real)y, (pfsph_real)z};
    pfsph_real vv[3] = {0, 0, 0};
    if (v)
        for (int a = 0; a < 3; a++) vv[a] = (pfsph_real)v[a];
    return pfsph_particles_push(ps, p, vv, (uint8_t)phase) < 0 ? -1 : 0;
}

static int inside_block(const pfsph_block *b, int dim, const double p[3])
{
    double r2 = 0;
    switch (b->shape) {
    case PFSPH_SHAPE_BOX:
        for (int a = 0; a < dim; a++)
            if (p[a] < b->min[a] || p[a] > b->max[a]) return 0;
        return 1;
    case PFSPH_SHAPE_SPHERE:
        for (int a = 0; a < dim; a++) r2 += (p[a] - b->center[a]) * (p[a] - b->center[a]);
        return r2 <= b->radius * b->radius;
    case PFSPH_SHAPE_CYLINDER:
        if (dim == 2) {
            for (int a = 0; a < 2; a++) r2 += (p[a] - b->center[a]) * (p[a] - b->center[a]);
            return r2 <= b->radius * b->radius;
        }
        for (int a = 0; a < 3; a++)
            if (a != b->axis) r2 += (p[a] - b->center[a]) * (p[a] - b->center[a]);
        return r2 <= b->radius * b->radius && fabs(p[b->axis] - b->center[b->axis]) <= 0.5 * b->height;
    default: return 0;
    }
}

/* The scene lattice. Site k along an axis lies at (k + 1/2) d, for every block alike, so that
 * blocks meet without gaps or doubled particles and a later block can take over the sites of
 * an earlier one (docs/scene-format.md, "Particle lattice"). Origin 0 rather than the domain's
 * corner: container walls are sampled from their own `min` (pfsph__sample_solid), and shipped
 * scenes put container and block faces on multiples of d, whatever the domain's margin. In 2D
 * the third axis holds the one site z = 0. A box takes the sites in [min, max) (a face on a
 * site gives it to the block above), a round shape those it contains (closed). */
#define LAT_TOL 1e-9 /* of d: rounding of faces that lie on sites */

static double lat_x(double d, long k) { return ((double)k + 0.5) * d; }

static long clamp_site(double k) { return k < -1e15 ? (long)-1e15 : k > 1e15 ? (long)1e15 : (long)k; }

static long clamp_count(double c) { return c > (double)LONG_MAX / 2 ? LONG_MAX / 2 : (long)c; }

/* Sites [k0, k1) per axis that can lie in block b: its box, a round shape's bounding box. */
static void block_range(const pfsph_block *b, int dim, double d, long k0[3], long k1[3])
{
    k0[2] = 0;
    k1[2] = 1;
    for (int a = 0; a < dim; a++) {
        if (b->shape == PFSPH_SHAPE_BOX) {
            k0[a] = clamp_site(ceil(b->min[a] / d - 0.5 - LAT_TOL));
            k1[a] = clamp_site(ceil(b->max[a] / d - 0.5 - LAT_TOL));
        } else {
            double ext = b->radius;
            if (b->shape == PFSPH_SHAPE_CYLINDER && dim == 3 && a == b->axis) ext = 0.5 * b->height;
            k0[a] = clamp_site(ceil((b->center[a] - ext) / d - 0.5 - LAT_TOL));
            k1[a] = clamp_site(floor((b->center[a] + ext) / d - 0.5 + LAT_TOL) + 1);
        }
        if (k1[a] < k0[a]) k1[a] = k0[a];
    }
}

/* Site k lies in block b (whose range is k0, k1). */
static int site_in(const pfsph_block *b, int dim, double d, const long *k0, const long *k1, const long k[3])
{
    for (int a = 0; a < 3; a++)
        if (k[a] < k0[a] || k[a] >= k1[a]) return 0;
    if (b->shape == PFSPH_SHAPE_BOX) return 1;
    double p[3] = {lat_x(d, k[0]), lat_x(d, k[1]), dim == 3 ? lat_x(d, k[2]) : 0};
    return inside_block(b, dim, p);
}

/* The sites of block b on the row (ky, kz) along x, [*lo, *hi] (empty: *lo > *hi). A box: its
 * range. A sphere or cylinder is convex, so the row holds an interval of sites, found in
 * closed form and its ends settled with the exact test (the same decisions as the walk). */
static void row_interval(const pfsph_block *b, int dim, double d, const long *k0, const long *k1, long ky, long kz,
                         long *lo, long *hi)
{
    *lo = 1;
    *hi = 0;
    if (ky < k0[1] || ky >= k1[1] || kz < k0[2] || kz >= k1[2] || k1[0] <= k0[0]) return;
    if (b->shape == PFSPH_SHAPE_BOX) {
        *lo = k0[0];
        *hi = k1[0] - 1;
        return;
    }
    const int cyl3 = b->shape == PFSPH_SHAPE_CYLINDER && dim == 3;
    long k[3] = {0, ky, kz};
    /* half-width in x of the shape on this row, about b->center[0] */
    double w2 = b->radius * b->radius, wx;
    for (int a = 1; a < dim; a++) {
        if (cyl3 && a == b->axis) continue;
        double q = lat_x(d, k[a]) - b->center[a];
        w2 -= q * q;
    }
    if (cyl3 && b->axis == 0) wx = w2 >= 0 ? 0.5 * b->height : 0;
    else wx = w2 > 0 ? sqrt(w2) : 0;
    long i0 = clamp_site(ceil((b->center[0] - wx) / d - 0.5));
    long i1 = clamp_site(floor((b->center[0] + wx) / d - 0.5));
    if (i0 < k0[0]) i0 = k0[0];
    if (i1 > k1[0] - 1) i1 = k1[0] - 1;
    while (i0 <= i1 && (k[0] = i0, !site_in(b, dim, d, k0, k1, k))) i0++;
    while (i0 <= i1 && (k[0] = i1, !site_in(b, dim, d, k0, k1, k))) i1--;
    if (i0 > i1) {
        /* nothing inside by the closed form; the exact test may still take a site or two
         * next to the centre (contiguous: the shape is convex) */
        long c = clamp_site(floor(b->center[0] / d - 0.5));
        for (k[0] = c - 1; k[0] <= c + 2; k[0]++)
            if (site_in(b, dim, d, k0, k1, k)) {
                if (*lo > *hi) *lo = k[0];
                *hi = k[0];
            }
        return;
    }
    while (i0 > k0[0] && (k[0] = i0 - 1, site_in(b, dim, d, k0, k1, k))) i0--;
    while (i1 < k1[0] - 1 && (k[0] = i1 + 1, site_in(b, dim, d, k0, k1, k))) i1++;
    *lo = i0;
    *hi = i1;
}

/* The sites of one block, without walking them: a box is a product, a round shape a sum of
 * row intervals (about N^(2/3) rows for N sites). */
static long count_block(const pfsph_block *b, int dim, double d, const long *k0, const long *k1)
{
    double n[3];
    for (int a = 0; a < 3; a++) n[a] = (double)(k1[a] - k0[a]);
    if (n[0] <= 0 || n[1] <= 0 || n[2] <= 0) return 0;
    if (b->shape == PFSPH_SHAPE_BOX) return clamp_count(n[0] * n[1] * n[2]);
    double total = 0;
    for (long kz = k0[2]; kz < k1[2]; kz++)
        for (long ky = k0[1]; ky < k1[1]; ky++) {
            long lo, hi;
            row_interval(b, dim, d, k0, k1, ky, kz, &lo, &hi);
            if (lo <= hi) total += (double)(hi - lo + 1);
        }
    return clamp_count(total);
}

static int ranges_meet(const long *a0, const long *a1, const long *b0, const long *b1)
{
    for (int a = 0; a < 3; a++)
        if (a1[a] <= b0[a] || b1[a] <= a0[a]) return 0;
    return 1;
}

/* The sites of block b in one slab kz of its lattice range, less those the later blocks lb take:
 * counted (ps NULL), or written from index at into ps, whose room exists, as
 * pfsph_particles_push would write them. Returns the count. */
typedef struct sites_of {
    const pfsph_scene *s;
    const pfsph_block *b;
    uint32_t stream;
    const pfsph_block *const *lb;
    const long (*lr)[6];
    int m;
    double d;
    long k0[3], k1[3];
    size_t base; /* the set's first new index, with id id0 */
    uint32_t id0;
} sites_of;

static long slab(const sites_of *L, long kz, pfsph_particles *ps, size_t at)
{
    const pfsph_block *b = L->b;
    const int dim = L->s->dim;
    const double d = L->d;
    const long *k0 = L->k0, *k1 = L->k1;
    const long n0 = k1[0] - k0[0], n1 = k1[1] - k0[1];
    long count = 0, k[3];
    k[2] = kz;
    for (k[1] = k0[1]; k[1] < k1[1]; k[1]++)
        for (k[0] = k0[0]; k[0] < k1[0]; k[0]++) {
            if (!site_in(b, dim, d, k0, k1, k)) continue;
            int taken = 0;
            for (int q = 0; q < L->m && !taken; q++) taken = site_in(L->lb[q], dim, d, L->lr[q], L->lr[q] + 3, k);
            if (taken) continue;
            if (!ps) {
                count++;
                continue;
            }
            double p[3] = {lat_x(d, k[0]), lat_x(d, k[1]), dim == 3 ? lat_x(d, k[2]) : 0};
            if (b->jitter > 0) { /* from the scene seed, the block and the lattice site */
                double u[4];
                long site = (k[0] - k0[0]) + n0 * ((k[1] - k0[1]) + n1 * (k[2] - k0[2]));
                pfsph_rng_uniform4(L->s->seed, (uint32_t)site, 0, 0x4a170000u + L->stream, u);
                for (int a = 0; a < dim; a++) p[a] += b->jitter * d * (2 * u[a] - 1);
            }
            const size_t i = at + (size_t)count++;
            for (int f = 0; f < PFSPH_NFIELDS; f++) ps->f[f][i] = 0;
            ps->x[i] = (pfsph_real)p[0];
            ps->y[i] = (pfsph_real)p[1];
            ps->z[i] = (pfsph_real)p[2];
            ps->vx[i] = (pfsph_real)b->velocity[0];
            ps->vy[i] = (pfsph_real)b->velocity[1];
            ps->vz[i] = (pfsph_real)b->velocity[2];
            ps->phase[i] = (uint8_t)b->phase;
            ps->wall[i] = 0;
            ps->bubble[i] = 0;
            ps->id[i] = L->id0 + (uint32_t)(i - L->base);
        }
    return count;
}

/* Sample (ps) or count (ps NULL) the sites of b, less those of the `nlater` blocks `later`
 * (blocks listed after b take the sites they contain). `stream` keys the jitter. */
static long sample(const pfsph_scene *s, const pfsph_block *b, uint32_t stream, const pfsph_block *const *later,
                   int nlater, double d, pfsph_particles *ps)
{
    const int dim = s->dim;
    long k0[3], k1[3];
    block_range(b, dim, d, k0, k1);
    for (int a = 0; a < 3; a++)
        if (k1[a] <= k0[a]) return 0;
    /* the later blocks that can take a site of b, with their ranges */
    long(*lr)[6] = nlater ? malloc((size_t)nlater * sizeof *lr) : NULL;
    const pfsph_block **lb = nlater ? malloc((size_t)nlater * sizeof *lb) : NULL;
    if (nlater && (!lr || !lb)) {
        free(lr);
        free(lb);
        return -1;
    }
    int m = 0;
    for (int q = 0; q < nlater; q++) {
        block_range(later[q], dim, d, lr[m], lr[m] + 3);
        if (ranges_meet(k0, k1, lr[m], lr[m] + 3)) lb[m++] = later[q];
    }
    long count = 0;
    if (!ps) {
        /* each site a later block takes is counted once, against the first later block that
         * contains it: walk the overlap of b with that block only */
        double removed = 0;
        for (int q = 0; q < m; q++) {
            long o0[3], o1[3];
            for (int a = 0; a < 3; a++) {
                o0[a] = k0[a] > lr[q][a] ? k0[a] : lr[q][a];
                o1[a] = k1[a] < lr[q][3 + a] ? k1[a] : lr[q][3 + a];
            }
            int between = 0; /* blocks between b and this one that reach into the overlap */
            for (int r = 0; r < q; r++) between |= ranges_meet(o0, o1, lr[r], lr[r] + 3);
            if (!between && b->shape == PFSPH_SHAPE_BOX && lb[q]->shape == PFSPH_SHAPE_BOX) {
                removed += (double)(o1[0] - o0[0]) * (double)(o1[1] - o0[1]) * (double)(o1[2] - o0[2]);
                continue;
            }
            /* row by row: the sites of both shapes are an interval (both convex); only
             * when blocks in between reach into the overlap are its sites tested one by one */
            long k[3];
            for (k[2] = o0[2]; k[2] < o1[2]; k[2]++)
                for (k[1] = o0[1]; k[1] < o1[1]; k[1]++) {
                    long a0, a1, b0, b1;
                    row_interval(b, dim, d, k0, k1, k[1], k[2], &a0, &a1);
                    row_interval(lb[q], dim, d, lr[q], lr[q] + 3, k[1], k[2], &b0, &b1);
                    if (b0 > a0) a0 = b0;
                    if (b1 < a1) a1 = b1;
                    if (a0 > a1) continue;
                    if (!between) {
                        removed += (double)(a1 - a0 + 1);
                        continue;
                    }
                    for (k[0] = a0; k[0] <= a1; k[0]++) {
                        int first = 1;
                        for (int r = 0; r < q && first; r++)
                            if (site_in(lb[r], dim, d, lr[r], lr[r] + 3, k)) first = 0;
                        removed += first;
                    }
                }
        }
        free(lr);
        free(lb);
        return clamp_count((double)count_block(b, dim, d, k0, k1) - removed);
    }
    /* Slab by slab of the lattice (z = k[2]), in parallel: each slab's sites counted, then
     * written at their place in the set, so that the particles and their order are those of one
     * pass on any thread count (1.9e8 particles took minutes on one thread) */
    const long nz = k1[2] - k0[2];
    long *off = malloc((size_t)(nz + 1) * sizeof *off);
    if (!off) {
        free(lr);
        free(lb);
        return -1;
    }
    sites_of L = {s, b, stream, lb, (const long(*)[6])lr, m, d, {k0[0], k0[1], k0[2]}, {k1[0], k1[1], k1[2]}, 0, 0};
    off[0] = 0;
#pragma omp parallel for schedule(dynamic, 1)
    for (long z = 0; z < nz; z++) off[z + 1] = slab(&L, k0[2] + z, NULL, 0);
    for (long z = 0; z < nz; z++) off[z + 1] += off[z];
    const size_t base = ps->n;
    L.base = base;
    L.id0 = ps->next_id;
    if (pfsph_particles_reserve(ps, base + (size_t)off[nz]) != PFSPH_OK) {
        count = -1;
    } else {
        ps->n = base + (size_t)off[nz];
#pragma omp parallel for schedule(dynamic, 1)
        for (long z = 0; z < nz; z++) slab(&L, k0[2] + z, ps, base + (size_t)off[z]);
        ps->next_id += (uint32_t)off[nz];
        count = off[nz];
    }
    free(off);
    free(lr);
    free(lb);
    return count;
}

long pfsph__sample_block(const pfsph_scene *s, const pfsph_block *b, double d, pfsph_particles *ps)
{
    return sample(s, b, (uint32_t)(b - s->blocks), NULL, 0, d, ps);
}

int pfsph__scene_block_covered(const pfsph_scene *s, int i, double d)
{
    long k0[3], k1[3];
    block_range(&s->blocks[i], s->dim, d, k0, k1);
    double sites = 1;
    for (int a = 0; a < 3; a++) sites *= (double)(k1[a] - k0[a]);
    /* a bound on the work: the count walks at most the overlaps, within this block's range */
    if (i + 1 >= s->nblocks || sites > 1e7) return 0;
    return pfsph__sample_scene_block(s, i, d, NULL) == 0;
}

long pfsph__sample_scene_block(const pfsph_scene *s, int i, double d, pfsph_particles *ps)
{
    int nlater = s->nblocks - 1 - i;
    const pfsph_block **later = nlater > 0 ? malloc((size_t)nlater * sizeof *later) : NULL;
    if (nlater > 0 && !later) return -1;
    for (int q = 0; q < nlater; q++) later[q] = &s->blocks[i + 1 + q];
    long c = sample(s, &s->blocks[i], (uint32_t)i, later, nlater > 0 ? nlater : 0, d, ps);
    free(later);
    return c;
}

/* Orthonormal basis (t1, t2) perpendicular to unit n. */
static void basis(const double n[3], double t1[3], double t2[3])
{
    double a[3] = {1, 0, 0};
    if (fabs(n[0]) > 0.9) a[0] = 0, a[1] = 1;
    t1[0] = a[1] * n[2] - a[2] * n[1];
    t1[1] = a[2] * n[0] - a[0] * n[2];
    t1[2] = a[0] * n[1] - a[1] * n[0];
    double l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int i = 0; i < 3; i++) t1[i] /= l;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
}

/* Points on a sphere of radius r (3D: Fibonacci lattice, 2D: circle) at spacing ~d. */
static int sample_sphere_layer(pfsph_particles *ps, long *count, const double c[3], double r, double d, int dim,
                               int phase)
{
    if (r <= 0) return 0;
    if (dim == 2) {
        long m = (long)ceil(2 * PI * r / d);
        if (m < 3) m = 3;
        for (long i = 0; i < m; i++) {
            double t = 2 * PI * (double)i / (double)m;
            if (emit(ps, count, c[0] + r * cos(t), c[1] + r * sin(t), 0, NULL, phase)) return -1;
        }
        return 0;
    }
    long m = (long)ceil(4 * PI * r * r / (d * d));
    if (m < 4) m = 4;
    const double ga = PI * (3 - sqrt(5.0));
    for (long i = 0; i < m; i++) {
        double y = 1 - 2 * ((double)i + 0.5) / (double)m, rr = sqrt(1 - y * y), t = ga * (double)i;
        if (emit(ps, count, c[0] + r * rr * cos(t), c[1] + r * y, c[2] + r * rr * sin(t), NULL, phase)) return -1;
    }
    return 0;
}

long pfsph__sample_solid(const pfsph_scene *s, const pfsph_solid *o, double d, pfsph_particles *ps)
{
    const int dim = s->dim, L = o->layers < 1 ? 1 : o->layers;
    long count = 0;
    switch (o->shape) {
    case PFSPH_SHAPE_CONTAINER:
    case PFSPH_SHAPE_BOX: {
        /* lattice cells of spacing d aligned with the box faces; a container keeps the L
         * layers outside its faces, a box the L layers inside. */
        int container = o->shape == PFSPH_SHAPE_CONTAINER;
        long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, n[3] = {1, 1, 1};
        for (int a = 0; a < dim; a++) {
            n[a] = (long)floor((o->max[a] - o->min[a]) / d + 0.5);
            if (n[a] < 1) n[a] = 1;
            lo[a] = container ? -L : 0;
            hi[a] = container ? n[a] + L : n[a];
        }
        if (!ps) {
            /* counted in closed form: a container is the shell of L cells around the box (less
             * the L rows above an open top), a box the cells less than L from its faces */
            double all = 1, core = 1, top = L;
            for (int a = 0; a < dim; a++) {
                all *= (double)(hi[a] - lo[a]);
                core *= container ? (double)n[a] : (double)(n[a] - 2 * L > 0 ? n[a] - 2 * L : 0);
                if (a != 1) top *= (double)(hi[a] - lo[a]);
            }
            return clamp_count(all - core - (container && o->open_top ? top : 0));
        }
        for (long k = lo[2]; k < (dim == 3 ? hi[2] : 1); k++)
            for (long j = lo[1]; j < hi[1]; j++)
                for (long i = lo[0]; i < hi[0]; i++) {
                    long idx[3] = {i, j, k};
                    int in_shell = 0;
                    long depth = L; /* distance in cells from the surface */
                    for (int a = 0; a < dim; a++) {
                        long dd = idx[a] < n[a] - 1 - idx[a] ? idx[a] : n[a] - 1 - idx[a];
                        if (container) {
                            if (idx[a] < 0 || idx[a] >= n[a]) in_shell = 1;
                        } else if (dd < depth) depth = dd;
                    }
                    if (container) {
                        if (!in_shell) continue;
                        if (o->open_top && j >= n[1]) continue;
                    } else if (depth >= L) continue;
                    double p[3] = {0, 0, 0};
                    for (int a = 0; a < dim; a++) {
                        double w = (o->max[a] - o->min[a]) / (double)n[a];
                        p[a] = o->min[a] + ((double)idx[a] + 0.5) * w;
                    }
                    if (emit(ps, &count, p[0], p[1], p[2], NULL, o->phase)) return -1;
                }
        return count;
    }
    case PFSPH_SHAPE_SPHERE:
        for (int l = 0; l < L; l++)
            if (sample_sphere_layer(ps, &count, o->center, o->radius - (l + 0.5) * d, d, dim, o->phase)) return -1;
        return count;
    case PFSPH_SHAPE_CYLINDER: {
        if (dim == 2) {
            for (int l = 0; l < L; l++)
                if (sample_sphere_layer(ps, &count, o->center, o->radius - (l + 0.5) * d, d, 2, o->phase)) return -1;
            return count;
        }
        int ax = o->axis, u = (ax + 1) % 3, v = (ax + 2) % 3;
        long nh = (long)floor(o->height / d + 0.5);
        if (nh < 1) nh = 1;
        double dh = o->height / (double)nh;
        for (long k = 0; k < nh; k++) {
            double t = -0.5 * o->height + (k + 0.5) * dh;
            long kd = k < nh - 1 - k ? k : nh - 1 - k; /* layers from the caps */
            for (int l = 0; l < L; l++) {
                double r = o->radius - (l + 0.5) * d;
                if (r <= 0) break;
                long m = (long)ceil(2 * PI * r / d);
                for (long i = 0; i < m; i++) {
                    double th = 2 * PI * (double)i / (double)m + 0.5 * (double)(k & 1) * 2 * PI / (double)m;
                    double p[3];
                    p[ax] = o->center[ax] + t;
                    p[u] = o->center[u] + r * cos(th);
                    p[v] = o->center[v] + r * sin(th);
                    if (emit(ps, &count, p[0], p[1], p[2], NULL, o->phase)) return -1;
                }
            }
            if (kd < L) {
                /* caps: fill the disc inside the lateral layers with rings */
                for (double r = o->radius - (L + 0.5) * d; r > 0.25 * d; r -= d) {
                    long m = (long)ceil(2 * PI * r / d);
                    for (long i = 0; i < m; i++) {
                        double th = 2 * PI * (double)i / (double)m;
                        double p[3];
                        p[ax] = o->center[ax] + t;
                        p[u] = o->center[u] + r * cos(th);
                        p[v] = o->center[v] + r * sin(th);
                        if (emit(ps, &count, p[0], p[1], p[2], NULL, o->phase)) return -1;
                    }
                }
                double p[3];
                p[ax] = o->center[ax] + t;
                p[u] = o->center[u];
                p[v] = o->center[v];
                if (emit(ps, &count, p[0], p[1], p[2], NULL, o->phase)) return -1;
            }
        }
        return count;
    }
    case PFSPH_SHAPE_PLANE: {
        double nrm[3] = {o->normal[0], o->normal[1], dim == 3 ? o->normal[2] : 0};
        double ln = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        for (int a = 0; a < 3; a++) nrm[a] /= ln;
        double t1[3], t2[3];
        if (dim == 2) {
            t1[0] = -nrm[1], t1[1] = nrm[0], t1[2] = 0;
            t2[0] = t2[1] = t2[2] = 0;
        } else basis(nrm, t1, t2);
        /* extent: the domain's diagonal around the plane point, clipped to the domain */
        double diag = 0;
        for (int a = 0; a < dim; a++)
            diag += (s->domain_max[a] - s->domain_min[a]) * (s->domain_max[a] - s->domain_min[a]);
        diag = sqrt(diag);
        long m = (long)ceil(diag / d);
        long m2 = dim == 3 ? m : 0;
        for (int l = 0; l < L; l++)
            for (long j = -m2; j <= m2; j++)
                for (long i = -m; i <= m; i++) {
                    double p[3];
                    for (int a = 0; a < 3; a++)
                        p[a] = o->center[a] + ((double)i * t1[a] + (double)j * t2[a]) * d - (l + 0.5) * d * nrm[a];
                    int in = 1;
                    for (int a = 0; a < dim; a++)
                        if (p[a] < s->domain_min[a] - L * d || p[a] > s->domain_max[a] + L * d) in = 0;
                    if (!in) continue;
                    if (dim == 2) p[2] = 0;
                    if (emit(ps, &count, p[0], p[1], p[2], NULL, o->phase)) return -1;
                }
        return count;
    }
    default: return 0;
    }
}

double pfsph__solid_distance(const pfsph_solid *o, int dim, double d, const double p[3])
{
    switch (o->shape) {
    case PFSPH_SHAPE_CONTAINER: {
        /* Inside the fluid region (above an open top too): distance to the nearest wall face.
         * Outside it, the walls are a shell layers x d thick: negative within the shell,
         * positive beyond it, so that fluid next to (or inside) another container is kept. */
        double m = INFINITY, q2 = 0;
        for (int a = 0; a < dim; a++) {
            double lo = p[a] - o->min[a], hi = o->max[a] - p[a];
            if (a == 1 && o->open_top) hi = INFINITY;
            double in = lo < hi ? lo : hi;
            if (in < m) m = in;
            if (in < 0) q2 += in * in;
        }
        if (m >= 0) return m;
        double q = sqrt(q2), T = o->layers * d;
        return q <= T ? -(q < T - q ? q : T - q) : q - T;
    }
    case PFSPH_SHAPE_BOX: {
        double out = 0, in = -INFINITY;
        for (int a = 0; a < dim; a++) {
            double c = 0.5 * (o->min[a] + o->max[a]), e = 0.5 * (o->max[a] - o->min[a]);
            double q = fabs(p[a] - c) - e;
            if (q > 0) out += q * q;
            if (q > in) in = q;
        }
        return out > 0 ? sqrt(out) : in;
    }
    case PFSPH_SHAPE_SPHERE: {
        double r2 = 0;
        for (int a = 0; a < dim; a++) r2 += (p[a] - o->center[a]) * (p[a] - o->center[a]);
        return sqrt(r2) - o->radius;
    }
    case PFSPH_SHAPE_CYLINDER: {
        double r2 = 0;
        if (dim == 2) {
            for (int a = 0; a < 2; a++) r2 += (p[a] - o->center[a]) * (p[a] - o->center[a]);
            return sqrt(r2) - o->radius;
        }
        for (int a = 0; a < 3; a++)
            if (a != o->axis) r2 += (p[a] - o->center[a]) * (p[a] - o->center[a]);
        double dr = sqrt(r2) - o->radius, dz = fabs(p[o->axis] - o->center[o->axis]) - 0.5 * o->height;
        if (dr > 0 && dz > 0) return sqrt(dr * dr + dz * dz);
        return dr > dz ? dr : dz;
    }
    case PFSPH_SHAPE_PLANE: {
        double ln = 0, s = 0;
        for (int a = 0; a < dim; a++) ln += o->normal[a] * o->normal[a];
        ln = sqrt(ln);
        for (int a = 0; a < dim; a++) s += (p[a] - o->center[a]) * o->normal[a] / ln;
        return s;
    }
    default: return INFINITY;
    }
}
