/* Surface sampling of closed meshes (pfsph_mesh_sample_surface, mesh.h): samples live in a hash
 * grid (cells of twice every query radius, so a query looks at 8 cells); a candidate becomes a
 * sample only if no sample is nearer than the phase's radius, which bounds the minimum distance,
 * and a final pass over a fine candidate lattice fills every gap, which bounds the largest hole.
 * Deterministic: no random numbers. */
#include "pfsph/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh_internal.h"
#include "core/vec.h"

#define SAMPLE_MAX ((size_t)20000000u)

/* Sampling parameters, in units of the spacing s (docs/meshes.md explains the choice):
 * samples on sharp edges are kept if no sample lies within R_EDGE, samples of the per-triangle
 * lattice (step STEP_STRUCT, scanned row by row) if none lies within R_STRUCT; the fill pass
 * then puts a sample at the centre of every hole wider than R_FILL, found on a candidate
 * lattice of step FILL_STEP, so that no surface point is farther than R_FILL + FILL_STEP
 * (0.74 s) from a sample and no two samples are closer than min(R_EDGE, R_STRUCT, R_FILL). */
#define R_EDGE 0.75
#define R_STRUCT 0.9
#define STEP_STRUCT 0.2
#define R_FILL 0.68
#define FILL_STEP 0.06
#define SHARP_DEG 30.0

typedef struct {
    int32_t c[3];
    uint32_t head; /* UINT32_MAX: empty slot */
} cell_slot;

typedef struct {
    double *p;
    uint32_t *next;
    size_t n, cap;
    cell_slot *tab;
    size_t tabsize, used; /* power of two; occupied slots */
    double lo[3], inv_cell;
    pfsph_error *err;
} sampler;

static size_t cell_hash(const int32_t c[3])
{
    uint64_t h = (uint64_t)(uint32_t)c[0] * 0x9E3779B97F4A7C15ULL;
    h ^= (uint64_t)(uint32_t)c[1] * 0xC2B2AE3D27D4EB4FULL;
    h ^= (uint64_t)(uint32_t)c[2] * 0x165667B19E3779F9ULL;
    h ^= h >> 29;
    return (size_t)h;
}

static void cell_of(const sampler *s, const double *p, int32_t c[3])
{
    for (int a = 0; a < 3; a++) c[a] = (int32_t)floor((p[a] - s->lo[a]) * s->inv_cell);
}

static cell_slot *find_slot(cell_slot *tab, size_t size, const int32_t c[3])
{
    size_t mask = size - 1, i = cell_hash(c) & mask;
    while (tab[i].head != UINT32_MAX && (tab[i].c[0] != c[0] || tab[i].c[1] != c[1] || tab[i].c[2] != c[2]))
        i = (i + 1) & mask;
    return tab + i;
}

static int rehash(sampler *s, size_t size)
{
    cell_slot *t = malloc(size * sizeof *t);
    if (!t) return -1;
    for (size_t i = 0; i < size; i++) t[i].head = UINT32_MAX;
    for (size_t i = 0; i < s->tabsize; i++)
        if (s->tab[i].head != UINT32_MAX) *find_slot(t, size, s->tab[i].c) = s->tab[i];
    free(s->tab);
    s->tab = t;
    s->tabsize = size;
    return 0;
}

/* The 2 x 2 x 2 cells that hold every point within half a cell of p: cells are twice the
 * largest query radius, so 8 lookups replace the 27 that cells of one radius would need. */
static void query_cells(const sampler *s, const double *p, int32_t c0[3])
{
    for (int a = 0; a < 3; a++) {
        double x = (p[a] - s->lo[a]) * s->inv_cell, f = floor(x);
        c0[a] = (int32_t)f - (x - f < 0.5);
    }
}

/* Is there a sample with squared distance below r2 from p? */
static int near_sample(const sampler *s, const double *p, double r2)
{
    int32_t c[3], q[3];
    query_cells(s, p, c);
    for (int k = 0; k < 8; k++) {
        q[0] = c[0] + (k & 1);
        q[1] = c[1] + (k >> 1 & 1);
        q[2] = c[2] + (k >> 2);
        const cell_slot *sl = find_slot(s->tab, s->tabsize, q);
        for (uint32_t j = sl->head; j != UINT32_MAX; j = s->next[j]) {
            const double *o = s->p + 3 * (size_t)j;
            double ex = o[0] - p[0], ey = o[1] - p[1], ez = o[2] - p[2];
            if (ex * ex + ey * ey + ez * ez < r2) return 1;
        }
    }
    return 0;
}

