/* Surface reconstruction (Yu & Turk 2013, "Reconstructing surfaces of particle-based fluids using
 * anisotropic kernels"): weighted PCA per particle, smoothed kernel centres, a volume-fraction
 * colour field on sparse blocks grown along the surface, marching cubes with every cube split into
 * six tetrahedra (Kuhn), vertices welded by edge id. docs/surfaces.md gives the choices. */
#include "pfsph/surface_mesh.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/eigen.h"

#define BS 8             /* cells per block edge */
#define BN (BS + 1)      /* nodes per block edge: 0 .. BS (the last layer is the next block's first) */
#define BNODES (BN * BN * BN)
#define COORD_BITS 20
#define COORD_BIAS (1 << (COORD_BITS - 1))

typedef struct kern {
    double c[3];  /* smoothed centre */
    double G[9];  /* world -> unit-kernel coordinates (row-major, includes 1 / h) */
    double det;   /* |det G| */
    double rad;   /* support radius in the world [m] */
} kern;

typedef struct block {
    int64_t key;
    int b[3];
    double *f; /* BNODES values */
} block;

static double cubic_unit(double q) /* cubic spline of support 1, 3D normalisation */
{
    const double sigma = 8.0 / 3.14159265358979323846;
    if (q >= 1) return 0;
    if (q <= 0.5) return sigma * (6 * (q * q * q - q * q) + 1);
    double t = 1 - q;
    return sigma * 2 * t * t * t;
}

void pfsph_surface_opts_default(pfsph_surface_opts *o, double spacing)
{
    memset(o, 0, sizeof *o);
    o->spacing = spacing;
}

static void resolve(const pfsph_surface_opts *in, pfsph_surface_opts *o)
{
    *o = *in;
    if (!(o->cell > 0)) o->cell = 0.5;
    if (!(o->support > 0)) o->support = 3;
    if (!(o->pca_radius > 0)) o->pca_radius = 3;
    if (o->lambda == 0) o->lambda = 0.9;
    if (o->lambda < 0) o->lambda = 0;
    if (!(o->kr > 0)) o->kr = 4;
    if (!(o->kn > 0)) o->kn = 0.5;
    if (o->n_eps <= 0) o->n_eps = -1; /* set from the neighbourhood size, see below */
}

/* Yu & Turk's N_eps = 25 is about a fifth of their full neighbourhood; keep that fraction */
static int lattice_count(double r)
{
    int m = (int)ceil(r), c = 0;
    for (int i = -m; i <= m; i++)
        for (int j = -m; j <= m; j++)
            for (int k = -m; k <= m; k++) c += i * i + j * j + k * k < r * r;
    return c;
}

/* ---- a sorted cell list over a point set (no domain needed) ---- */
typedef struct cells {
    double inv;
    size_t n;          /* points */
    int64_t *ukey;     /* unique cell keys, ascending */
    uint32_t *ustart;  /* nu + 1 */
    size_t nu;
    uint32_t *idx;     /* point indices by cell, ascending within a cell */
} cells;

static int64_t pack3(int64_t i, int64_t j, int64_t k)
{
    return ((i + COORD_BIAS) << (2 * COORD_BITS)) | ((j + COORD_BIAS) << COORD_BITS) | (k + COORD_BIAS);
}

typedef struct kv {
    int64_t key;
    uint32_t i;
} kv;

static int kv_cmp(const void *a, const void *b)
{
    const kv *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->i < y->i ? -1 : (x->i > y->i);
}

static int i64_cmp(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : (x > y);
}

static int u32_cmp(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : (x > y);
}

static long cell_of(double x, double inv) { return (long)floor(x * inv); }

static int cells_build(cells *g, const double *p, size_t n, double size)
{
    memset(g, 0, sizeof *g);
    g->inv = 1.0 / size;
    g->n = n;
    kv *t = malloc((n ? n : 1) * sizeof *t);
    g->idx = malloc((n ? n : 1) * sizeof *g->idx);
    g->ukey = malloc((n ? n : 1) * sizeof *g->ukey);
    g->ustart = malloc((n + 1) * sizeof *g->ustart);
    if (!t || !g->idx || !g->ukey || !g->ustart) {
        free(t);
        return PFSPH_ENOMEM;
    }
    for (size_t i = 0; i < n; i++) {
        t[i].key = pack3(cell_of(p[3 * i], g->inv), cell_of(p[3 * i + 1], g->inv), cell_of(p[3 * i + 2], g->inv));
        t[i].i = (uint32_t)i;
    }
    qsort(t, n, sizeof *t, kv_cmp);
    for (size_t i = 0; i < n; i++) {
        g->idx[i] = t[i].i;
        if (i == 0 || t[i].key != t[i - 1].key) {
            g->ukey[g->nu] = t[i].key;
            g->ustart[g->nu++] = (uint32_t)i;
        }
    }
    g->ustart[g->nu] = (uint32_t)n;
    free(t);
    return PFSPH_OK;
}

static void cells_free(cells *g)
{
    free(g->ukey);
    free(g->ustart);
    free(g->idx);
}

