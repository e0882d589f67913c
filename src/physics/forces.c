/* Non-pressure forces (gravity, viscosity) and the pressure acceleration. */
#include "stages.h"

void pfsph__nonpressure(const pfsph_ctx *ctx)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h, eps = (pfsph_real)0.01 * h2;
    const pfsph_real gx = (pfsph_real)ctx->scene->gravity[0],
                     gy = (pfsph_real)ctx->scene->gravity[1],
                     gz = (pfsph_real)ctx->scene->gravity[2];
    /* Morris et al. 1997 / SPlisHSPlasH "standard" viscosity: 2(d+2) nu sum_j (m_j/rho_j)
     * (v_ij . x_ij)/(|x_ij|^2 + 0.01 h^2) grad W_ij, with m_j/rho_j = 1/delta_j. */
    const pfsph_real visc_c = (pfsph_real)(2 * (ctx->dim + 2));
    const size_t n = f->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        const pfsph_real vxi = f->vx[i], vyi = f->vy[i], vzi = f->vz[i];
        const pfsph_real nui = ctx->nu[f->phase[i]];
        pfsph_real ax = 0, ay = 0, az = 0;
        pfsph_ranges r;
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2 || j == i) continue;
                pfsph_real nu = (pfsph_real)0.5 * (nui + ctx->nu[f->phase[j]]);
                pfsph_real vdx = (vxi - f->vx[j]) * dx + (vyi - f->vy[j]) * dy + (vzi - f->vz[j]) * dz;
                pfsph_real s = nu / ctx->nd[j] * vdx / (r2 + eps) * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                ax += s * dx;
                ay += s * dy;
                az += s * dz;
            }
        if (b->n && nui > 0) {
            /* Akinci 2012 boundary friction with the fluid's own viscosity (static walls) */
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            pfsph_real bx = 0, by = 0, bz = 0;
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2) continue;
                    /* relative to the wall: static walls rest, body particles move */
                    pfsph_real vdx = (vxi - b->vx[j]) * dx + (vyi - b->vy[j]) * dy + (vzi - b->vz[j]) * dz;
                    pfsph_real s = b->aux[j] * vdx / (r2 + eps) * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                    bx += s * dx;
                    by += s * dy;
                    bz += s * dz;
                }
            /* the boundary particle's volume V_b plays the role of m_j / rho_j */
            ax += nui * bx;
            ay += nui * by;
            az += nui * bz;
        }
        ctx->ax[i] = gx + visc_c * ax;
        ctx->ay[i] = gy + visc_c * ay;
        ctx->az[i] = gz + visc_c * az;
    }
}

void pfsph__pressure_accel(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                           const pfsph_real *z, const pfsph_real *nd, const pfsph_real *p,
                           pfsph_real *apx, pfsph_real *apy, pfsph_real *apz)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = f->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        const pfsph_real xi = x[i], yi = y[i], zi = z[i];
        const pfsph_real pi = p[i] / (nd[i] * nd[i]);
        pfsph_real ax = 0, ay = 0, az = 0;
        pfsph_ranges r;
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2 || j == i) continue;
                pfsph_real s = (pi + p[j] / (nd[j] * nd[j])) * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                ax += s * dx;
                ay += s * dy;
                az += s * dz;
            }
        if (b->n && pi > 0) {
            pfsph_real bx = 0, by = 0, bz = 0;
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2) continue;
                    pfsph_real s = b->aux[j] * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                    bx += s * dx;
                    by += s * dy;
                    bz += s * dz;
                }
            /* Akinci 2012: the wall pushes with p_i alone. Mirroring (2 p_i) was tried: it
             * pumps energy into a WCSPH tank at rest (kinetic energy x100 in 0.3 s). */
            const pfsph_real wb = pi * inv_v0;
            ax += wb * bx;
            ay += wb * by;
            az += wb * bz;
        }
        const pfsph_real inv_m = -(pfsph_real)1 / ctx->mass[f->phase[i]];
        apx[i] = inv_m * ax;
        apy[i] = inv_m * ay;
        apz[i] = inv_m * az;
    }
}

void pfsph__tait(const pfsph_ctx *ctx, const pfsph_real *nd, double B, double gamma,
                 double rho_common, pfsph_real *p)
{
    const pfsph_particles *f = ctx->fluid;
    const double inv_nd0 = 1.0 / (double)ctx->nd0;
    const size_t n = f->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        double ratio = (double)nd[i] * inv_nd0;
        double pw;
        if (gamma == 7) {
            double r2 = ratio * ratio, r4 = r2 * r2;
            pw = r4 * r2 * ratio;
        } else
            pw = pow(ratio, gamma);
        /* rho_common > 0: one pressure scale for all phases (scene.h, pfsph_pressure_scale) */
        double rho0 = rho_common > 0 ? rho_common : (double)ctx->rest_density[f->phase[i]];
        double pr = ratio > 1 ? B * rho0 * (pw - 1) : 0;
        p[i] = (pfsph_real)pr;
    }
}