/* Add p unless a sample is nearer than sqrt(r2). Returns 0, or an error code. */
static int offer(sampler *s, const double *p, double r2)
{
    if (near_sample(s, p, r2)) return 0;
    if (s->n >= SAMPLE_MAX)
        return pfsph_fail(s->err, PFSPH_EINPUT, "spacing too small: more than %zu samples", SAMPLE_MAX);
    if (s->n == s->cap) {
        size_t nc = s->cap ? 2 * s->cap : 1024;
        double *np = realloc(s->p, 3 * nc * sizeof(double));
        if (!np) return pfsph_fail(s->err, PFSPH_ENOMEM, "out of memory sampling the surface");
        s->p = np;
        uint32_t *nn = realloc(s->next, nc * sizeof(uint32_t));
        if (!nn) return pfsph_fail(s->err, PFSPH_ENOMEM, "out of memory sampling the surface");
        s->next = nn;
        s->cap = nc;
    }
    if (2 * (s->used + 1) > s->tabsize && rehash(s, 2 * s->tabsize))
        return pfsph_fail(s->err, PFSPH_ENOMEM, "out of memory sampling the surface");
    int32_t c[3];
    cell_of(s, p, c);
    cell_slot *sl = find_slot(s->tab, s->tabsize, c);
    if (sl->head == UINT32_MAX) {
        sl->c[0] = c[0];
        sl->c[1] = c[1];
        sl->c[2] = c[2];
        s->used++;
    }
    memcpy(s->p + 3 * s->n, p, 3 * sizeof(double));
    s->next[s->n] = sl->head;
    sl->head = (uint32_t)s->n;
    s->n++;
    return 0;
}

/* Distance from p to the nearest sample, or `cap` (<= half a cell) if none is nearer. */
static double nearest_sample(const sampler *s, const double *p, double cap)
{
    int32_t c[3], q[3];
    double best = cap * cap;
    query_cells(s, p, c);
    for (int k = 0; k < 8; k++) {
        q[0] = c[0] + (k & 1);
        q[1] = c[1] + (k >> 1 & 1);
        q[2] = c[2] + (k >> 2);
        const cell_slot *sl = find_slot(s->tab, s->tabsize, q);
        for (uint32_t j = sl->head; j != UINT32_MAX; j = s->next[j]) {
            const double *o = s->p + 3 * (size_t)j;
            double ex = o[0] - p[0], ey = o[1] - p[1], ez = o[2] - p[2];
            double d2 = ex * ex + ey * ey + ez * ez;
            if (d2 < best) best = d2;
        }
    }
    return sqrt(best);
}

/* Max-heap of hole candidates keyed by distance to the nearest sample (ties: earlier first,
 * so the result does not depend on the heap's internal order). */
typedef struct {
    double d, p[3];
    size_t seq;
} hole;

typedef struct {
    hole *h;
    size_t n, cap;
} hole_heap;

static int hole_above(const hole *a, const hole *b) { return a->d > b->d || (a->d == b->d && a->seq < b->seq); }

static int heap_push(hole_heap *hp, const hole *x)
{
    if (hp->n == hp->cap) {
        size_t nc = hp->cap ? 2 * hp->cap : 1024;
        hole *nh = realloc(hp->h, nc * sizeof *nh);
        if (!nh) return -1;
        hp->h = nh;
        hp->cap = nc;
    }
    size_t i = hp->n++;
    while (i > 0 && hole_above(x, &hp->h[(i - 1) / 2])) {
        hp->h[i] = hp->h[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    hp->h[i] = *x;
    return 0;
}

static hole heap_pop(hole_heap *hp)
{
    hole top = hp->h[0], last = hp->h[--hp->n];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= hp->n) break;
        if (c + 1 < hp->n && hole_above(&hp->h[c + 1], &hp->h[c])) c++;
        if (!hole_above(&hp->h[c], &last)) break;
        hp->h[i] = hp->h[c];
        i = c;
    }
    if (hp->n) hp->h[i] = last;
    return top;
}

/* Fill-pass candidates of one segment or triangle go to the heap when they lie farther than
 * `thr` from every sample. */
typedef struct {
    sampler *s;
    hole_heap *hp;
    double thr, cap;
    size_t seq;
} hole_scan;