/* index range of cell (i, j, k); b == e when empty */
static void cells_range(const cells *g, long i, long j, long k, uint32_t *b, uint32_t *e)
{
    int64_t key = pack3(i, j, k);
    size_t lo = 0, hi = g->nu;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (g->ukey[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    if (lo < g->nu && g->ukey[lo] == key) {
        *b = g->ustart[lo];
        *e = g->ustart[lo + 1];
    } else *b = *e = 0;
}

/* sum over a lattice's offsets within r of weight and weighted squared distance: the
 * covariance of a full lattice neighbourhood, which normalises the kernel scales (ks) */
static double lattice_sigma(double r)
{
    int m = (int)ceil(r);
    double sw = 0, sw2 = 0;
    for (int i = -m; i <= m; i++)
        for (int j = -m; j <= m; j++)
            for (int k = -m; k <= m; k++) {
                double s = sqrt((double)(i * i + j * j + k * k));
                if (s >= r) continue;
                double w = 1 - (s / r) * (s / r) * (s / r);
                sw += w;
                sw2 += w * s * s / 3;
            }
    return sw2 / sw;
}

/* Kernels of n points: centres, anisotropy. surf[i] (may be NULL) gets 1 for particles near
 * the surface (few neighbours, offset centre of mass or flattened neighbourhood). */
static int kernels_build(const double *x, size_t n, const pfsph_surface_opts *o, kern *K, uint8_t *surf,
                         double *rad_max)
{
    const double d = o->spacing, r = o->pca_radius * d, h = o->support * d;
    const double ks = 1.0 / (lattice_sigma(o->pca_radius) * d * d);
    const int n_eps = o->n_eps > 0 ? o->n_eps : (lattice_count(o->pca_radius) + 2) / 5;
    cells g;
    int rc = cells_build(&g, x, n, r);
    if (rc) {
        cells_free(&g);
        return rc;
    }
    double rmax = 0;
#pragma omp parallel for schedule(static) reduction(max : rmax)
    for (size_t i = 0; i < n; i++) {
        const double *xi = x + 3 * i;
        long ci = cell_of(xi[0], g.inv), cj = cell_of(xi[1], g.inv), ck = cell_of(xi[2], g.inv);
        double sw = 0, m[3] = {0, 0, 0};
        int cnt = 0;
        /* one pass: weighted sums of offsets e = x_j - x_i and of e e^T; the covariance about
         * the weighted mean is S2 / sw - mu mu^T (offsets keep it well conditioned) */
        double C[3][3] = {{0}}, mu[3] = {0, 0, 0};
        for (long a = ci - 1; a <= ci + 1; a++)
            for (long b = cj - 1; b <= cj + 1; b++)
                for (long c = ck - 1; c <= ck + 1; c++) {
                    uint32_t lo, hi;
                    cells_range(&g, a, b, c, &lo, &hi);
                    for (uint32_t q = lo; q < hi; q++) {
                        const double *xj = x + 3 * g.idx[q];
                        double e[3] = {xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]};
                        double s2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
                        if (s2 >= r * r) continue;
                        double sr = sqrt(s2) / r, w = 1 - sr * sr * sr;
                        sw += w;
                        for (int u = 0; u < 3; u++) {
                            mu[u] += w * e[u];
                            for (int v = u; v < 3; v++) C[u][v] += w * e[u] * e[v];
                        }
                        cnt++;
                    }
                }
        for (int u = 0; u < 3; u++) mu[u] /= sw;
        for (int u = 0; u < 3; u++) {
            m[u] = xi[u] + mu[u];
            for (int v = u; v < 3; v++) C[u][v] = C[u][v] / sw - mu[u] * mu[v];
        }
        {
            kern *k = K + i;
            for (int u = 0; u < 3; u++) k->c[u] = (1 - o->lambda) * xi[u] + o->lambda * m[u];
            double off = sqrt((m[0] - xi[0]) * (m[0] - xi[0]) + (m[1] - xi[1]) * (m[1] - xi[1]) +
                              (m[2] - xi[2]) * (m[2] - xi[2]));
            double scale[3] = {o->kn, o->kn, o->kn}, V[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
            int flat = 0;
            if (o->isotropic) scale[0] = scale[1] = scale[2] = 1;
            else if (cnt >= n_eps) {
                double w[3];
                pfsph_eigen_sym3((const double(*)[3])C, w, V);
                for (int u = 0; u < 3; u++) {
                    double s = w[u] < w[0] / o->kr ? w[0] / o->kr : w[u];
                    scale[u] = sqrt(ks * s); /* axis length ~ standard deviation (docs/surfaces.md) */
                    if (scale[u] > 2) scale[u] = 2; /* bounded search radius (docs/surfaces.md) */
                }
                flat = w[2] < 0.6 * w[0];
            }
            if (surf) surf[i] = (uint8_t)(cnt < n_eps || flat || off > 0.1 * r);
            /* G = V diag(1 / (h s)) V^T */
            for (int u = 0; u < 3; u++)
                for (int v = 0; v < 3; v++) {
                    double acc = 0;
                    for (int a = 0; a < 3; a++) acc += V[u][a] * V[v][a] / (h * scale[a]);
                    k->G[3 * u + v] = acc;
                }
            k->det = 1.0 / (h * h * h * scale[0] * scale[1] * scale[2]);
            double smax = scale[0] > scale[1] ? scale[0] : scale[1];
            if (scale[2] > smax) smax = scale[2];
            k->rad = h * smax;
            if (k->rad > rmax) rmax = k->rad;
        }
    }
    cells_free(&g);
    *rad_max = rmax;
    return PFSPH_OK;
}

static double kern_eval(const kern *k, const double p[3])
{
    double r[3] = {p[0] - k->c[0], p[1] - k->c[1], p[2] - k->c[2]};
    if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] >= k->rad * k->rad) return 0;
    double q2 = 0;
    for (int u = 0; u < 3; u++) {
        double t = k->G[3 * u] * r[0] + k->G[3 * u + 1] * r[1] + k->G[3 * u + 2] * r[2];
        q2 += t * t;
    }
    if (q2 >= 1) return 0;
    return k->det * cubic_unit(sqrt(q2));
}

