/* 2D: the outline of a liquid as closed polylines (pfsph_surface_contour2d, surface_mesh.h;
 * docs/surfaces.md#2d-contours). The surface reconstruction's method in the plane: weighted PCA
 * over the neighbourhood (2 x 2), smoothed centres, clamped anisotropy, a cubic-spline
 * volume-fraction field with the iso-level calibrated on a flat lattice slab, on a dense grid of
 * nodes over the kernels' reach (2D grids are small), and marching triangles: each square split
 * along its diagonal, so that the contour of the piecewise-linear field is a set of closed curves
 * with no ambiguous case. Serial and in particle order: the same bytes for any thread count. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/surface_mesh_internal.h"
#include "pfsph/eigen.h"

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
    /* cleared: gcc 12 at -O1 cannot see that n = 0 leaves nothing to read (-Wmaybe-uninitialized) */
    int32_t *cell = calloc(3 * (n ? n : 1), sizeof *cell);
    if (!cell) return PFSPH_ENOMEM;
    for (size_t i = 0; i < n; i++) {
        cell[3 * i] = (int32_t)floor(x[3 * i] / r);
        cell[3 * i + 1] = (int32_t)floor(x[3 * i + 1] / r);
        cell[3 * i + 2] = 0;
    }
    grid g;
    int rc = pfsph__surface_grid_build(&g, cell, n);
    if (rc) {
        free(cell);
        pfsph__surface_grid_free(&g);
        return rc;
    }
    for (size_t i = 0; i < n; i++) {
        const double *xi = x + 3 * i;
        double sw = 0, mu[2] = {0, 0}, S[3] = {0, 0, 0};
        int cnt = 0;
        for (int64_t a = cell[3 * i] - 1; a <= cell[3 * i] + 1; a++)
            for (int64_t b = cell[3 * i + 1] - 1; b <= cell[3 * i + 1] + 1; b++) {
                uint32_t s, e;
                pfsph__surface_grid_col(&g, a, b, 0, 0, &s, &e);
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
    pfsph__surface_grid_free(&g);
    return PFSPH_OK;
}

double pfsph_surface_calibrate_iso2d(const pfsph_surface_opts *in)
{
    pfsph_surface_opts o;
    pfsph__surface_resolve(in, &o);
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
    int rc0 = pfsph__surface_resolve_checked(in, false, &o, err);
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