static int scan_point(hole_scan *hs, const double *p, double *dist)
{
    double d = nearest_sample(hs->s, p, hs->cap);
    *dist = d;
    if (d <= hs->thr) return 0;
    hole h = {.d = d, .p = {p[0], p[1], p[2]}, .seq = hs->seq++};
    return heap_push(hs->hp, &h) ? pfsph_fail(hs->s->err, PFSPH_ENOMEM, "out of memory sampling the surface") : 0;
}

/* Points along the segment a-b at steps of at most `step` (endpoints excluded). */
static int offer_edge(sampler *s, const double *a, const double *b, double step, double r2, hole_scan *hs)
{
    double d[3];
    vec3_sub(b, a, d);
    double len = vec3_norm(d);
    size_t k = (size_t)ceil(len / step); /* bounded by the size check in the caller */
    for (size_t i = 1; i < k; i++) {
        double t = (double)i / (double)k, p[3];
        for (int a2 = 0; a2 < 3; a2++) p[a2] = a[a2] + t * d[a2];
        int rc;
        if (hs) {
            /* the next candidates within thr - dist of p are covered by p's nearest sample */
            double dist;
            rc = scan_point(hs, p, &dist);
            if (dist < hs->thr) i += (size_t)((hs->thr - dist) / (len / (double)k));
        } else {
            rc = offer(s, p, r2);
        }
        if (rc) return rc;
    }
    return 0;
}

/* A hex lattice of the given step over the triangle (rows parallel to its longest edge),
 * keeping points at least `margin` from every edge. */
static int offer_lattice(sampler *s, const double *P0, const double *P1, const double *P2, double step, double margin,
                         double r2, hole_scan *hs)
{
    const double *P[3] = {P0, P1, P2};
    double len2[3];
    for (int k = 0; k < 3; k++) {
        double d[3];
        vec3_sub(P[(k + 1) % 3], P[k], d);
        len2[k] = vec3_dot(d, d);
    }
    int b = 0; /* base edge: P[b] -> P[b+1], the longest */
    if (len2[1] > len2[b]) b = 1;
    if (len2[2] > len2[b]) b = 2;
    const double *A = P[b], *B = P[(b + 1) % 3], *C = P[(b + 2) % 3];
    double u[3], w[3], nrm[3], v[3];
    vec3_sub(B, A, u);
    vec3_sub(C, A, w);
    double L = vec3_norm(u);
    vec3_cross(u, w, nrm);
    double nn = vec3_norm(nrm);
    if (!(L > 0) || !(nn > 0)) return 0;
    double H = nn / L; /* height over the base */
    if (H <= 2 * margin) return 0;
    for (int a = 0; a < 3; a++) u[a] /= L;
    vec3_cross(nrm, u, v); /* in-plane, towards C */
    for (int a = 0; a < 3; a++) v[a] /= nn;
    double cx = vec3_dot(w, u); /* C at (cx, H) in the (u, v) frame */
    /* distance of (x, y) to the left edge A-C and the right edge B-C */
    double lenl = sqrt(cx * cx + H * H), lenr = sqrt((L - cx) * (L - cx) + H * H);
    double rowh = step * 0.8660254037844386;
    size_t nrows = (size_t)ceil((H - margin) / rowh);
    for (size_t j = 1; j <= nrows; j++) {
        double y = (double)j * rowh;
        if (y > H - margin) break;
        /* x range from the two slanted edges, widened by their slope for the margin */
        double xl = cx * y / H + margin * lenl / H, xr = L + (cx - L) * y / H - margin * lenr / H;
        if (xr < xl) continue;
        double off = (j & 1) ? 0.5 * step : 0.0;
        double i0 = ceil((xl - off) / step), i1 = floor((xr - off) / step);
        if (!(i1 >= i0)) continue;
        size_t cnt = (size_t)(i1 - i0 + 1.0); /* <= L / step, bounded by the size guard */
        for (size_t i = 0; i < cnt; i++) {
            double x = off + (i0 + (double)i) * step, p[3];
            for (int a = 0; a < 3; a++) p[a] = A[a] + x * u[a] + y * v[a];
            int rc;
            if (hs) { /* skip what p's nearest sample provably covers (see offer_edge) */
                double dist;
                rc = scan_point(hs, p, &dist);
                if (dist < hs->thr) i += (size_t)((hs->thr - dist) / step);
            } else {
                rc = offer(s, p, r2);
            }
            if (rc) return rc;
        }
    }
    return 0;
}