double pfsph_surface_calibrate_iso(const pfsph_surface_opts *in)
{
    pfsph_surface_opts o;
    resolve(in, &o);
    const double d = o.spacing;
    const int L = 8, D = 6;
    size_t n = (size_t)(2 * L + 1) * (2 * L + 1) * (size_t)D, c = 0;
    double *x = malloc(3 * n * sizeof *x);
    kern *K = malloc(n * sizeof *K);
    double iso = 0.5, rmax;
    if (!x || !K) goto out;
    for (int i = -L; i <= L; i++)
        for (int j = -L; j <= L; j++)
            for (int k = 0; k < D; k++) {
                x[3 * c] = i * d;
                x[3 * c + 1] = j * d;
                x[3 * c + 2] = -k * d;
                c++;
            }
    if (kernels_build(x, n, &o, K, NULL, &rmax)) goto out;
    /* the true surface of the slab is half a spacing above its top layer; average over one
     * lattice cell of lateral positions */
    double sum = 0;
    int ns = 0;
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++) {
            double p[3] = {a * d / 4, b * d / 4, d / 2}, f = 0;
            for (size_t j = 0; j < n; j++) f += kern_eval(K + j, p);
            sum += f * d * d * d;
            ns++;
        }
    iso = sum / ns;
out:
    free(x);
    free(K);
    return iso;
}

/* ---- sparse blocks: open-addressing hash of block keys ---- */
typedef struct bmap {
    int64_t *keys;
    int32_t *val;
    size_t cap, n;
} bmap;

static size_t hash64(int64_t k)
{
    uint64_t x = (uint64_t)k;
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    return (size_t)x;
}

static int bmap_find(const bmap *m, int64_t key)
{
    if (!m->cap) return -1;
    size_t i = hash64(key) & (m->cap - 1);
    while (m->val[i] >= 0) {
        if (m->keys[i] == key) return m->val[i];
        i = (i + 1) & (m->cap - 1);
    }
    return -1;
}

static int bmap_put(bmap *m, int64_t key, int32_t v)
{
    if (2 * (m->n + 1) > m->cap) {
        size_t nc = m->cap ? 2 * m->cap : 1024;
        int64_t *nk = malloc(nc * sizeof *nk);
        int32_t *nv = malloc(nc * sizeof *nv);
        if (!nk || !nv) {
            free(nk);
            free(nv);
            return PFSPH_ENOMEM;
        }
        for (size_t i = 0; i < nc; i++) nv[i] = -1;
        for (size_t i = 0; i < m->cap; i++)
            if (m->val[i] >= 0) {
                size_t j = hash64(m->keys[i]) & (nc - 1);
                while (nv[j] >= 0) j = (j + 1) & (nc - 1);
                nk[j] = m->keys[i];
                nv[j] = m->val[i];
            }
        free(m->keys);
        free(m->val);
        m->keys = nk;
        m->val = nv;
        m->cap = nc;
    }
    size_t i = hash64(key) & (m->cap - 1);
    while (m->val[i] >= 0) i = (i + 1) & (m->cap - 1);
    m->keys[i] = key;
    m->val[i] = v;
    m->n++;
    return PFSPH_OK;
}

static void unpack3(int64_t key, int b[3])
{
    const int64_t mask = (1 << COORD_BITS) - 1;
    b[0] = (int)((key >> (2 * COORD_BITS)) & mask) - COORD_BIAS;
    b[1] = (int)((key >> COORD_BITS) & mask) - COORD_BIAS;
    b[2] = (int)(key & mask) - COORD_BIAS;
}

#define NIDX(a, b, c) (((c) * BN + (b)) * BN + (a))

/* node values of a block: block-local splat of candidate kernels in ascending index, so a node
 * shared with another block gets the same sum in the same order (the same bits) */
