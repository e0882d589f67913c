/* Number density and Akinci boundary volumes. */
#include "stages.h"

void pfsph__boundary_volumes(pfsph_particles *b, const pfsph_grid *bg, const pfsph_kernel *k)
{
    const pfsph_real h2 = k->h * k->h;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < b->n; i++) {
        if (b->aux[i] > 0) continue; /* volume given (multi-layer walls) */
        pfsph_ranges r;
        pfsph_grid_ranges(bg, b->x[i], b->y[i], b->z[i], &r);
        double s = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = b->x[i] - b->x[j], dy = b->y[i] - b->y[j], dz = b->z[i] - b->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 < h2) s += pfsph_kernel_w(k, pfsph_sqrt(r2));
            }
        b->aux[i] = (pfsph_real)(1.0 / s);
    }
}

void pfsph__number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                           const pfsph_real *z, pfsph_real *nd)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_particles *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = ctx->fluid->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        pfsph_ranges r;
        const pfsph_real xi = x[i], yi = y[i], zi = z[i];
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        pfsph_real s = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 < h2) s += pfsph_kernel_w(k, pfsph_sqrt(r2));
            }
        if (b->n) {
            pfsph_real sb = 0;
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 < h2) sb += b->aux[j] * pfsph_kernel_w(k, pfsph_sqrt(r2));
                }
            s += sb * inv_v0;
        }
        nd[i] = s;
    }
}

double pfsph__sum(const pfsph_real *a, size_t n)
{
    enum { BLOCK = 4096 };
    size_t nb = (n + BLOCK - 1) / BLOCK;
    double total = 0;
    /* Small fixed-size stack buffer of partials per chunk of blocks keeps this allocation free. */
    enum { CHUNK = 256 };
    double part[CHUNK];
    for (size_t b0 = 0; b0 < nb; b0 += CHUNK) {
        size_t b1 = b0 + CHUNK < nb ? b0 + CHUNK : nb;
#pragma omp parallel for schedule(static)
        for (size_t b = b0; b < b1; b++) {
            size_t lo = b * BLOCK, hi = lo + BLOCK < n ? lo + BLOCK : n;
            double s = 0;
            for (size_t i = lo; i < hi; i++) s += (double)a[i];
            part[b - b0] = s;
        }
        for (size_t b = b0; b < b1; b++) total += part[b - b0];
    }
    return total;
}

double pfsph__pcisph_prototype(const pfsph_kernel *k, int dim, pfsph_real spacing)
{
    double gs[3] = {0, 0, 0}, gg = 0;
    int m = (int)(k->h / spacing) + 1;
    int mz = dim == 3 ? m : 0;
    for (int a = -m; a <= m; a++)
        for (int b = -m; b <= m; b++)
            for (int c = -mz; c <= mz; c++) {
                double dx = -a * (double)spacing, dy = -b * (double)spacing,
                       dz = -c * (double)spacing;
                double r = sqrt(dx * dx + dy * dy + dz * dz);
                if (r <= 0 || r >= k->h) continue;
                double f = pfsph_kernel_dw_r(k, (pfsph_real)r);
                double g[3] = {f * dx, f * dy, f * dz};
                for (int t = 0; t < 3; t++) gs[t] += g[t];
                gg += g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
            }
    return gs[0] * gs[0] + gs[1] * gs[1] + gs[2] * gs[2] + gg;
}
