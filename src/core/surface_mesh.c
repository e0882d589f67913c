/* Surface reconstruction (Yu & Turk 2013, "Reconstructing surfaces of particle-based fluids using
 * anisotropic kernels"): weighted PCA per particle, smoothed kernel centres, a volume-fraction
 * colour field on sparse blocks grown along the surface, marching cubes with every cube split into
 * six tetrahedra (Kuhn), vertices welded by edge ownership. docs/surfaces.md gives the choices.
 *
 * Speed (docs/benchmarks.md#surface-meshes): the neighbour searches use flat sorted cell lists
 * (one counting sort, contiguous columns of cells), the PCA and the field are single-precision
 * loops the compiler vectorises, the field is splatted kernel by kernel into rows of eight nodes,
 * and marching cubes reads a case table built once per call from the tetrahedral split, with
 * vertices numbered through a per-block edge table (no hashing, no sorting of vertices). */
#include "pfsph/surface_mesh.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/eigen.h"

#define BS 7 /* cells per block edge */
#define BN \
    (BS + 1) /* nodes per block edge: 0 .. BS (the last layer is the next block's first);
                          * 8, so that a row of nodes is two 4-wide vectors */
#define BNODES (BN * BN * BN)
#define NEDGE (BNODES * 7) /* edges of a block: lower node x direction (1..7 as xyz bits) */
#define MAXTRI (BS * BS * BS * 12)
#define COORD_BITS 21
#define LANES 8   /* PCA candidates are padded to a multiple of this (any vector width) */
#define FAR 1e18f /* padding candidate: beyond every radius, squares stay finite */
#define PI 3.14159265358979323846

/* A kernel as the field reads it, in grid cells: centre I + f (I the node at or below it, f in
 * [0, 1)), so that a node's offset from the centre is an exact small integer minus f whatever the
 * block and however far from the origin: every node's value is a function of its global index. */
typedef struct kern {
    int32_t I[3];
    float f[3];
    float g[6]; /* symmetric map cell offsets -> unit-kernel coordinates: xx xy xz yy yz zz */
    float amp;  /* d^3 |det G| sigma: the value at the centre over W(0) */
    float rad;  /* support radius [cells] */
} kern;

typedef struct block {
    int64_t key;
    int32_t b[3];
    float *f; /* BNODES node values */
    /* marching output: owned vertices (edges whose lower node lies in [0, BS)^3), ascending edge */
    uint32_t nv, nt;
    uint16_t *ve;  /* nv edge indices */
    double *vp;    /* 3 nv */
    float *vn;     /* 3 nv */
    uint32_t *tri; /* 3 nt: owned rank, or FOREIGN | neighbour offset bits << 12 | its edge */
} block;

#define FOREIGN 0x80000000u