static void block_field(block *bl, const kern *K, const cells *cg, double rmax, double cellw, double vol)
{
    double lo[3], hi[3];
    for (int u = 0; u < 3; u++) {
        lo[u] = ((double)bl->b[u] * BS) * cellw;
        hi[u] = ((double)bl->b[u] * BS + BS) * cellw;
    }
    for (int i = 0; i < BNODES; i++) bl->f[i] = 0;
    long c0[3], c1[3];
    for (int u = 0; u < 3; u++) {
        c0[u] = cell_of(lo[u] - rmax, cg->inv);
        c1[u] = cell_of(hi[u] + rmax, cg->inv);
    }
    size_t cap = 256, nc = 0;
    uint32_t *cand = malloc(cap * sizeof *cand);
    if (!cand) return;
    for (long a = c0[0]; a <= c1[0]; a++)
        for (long b = c0[1]; b <= c1[1]; b++)
            for (long c = c0[2]; c <= c1[2]; c++) {
                uint32_t s, e;
                cells_range(cg, a, b, c, &s, &e);
                for (uint32_t q = s; q < e; q++) {
                    uint32_t j = cg->idx[q];
                    const kern *k = K + j;
                    int in = 1;
                    for (int u = 0; u < 3; u++)
                        if (k->c[u] + k->rad < lo[u] || k->c[u] - k->rad > hi[u]) in = 0;
                    if (!in) continue;
                    if (nc == cap) {
                        uint32_t *t = realloc(cand, 2 * cap * sizeof *cand);
                        if (!t) {
                            free(cand);
                            return;
                        }
                        cand = t;
                        cap *= 2;
                    }
                    cand[nc++] = j;
                }
            }
    qsort(cand, nc, sizeof *cand, u32_cmp);
    const double inv = 1.0 / cellw;
    for (size_t q = 0; q < nc; q++) {
        const kern *k = K + cand[q];
        int n0[3], n1[3];
        for (int u = 0; u < 3; u++) {
            long g0 = (long)ceil((k->c[u] - k->rad) * inv), g1 = (long)floor((k->c[u] + k->rad) * inv);
            long base = (long)bl->b[u] * BS;
            n0[u] = (int)(g0 - base < 0 ? 0 : g0 - base);
            n1[u] = (int)(g1 - base > BS ? BS : g1 - base);
        }
        /* along a row of nodes G r = t0 + A gx with A the global node index: each node's value is
         * a function of its global index alone (the same bits in every block that holds it), and
         * the row's range inside the ellipsoid comes from the quadratic |t0 + A gx|^2 < 1 */
        const double gx[3] = {k->G[0] * cellw, k->G[3] * cellw, k->G[6] * cellw};
        const double gxx = gx[0] * gx[0] + gx[1] * gx[1] + gx[2] * gx[2];
        const long base0 = (long)bl->b[0] * BS;
        for (int c = n0[2]; c <= n1[2]; c++)
            for (int b = n0[1]; b <= n1[1]; b++) {
                double ry = ((double)bl->b[1] * BS + b) * cellw - k->c[1];
                double rz = ((double)bl->b[2] * BS + c) * cellw - k->c[2];
                double t0[3];
                for (int u = 0; u < 3; u++) t0[u] = k->G[3 * u] * -k->c[0] + k->G[3 * u + 1] * ry + k->G[3 * u + 2] * rz;
                double tg = t0[0] * gx[0] + t0[1] * gx[1] + t0[2] * gx[2];
                double tt = t0[0] * t0[0] + t0[1] * t0[1] + t0[2] * t0[2];
                double disc = tg * tg - gxx * (tt - 1);
                if (disc < 0) continue;
                double sq = sqrt(disc);
                long A0 = (long)floor((-tg - sq) / gxx) - 1, A1 = (long)ceil((-tg + sq) / gxx) + 1;
                int a0 = A0 - base0 > n0[0] ? (int)(A0 - base0) : n0[0];
                int a1 = A1 - base0 < n1[0] ? (int)(A1 - base0) : n1[0];
                double *row = bl->f + NIDX(0, b, c);
                for (int a = a0; a <= a1; a++) {
                    double A = (double)(base0 + a);
                    double x0 = t0[0] + A * gx[0], x1 = t0[1] + A * gx[1], x2 = t0[2] + A * gx[2];
                    double q2 = x0 * x0 + x1 * x1 + x2 * x2;
                    if (q2 < 1) row[a] += vol * k->det * cubic_unit(sqrt(q2));
                }
            }
    }
    free(cand);
}

static int cell_mixed(const double *f, int a, int b, int c, double iso)
{
    int in = 0;
    for (int t = 0; t < 8; t++) in += f[NIDX(a + (t & 1), b + ((t >> 1) & 1), c + (t >> 2))] > iso;
    return in > 0 && in < 8;
}

/* ---- marching tetrahedra in each cube ---- */
typedef struct vrec {
    int64_t key; /* edge: lower node packed << 3 | direction bits */
    double p[3];
    float n[3];
    float pad; /* zero: records are compared bytewise */
} vrec;

typedef struct tribuf {
    vrec *v;
    size_t nv, cv;
    int64_t *t; /* 3 edge keys per triangle */
    size_t nt, ct;
    int fail;
} tribuf;