/* Flag each triangle edge (3 t + k: from corner k to k+1) as sharp: a crease whose dihedral
 * angle exceeds SHARP_DEG, or an open or non-manifold edge. Sharp edges and their vertices get
 * samples of their own so corners and creases are represented exactly; smooth edges get none,
 * which keeps a curved surface from growing extra lines of samples along its edges. */
static int sharp_edges(const pfsph_mesh *m, unsigned char *sharp)
{
    size_t ne = 3 * m->ntris;
    pfsph__mesh_edge *e = malloc(ne * sizeof *e);
    double *nrm = malloc(3 * m->ntris * sizeof(double));
    if (!e || !nrm) {
        free(e);
        free(nrm);
        return -1;
    }
    for (size_t t = 0; t < m->ntris; t++) {
        double e1[3], e2[3], *n = nrm + 3 * t;
        vec3_sub(m->v + 3 * (size_t)m->tri[3 * t + 1], m->v + 3 * (size_t)m->tri[3 * t], e1);
        vec3_sub(m->v + 3 * (size_t)m->tri[3 * t + 2], m->v + 3 * (size_t)m->tri[3 * t], e2);
        vec3_cross(e1, e2, n);
        double l = vec3_norm(n);
        for (int a = 0; a < 3; a++) n[a] = l > 0 ? n[a] / l : 0;
        for (int k = 0; k < 3; k++) {
            uint32_t va = m->tri[3 * t + k], vb = m->tri[3 * t + (k + 1) % 3];
            pfsph__mesh_edge *r = e + 3 * t + k;
            r->key = va < vb ? ((uint64_t)va << 32 | vb) : ((uint64_t)vb << 32 | va);
            r->tri = (uint32_t)t;
            r->fwd = (uint32_t)k; /* here: which edge of the triangle */
        }
    }
    qsort(e, ne, sizeof *e, pfsph__mesh_edge_cmp);
    const double cos_sharp = cos(SHARP_DEG * MESH_PI / 180);
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].key == e[i].key) j++;
        int sh = 1;
        if (j - i == 2) sh = vec3_dot(nrm + 3 * (size_t)e[i].tri, nrm + 3 * (size_t)e[i + 1].tri) < cos_sharp;
        for (size_t k = i; k < j; k++) sharp[3 * (size_t)e[k].tri + e[k].fwd] = (unsigned char)sh;
        i = j;
    }
    free(e);
    free(nrm);
    return 0;
}

