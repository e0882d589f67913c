/* The surface reconstruction's kernels (Yu & Turk 2013): the options' defaults, a weighted PCA
 * per particle, smoothed centres, anisotropic kernels, and the iso-level calibrated on a flat
 * lattice slab (surface_mesh_internal.h, docs/surfaces.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/surface_mesh_internal.h"
#include "pfsph/eigen.h"

#define LANES 8   /* PCA candidates are padded to a multiple of this (any vector width) */
#define FAR 1e18f /* padding candidate: beyond every radius, squares stay finite */

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

void pfsph__surface_resolve(const pfsph_surface_opts *in, pfsph_surface_opts *o)
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

/* The options with their defaults filled in, checked; smoothing passes only where they are used
 * (the 2D outline ignores them). A PCA radius of at least a cell keeps the neighbour grid's
 * coordinates within 21 bits. */
int pfsph__surface_resolve_checked(const pfsph_surface_opts *in, bool smoothing, pfsph_surface_opts *o,
                                   pfsph_error *err)
{
    if (!(in->spacing > 0) || !isfinite(in->spacing))
        return pfsph_fail(err, PFSPH_EINPUT, "surface: the particle spacing %g is not positive", in->spacing);
    pfsph__surface_resolve(in, o);
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
int pfsph__surface_kernels(const double *x, size_t n, const pfsph_surface_opts *o, double drop_scale, kern *K,
                           uint8_t *surf, float *rad_max)
{
    const double d = o->spacing, r = o->pca_radius, h = o->support * d, cellw = o->cell * d;
    const double ks = 1.0 / lattice_sigma(o->pca_radius), cs = 0.5 * r * d; /* cells of half the radius */
    const int n_eps = o->n_eps > 0 ? o->n_eps : (lattice_count(o->pca_radius) + 2) / 5;
    grid g;
    /* calloc: with n = 0 the grid gets one unread cell, which GCC's -Wmaybe-uninitialized flags */
    int32_t *cell = calloc(3 * (n ? n : 1), sizeof *cell);
    int rc = PFSPH_ENOMEM;
    if (!cell) return rc;
    for (size_t i = 0; i < 3 * n; i++) cell[i] = (int32_t)floor(x[i] / cs);
    rc = pfsph__surface_grid_build(&g, cell, n);
    free(cell);
    /* positions in units of d, in cell order: the candidates' gather reads them contiguously */
    double *ps = rc ? NULL : malloc(3 * (n ? n : 1) * sizeof *ps);
    if (rc || !ps) {
        pfsph__surface_grid_free(&g);
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
                    pfsph__surface_grid_col(&g, a, b, (int64_t)uc[2] - 2, (int64_t)uc[2] + 2, &s, &e);
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
                /* an isolated particle: a droplet of its own volume (pfsph__surface_drop_scale) */
                if (drop_scale > 0 && cnt < PFSPH__ISOLATED && !o->isotropic) k->amp *= (float)drop_scale;
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
    pfsph__surface_grid_free(&g);
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

/* A lone kn kernel's field at the distance R d is amp W(R / u), u = kn h / d its support in units
 * of d and amp = (8 / pi) u^-3. Scaling its amplitude by iso / (amp W(R / u)) puts the iso-level
 * at R d. The amplitude, not the support, shrinks: the field stays as smooth as the kn kernel's,
 * which the marching follows closely (a narrower kernel's steep rim came out 25 % wider in radius
 * than the level set it stood for, at a cell of d / 2). Splashsurf and Houdini shrink or drop such
 * blobs likewise. Returns 0 when no bound applies (the kn blob is not larger than R d). */
double pfsph__surface_drop_scale(const pfsph_surface_opts *o, double iso)
{
    if (o->isotropic || o->droplet < 0) return 0;
    const double R = o->droplet > 0 ? o->droplet : cbrt(3.0 / (4.0 * PI)), u = o->kn * o->support;
    const double f = 8.0 / PI / (u * u * u) * (double)cubic_q2((float)((R / u) * (R / u)));
    return f > iso ? iso / f : 0;
}

double pfsph_surface_calibrate_iso(const pfsph_surface_opts *in)
{
    pfsph_surface_opts o;
    pfsph__surface_resolve(in, &o);
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
    if (pfsph__surface_kernels(x, n, &o, 0, K, NULL, &rmax)) goto out;
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