static const int KUHN[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

static void grad_at(const double *f, int a, int b, int c, double cellw, double g[3])
{
    /* central differences, one-sided on the block's faces */
    int i[3] = {a, b, c};
    for (int u = 0; u < 3; u++) {
        int lo[3] = {a, b, c}, hi[3] = {a, b, c};
        lo[u] = i[u] > 0 ? i[u] - 1 : 0;
        hi[u] = i[u] < BS ? i[u] + 1 : BS;
        g[u] = (f[NIDX(hi[0], hi[1], hi[2])] - f[NIDX(lo[0], lo[1], lo[2])]) / ((hi[u] - lo[u]) * cellw);
    }
}

/* vertex on the edge between local nodes p and q (integer coordinates, p <= q componentwise) */
static int64_t edge_vertex(tribuf *tb, const block *bl, const int p[3], const int q[3], double iso, double cellw)
{
    int64_t gx = (int64_t)bl->b[0] * BS + p[0], gy = (int64_t)bl->b[1] * BS + p[1],
            gz = (int64_t)bl->b[2] * BS + p[2];
    int dir = (q[0] - p[0]) | ((q[1] - p[1]) << 1) | ((q[2] - p[2]) << 2);
    int64_t key = (pack3(gx, gy, gz) << 3) | dir;
    if (tb->nv == tb->cv) {
        size_t nc = tb->cv ? 2 * tb->cv : 256;
        vrec *t = realloc(tb->v, nc * sizeof *t);
        if (!t) {
            tb->fail = 1;
            return key;
        }
        tb->v = t;
        tb->cv = nc;
    }
    double fp = bl->f[NIDX(p[0], p[1], p[2])], fq = bl->f[NIDX(q[0], q[1], q[2])];
    double t = (iso - fp) / (fq - fp);
    if (t < 1e-3) t = 1e-3; /* no vertex on a node: no zero-area faces */
    if (t > 1 - 1e-3) t = 1 - 1e-3;
    vrec *v = tb->v + tb->nv++;
    v->key = key;
    v->pad = 0;
    v->p[0] = ((double)gx + t * (q[0] - p[0])) * cellw;
    v->p[1] = ((double)gy + t * (q[1] - p[1])) * cellw;
    v->p[2] = ((double)gz + t * (q[2] - p[2])) * cellw;
    double gp[3], gq[3], g[3], len = 0;
    grad_at(bl->f, p[0], p[1], p[2], cellw, gp);
    grad_at(bl->f, q[0], q[1], q[2], cellw, gq);
    for (int u = 0; u < 3; u++) {
        g[u] = -((1 - t) * gp[u] + t * gq[u]);
        len += g[u] * g[u];
    }
    len = len > 0 ? 1 / sqrt(len) : 0;
    for (int u = 0; u < 3; u++) v->n[u] = (float)(g[u] * len);
    return key;
}

/* a triangle on the edges (e[k][0], e[k][1]) of a tetrahedron, oriented so that its normal points
 * away from the node `in` (inside) — decided on edge midpoints in integer arithmetic, which has
 * the sign of the real triangle for any interpolation parameters */
static void emit(tribuf *tb, const block *bl, int e[3][2][3], const int in[3], int away, double iso, double cellw)
{
    long m[3][3];
    for (int k = 0; k < 3; k++)
        for (int u = 0; u < 3; u++) m[k][u] = e[k][0][u] + e[k][1][u];
    long ab[3], ac[3], ai[3];
    for (int u = 0; u < 3; u++) {
        ab[u] = m[1][u] - m[0][u];
        ac[u] = m[2][u] - m[0][u];
        ai[u] = m[0][u] - 2L * in[u];
    }
    long nx = ab[1] * ac[2] - ab[2] * ac[1], ny = ab[2] * ac[0] - ab[0] * ac[2], nz = ab[0] * ac[1] - ab[1] * ac[0];
    long s = nx * ai[0] + ny * ai[1] + nz * ai[2];
    if (!away) s = -s;
    int order[3] = {0, 1, 2};
    if (s < 0) {
        order[1] = 2;
        order[2] = 1;
    }
    if (tb->nt == tb->ct) {
        size_t nc = tb->ct ? 2 * tb->ct : 256;
        int64_t *t = realloc(tb->t, 3 * nc * sizeof *t);
        if (!t) {
            tb->fail = 1;
            return;
        }
        tb->t = t;
        tb->ct = nc;
    }
    int64_t *t = tb->t + 3 * tb->nt++;
    for (int k = 0; k < 3; k++) {
        int *p = e[order[k]][0], *q = e[order[k]][1];
        int lo[3], hi[3];
        int le = p[0] <= q[0] && p[1] <= q[1] && p[2] <= q[2];
        for (int u = 0; u < 3; u++) {
            lo[u] = le ? p[u] : q[u];
            hi[u] = le ? q[u] : p[u];
        }
        t[k] = edge_vertex(tb, bl, lo, hi, iso, cellw);
    }
}

static int vrec_cmp_full(const void *a, const void *b);

static void march_block(tribuf *tb, const block *bl, double iso, double cellw)
{
    for (int c = 0; c < BS; c++)
        for (int b = 0; b < BS; b++)
            for (int a = 0; a < BS; a++) {
                if (!cell_mixed(bl->f, a, b, c, iso)) continue;
                for (int t = 0; t < 6; t++) {
                    int v[4][3];
                    v[0][0] = a, v[0][1] = b, v[0][2] = c;
                    for (int k = 1; k < 4; k++) {
                        memcpy(v[k], v[k - 1], sizeof v[k]);
                        if (k < 3) v[k][KUHN[t][k - 1]]++;
                        else v[k][KUHN[t][2]]++;
                    }
                    int ins[4], nin = 0, outs[4], nout = 0;
                    for (int k = 0; k < 4; k++) {
                        if (bl->f[NIDX(v[k][0], v[k][1], v[k][2])] > iso) ins[nin++] = k;
                        else outs[nout++] = k;
                    }
                    int e[3][2][3];
                    if (nin == 1 || nin == 3) {
                        int apex = nin == 1 ? ins[0] : outs[0];
                        const int *others = nin == 1 ? outs : ins;
                        for (int k = 0; k < 3; k++) {
                            memcpy(e[k][0], v[apex], sizeof e[k][0]);
                            memcpy(e[k][1], v[others[k]], sizeof e[k][1]);
                        }
                        emit(tb, bl, e, v[apex], nin == 1, iso, cellw);
                    } else if (nin == 2) {
                        int i0 = ins[0], i1 = ins[1], o0 = outs[0], o1 = outs[1];
                        /* quad (i0 o0) (i0 o1) (i1 o1) (i1 o0), two triangles */
                        int q[4][2] = {{i0, o0}, {i0, o1}, {i1, o1}, {i1, o0}};
                        int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
                        for (int s = 0; s < 2; s++) {
                            for (int k = 0; k < 3; k++) {
                                memcpy(e[k][0], v[q[tri[s][k]][0]], sizeof e[k][0]);
                                memcpy(e[k][1], v[q[tri[s][k]][1]], sizeof e[k][1]);
                            }
                            emit(tb, bl, e, v[i0], 1, iso, cellw);
                        }
                    }
                }
            }
    /* a vertex appears once per tetrahedron edge use: keep one per edge (within a block every
     * copy is the same record), so that the serial merge sorts few */
    qsort(tb->v, tb->nv, sizeof *tb->v, vrec_cmp_full);
    size_t u = 0;
    for (size_t i = 0; i < tb->nv; i++)
        if (!u || tb->v[i].key != tb->v[u - 1].key) tb->v[u++] = tb->v[i];
    tb->nv = u;
}

static int vrec_cmp(const void *a, const void *b)
{
    int64_t x = ((const vrec *)a)->key, y = ((const vrec *)b)->key;
    return x < y ? -1 : (x > y);
}

/* the order of the merge: by edge, then by the record's bytes (a vertex on a block face has a
 * one-sided normal in each block; which one is kept must not depend on the sort) */
static int vrec_cmp_full(const void *a, const void *b)
{
    int c = vrec_cmp(a, b);
    return c ? c : memcmp(a, b, sizeof(vrec));
}

static int block_cmp(const void *a, const void *b)
{
    int64_t x = ((const block *)a)->key, y = ((const block *)b)->key;
    return x < y ? -1 : (x > y);
}

/* Taubin lambda|mu smoothing over the welded mesh's vertex graph */
static int taubin(pfsph_surface_mesh *m, size_t v0, size_t t0, int iters)
{
    size_t nv = m->nverts - v0, nt = m->ntris - t0;
    if (!nv || iters <= 0) return PFSPH_OK;
    int64_t *e = malloc(6 * nt * sizeof *e);
    uint32_t *start = calloc(nv + 1, sizeof *start), *adj = NULL;
    double *tmp = malloc(3 * nv * sizeof *tmp);
    int rc = PFSPH_ENOMEM;
    if (!e || !start || !tmp) goto out;
    size_t ne = 0;
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int64_t a = m->tri[3 * (t0 + t) + k] - v0, b = m->tri[3 * (t0 + t) + (k + 1) % 3] - v0;
            e[ne++] = (a << 32) | b;
            e[ne++] = (b << 32) | a;
        }
    qsort(e, ne, sizeof *e, i64_cmp);
    size_t u = 0;
    for (size_t i = 0; i < ne; i++)
        if (!u || e[i] != e[u - 1]) e[u++] = e[i];
    adj = malloc((u ? u : 1) * sizeof *adj);
    if (!adj) goto out;
    for (size_t i = 0; i < u; i++) {
        start[(e[i] >> 32) + 1]++;
        adj[i] = (uint32_t)(e[i] & 0xffffffff);
    }
    for (size_t i = 0; i < nv; i++) start[i + 1] += start[i];
    for (int it = 0; it < 2 * iters; it++) {
        double f = it % 2 ? -0.53 : 0.5;
        double *v = m->v + 3 * v0;
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < nv; i++) {
            double s[3] = {0, 0, 0};
            uint32_t k0 = start[i], k1 = start[i + 1];
            for (uint32_t k = k0; k < k1; k++)
                for (int a = 0; a < 3; a++) s[a] += v[3 * adj[k] + a];
            for (int a = 0; a < 3; a++)
                tmp[3 * i + a] = k1 > k0 ? v[3 * i + a] + f * (s[a] / (k1 - k0) - v[3 * i + a]) : v[3 * i + a];
        }
        memcpy(v, tmp, 3 * nv * sizeof *tmp);
    }
    rc = PFSPH_OK;