int pfsph_mesh_sample_surface(const pfsph_mesh *m, double spacing, double **pts, size_t *n, pfsph_error *err)
{
    *pts = NULL;
    *n = 0;
    if (!(spacing > 0) || !isfinite(spacing))
        return pfsph_fail(err, PFSPH_EINPUT, "sampling spacing %g must be positive and finite", spacing);
    if (!m || m->ntris == 0) return pfsph_fail(err, PFSPH_EINPUT, "mesh has no triangles");
    if (m->ntris > MESH_MAX_TRIS) return pfsph_fail(err, PFSPH_EINPUT, "mesh too large");
    double lo[3], hi[3];
    if (pfsph_mesh_bounds(m, lo, hi))
        return pfsph_fail(err, PFSPH_EINPUT, "mesh has a non-finite vertex or a bad index");
    /* size guard before anything is allocated: every loop below is bounded by these */
    double area = 0, elen = 0, ext = 0;
    for (int a = 0; a < 3; a++) ext = fmax(ext, hi[a] - lo[a]);
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p0 = m->v + 3 * (size_t)m->tri[3 * t], *p1 = m->v + 3 * (size_t)m->tri[3 * t + 1],
                     *p2 = m->v + 3 * (size_t)m->tri[3 * t + 2];
        double e1[3], e2[3], e3[3], c[3];
        vec3_sub(p1, p0, e1);
        vec3_sub(p2, p0, e2);
        vec3_sub(p2, p1, e3);
        vec3_cross(e1, e2, c);
        area += 0.5 * vec3_norm(c);
        elen += vec3_norm(e1) + vec3_norm(e2) + vec3_norm(e3);
    }
    double est = area / (spacing * spacing) + elen / spacing + (double)m->nverts;
    if (!isfinite(est) || est > 2e7 || ext / spacing > 1e7)
        return pfsph_fail(err, PFSPH_EINPUT, "spacing %g too small for a mesh of area %g (about %.3g samples)", spacing,
                          area, est);
    unsigned char *sharp = malloc(3 * m->ntris);
    if (!sharp || sharp_edges(m, sharp)) {
        free(sharp);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling the surface");
    }

    const double re = R_EDGE * spacing, ra = R_STRUCT * spacing, rf = R_FILL * spacing;
    const double rmax = fmax(re, fmax(ra, rf));
    sampler s = {.err = err, .inv_cell = 0.5 / rmax};
    for (int a = 0; a < 3; a++) s.lo[a] = lo[a] - 4 * rmax;
    int rc = rehash(&s, 1024) ? pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling") : 0;
    /* 1. ends of sharp edges (corners), 2. points along sharp edges at most one spacing apart
     * (kept if no sample within R_EDGE) */
    for (size_t i = 0; i < 3 * m->ntris && !rc; i++)
        if (sharp[i] || sharp[i - i % 3 + (i + 2) % 3]) rc = offer(&s, m->v + 3 * (size_t)m->tri[i], re * re);
    for (size_t i = 0; i < 3 * m->ntris && !rc; i++)
        if (sharp[i])
            rc = offer_edge(&s, m->v + 3 * (size_t)m->tri[i], m->v + 3 * (size_t)m->tri[i - i % 3 + (i + 1) % 3],
                            spacing, re * re, NULL);
    /* 3. each triangle's fine lattice in raster order, kept if no sample within R_STRUCT:
     * greedy in scan order this settles into nearly hexagonal rows about R_STRUCT apart */
    for (size_t t = 0; t < m->ntris && !rc; t++)
        rc = offer_lattice(&s, m->v + 3 * (size_t)m->tri[3 * t], m->v + 3 * (size_t)m->tri[3 * t + 1],
                           m->v + 3 * (size_t)m->tri[3 * t + 2], STEP_STRUCT * spacing, 0.0, ra * ra, NULL);
    /* 4. gap filling, farthest point first: every candidate of a lattice of step FILL_STEP
     * (covering each triangle up to its edges, covering radius <= FILL_STEP) farther than
     * R_FILL from all samples goes into a max-heap; the farthest becomes a sample (its key is
     * re-checked first, as new samples only shrink distances), until none is left. A sample
     * placed at the centre of each hole rather than at its rim keeps the count low; at the end
     * no candidate is farther than R_FILL, so no surface point is farther than
     * R_FILL + FILL_STEP, and every fill sample is at least R_FILL from the others. */
    const double fs = FILL_STEP * spacing;
    hole_heap hp = {0};
    hole_scan hs = {.s = &s, .hp = &hp, .thr = rf, .cap = rmax};
    for (size_t t = 0; t < m->ntris && !rc; t++) {
        const double *p0 = m->v + 3 * (size_t)m->tri[3 * t], *p1 = m->v + 3 * (size_t)m->tri[3 * t + 1],
                     *p2 = m->v + 3 * (size_t)m->tri[3 * t + 2];
        rc = offer_edge(&s, p0, p1, fs, 0, &hs);
        if (!rc) rc = offer_edge(&s, p1, p2, fs, 0, &hs);
        if (!rc) rc = offer_edge(&s, p2, p0, fs, 0, &hs);
        double d0;
        if (!rc) rc = scan_point(&hs, p0, &d0);
        if (!rc) rc = offer_lattice(&s, p0, p1, p2, fs, 0.0, 0, &hs);
    }
    while (!rc && hp.n) {
        hole h = heap_pop(&hp);
        double d = nearest_sample(&s, h.p, rmax);
        if (d <= rf) continue;
        if (d < h.d && hp.n && hole_above(&hp.h[0], &(hole){d, {0, 0, 0}, h.seq})) {
            h.d = d; /* stale key: back in at its true distance */
            if (heap_push(&hp, &h)) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling the surface");
            continue;
        }
        rc = offer(&s, h.p, 0.0);
    }
    free(hp.h);
    free(sharp);
    free(s.tab);
    free(s.next);
    if (rc) {
        free(s.p);
        return rc;
    }
    double *shrunk = realloc(s.p, 3 * s.n * sizeof(double));
    *pts = shrunk ? shrunk : s.p;
    *n = s.n;
    return PFSPH_OK;
}