/* cubic spline of unit support (3D normalisation left to amp), of q^2 */
static inline float cubic_q2(float q2)
{
    float q = sqrtf(q2), t = 1.0f - q;
    float outer = 2.0f * t * t * t, inner = 6.0f * q * q * (q - 1.0f) + 1.0f;
    float v = q <= 0.5f ? inner : outer;
    return q2 < 1.0f ? v : 0.0f;
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

static int64_t pack3(int64_t i, int64_t j, int64_t k)
{
    const int64_t bias = (int64_t)1 << (COORD_BITS - 1);
    return ((i + bias) << (2 * COORD_BITS)) | ((j + bias) << COORD_BITS) | (k + bias);
}

static void unpack3(int64_t key, int32_t b[3])
{
    const int64_t mask = ((int64_t)1 << COORD_BITS) - 1, bias = (int64_t)1 << (COORD_BITS - 1);
    b[0] = (int32_t)(((key >> (2 * COORD_BITS)) & mask) - bias);
    b[1] = (int32_t)(((key >> COORD_BITS) & mask) - bias);
    b[2] = (int32_t)((key & mask) - bias);
}

static int32_t floordiv(int32_t a, int32_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

static int i64_cmp(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : (x > y);
}

/* ---- a flat sorted cell list: points ordered by cell (x, y, z lexicographic, z fastest), in
 * ascending index within a cell, so that a column of cells (i, j, k0..k1) is one contiguous
 * range. Dense (a start per cell of the bounding box, one counting sort) when the box holds at
 * most a few cells per point; otherwise sparse (radix-sorted keys, binary search per column). */
typedef struct grid {
    int32_t lo[3];
    int64_t ext[3];
    int dense;
    size_t nu;
    uint32_t *idx;    /* n point indices in cell order */
    uint32_t *start;  /* dense: cells + 1 */
    int64_t *ukey;    /* sparse: nu keys */
    uint32_t *ustart; /* nu + 1: the non-empty cells' ranges in idx */
    int32_t *ucell;   /* 3 nu: their coordinates */
} grid;

static void grid_free(grid *g)
{
    free(g->idx);
    free(g->start);
    free(g->ukey);
    free(g->ustart);
    free(g->ucell);
    memset(g, 0, sizeof *g);
}

static int grid_build(grid *g, const int32_t *cell, size_t n)
{
    memset(g, 0, sizeof *g);
    g->idx = malloc((n ? n : 1) * sizeof *g->idx);
    g->ustart = malloc((n + 1) * sizeof *g->ustart);
    g->ucell = malloc(3 * (n ? n : 1) * sizeof *g->ucell);
    if (!g->idx || !g->ustart || !g->ucell) return PFSPH_ENOMEM;
    g->ustart[0] = 0;
    if (!n) return PFSPH_OK;
    int32_t hi[3];
    for (int u = 0; u < 3; u++) g->lo[u] = hi[u] = cell[u];
    for (size_t i = 0; i < n; i++)
        for (int u = 0; u < 3; u++) {
            if (cell[3 * i + u] < g->lo[u]) g->lo[u] = cell[3 * i + u];
            if (cell[3 * i + u] > hi[u]) hi[u] = cell[3 * i + u];
        }
    for (int u = 0; u < 3; u++) g->ext[u] = (int64_t)hi[u] - g->lo[u] + 1;
    double cells = (double)g->ext[0] * (double)g->ext[1] * (double)g->ext[2];
    if (cells <= 4.0 * (double)n + 4096) {
        size_t nc = (size_t)cells;
        g->dense = 1;
        g->start = calloc(nc + 1, sizeof *g->start);
        uint32_t *cid = malloc(n * sizeof *cid);
        if (!g->start || !cid) {
            free(cid);
            return PFSPH_ENOMEM;
        }
        for (size_t i = 0; i < n; i++) {
            cid[i] = (uint32_t)(((cell[3 * i] - g->lo[0]) * g->ext[1] + (cell[3 * i + 1] - g->lo[1])) * g->ext[2] +
                                (cell[3 * i + 2] - g->lo[2]));
            g->start[cid[i] + 1]++;
        }
        for (size_t c = 0; c < nc; c++) g->start[c + 1] += g->start[c];
        for (size_t i = 0; i < n; i++) g->idx[g->start[cid[i]]++] = (uint32_t)i; /* stable */
        memmove(g->start + 1, g->start, nc * sizeof *g->start);
        g->start[0] = 0;
        for (size_t c = 0; c < nc; c++)
            if (g->start[c + 1] > g->start[c]) {
                uint32_t i = g->idx[g->start[c]];
                memcpy(g->ucell + 3 * g->nu, cell + 3 * (size_t)i, 3 * sizeof *cell);
                g->ustart[++g->nu] = g->start[c + 1];
            }
        free(cid);
        return PFSPH_OK;
    }
    /* sparse: LSD radix sort of (key, index), 16 bits a pass, stable */
    uint64_t *k0 = malloc(n * sizeof *k0), *k1 = malloc(n * sizeof *k1);
    uint32_t *i1 = malloc(n * sizeof *i1), *cnt = malloc(65536 * sizeof *cnt);
    g->ukey = malloc(n * sizeof *g->ukey);
    int rc = PFSPH_ENOMEM;
    if (!k0 || !k1 || !i1 || !cnt || !g->ukey) goto out;
    for (size_t i = 0; i < n; i++) {
        k0[i] = (uint64_t)pack3(cell[3 * i], cell[3 * i + 1], cell[3 * i + 2]);
        g->idx[i] = (uint32_t)i;
    }
    for (int pass = 0; pass < 4; pass++) {
        int sh = 16 * pass;
        memset(cnt, 0, 65536 * sizeof *cnt);
        for (size_t i = 0; i < n; i++) cnt[(k0[i] >> sh) & 0xffff]++;
        uint32_t s = 0;
        for (int c = 0; c < 65536; c++) {
            uint32_t t = cnt[c];
            cnt[c] = s;
            s += t;
        }
        for (size_t i = 0; i < n; i++) {
            uint32_t at = cnt[(k0[i] >> sh) & 0xffff]++;
            k1[at] = k0[i];
            i1[at] = g->idx[i];
        }
        uint64_t *tk = k0;
        k0 = k1;
        k1 = tk;
        memcpy(g->idx, i1, n * sizeof *i1);
    }
    for (size_t i = 0; i < n; i++)
        if (i == 0 || k0[i] != k0[i - 1]) {
            g->ukey[g->nu] = (int64_t)k0[i];
            memcpy(g->ucell + 3 * g->nu, cell + 3 * (size_t)g->idx[i], 3 * sizeof *cell);
            g->ustart[g->nu++] = (uint32_t)i;
            g->ustart[g->nu] = (uint32_t)(i + 1);
        } else g->ustart[g->nu] = (uint32_t)(i + 1);
    rc = PFSPH_OK;
out:
    free(k0);
    free(k1);
    free(i1);
    free(cnt);
    return rc;
}

/* the range in idx of the column of cells (i, j, k0..k1); b == e when empty */
static void grid_col(const grid *g, int64_t i, int64_t j, int64_t k0, int64_t k1, uint32_t *b, uint32_t *e)
{
    *b = *e = 0;
    if (!g->nu) return;
    if (g->dense) {
        i -= g->lo[0];
        j -= g->lo[1];
        k0 -= g->lo[2];
        k1 -= g->lo[2];
        if (i < 0 || i >= g->ext[0] || j < 0 || j >= g->ext[1]) return;
        if (k0 < 0) k0 = 0;
        if (k1 >= g->ext[2]) k1 = g->ext[2] - 1;
        if (k0 > k1) return;
        size_t c = (size_t)((i * g->ext[1] + j) * g->ext[2]);
        *b = g->start[c + (size_t)k0];
        *e = g->start[c + (size_t)k1 + 1];
        return;
    }
    const int64_t lim = ((int64_t)1 << (COORD_BITS - 1)) - 1;
    if (i < -lim || i > lim || j < -lim || j > lim) return;
    if (k0 < -lim) k0 = -lim;
    if (k1 > lim) k1 = lim;
    if (k0 > k1) return;
    int64_t key0 = pack3(i, j, k0), key1 = pack3(i, j, k1);
    size_t lo = 0, hi = g->nu;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (g->ukey[mid] < key0) lo = mid + 1;
        else hi = mid;
    }
    size_t end = lo;
    while (end < g->nu && g->ukey[end] <= key1) end++;
    *b = g->ustart[lo];
    *e = g->ustart[end];
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

/* weighted sums over the candidates (bx, by, bz: offsets in units of d from the cell's corner,
 * padded with FAR to a multiple of LANES) of the point xi: weight, count, first and second
 * moments. A vectorised reduction: its order is fixed by the code, the length and the buffers'
 * 64-byte alignment, so the same bits on any thread and in any run. Eleven scalar sums keep the
 * vector accumulators in registers (explicit lanes of eight spilled them). */
static void pca_sums(const float *bx, const float *by, const float *bz, size_t nb, const float xi[3], float r,
                     double out[11])
{
    const float r2 = r * r, ir = 1.0f / r, x0 = xi[0], y0 = xi[1], z0 = xi[2];
    float sw = 0, sn = 0, sx = 0, sy = 0, sz = 0, sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;
#pragma omp simd reduction(+ : sw, sn, sx, sy, sz, sxx, sxy, sxz, syy, syz, szz)
    for (size_t q = 0; q < nb; q++) {
        float ex = bx[q] - x0, ey = by[q] - y0, ez = bz[q] - z0;
        float s2 = ex * ex + ey * ey + ez * ez;
        float s = sqrtf(s2) * ir;
        float in = s2 < r2 ? 1.0f : 0.0f;
        float w = s2 < r2 ? 1.0f - s * s * s : 0.0f; /* a select: FAR gives 0, not 0 * inf */
        float wx = w * ex, wy = w * ey, wz = w * ez;
        sw += w;
        sn += in;
        sx += wx;
        sy += wy;
        sz += wz;
        sxx += wx * ex;
        sxy += wx * ey;
        sxz += wx * ez;
        syy += wy * ey;
        syz += wy * ez;
        szz += wz * ez;
    }
    out[0] = sw;
    out[1] = sn;
    out[2] = sx;
    out[3] = sy;
    out[4] = sz;
    out[5] = sxx;
    out[6] = sxy;
    out[7] = sxz;
    out[8] = syy;
    out[9] = syz;
    out[10] = szz;
}

/* Kernels of n points: centres, anisotropy, in grid cells of cellw. surf[i] (may be NULL) gets
 * 1 for particles near the surface (few neighbours, offset centre of mass or flattened
 * neighbourhood). *rad_max: the largest support radius [cells]. */
static int kernels_build(const double *x, size_t n, const pfsph_surface_opts *o, kern *K, uint8_t *surf, float *rad_max)
{
    const double d = o->spacing, r = o->pca_radius, h = o->support * d, cellw = o->cell * d;
    const double ks = 1.0 / lattice_sigma(o->pca_radius), cs = 0.5 * r * d; /* cells of half the radius */
    const int n_eps = o->n_eps > 0 ? o->n_eps : (lattice_count(o->pca_radius) + 2) / 5;
    grid g;
    int32_t *cell = malloc(3 * (n ? n : 1) * sizeof *cell);
    int rc = PFSPH_ENOMEM;
    if (!cell) return rc;
    for (size_t i = 0; i < 3 * n; i++) cell[i] = (int32_t)floor(x[i] / cs);
    rc = grid_build(&g, cell, n);
    free(cell);
    /* positions in units of d, in cell order: the candidates' gather reads them contiguously */
    double *ps = rc ? NULL : malloc(3 * (n ? n : 1) * sizeof *ps);
    if (rc || !ps) {
        grid_free(&g);
        return rc ? rc : PFSPH_ENOMEM;
    }
    const double inv_d = 1.0 / d, csd = 0.5 * r;
    double *xs = ps, *ys = ps + n, *zs = ps + 2 * n;
    for (size_t q = 0; q < n; q++) {
        const double *xq = x + 3 * (size_t)g.idx[q];
        xs[q] = xq[0] * inv_d;
        ys[q] = xq[1] * inv_d;
        zs[q] = xq[2] * inv_d;
    }
    float rmax = 0;
    int fail = 0;
#pragma omp parallel reduction(max : rmax) reduction(| : fail)
    {
        /* 64-byte aligned: a vectorised reduction then splits the same way whatever the vector
         * width and wherever the buffer lies (the same bits in every run) */
        size_t cap = 1024;
        float *bx = aligned_alloc(64, cap * sizeof *bx), *by = aligned_alloc(64, cap * sizeof *by),
              *bz = aligned_alloc(64, cap * sizeof *bz);
        if (!bx || !by || !bz) fail = 1;
#pragma omp for schedule(dynamic, 16)
        for (size_t U = 0; U < g.nu; U++) {
            if (fail) continue;
            const int32_t *uc = g.ucell + 3 * U;
            const double cx = uc[0] * csd, cy = uc[1] * csd, cz = uc[2] * csd; /* the cell's corner / d */
            size_t nb = 0;
            /* the 5 x 5 columns of 5 cells within two cells: every point within r = 2 cells */
            for (int64_t a = uc[0] - 2; a <= uc[0] + 2; a++)
                for (int64_t b = uc[1] - 2; b <= uc[1] + 2; b++) {
                    uint32_t s, e;
                    grid_col(&g, a, b, (int64_t)uc[2] - 2, (int64_t)uc[2] + 2, &s, &e);
                    if (nb + (e - s) + LANES > cap) {
                        size_t nc = cap;
                        while (nb + (e - s) + LANES > nc) nc *= 2;
                        float *t[3] = {aligned_alloc(64, nc * sizeof *bx), aligned_alloc(64, nc * sizeof *bx),
                                       aligned_alloc(64, nc * sizeof *bx)};
                        float **old[3] = {&bx, &by, &bz};
                        for (int u = 0; u < 3; u++) {
                            if (t[u]) memcpy(t[u], *old[u], nb * sizeof *bx);
                            free(*old[u]);
                            *old[u] = t[u];
                        }
                        cap = nc;
                        if (!bx || !by || !bz) {
                            fail = 1;
                            break;
                        }
                    }
                    for (uint32_t q = s; q < e; q++) {
                        bx[nb + q - s] = (float)(xs[q] - cx);
                        by[nb + q - s] = (float)(ys[q] - cy);
                        bz[nb + q - s] = (float)(zs[q] - cz);
                    }
                    nb += e - s;
                }
            if (fail) continue;
            while (nb % LANES) {
                bx[nb] = by[nb] = bz[nb] = FAR;
                nb++;
            }
            for (uint32_t q = g.ustart[U]; q < g.ustart[U + 1]; q++) {
                const size_t i = g.idx[q];
                const double *xi = x + 3 * i;
                const float xr[3] = {(float)(xs[q] - cx), (float)(ys[q] - cy), (float)(zs[q] - cz)};
                double S[11];
                pca_sums(bx, by, bz, nb, xr, (float)r, S);
                const double sw = S[0];
                const int cnt = (int)S[1];
                /* mean offset (units of d) and the covariance about it */
                double mu[3] = {S[2] / sw, S[3] / sw, S[4] / sw}, C[3][3];
                C[0][0] = S[5] / sw - mu[0] * mu[0];
                C[0][1] = S[6] / sw - mu[0] * mu[1];
                C[0][2] = S[7] / sw - mu[0] * mu[2];
                C[1][1] = S[8] / sw - mu[1] * mu[1];
                C[1][2] = S[9] / sw - mu[1] * mu[2];
                C[2][2] = S[10] / sw - mu[2] * mu[2];
                C[1][0] = C[0][1];
                C[2][0] = C[0][2];
                C[2][1] = C[1][2];
                double c[3];
                for (int u = 0; u < 3; u++) c[u] = xi[u] + o->lambda * mu[u] * d; /* (1 - l) x + l x^w */
                double off = sqrt(mu[0] * mu[0] + mu[1] * mu[1] + mu[2] * mu[2]);
                double scale[3] = {o->kn, o->kn, o->kn}, V[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
                int flat = 0;
                if (o->isotropic) scale[0] = scale[1] = scale[2] = 1;
                else if (cnt >= n_eps) {
                    double w[3];
                    pfsph_eigen_sym3((const double(*)[3])C, w, V);
                    for (int u = 0; u < 3; u++) {
                        double sv = w[u] < w[0] / o->kr ? w[0] / o->kr : w[u];
                        scale[u] = sqrt(ks * sv);       /* axis length ~ standard deviation (docs/surfaces.md) */
                        if (scale[u] > 2) scale[u] = 2; /* bounded search radius (docs/surfaces.md) */
                    }
                    flat = w[2] < 0.6 * w[0];
                }
                if (surf) surf[i] = (uint8_t)(cnt < n_eps || flat || off > 0.1 * r);
                kern *k = K + i;
                /* G = V diag(cellw / (h s)) V^T: cell offsets to unit-kernel coordinates */
                double G[3][3], is[3];
                for (int a = 0; a < 3; a++) is[a] = cellw / (h * scale[a]);
                for (int u = 0; u < 3; u++)
                    for (int v = 0; v < 3; v++) {
                        double acc = 0;
                        for (int a = 0; a < 3; a++) acc += V[u][a] * V[v][a] * is[a];
                        G[u][v] = acc;
                    }
                k->g[0] = (float)G[0][0];
                k->g[1] = (float)(0.5 * (G[0][1] + G[1][0]));
                k->g[2] = (float)(0.5 * (G[0][2] + G[2][0]));
                k->g[3] = (float)G[1][1];
                k->g[4] = (float)(0.5 * (G[1][2] + G[2][1]));
                k->g[5] = (float)G[2][2];
                k->amp = (float)(d * d * d / (h * h * h * scale[0] * scale[1] * scale[2]) * 8.0 / PI);
                double smax = scale[0] > scale[1] ? scale[0] : scale[1];
                if (scale[2] > smax) smax = scale[2];
                k->rad = (float)(h * smax / cellw);
                for (int u = 0; u < 3; u++) {
                    double cc = c[u] / cellw, fl = floor(cc);
                    k->I[u] = (int32_t)fl;
                    k->f[u] = (float)(cc - fl);
                }
                if (k->rad > rmax) rmax = k->rad;
            }
        }
        free(bx);
        free(by);
        free(bz);
    }
    grid_free(&g);
    free(ps);
    *rad_max = rmax;
    return fail ? PFSPH_ENOMEM : PFSPH_OK;
}

/* the field of one kernel at the point p (grid cells), as the nodes get it */
static float kern_at(const kern *k, const double p[3])
{
    float u = (float)(p[0] - k->I[0]) - k->f[0], v = (float)(p[1] - k->I[1]) - k->f[1],
          w = (float)(p[2] - k->I[2]) - k->f[2];
    float t0 = k->g[0] * u + (k->g[1] * v + k->g[2] * w), t1 = k->g[1] * u + (k->g[3] * v + k->g[4] * w),
          t2 = k->g[2] * u + (k->g[4] * v + k->g[5] * w);
    return k->amp * cubic_q2(t0 * t0 + t1 * t1 + t2 * t2);
}

double pfsph_surface_calibrate_iso(const pfsph_surface_opts *in)
{
    pfsph_surface_opts o;
    resolve(in, &o);
    const double d = o.spacing, cellw = o.cell * d;
    const int L = 8, D = 6;
    size_t n = (size_t)(2 * L + 1) * (2 * L + 1) * (size_t)D, c = 0;
    double *x = malloc(3 * n * sizeof *x);
    kern *K = malloc(n * sizeof *K);
    double iso = 0.5;
    float rmax;
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
            double p[3] = {a * d / 4 / cellw, b * d / 4 / cellw, d / 2 / cellw}, f = 0;
            for (size_t j = 0; j < n; j++) f += kern_at(K + j, p);
            sum += f;
            ns++;
        }
    iso = sum / ns;
out:
    free(x);
    free(K);
    return iso;
}

/* ---- sparse blocks: open-addressing hash of block keys (growth only) ---- */
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

#define NIDX(a, b, c) (((c)*BN + (b)) * BN + (a))

/* one kernel into the block whose first node is O (global node index): rows of BN nodes along x.
 * A node's offset from the centre is (global index - I) - f, exact integers converted, and its
 * unit-kernel coordinates are formed in a fixed order, so its term has the same bits in every
 * block that holds it. The ellipsoid q^2 = r^T M r < 1 (M = G G) is rasterised: per z slice the
 * rows that meet it (each row then evaluated whole, two 4-wide vectors). The ranges are those of a
 * slightly larger ellipsoid (1.0001, plus 1e-3 cell), so that whatever is skipped has q^2 >= 1
 * beyond any rounding and would add exactly nothing: a node gets the same terms in every block. */
#define GROW 1.0001f
#define MARGIN 1e-3f
static void splat(float *restrict fv, const kern *k, const int32_t O[3], const int8_t rlo[BN], const int8_t rhi[BN])
{
    const float *g = k->g, rad = k->rad * GROW + MARGIN; /* bounds: a superset of the support */
    float cen[3];
    for (int u = 0; u < 3; u++) cen[u] = (float)(k->I[u] - O[u]) + k->f[u];
    if (cen[0] + rad < 0 || cen[0] - rad > BS || cen[1] + rad < 0 || cen[1] - rad > BS) return;
    float za = ceilf(cen[2] - rad), zb = floorf(cen[2] + rad);
    if (zb < 0 || za > BS) return;
    const int c0 = za < 0 ? 0 : (int)za, c1 = zb > BS ? BS : (int)zb;
    /* M = G G (G symmetric), and the Schur complements that give a slice's row range */
    const float m00 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2], m01 = g[0] * g[1] + g[1] * g[3] + g[2] * g[4],
                m02 = g[0] * g[2] + g[1] * g[4] + g[2] * g[5], m11 = g[1] * g[1] + g[3] * g[3] + g[4] * g[4],
                m12 = g[1] * g[2] + g[3] * g[4] + g[4] * g[5], m22 = g[2] * g[2] + g[4] * g[4] + g[5] * g[5];
    const float i00 = 1.0f / m00, sa = m11 - m01 * m01 * i00, sb = m12 - m01 * m02 * i00, sc = m22 - m02 * m02 * i00,
                isa = 1.0f / sa, amp = k->amp;
    const int32_t ux0 = O[0] - k->I[0], vy0 = O[1] - k->I[1];
    float us[BN];
    for (int a = 0; a < BN; a++) us[a] = (float)(ux0 + a) - k->f[0];
    for (int c = c0; c <= c1; c++) {
        if (rlo[c] > rhi[c]) continue; /* no row of this slice wanted */
        const float w = (float)(O[2] + c - k->I[2]) - k->f[2];
        /* rows: sa v^2 + 2 sb w v + sc w^2 < GROW, v = (y - I) - f */
        const float B = sb * w, disc = B * B - sa * (sc * w * w - GROW);
        if (disc < 0) continue;
        const float sq = sqrtf(disc), ylo = cen[1] + (-B - sq) * isa - MARGIN, yhi = cen[1] + (-B + sq) * isa + MARGIN;
        const int b0 = ylo < rlo[c] ? rlo[c] : (int)ceilf(ylo), b1 = yhi > rhi[c] ? rhi[c] : (int)floorf(yhi);
        const float wr0 = g[2] * w, wr1 = g[4] * w, wr2 = g[5] * w;
        for (int b = b0; b <= b1; b++) {
            const float v = (float)(vy0 + b) - k->f[1];
            const float rt0 = g[1] * v + wr0, rt1 = g[3] * v + wr1, rt2 = g[4] * v + wr2;
            float *restrict row = fv + NIDX(0, b, c);
#pragma omp simd
            for (int a = 0; a < BN; a++) {
                const float u = us[a];
                const float t0 = g[0] * u + rt0, t1 = g[1] * u + rt1, t2 = g[2] * u + rt2;
                const float q2 = t0 * t0 + t1 * t1 + t2 * t2;
                const float q = sqrtf(q2), t = 1.0f - q;
                const float outer = 2.0f * t * t * t, inner = 6.0f * q * q * (q - 1.0f) + 1.0f;
                const float val = q <= 0.5f ? inner : outer;
                row[a] += q2 < 1.0f ? amp * val : 0.0f;
            }
        }
    }
}

/* node values of a block (the rows (b, c) set in `rows`, bit b + 8 c; the others 0): the kernels
 * whose centres lie in the block cells within R, visited in
 * ascending cell then index order; a node shared with another block sees its kernels in the same
 * order there (both visit the same global order), so it gets the same sum, bit for bit */
static void block_field(block *bl, const kern *K, const grid *kg, int R, uint64_t rows)
{
    memset(bl->f, 0, BNODES * sizeof *bl->f);
    int8_t rlo[BN], rhi[BN]; /* the rows wanted in a slice form one range (own rows, then faces) */
    for (int c = 0; c < BN; c++) {
        unsigned m = (unsigned)(rows >> (BN * c)) & 0xffu;
        rlo[c] = BN;
        rhi[c] = -1;
        for (int b = 0; b < BN; b++)
            if (m >> b & 1) {
                if (rlo[c] == BN) rlo[c] = (int8_t)b;
                rhi[c] = (int8_t)b;
            }
    }
    const int32_t O[3] = {bl->b[0] * BS, bl->b[1] * BS, bl->b[2] * BS};
    for (int64_t a = (int64_t)bl->b[0] - R; a <= (int64_t)bl->b[0] + R; a++)
        for (int64_t b = (int64_t)bl->b[1] - R; b <= (int64_t)bl->b[1] + R; b++) {
            uint32_t s, e;
            grid_col(kg, a, b, (int64_t)bl->b[2] - R, (int64_t)bl->b[2] + R, &s, &e);
            for (uint32_t q = s; q < e; q++) splat(bl->f, K + kg->idx[q], O, rlo, rhi);
        }
}

/* the corner case of each cell (bit t for corner (t & 1, t >> 1 & 1, t >> 2) inside) */
static inline int cell_case(const uint8_t *in, int a, int b, int c)
{
    const uint8_t *p = in + NIDX(a, b, c);
    return p[0] | p[1] << 1 | p[BN] << 2 | p[BN + 1] << 3 | p[BN * BN] << 4 | p[BN * BN + 1] << 5 |
        p[BN * BN + BN] << 6 | p[BN * BN + BN + 1] << 7;
}

static void block_inside(const float *f, float iso, uint8_t *in)
{
    for (int i = 0; i < BNODES; i++) in[i] = f[i] > iso;
}

/* ---- marching tetrahedra: a case table for the cube, built from the six Kuhn tetrahedra ---- */
static const int KUHN[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

typedef struct mc_table {
    uint8_t ntri[256];
    uint8_t tri[256][12][3]; /* cube edges 0..18 */
    uint8_t es[19], ed[19];  /* cube edge: lower corner (xyz bits), direction (xyz bits, 1..7) */
} mc_table;

static void corner_xyz(int t, int p[3])
{
    p[0] = t & 1;
    p[1] = (t >> 1) & 1;
    p[2] = t >> 2;
}

/* a triangle on the tetrahedron edges e[k] = (corner, corner), oriented so that its normal points
 * away from corner `in` (inside), decided on the edges' midpoints in integers: the sign of the
 * real triangle for any interpolation parameters */
static void table_emit(mc_table *T, int cs, const int e[3][2], int in, int away, const int eid[8][8])
{
    long m[3][3];
    int pin[3];
    corner_xyz(in, pin);
    for (int k = 0; k < 3; k++) {
        int p[3], q[3];
        corner_xyz(e[k][0], p);
        corner_xyz(e[k][1], q);
        for (int u = 0; u < 3; u++) m[k][u] = p[u] + q[u];
    }
    long ab[3], ac[3], ai[3];
    for (int u = 0; u < 3; u++) {
        ab[u] = m[1][u] - m[0][u];
        ac[u] = m[2][u] - m[0][u];
        ai[u] = m[0][u] - 2L * pin[u];
    }
    long nx = ab[1] * ac[2] - ab[2] * ac[1], ny = ab[2] * ac[0] - ab[0] * ac[2], nz = ab[0] * ac[1] - ab[1] * ac[0];
    long s = nx * ai[0] + ny * ai[1] + nz * ai[2];
    if (!away) s = -s;
    int order[3] = {0, 1, 2};
    if (s < 0) {
        order[1] = 2;
        order[2] = 1;
    }
    uint8_t *t = T->tri[cs][T->ntri[cs]++];
    for (int k = 0; k < 3; k++) t[k] = (uint8_t)eid[e[order[k]][0]][e[order[k]][1]];
}

static void table_build(mc_table *T)
{
    memset(T, 0, sizeof *T);
    int eid[8][8], ne = 0;
    for (int s = 0; s < 8; s++)
        for (int q = 0; q < 8; q++) eid[s][q] = -1;
    for (int s = 0; s < 8; s++)
        for (int dir = 1; dir < 8; dir++)
            if (!(s & dir)) {
                T->es[ne] = (uint8_t)s;
                T->ed[ne] = (uint8_t)dir;
                eid[s][s | dir] = eid[s | dir][s] = ne++;
            }
    for (int cs = 1; cs < 255; cs++)
        for (int t = 0; t < 6; t++) {
            int v[4] = {0, 1 << KUHN[t][0], (1 << KUHN[t][0]) | (1 << KUHN[t][1]), 7};
            int ins[4], nin = 0, outs[4], nout = 0;
            for (int k = 0; k < 4; k++) {
                if (cs >> v[k] & 1) ins[nin++] = v[k];
                else outs[nout++] = v[k];
            }
            int e[3][2];
            if (nin == 1 || nin == 3) {
                int apex = nin == 1 ? ins[0] : outs[0];
                const int *others = nin == 1 ? outs : ins;
                for (int k = 0; k < 3; k++) {
                    e[k][0] = apex;
                    e[k][1] = others[k];
                }
                table_emit(T, cs, e, apex, nin == 1, eid);
            } else if (nin == 2) {
                /* quad (i0 o0) (i0 o1) (i1 o1) (i1 o0), two triangles */
                int q[4][2] = {{ins[0], outs[0]}, {ins[0], outs[1]}, {ins[1], outs[1]}, {ins[1], outs[0]}};
                int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
                for (int s = 0; s < 2; s++) {
                    for (int k = 0; k < 3; k++) {
                        e[k][0] = q[tri[s][k]][0];
                        e[k][1] = q[tri[s][k]][1];
                    }
                    table_emit(T, cs, e, ins[0], 1, eid);
                }
            }
        }
}

static void grad_at(const float *f, int a, int b, int c, double cellw, double g[3])
{
    /* central differences, one-sided on the block's faces */
    int i[3] = {a, b, c};
    for (int u = 0; u < 3; u++) {
        int lo[3] = {a, b, c}, hi[3] = {a, b, c};
        lo[u] = i[u] > 0 ? i[u] - 1 : 0;
        hi[u] = i[u] < BS ? i[u] + 1 : BS;
        g[u] = ((double)f[NIDX(hi[0], hi[1], hi[2])] - f[NIDX(lo[0], lo[1], lo[2])]) / ((hi[u] - lo[u]) * cellw);
    }
}

/* per-thread scratch of the marching: the edge table (local vertex number or -1) and buffers */
typedef struct march_scratch {
    int32_t tab[NEDGE];
    uint32_t ren[NEDGE]; /* local number -> owned rank or foreign reference */
    uint32_t tri[3 * MAXTRI];
    uint8_t in[BNODES];
} march_scratch;

/* triangles of one block; vertices only for the edges it owns (lower node in [0, BS)^3: each edge
 * has exactly one owner, the block that also holds the cell at its lower node, which the growth
 * always computes and keeps when the edge is crossed) */
static int march_block(march_scratch *S, block *bl, const mc_table *T, float iso, double cellw)
{
    block_inside(bl->f, iso, S->in);
    uint32_t nloc = 0, nt = 0;
    for (int c = 0; c < BS; c++)
        for (int b = 0; b < BS; b++)
            for (int a = 0; a < BS; a++) {
                int cs = cell_case(S->in, a, b, c);
                if (cs == 0 || cs == 255) continue;
                for (int t = 0; t < T->ntri[cs]; t++)
                    for (int k = 0; k < 3; k++) {
                        int ce = T->tri[cs][t][k], s = T->es[ce];
                        int E = NIDX(a + (s & 1), b + (s >> 1 & 1), c + (s >> 2)) * 7 + T->ed[ce] - 1;
                        if (S->tab[E] < 0) S->tab[E] = (int32_t)nloc++;
                        S->tri[3 * (nt + (uint32_t)t) + (uint32_t)k] = (uint32_t)S->tab[E];
                    }
                nt += T->ntri[cs];
            }
    /* number the owned vertices in ascending edge order, refer to foreign ones by their owner */
    uint32_t nv = 0;
    uint16_t ve[NEDGE];
    for (int E = 0; E < NEDGE && nloc; E++) {
        if (S->tab[E] < 0) continue;
        int node = E / 7, dir = E % 7 + 1;
        int p[3] = {node % BN, node / BN % BN, node / (BN * BN)}, o = 0;
        for (int u = 0; u < 3; u++)
            if (p[u] == BS) {
                o |= 1 << u;
                p[u] = 0;
            }
        if (!o) {
            S->ren[S->tab[E]] = nv;
            ve[nv++] = (uint16_t)E;
        } else S->ren[S->tab[E]] = FOREIGN | (uint32_t)o << 12 | (uint32_t)(NIDX(p[0], p[1], p[2]) * 7 + dir - 1);
        S->tab[E] = -1;
    }
    bl->nv = nv;
    bl->nt = nt;
    bl->ve = malloc((nv ? nv : 1) * sizeof *bl->ve);
    bl->vp = malloc(3 * (nv ? nv : 1) * sizeof *bl->vp);
    bl->vn = malloc(3 * (nv ? nv : 1) * sizeof *bl->vn);
    bl->tri = malloc(3 * (nt ? nt : 1) * sizeof *bl->tri);
    if (!bl->ve || !bl->vp || !bl->vn || !bl->tri) return PFSPH_ENOMEM;
    memcpy(bl->ve, ve, nv * sizeof *ve);
    for (uint32_t i = 0; i < 3 * nt; i++) bl->tri[i] = S->ren[S->tri[i]];
    for (uint32_t i = 0; i < nv; i++) {
        int node = ve[i] / 7, dir = ve[i] % 7 + 1;
        int p[3] = {node % BN, node / BN % BN, node / (BN * BN)}, q[3];
        for (int u = 0; u < 3; u++) q[u] = p[u] + (dir >> u & 1);
        double fp = bl->f[NIDX(p[0], p[1], p[2])], fq = bl->f[NIDX(q[0], q[1], q[2])];
        double t = (iso - fp) / (fq - fp);
        if (t < 1e-3) t = 1e-3; /* no vertex on a node: no zero-area faces */
        if (t > 1 - 1e-3) t = 1 - 1e-3;
        double gp[3], gq[3], g[3], len = 0;
        grad_at(bl->f, p[0], p[1], p[2], cellw, gp);
        grad_at(bl->f, q[0], q[1], q[2], cellw, gq);
        for (int u = 0; u < 3; u++) {
            bl->vp[3 * i + u] = ((double)bl->b[u] * BS + p[u] + t * (q[u] - p[u])) * cellw;
            g[u] = -((1 - t) * gp[u] + t * gq[u]);
            len += g[u] * g[u];
        }
        len = len > 0 ? 1 / sqrt(len) : 0;
        for (int u = 0; u < 3; u++) bl->vn[3 * i + u] = (float)(g[u] * len);
    }
    return PFSPH_OK;
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

/* the blocks that a block's rim cells crossed by the surface call for: bit (ox + 1) + 3 (oy + 1)
 * + 9 (oz + 1) for the neighbour at offset (ox, oy, oz); *any: some cell of the block is crossed */
static uint32_t block_needs(const float *f, float iso, int *any)
{
    uint8_t in[BNODES];
    block_inside(f, iso, in);
    uint32_t need = 0;
    *any = 0;
    for (int c = 0; c < BS; c++)
        for (int b = 0; b < BS; b++)
            for (int a = 0; a < BS; a++) {
                int cs = cell_case(in, a, b, c);
                if (cs == 0 || cs == 255) continue;
                *any = 1;
                int lo[3] = {a == 0 ? -1 : 0, b == 0 ? -1 : 0, c == 0 ? -1 : 0},
                    hi[3] = {a == BS - 1 ? 1 : 0, b == BS - 1 ? 1 : 0, c == BS - 1 ? 1 : 0};
                for (int z = lo[2]; z <= hi[2]; z++)
                    for (int y = lo[1]; y <= hi[1]; y++)
                        for (int xx = lo[0]; xx <= hi[0]; xx++) need |= 1u << ((xx + 1) + 3 * (y + 1) + 9 * (z + 1));
            }
    return need & ~(1u << 13); /* not itself */
}

static long block_find(const block *bl, size_t nb, int64_t key)
{
    size_t lo = 0, hi = nb;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (bl[mid].key < key) lo = mid + 1;
        else hi = mid;
    }
    return lo < nb && bl[lo].key == key ? (long)lo : -1;
}

static long edge_find(const block *b, uint32_t E)
{
    size_t lo = 0, hi = b->nv;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (b->ve[mid] < E) lo = mid + 1;
        else hi = mid;
    }
    return lo < b->nv && b->ve[lo] == E ? (long)lo : -1;
}

static void blocks_free(block *bl, size_t nb)
{
    for (size_t i = 0; bl && i < nb; i++) {
        free(bl[i].f);
        free(bl[i].ve);
        free(bl[i].vp);
        free(bl[i].vn);
        free(bl[i].tri);
    }
    free(bl);
}

/* one phase's points into m (appended) */
static int reconstruct_one(const double *x, size_t n, uint8_t phase, const pfsph_surface_opts *o, float iso,
                           const mc_table *T, pfsph_surface_mesh *m, pfsph_error *err)
{
    const double cellw = o->cell * o->spacing;
    kern *K = malloc((n ? n : 1) * sizeof *K);
    uint8_t *surf = malloc(n ? n : 1);
    int32_t *kc = malloc(3 * (n ? n : 1) * sizeof *kc);
    block *bl = NULL;
    size_t nb = 0, cb = 0, kept = 0;
    bmap map = {0};
    grid kg = {0};
    int64_t *pend = NULL;
    uint32_t *need = NULL;
    int32_t *src = NULL; /* 3 per block: the blocks at +y, +z, +y+z that hold its face rows, or -1 */
    size_t *voff = NULL, *toff = NULL;
    int rc = PFSPH_ENOMEM;
    if (!K || !surf || !kc) goto out;
    float rmax;
    double w0 = omp_get_wtime();
    if ((rc = kernels_build(x, n, o, K, surf, &rmax))) goto out;
    double w1 = omp_get_wtime();
    m->seconds[0] += w1 - w0;
    /* the kernels by block: a block reads the block cells within R of its own */
    for (size_t i = 0; i < n; i++)
        for (int u = 0; u < 3; u++) kc[3 * i + u] = floordiv(K[i].I[u], BS);
    if ((rc = grid_build(&kg, kc, n))) goto out;
    rc = PFSPH_ENOMEM;
    const int R = (int)floorf(rmax / BS) + 1;
    /* seeds: the blocks of the particles near the surface; growth finds the rest */
    size_t np = 0, cp = 1024;
    pend = malloc(cp * sizeof *pend);
    if (!pend) goto out;
    for (size_t i = 0; i < n; i++) {
        if (!surf[i]) continue;
        m->surface_particles++;
        if (np == cp) {
            int64_t *t = realloc(pend, 2 * cp * sizeof *t);
            if (!t) goto out;
            pend = t;
            cp *= 2;
        }
        pend[np++] = pack3(kc[3 * i], kc[3 * i + 1], kc[3 * i + 2]);
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
            uint32_t *tn = realloc(need, nc * sizeof *tn);
            int32_t *ts = realloc(src, 3 * nc * sizeof *ts);
            if (t) bl = t;
            if (tn) need = tn;
            if (ts) src = ts;
            if (!t || !tn || !ts) goto out;
            cb = nc;
        }
        for (size_t i = 0; i < np; i++) {
            block *b = bl + nb;
            memset(b, 0, sizeof *b);
            b->key = pend[i];
            unpack3(pend[i], b->b);
            b->f = malloc(BNODES * sizeof *b->f);
            nb++;
            if (!b->f || bmap_put(&map, pend[i], (int32_t)(nb - 1))) goto out;
        }
        live += np;
        if (live > peak) peak = live;
        /* The node rows on a block's +y and +z faces are the first rows of the blocks there: taken
         * from those blocks where they exist (from earlier generations or this one), computed
         * otherwise. Either way the same bits (a node's sum is the same in every block). */
        static const int NB_OFF[3][3] = {{0, 1, 0}, {0, 0, 1}, {0, 1, 1}};
        uint64_t *rows = malloc((nb - first) * sizeof *rows);
        if (!rows) goto out;
        for (size_t i = first; i < nb; i++) {
            uint64_t m = 0;
            for (int c = 0; c < BS; c++) m |= (uint64_t)0x7f << (BN * c); /* own rows: b, c < BS */
            for (int g = 0; g < 3; g++) {
                int j = bmap_find(&map,
                                  pack3((int64_t)bl[i].b[0] + NB_OFF[g][0], (int64_t)bl[i].b[1] + NB_OFF[g][1],
                                        (int64_t)bl[i].b[2] + NB_OFF[g][2]));
                src[3 * i + g] = j >= 0 && bl[j].f ? j : -1;
                if (src[3 * i + g] >= 0) continue;
                if (g == 0)
                    for (int c = 0; c < BS; c++) m |= (uint64_t)1 << (BS + BN * c);
                else if (g == 1) m |= (uint64_t)0x7f << (BN * BS);
                else m |= (uint64_t)1 << (BS + BN * BS);
            }
            rows[i - first] = m;
        }
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t i = first; i < nb; i++) block_field(bl + i, K, &kg, R, rows[i - first]);
        free(rows);
#pragma omp parallel for schedule(dynamic, 4)
        for (size_t i = first; i < nb; i++) {
            float *f = bl[i].f;
            if (src[3 * i] >= 0)
                for (int c = 0; c < BS; c++)
                    memcpy(f + NIDX(0, BS, c), bl[src[3 * i]].f + NIDX(0, 0, c), BN * sizeof *f);
            if (src[3 * i + 1] >= 0)
                for (int b = 0; b < BS; b++)
                    memcpy(f + NIDX(0, b, BS), bl[src[3 * i + 1]].f + NIDX(0, b, 0), BN * sizeof *f);
            if (src[3 * i + 2] >= 0) memcpy(f + NIDX(0, BS, BS), bl[src[3 * i + 2]].f + NIDX(0, 0, 0), BN * sizeof *f);
            int any;
            need[i] = block_needs(f, iso, &any);
            if (!any) need[i] |= 1u << 31; /* not crossed: not kept */
        }
        /* crossed cells on a block's rim call for the blocks of their neighbour cells */
        np = 0;
        for (size_t i = first; i < nb; i++) {
            for (int s = 0; s < 27; s++) {
                if (!(need[i] >> s & 1)) continue;
                if (np + 1 > cp) {
                    int64_t *t = realloc(pend, 2 * cp * sizeof *t);
                    if (!t) goto out;
                    pend = t;
                    cp *= 2;
                }
                pend[np++] = pack3((int64_t)bl[i].b[0] + s % 3 - 1, (int64_t)bl[i].b[1] + s / 3 % 3 - 1,
                                   (int64_t)bl[i].b[2] + s / 9 - 1);
            }
            if (need[i] >> 31) {
                free(bl[i].f);
                bl[i].f = NULL;
                live--;
            }
        }
    }
    /* compact and sort the kept blocks: the order of the output */
    for (size_t i = 0; i < nb; i++)
        if (bl[i].f) bl[kept++] = bl[i];
    nb = kept;
    qsort(bl, kept, sizeof *bl, block_cmp);
    m->blocks += kept;
    if (peak > m->blocks_peak) m->blocks_peak = peak;
    if (peak * BNODES * sizeof(float) > m->grid_bytes) m->grid_bytes = peak * BNODES * sizeof(float);
    double w2 = omp_get_wtime();
    m->seconds[1] += w2 - w1;
    int fail = 0;