out:
    free(e);
    free(start);
    free(adj);
    free(tmp);
    return rc;
}

static int append(pfsph_surface_mesh *m, size_t nv, size_t nt)
{
    double *v = realloc(m->v, 3 * (m->nverts + nv) * sizeof *v + 1);
    if (!v) return PFSPH_ENOMEM;
    m->v = v;
    float *n = realloc(m->n, 3 * (m->nverts + nv) * sizeof *n + 1);
    if (!n) return PFSPH_ENOMEM;
    m->n = n;
    uint32_t *t = realloc(m->tri, 3 * (m->ntris + nt) * sizeof *t + 1);
    if (!t) return PFSPH_ENOMEM;
    m->tri = t;
    uint8_t *p = realloc(m->phase, m->ntris + nt + 1);
    if (!p) return PFSPH_ENOMEM;
    m->phase = p;
    return PFSPH_OK;
}

/* one phase's points into m (appended) */
static int reconstruct_one(const double *x, size_t n, uint8_t phase, const pfsph_surface_opts *o, double iso,
                           pfsph_surface_mesh *m, pfsph_error *err)
{
    const double d = o->spacing, cellw = o->cell * d, vol = d * d * d;
    kern *K = malloc((n ? n : 1) * sizeof *K);
    uint8_t *surf = malloc(n ? n : 1);
    block *bl = NULL;
    size_t nb = 0, cb = 0;
    bmap map = {0};
    cells cg = {0};
    int64_t *pend = NULL;
    tribuf *tbs = NULL;
    vrec *all = NULL;
    int rc = PFSPH_ENOMEM;
    if (!K || !surf) goto out;
    double rmax, w0 = omp_get_wtime();
    if ((rc = kernels_build(x, n, o, K, surf, &rmax))) goto out;
    double w1 = omp_get_wtime();
    m->seconds[0] += w1 - w0;
    rc = PFSPH_ENOMEM;
    double *cen = malloc(3 * (n ? n : 1) * sizeof *cen);
    if (!cen) goto out;
    for (size_t i = 0; i < n; i++) memcpy(cen + 3 * i, K[i].c, sizeof K[i].c);
    int crc = cells_build(&cg, cen, n, rmax > 0 ? rmax : d);
    free(cen);
    if (crc) goto out;
    /* seeds: blocks around the particles near the surface */
    size_t np = 0, cp = 1024;
    pend = malloc(cp * sizeof *pend);
    if (!pend) goto out;
    const double inv_bw = 1.0 / (BS * cellw);
    for (size_t i = 0; i < n; i++) {
        if (!surf[i]) continue;
        m->surface_particles++;
        {
            const double *p = K[i].c; /* its block: growth finds the rest */
            long b[3];
            for (int u = 0; u < 3; u++) {
                b[u] = cell_of(p[u], inv_bw);
                if (b[u] < -COORD_BIAS / BS + 2 || b[u] > COORD_BIAS / BS - 2) {
                    rc = pfsph_fail(err, PFSPH_EINPUT, "surface: particle %zu at (%g, %g, %g) m is too far from the "
                                    "origin for the meshing grid (cell %g m)", i, x[3 * i], x[3 * i + 1],
                                    x[3 * i + 2], cellw);
                    goto out;
                }
            }
            if (np == cp) {
                int64_t *t = realloc(pend, 2 * cp * sizeof *t);
                if (!t) goto out;
                pend = t;
                cp *= 2;
            }
            pend[np++] = pack3(b[0], b[1], b[2]);
        }
    }
    size_t live = 0, peak = 0;
    while (np) {
        qsort(pend, np, sizeof *pend, i64_cmp);
        size_t u = 0;
        for (size_t i = 0; i < np; i++)
            if ((!u || pend[i] != pend[u - 1]) && bmap_find(&map, pend[i]) < 0) pend[u++] = pend[i];
        np = u;
        if (!np) break;
        size_t first = nb;
        if (nb + np > cb) {
            size_t nc = cb ? cb : 256;
            while (nc < nb + np) nc *= 2;
            block *t = realloc(bl, nc * sizeof *t);
            if (!t) goto out;
            bl = t;
            cb = nc;
        }
        for (size_t i = 0; i < np; i++) {
            block *b = bl + nb;
            b->key = pend[i];
            unpack3(pend[i], b->b);
            b->f = malloc(BNODES * sizeof *b->f);
            nb++;
            if (!b->f || bmap_put(&map, pend[i], (int32_t)(nb - 1))) goto out;
        }
        live += np;
        if (live > peak) peak = live;
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t i = first; i < nb; i++) block_field(bl + i, K, &cg, rmax, cellw, vol);
        /* mixed cells on a block's rim call for the blocks of their neighbour cells */
        np = 0;
        for (size_t i = first; i < nb; i++) {
            const block *b = bl + i;
            for (int c = 0; c < BS; c++)
                for (int bb = 0; bb < BS; bb++)
                    for (int a = 0; a < BS; a++) {
                        int rim = a == 0 || a == BS - 1 || bb == 0 || bb == BS - 1 || c == 0 || c == BS - 1;
                        if (!rim || !cell_mixed(b->f, a, bb, c, iso)) continue;
                        for (int s = 0; s < 27; s++) {
                            int q[3] = {a + s % 3 - 1, bb + (s / 3) % 3 - 1, c + s / 9 - 1};
                            int off[3];
                            for (int w = 0; w < 3; w++) off[w] = q[w] < 0 ? -1 : (q[w] >= BS ? 1 : 0);
                            if (!off[0] && !off[1] && !off[2]) continue;
                            if (np + 1 > cp) {
                                int64_t *t = realloc(pend, 2 * cp * sizeof *t);
                                if (!t) goto out;
                                pend = t;
                                cp *= 2;
                            }
                            pend[np++] = pack3(b->b[0] + off[0], b->b[1] + off[1], b->b[2] + off[2]);
                        }
                    }
        }
        /* blocks the surface does not cross are not kept */
        for (size_t i = first; i < nb; i++) {
            int any = 0;
            for (int c = 0; c < BS && !any; c++)
                for (int bb = 0; bb < BS && !any; bb++)
                    for (int a = 0; a < BS && !any; a++) any = cell_mixed(bl[i].f, a, bb, c, iso);
            if (!any) {
                free(bl[i].f);
                bl[i].f = NULL;
                live--;
            }
        }
    }
    /* compact and sort the kept blocks: the order of the output */
    size_t kept = 0;
    for (size_t i = 0; i < nb; i++)
        if (bl[i].f) bl[kept++] = bl[i];
    nb = kept;
    qsort(bl, kept, sizeof *bl, block_cmp);
    m->blocks += kept;
    if (peak > m->blocks_peak) m->blocks_peak = peak;
    if (peak * BNODES * sizeof(double) > m->grid_bytes) m->grid_bytes = peak * BNODES * sizeof(double);
    double w2 = omp_get_wtime();
    m->seconds[1] += w2 - w1;
    tbs = calloc(kept ? kept : 1, sizeof *tbs);
    if (!tbs) goto out;
