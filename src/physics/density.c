/* Number density delta_i (PF Eq. 23), fluid and boundary neighbours. */
#include "physics/density.h"

/* cnt: NULL, or where to count each particle's fluid neighbours j != i within h (the lists'
 * counts, src/core/nlist.h): the walk is the density's own, so counting costs a compare. */
static inline void number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                                  const pfsph_real *z, pfsph_real *nd, uint32_t *cnt)
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
        uint32_t c = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 < h2) {
                    s += pfsph_kernel_w(k, pfsph_sqrt(r2));
                    c++;
                }
            }
        if (cnt) cnt[i] = c - 1; /* less i itself */
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

void pfsph__number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                           const pfsph_real *z, pfsph_real *nd)
{
    number_density(ctx, x, y, z, nd, NULL);
}

void pfsph__number_density_count(const pfsph_ctx *ctx, pfsph_real *nd, uint32_t *cnt)
{
    const pfsph_particles *f = ctx->fluid;
    number_density(ctx, f->x, f->y, f->z, nd, cnt);
}

void pfsph__number_density_rate(const pfsph_ctx *ctx, const pfsph_real *vx, const pfsph_real *vy,
                                const pfsph_real *vz, pfsph_real *rate)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = f->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        pfsph_ranges r;
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        const pfsph_real vxi = vx[i], vyi = vy[i], vzi = vz[i];
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        pfsph_real s = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2 || j == i) continue;
                pfsph_real vd = (vxi - vx[j]) * dx + (vyi - vy[j]) * dy + (vzi - vz[j]) * dz;
                s += vd * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
            }
        if (b->n) {
            pfsph_real sb = 0;
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2) continue;
                    pfsph_real vd = (vxi - b->vx[j]) * dx + (vyi - b->vy[j]) * dy + (vzi - b->vz[j]) * dz;
                    sb += b->aux[j] * vd * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                }
            s += sb * inv_v0;
        }
        rate[i] = s;
    }
}