#pragma omp parallel reduction(| : fail)
    {
        march_scratch *S = malloc(sizeof *S);
        if (!S) fail = 1;
        else
            for (int i = 0; i < NEDGE; i++) S->tab[i] = -1;
#pragma omp for schedule(dynamic, 1)
        for (size_t i = 0; i < kept; i++)
            if (!fail && march_block(S, bl + i, T, iso, cellw)) fail = 1;
        free(S);
    }
    if (fail) goto out;
    double w3 = omp_get_wtime();
    m->seconds[2] += w3 - w2;
    /* the mesh: blocks in key order, each its owned vertices in edge order */
    voff = malloc((kept + 1) * sizeof *voff);
    toff = malloc((kept + 1) * sizeof *toff);
    if (!voff || !toff) goto out;
    voff[0] = m->nverts;
    toff[0] = m->ntris;
    for (size_t i = 0; i < kept; i++) {
        voff[i + 1] = voff[i] + bl[i].nv;
        toff[i + 1] = toff[i] + bl[i].nt;
    }
    if (voff[kept] > UINT32_MAX) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "surface: more than 2^32 vertices");
        goto out;
    }
    if ((rc = append(m, voff[kept] - m->nverts, toff[kept] - m->ntris))) goto out;
    rc = PFSPH_ENOMEM;