#pragma omp parallel for schedule(dynamic, 1)
    for (size_t i = 0; i < kept; i++) march_block(tbs + i, bl + i, iso, cellw);
    double w3 = omp_get_wtime();
    m->seconds[2] += w3 - w2;
    size_t nvr = 0, ntr = 0;
    for (size_t i = 0; i < kept; i++) {
        if (tbs[i].fail) goto out;
        nvr += tbs[i].nv;
        ntr += tbs[i].nt;
    }
    all = malloc((nvr ? nvr : 1) * sizeof *all);
    if (!all) goto out;
    nvr = 0;
    for (size_t i = 0; i < kept; i++) {
        memcpy(all + nvr, tbs[i].v, tbs[i].nv * sizeof *all);
        nvr += tbs[i].nv;
    }
    qsort(all, nvr, sizeof *all, vrec_cmp_full);
    size_t uv = 0;
    for (size_t i = 0; i < nvr; i++)
        if (!uv || all[i].key != all[uv - 1].key) all[uv++] = all[i];
    size_t v0 = m->nverts, t0 = m->ntris;
    if (v0 + uv > UINT32_MAX) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "surface: more than 2^32 vertices");
        goto out;
    }
    if ((rc = append(m, uv, ntr))) goto out;
    for (size_t i = 0; i < uv; i++) {
        memcpy(m->v + 3 * (v0 + i), all[i].p, sizeof all[i].p);
        memcpy(m->n + 3 * (v0 + i), all[i].n, sizeof all[i].n);
    }
    size_t *tstart = malloc((kept + 1) * sizeof *tstart);
    if (!tstart) goto out;
    tstart[0] = t0;
    for (size_t i = 0; i < kept; i++) tstart[i + 1] = tstart[i] + tbs[i].nt;
