/* Gravity plus Morris 1997 viscosity, with Akinci 2012 wall friction (per solid: no slip with
 * the fluid's or the solid's own viscosity, or free slip). */
#include "physics/viscosity.h"

void pfsph__nonpressure(const pfsph_ctx *ctx)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h, eps = (pfsph_real)0.01 * h2;
    const pfsph_real gx = (pfsph_real)ctx->gravity[0],
                     gy = (pfsph_real)ctx->gravity[1],
                     gz = (pfsph_real)ctx->gravity[2];
    /* Morris et al. 1997 / SPlisHSPlasH "standard" viscosity: 2(d+2) nu sum_j (m_j/rho_j)
     * (v_ij . x_ij)/(|x_ij|^2 + 0.01 h^2) grad W_ij, with m_j/rho_j = 1/delta_j. */
    const pfsph_real visc_c = (pfsph_real)(2 * (ctx->dim + 2));
    const size_t n = f->n;
    const int mixed = ctx->nwalls > 1;
    const uint8_t *wall = b->wall;
    const pfsph_real *wall_scale = ctx->wall_scale, *wall_nu = ctx->wall_nu, wall_nu_max = ctx->wall_nu_max;
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
        /* Akinci 2012 boundary friction, with the fluid's own viscosity unless the solid
         * says otherwise (ctx wall tables: free slip, its own viscosity); static walls rest,
         * body particles move. With only default walls the table is skipped and the sum is
         * the one of a single viscosity, nui times the sum. */
        if (b->n && (nui > 0 || (mixed && wall_nu_max > 0))) {
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            pfsph_real bx = 0, by = 0, bz = 0;
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2) continue;
                    pfsph_real vdx = (vxi - b->vx[j]) * dx + (vyi - b->vy[j]) * dy + (vzi - b->vz[j]) * dz;
                    /* the boundary particle's volume V_b plays the role of m_j / rho_j */
                    pfsph_real s = b->aux[j] * vdx / (r2 + eps) * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                    if (mixed) s *= wall_scale[wall[j]] * nui + wall_nu[wall[j]];
                    bx += s * dx;
                    by += s * dy;
                    bz += s * dz;
                }
            const pfsph_real nub = mixed ? (pfsph_real)1 : nui;
            ax += nub * bx;
            ay += nub * by;
            az += nub * bz;
        }
        ctx->ax[i] = gx + visc_c * ax;
        ctx->ay[i] = gy + visc_c * ay;
        ctx->az[i] = gz + visc_c * az;
    }
}