#pragma omp parallel for schedule(dynamic, 4) reduction(| : fail)
    for (size_t i = 0; i < kept; i++) {
        const block *b = bl + i;
        memcpy(m->v + 3 * voff[i], b->vp, 3 * b->nv * sizeof *b->vp);
        memcpy(m->n + 3 * voff[i], b->vn, 3 * b->nv * sizeof *b->vn);
        memset(m->phase + toff[i], phase, b->nt);
        uint32_t *t = m->tri + 3 * toff[i];
        for (uint32_t k = 0; k < 3 * b->nt; k++) {
            uint32_t r = b->tri[k];
            if (!(r & FOREIGN)) {
                t[k] = (uint32_t)(voff[i] + r);
                continue;
            }
            int o = (int)(r >> 12 & 7);
            long j = block_find(
                bl, kept,
                pack3((int64_t)b->b[0] + (o & 1), (int64_t)b->b[1] + (o >> 1 & 1), (int64_t)b->b[2] + (o >> 2)));
            long v = j < 0 ? -1 : edge_find(bl + j, r & 0xfff);
            if (v < 0) fail = 1; /* cannot happen: the owner holds every crossed edge of its cells */
            else t[k] = (uint32_t)(voff[j] + (size_t)v);
        }
    }
    if (fail) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "surface: internal error: a vertex without its block");
        goto out;
    }
    size_t v0 = m->nverts, t0 = m->ntris;
    m->nverts = voff[kept];
    m->ntris = toff[kept];
    rc = taubin(m, v0, t0, o->smooth_iters);
    m->seconds[3] += omp_get_wtime() - w3;