#pragma omp parallel for schedule(dynamic, 4)
    for (size_t i = 0; i < kept; i++)
        for (size_t k = 0; k < tbs[i].nt; k++) {
            size_t t = tstart[i] + k;
            for (int c = 0; c < 3; c++) {
                vrec key = {.key = tbs[i].t[3 * k + c]};
                const vrec *f = bsearch(&key, all, uv, sizeof *all, vrec_cmp);
                m->tri[3 * t + c] = (uint32_t)(v0 + (size_t)(f - all));
            }
            m->phase[t] = phase;
        }
    size_t t = tstart[kept];
    free(tstart);
    m->nverts = v0 + uv;
    m->ntris = t;
    rc = taubin(m, v0, t0, o->smooth_iters);
    m->seconds[3] += omp_get_wtime() - w3;
out:
    if (rc == PFSPH_ENOMEM && !err->msg[0]) pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    if (tbs)
        for (size_t i = 0; i < nb; i++) {
            free(tbs[i].v);
            free(tbs[i].t);
        }
    free(tbs);
    for (size_t i = 0; i < nb; i++) free(bl ? bl[i].f : NULL);
    free(bl);
    free(map.keys);
    free(map.val);
    free(pend);
    free(all);
    cells_free(&cg);
    free(K);
    free(surf);
    return rc;
}

int pfsph_surface_reconstruct(const double *x, const uint8_t *phase, size_t n, const pfsph_surface_opts *in,
                              pfsph_surface_mesh *m, pfsph_error *err)
{
    memset(m, 0, sizeof *m);
    err->msg[0] = 0;
    if (!(in->spacing > 0) || !isfinite(in->spacing))
        return pfsph_fail(err, PFSPH_EINPUT, "surface: the particle spacing %g is not positive", in->spacing);
    pfsph_surface_opts o;
    resolve(in, &o);
    if (o.lambda > 1 || o.kr < 1 || o.cell > 4 || o.support > 8 || o.pca_radius > 8 || o.smooth_iters > 1000)
        return pfsph_fail(err, PFSPH_EINPUT, "surface: options out of range (lambda %g, kr %g, cell %g d, "
                          "support %g d, neighbourhood %g d, %d smoothing passes)", o.lambda, o.kr, o.cell,
                          o.support, o.pca_radius, o.smooth_iters);
    const double reach = (double)(1 << 18) * o.cell * o.spacing; /* the grid's integer coordinates */
    for (size_t i = 0; i < 3 * n; i++) {
        if (!isfinite(x[i])) return pfsph_fail(err, PFSPH_EINPUT, "surface: particle %zu has a non-finite position", i / 3);
        if (fabs(x[i]) > reach)
            return pfsph_fail(err, PFSPH_EINPUT, "surface: particle %zu is %g m from the origin, beyond the meshing "
                              "grid's %g m (2^18 cells)", i / 3, fabs(x[i]), reach);
    }
    double iso = o.iso > 0 ? o.iso : pfsph_surface_calibrate_iso(&o);
    int present[256] = {0};
    for (size_t i = 0; i < n; i++) present[phase ? phase[i] : 0]++;
    double *xs = malloc(3 * (n ? n : 1) * sizeof *xs);
    if (!xs) return pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    int rc = PFSPH_OK;
    for (int p = 0; p < 256 && !rc; p++) {
        if (!present[p]) continue;
        size_t k = 0;
        for (size_t i = 0; i < n; i++)
            if ((phase ? phase[i] : 0) == p) {
                memcpy(xs + 3 * k, x + 3 * i, 3 * sizeof *xs);
                k++;
            }
        rc = reconstruct_one(xs, k, (uint8_t)p, &o, iso, m, err);
    }
    free(xs);
    if (rc) pfsph_surface_mesh_free(m);
    return rc;
}

void pfsph_surface_mesh_free(pfsph_surface_mesh *m)
{
    if (!m) return;
    free(m->v);
    free(m->n);
    free(m->tri);
    free(m->phase);
    memset(m, 0, sizeof *m);
}