out:
    if (rc == PFSPH_ENOMEM && !err->msg[0]) pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    blocks_free(bl, nb);
    free(map.keys);
    free(map.val);
    free(pend);
    free(need);
    free(src);
    free(voff);
    free(toff);
    grid_free(&kg);
    free(K);
    free(surf);
    free(kc);
    return rc;
}

/* The options with their defaults filled in, checked; smoothing passes only where they are used
 * (the 2D outline ignores them). A PCA radius of at least a cell keeps the neighbour grid's
 * coordinates within 21 bits. */
static int resolve_checked(const pfsph_surface_opts *in, bool smoothing, pfsph_surface_opts *o, pfsph_error *err)
{
    if (!(in->spacing > 0) || !isfinite(in->spacing))
        return pfsph_fail(err, PFSPH_EINPUT, "surface: the particle spacing %g is not positive", in->spacing);
    resolve(in, o);
    if (o->lambda > 1 || o->kr < 1 || o->cell > 4 || o->cell < 0.05 || o->support > 8 || o->support < 0.5 ||
        o->pca_radius > 8 || o->pca_radius < o->cell || (smoothing && o->smooth_iters > 1000)) {
        if (smoothing)
            return pfsph_fail(err, PFSPH_EINPUT,
                              "surface: options out of range (lambda %g, kr %g, cell %g d, "
                              "support %g d, neighbourhood %g d, %d smoothing passes)",
                              o->lambda, o->kr, o->cell, o->support, o->pca_radius, o->smooth_iters);
        return pfsph_fail(err, PFSPH_EINPUT,
                          "surface: options out of range (lambda %g, kr %g, cell %g d, "
                          "support %g d, neighbourhood %g d)",
                          o->lambda, o->kr, o->cell, o->support, o->pca_radius);
    }
    return PFSPH_OK;
}

int pfsph_surface_reconstruct(const double *x, const uint8_t *phase, size_t n, const pfsph_surface_opts *in,
                              pfsph_surface_mesh *m, pfsph_error *err)
{
    memset(m, 0, sizeof *m);
    err->msg[0] = 0;
    pfsph_surface_opts o;
    int rc0 = resolve_checked(in, true, &o, err);
    if (rc0 != PFSPH_OK) return rc0;
    const double reach = (double)(1 << 18) * o.cell * o.spacing; /* the grid's integer coordinates */
    for (size_t i = 0; i < 3 * n; i++) {
        if (!isfinite(x[i]))
            return pfsph_fail(err, PFSPH_EINPUT, "surface: particle %zu has a non-finite position", i / 3);
        if (fabs(x[i]) > reach)
            return pfsph_fail(err, PFSPH_EINPUT,
                              "surface: particle %zu is %g m from the origin, beyond the meshing "
                              "grid's %g m (2^18 cells)",
                              i / 3, fabs(x[i]), reach);
    }
    const float iso = (float)(o.iso > 0 ? o.iso : pfsph_surface_calibrate_iso(&o));
    mc_table *T = malloc(sizeof *T);
    if (!T) return pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    table_build(T);
    int present[256] = {0};
    for (size_t i = 0; i < n; i++) present[phase ? phase[i] : 0]++;
    double *xs = malloc(3 * (n ? n : 1) * sizeof *xs);
    if (!xs) {
        free(T);
        return pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    }
    int rc = PFSPH_OK;
    for (int p = 0; p < 256 && !rc; p++) {
        if (!present[p]) continue;
        size_t k = 0;
        for (size_t i = 0; i < n; i++)
            if ((phase ? phase[i] : 0) == p) {
                memcpy(xs + 3 * k, x + 3 * i, 3 * sizeof *xs);
                k++;
            }
        rc = reconstruct_one(xs, k, (uint8_t)p, &o, iso, T, m, err);
    }
    free(xs);
    free(T);
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

/* ---- 2D: the outline of a liquid as closed polylines (docs/surfaces.md#2d-contours) ----
 * The same method in the plane: weighted PCA over the neighbourhood (2 x 2), smoothed centres,
 * clamped anisotropy, a cubic-spline volume-fraction field with the iso-level calibrated on a flat
 * lattice slab, on a dense grid of nodes over the kernels' reach (2D grids are small), and
 * marching triangles: each square split along its diagonal, so that the contour of the
 * piecewise-linear field is a set of closed curves with no ambiguous case. Serial and in
 * particle order: the same bytes for any thread count. */

typedef struct kern2 {
    double c[2];
    double g[3]; /* symmetric world -> unit-kernel map: xx xy yy (includes 1 / h) */
    double amp;  /* d^2 |det G| sigma_2 */
    double rad;  /* support radius [m] */
} kern2;

static int lattice_count2(double r)
{
    int m = (int)ceil(r), c = 0;
    for (int i = -m; i <= m; i++)
        for (int j = -m; j <= m; j++) c += i * i + j * j < r * r;
    return c;
}

static double lattice_sigma2(double r)
{
    int m = (int)ceil(r);
    double sw = 0, sw2 = 0;
    for (int i = -m; i <= m; i++)
        for (int j = -m; j <= m; j++) {
            double s = sqrt((double)(i * i + j * j));
            if (s >= r) continue;
            double w = 1 - (s / r) * (s / r) * (s / r);
            sw += w;
            sw2 += w * s * s / 2;
        }
    return sw2 / sw;
}

static double cubic2(double q) /* unit support, 2D normalisation */
{
    const double sigma = 40.0 / (7.0 * PI);
    if (q >= 1) return 0;
    double t = 1 - q, m = 1 - 2 * q;
    return sigma * (2 * t * t * t - (m > 0 ? m * m * m : 0));
}

static double kern2_at(const kern2 *k, double px, double py)
{
    double rx = px - k->c[0], ry = py - k->c[1];
    double t0 = k->g[0] * rx + k->g[1] * ry, t1 = k->g[1] * rx + k->g[2] * ry;
    double q2 = t0 * t0 + t1 * t1;
    return q2 < 1 ? k->amp * cubic2(sqrt(q2)) : 0;
}

/* kernels of n points (x: 3 per point, z ignored) */
static int kernels2_build(const double *x, size_t n, const pfsph_surface_opts *o, kern2 *K)
{
    const double d = o->spacing, r = o->pca_radius * d, h = o->support * d;
    const double ks = 1.0 / (lattice_sigma2(o->pca_radius) * d * d);
    const int n_eps = o->n_eps > 0 ? o->n_eps : (lattice_count2(o->pca_radius) + 2) / 5;
    int32_t *cell = malloc(3 * (n ? n : 1) * sizeof *cell);
    if (!cell) return PFSPH_ENOMEM;
    for (size_t i = 0; i < n; i++) {
        cell[3 * i] = (int32_t)floor(x[3 * i] / r);
        cell[3 * i + 1] = (int32_t)floor(x[3 * i + 1] / r);
        cell[3 * i + 2] = 0;
    }
    grid g;
    int rc = grid_build(&g, cell, n);
    if (rc) {
        free(cell);
        grid_free(&g);
        return rc;
    }
    for (size_t i = 0; i < n; i++) {
        const double *xi = x + 3 * i;
        double sw = 0, mu[2] = {0, 0}, S[3] = {0, 0, 0};
        int cnt = 0;
        for (int64_t a = cell[3 * i] - 1; a <= cell[3 * i] + 1; a++)
            for (int64_t b = cell[3 * i + 1] - 1; b <= cell[3 * i + 1] + 1; b++) {
                uint32_t s, e;
                grid_col(&g, a, b, 0, 0, &s, &e);
                for (uint32_t q = s; q < e; q++) {
                    const double *xj = x + 3 * (size_t)g.idx[q];
                    double ex = xj[0] - xi[0], ey = xj[1] - xi[1], s2 = ex * ex + ey * ey;
                    if (s2 >= r * r) continue;
                    double sr = sqrt(s2) / r, w = 1 - sr * sr * sr;
                    sw += w;
                    mu[0] += w * ex;
                    mu[1] += w * ey;
                    S[0] += w * ex * ex;
                    S[1] += w * ex * ey;
                    S[2] += w * ey * ey;
                    cnt++;
                }
            }
        mu[0] /= sw;
        mu[1] /= sw;
        double C[2][2] = {{S[0] / sw - mu[0] * mu[0], S[1] / sw - mu[0] * mu[1]},
                          {S[1] / sw - mu[0] * mu[1], S[2] / sw - mu[1] * mu[1]}};
        kern2 *k = K + i;
        k->c[0] = xi[0] + o->lambda * mu[0];
        k->c[1] = xi[1] + o->lambda * mu[1];
        double scale[2] = {o->kn, o->kn}, V[2][2] = {{1, 0}, {0, 1}};
        if (o->isotropic) scale[0] = scale[1] = 1;
        else if (cnt >= n_eps) {
            double w[2];
            pfsph_eigen_sym2((const double(*)[2])C, w, V);
            for (int u = 0; u < 2; u++) {
                double sv = w[u] < w[0] / o->kr ? w[0] / o->kr : w[u];
                scale[u] = sqrt(ks * sv);
                if (scale[u] > 2) scale[u] = 2;
            }
        }
        double is[2] = {1 / (h * scale[0]), 1 / (h * scale[1])};
        k->g[0] = V[0][0] * V[0][0] * is[0] + V[0][1] * V[0][1] * is[1];
        k->g[1] = V[0][0] * V[1][0] * is[0] + V[0][1] * V[1][1] * is[1];
        k->g[2] = V[1][0] * V[1][0] * is[0] + V[1][1] * V[1][1] * is[1];
        k->amp = d * d * is[0] * is[1];
        k->rad = h * (scale[0] > scale[1] ? scale[0] : scale[1]);
    }
    free(cell);
    grid_free(&g);
    return PFSPH_OK;
}

double pfsph_surface_calibrate_iso2d(const pfsph_surface_opts *in)
{
    pfsph_surface_opts o;
    resolve(in, &o);
    const double d = o.spacing;
    const int L = 8, D = 6;
    size_t n = (size_t)(2 * L + 1) * (size_t)D, c = 0;
    double *x = malloc(3 * n * sizeof *x), iso = 0.5;
    kern2 *K = malloc(n * sizeof *K);
    if (!x || !K) goto out;
    for (int i = -L; i <= L; i++)
        for (int k = 0; k < D; k++) {
            x[3 * c] = i * d;
            x[3 * c + 1] = -k * d;
            x[3 * c + 2] = 0;
            c++;
        }
    if (kernels2_build(x, n, &o, K)) goto out;
    /* half a spacing above the top row, averaged over one lattice spacing */
    double sum = 0;
    for (int a = 0; a < 4; a++)
        for (size_t j = 0; j < n; j++) sum += kern2_at(K + j, a * d / 4, d / 2);
    iso = sum / 4;
out:
    free(x);
    free(K);
    return iso;
}

void pfsph_surface_contour_free(pfsph_surface_contour *c)
{
    if (!c) return;
    free(c->v);
    free(c->n);
    free(c->seg);
    free(c->phase);
    memset(c, 0, sizeof *c);
}

/* one phase's outline into c (appended) */
static int contour_one(const double *x, size_t n, uint8_t phase, const pfsph_surface_opts *o, double iso,
                       pfsph_surface_contour *ct, pfsph_error *err)
{
    const double cellw = o->cell * o->spacing;
    kern2 *K = malloc((n ? n : 1) * sizeof *K);
    double *f = NULL;
    int64_t *seg = NULL, *keys = NULL;
    int rc = PFSPH_ENOMEM;
    if (!K) goto out;
    if ((rc = kernels2_build(x, n, o, K))) goto out;
    rc = PFSPH_ENOMEM;
    /* nodes over the kernels' reach, one spare layer outside: the field is 0 on the border */
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int u = 0; u < 2; u++) {
            if (K[i].c[u] - K[i].rad < lo[u]) lo[u] = K[i].c[u] - K[i].rad;
            if (K[i].c[u] + K[i].rad > hi[u]) hi[u] = K[i].c[u] + K[i].rad;
        }
    int64_t i0 = (int64_t)floor(lo[0] / cellw) - 1, j0 = (int64_t)floor(lo[1] / cellw) - 1;
    int64_t nx = (int64_t)ceil(hi[0] / cellw) + 1 - i0 + 1, ny = (int64_t)ceil(hi[1] / cellw) + 1 - j0 + 1;
    if ((double)nx * (double)ny > (double)(1 << 26)) {
        rc = pfsph_fail(err, PFSPH_EINPUT,
                        "surface: the 2D contour's grid would have %.3g nodes (the particles "
                        "span %g x %g m at cells of %g m); at most 2^26",
                        (double)nx * (double)ny, hi[0] - lo[0], hi[1] - lo[1], cellw);
        goto out;
    }
    f = calloc((size_t)(nx * ny), sizeof *f);
    if (!f) goto out;
    for (size_t q = 0; q < n; q++) { /* in particle order: one sum order for every node */
        const kern2 *k = K + q;
        int64_t a0 = (int64_t)ceil((k->c[0] - k->rad) / cellw) - i0,
                a1 = (int64_t)floor((k->c[0] + k->rad) / cellw) - i0;
        int64_t b0 = (int64_t)ceil((k->c[1] - k->rad) / cellw) - j0,
                b1 = (int64_t)floor((k->c[1] + k->rad) / cellw) - j0;
        for (int64_t b = b0; b <= b1; b++)
            for (int64_t a = a0; a <= a1; a++)
                f[b * nx + a] += kern2_at(k, (double)(i0 + a) * cellw, (double)(j0 + b) * cellw);
    }
    /* marching triangles: square (a, b) split along its diagonal (a, b)-(a+1, b+1); an edge is
     * (lower node, direction 0 +x, 1 +y, 2 +x+y), key node * 3 + direction */
    static const int TRI[2][3][2] = {{{0, 0}, {1, 0}, {1, 1}}, {{0, 0}, {1, 1}, {0, 1}}};
    size_t ns = 0, cs = 1024;
    seg = malloc(2 * cs * sizeof *seg);
    if (!seg) goto out;
    for (int64_t b = 0; b + 1 < ny; b++)
        for (int64_t a = 0; a + 1 < nx; a++)
            for (int t = 0; t < 2; t++) {
                int p[3][2], in[3], nin = 0;
                for (int k = 0; k < 3; k++) {
                    p[k][0] = (int)a + TRI[t][k][0];
                    p[k][1] = (int)b + TRI[t][k][1];
                    in[k] = f[(int64_t)p[k][1] * nx + p[k][0]] > iso;
                    nin += in[k];
                }
                if (nin == 0 || nin == 3) continue;
                int apex = 0; /* the corner on its own side */
                for (int k = 0; k < 3; k++)
                    if ((nin == 1) == (in[k] == 1)) apex = k;
                int oa = (apex + 1) % 3, ob = (apex + 2) % 3, inside = in[apex] ? apex : oa;
                /* liquid on the left, decided on doubled edge midpoints: the side of the inside
                 * corner does not depend on where the vertices sit on their edges */
                long sx = p[apex][0] + p[oa][0], sy = p[apex][1] + p[oa][1];
                long ex = p[apex][0] + p[ob][0], ey = p[apex][1] + p[ob][1];
                long ix = 2L * p[inside][0] - sx, iy = 2L * p[inside][1] - sy;
                int flip = (ex - sx) * iy - (ey - sy) * ix < 0;
                int ends[2] = {flip ? ob : oa, flip ? oa : ob};
                if (ns == cs) {
                    int64_t *tmp = realloc(seg, 4 * cs * sizeof *seg);
                    if (!tmp) goto out;
                    seg = tmp;
                    cs *= 2;
                }
                for (int e = 0; e < 2; e++) {
                    const int *u = p[apex], *v = p[ends[e]];
                    int le = u[0] <= v[0] && u[1] <= v[1];
                    const int *l = le ? u : v, *g = le ? v : u;
                    int dir = g[0] - l[0] + g[1] - l[1] == 2 ? 2 : (g[1] > l[1]);
                    seg[2 * ns + e] = ((int64_t)l[1] * nx + l[0]) * 3 + dir;
                }
                ns++;
            }
    keys = malloc((ns ? 2 * ns : 1) * sizeof *keys);
    if (!keys) goto out;
    memcpy(keys, seg, 2 * ns * sizeof *keys);
    qsort(keys, 2 * ns, sizeof *keys, i64_cmp);
    size_t nv = 0;
    for (size_t i = 0; i < 2 * ns; i++)
        if (!nv || keys[i] != keys[nv - 1]) keys[nv++] = keys[i];
    size_t v0 = ct->nverts, s0 = ct->nsegs;
    if (v0 + nv > UINT32_MAX) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "surface: more than 2^32 vertices");
        goto out;
    }
    double *v = realloc(ct->v, 3 * (v0 + nv) * sizeof *v + 1);
    if (v) ct->v = v;
    float *nn = realloc(ct->n, 3 * (v0 + nv) * sizeof *nn + 1);
    if (nn) ct->n = nn;
    uint32_t *sg = realloc(ct->seg, 2 * (s0 + ns) * sizeof *sg + 1);
    if (sg) ct->seg = sg;
    uint8_t *ph = realloc(ct->phase, s0 + ns + 1);
    if (ph) ct->phase = ph;
    if (!v || !nn || !sg || !ph) goto out;
    for (size_t i = 0; i < nv; i++) {
        int64_t node = keys[i] / 3;
        int dir = (int)(keys[i] % 3);
        int64_t a = node % nx, b = node / nx, da = dir != 1, db = dir != 0;
        double fp = f[b * nx + a], fq = f[(b + db) * nx + a + da], t = (iso - fp) / (fq - fp);
        if (t < 1e-3) t = 1e-3;
        if (t > 1 - 1e-3) t = 1 - 1e-3;
        ct->v[3 * (v0 + i)] = ((double)(i0 + a) + t * (double)da) * cellw;
        ct->v[3 * (v0 + i) + 1] = ((double)(j0 + b) + t * (double)db) * cellw;
        ct->v[3 * (v0 + i) + 2] = 0;
        /* normal: minus the field's gradient (central differences, one-sided on the border),
         * interpolated along the edge */
        double gr[2] = {0, 0};
        for (int e = 0; e < 2; e++) {
            int64_t pa = a + (e ? da : 0), pb = b + (e ? db : 0);
            double w = e ? t : 1 - t;
            int64_t al = pa > 0 ? pa - 1 : 0, ah = pa + 1 < nx ? pa + 1 : nx - 1;
            int64_t bl = pb > 0 ? pb - 1 : 0, bh = pb + 1 < ny ? pb + 1 : ny - 1;
            gr[0] += w * (f[pb * nx + ah] - f[pb * nx + al]) / (double)(ah - al);
            gr[1] += w * (f[bh * nx + pa] - f[bl * nx + pa]) / (double)(bh - bl);
        }
        double len = sqrt(gr[0] * gr[0] + gr[1] * gr[1]);
        len = len > 0 ? 1 / len : 0;
        ct->n[3 * (v0 + i)] = (float)(-gr[0] * len);
        ct->n[3 * (v0 + i) + 1] = (float)(-gr[1] * len);
        ct->n[3 * (v0 + i) + 2] = 0;
    }
    for (size_t s = 0; s < 2 * ns; s++) {
        const int64_t *hit = bsearch(seg + s, keys, nv, sizeof *keys, i64_cmp);
        ct->seg[2 * s0 + s] = (uint32_t)(v0 + (size_t)(hit - keys));
    }
    memset(ct->phase + s0, phase, ns);
    ct->nverts = v0 + nv;
    ct->nsegs = s0 + ns;
    rc = PFSPH_OK;
out:
    if (rc == PFSPH_ENOMEM && !err->msg[0]) pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    free(K);
    free(f);
    free(seg);
    free(keys);
    return rc;
}

int pfsph_surface_contour2d(const double *x, const uint8_t *phase, size_t n, const pfsph_surface_opts *in,
                            pfsph_surface_contour *c, pfsph_error *err)
{
    memset(c, 0, sizeof *c);
    err->msg[0] = 0;
    pfsph_surface_opts o;
    int rc0 = resolve_checked(in, false, &o, err);
    if (rc0 != PFSPH_OK) return rc0;
    const double reach = (double)(1 << 18) * o.cell * o.spacing;
    for (size_t i = 0; i < n; i++)
        for (int u = 0; u < 2; u++) {
            double v = x[3 * i + u];
            if (!isfinite(v))
                return pfsph_fail(err, PFSPH_EINPUT, "surface: particle %zu has a non-finite position", i);
            if (fabs(v) > reach)
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "surface: particle %zu is %g m from the origin, beyond the "
                                  "contour grid's %g m (2^18 cells)",
                                  i, fabs(v), reach);
        }
    double iso = o.iso > 0 ? o.iso : pfsph_surface_calibrate_iso2d(&o);
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
        rc = contour_one(xs, k, (uint8_t)p, &o, iso, c, err);
    }
    free(xs);
    if (rc) pfsph_surface_contour_free(c);
    return rc;
}
