/* Particle shifting: Fick's law for the particle concentration (Lind et al. 2012, "Incompressible
 * smoothed particle hydrodynamics for free-surface flows: a generalised diffusion-based
 * algorithm for stability and validations"; Skillen et al. 2013), the anti-clumping weight
 * 1 + R (W_ij / W(d))^4, R = 0.2 (Monaghan 2000, used in Lind 2012 and Sun et al. 2017), and the
 * free-surface correction of Lind 2012: a particle at the free surface keeps only the tangential
 * part of its shift. Docs: docs/pairwise.md, "Particle shifting". */
#include "pfsph/shifting.h"

#include <math.h>

#define ANTI_CLUMP_R 0.2

/* C_i and grad C_i (anti-clumping weighted) of fluid particle i at (xi, yi, zi); if nk is
 * not NULL, also the gradient of the concentration over nk's (wider) support in gn[3], whose
 * direction is the surface normal (inwards). */
static double concentration(const pfsph_ctx *ctx, size_t i, pfsph_real xi, pfsph_real yi, pfsph_real zi, double inv_wd,
                            double g[3], const pfsph_kernel *nk, double gn[3])
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_real n2 = nk ? nk->h * nk->h : 0;
    double nx = 0, ny = 0, nz = 0;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    double c = 0, gx = 0, gy = 0, gz = 0;
    pfsph_ranges r;
    for (int set = 0; set < 2; set++) {
        const pfsph_particles *ps = set ? b : f;
        if (!ps || ps->n == 0) continue;
        pfsph_grid_ranges_far(set ? ctx->bgrid : ctx->grid, xi, yi, zi, &r); /* h and k h */
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - ps->x[j], dy = yi - ps->y[j], dz = zi - ps->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (nk && r2 < n2 && r2 > 0) {
                    double V = set ? (double)ps->aux[j] : (double)ctx->V0;
                    double s = V * (double)pfsph_kernel_dw_r(nk, pfsph_sqrt(r2));
                    nx += s * dx;
                    ny += s * dy;
                    nz += s * dz;
                }
                if (r2 >= h2) continue;
                double V = set ? (double)ps->aux[j] : (double)ctx->V0;
                double rr = sqrt((double)r2);
                double w = (double)pfsph_kernel_w(k, (pfsph_real)rr);
                c += V * w;
                if (!set && (size_t)j == i) continue;
                if (r2 <= 0) continue;
                double t = w * inv_wd, t2 = t * t;
                double s = V * (1.0 + ANTI_CLUMP_R * t2 * t2) * (double)pfsph_kernel_dw_r(k, (pfsph_real)rr);
                gx += s * dx;
                gy += s * dy;
                gz += s * dz;
            }
    }
    g[0] = gx;
    g[1] = gy;
    g[2] = gz;
    if (gn) {
        gn[0] = nx;
        gn[1] = ny;
        gn[2] = nz;
    }
    return c;
}

double pfsph_shift_concentration(const pfsph_ctx *ctx, size_t i, double g[3])
{
    const pfsph_particles *f = ctx->fluid;
    double inv_wd = 1.0 / (double)pfsph_kernel_w(&ctx->kern, ctx->spacing);
    return concentration(ctx, i, f->x[i], f->y[i], f->z[i], inv_wd, g, NULL, NULL);
}

double pfsph_shift_apply(const pfsph_ctx *ctx, const pfsph_shift_params *p, double dt, double normal_radius,
                         pfsph_real *sx, pfsph_real *sy, pfsph_real *sz)
{
    pfsph_particles *f = ctx->fluid;
    const size_t n = f->n;
    if (!(p->D > 0 || p->A > 0) || !(dt > 0) || n == 0) return 0;
    const double Ah = p->A * (double)ctx->h;
    const double cap = p->max_frac * (double)ctx->spacing;
    const double inv_wd = 1.0 / (double)pfsph_kernel_w(&ctx->kern, ctx->spacing);
    pfsph_kernel nk;
    pfsph_kernel_init(&nk, ctx->dim, (pfsph_real)(normal_radius > (double)ctx->h ? normal_radius : (double)ctx->h));
    double smax = 0;
#pragma omp parallel for schedule(static) reduction(max : smax)
    for (size_t i = 0; i < n; i++) {
        double g[3], gw[3];
        double c = concentration(ctx, i, f->x[i], f->y[i], f->z[i], inv_wd, g, &nk, gw);
        double v = sqrt((double)f->vx[i] * f->vx[i] + (double)f->vy[i] * f->vy[i] + (double)f->vz[i] * f->vz[i]);
        double Ddt = (p->D + Ah * v) * dt;
        double s[3] = {-Ddt * g[0], -Ddt * g[1], -Ddt * g[2]};
        if (c < p->surface) {
            /* free surface: keep the tangential part of the shift only (Lind et al. 2012), or
             * the surface would be pushed out. The normal is the direction of the
             * concentration gradient over the wider support, which sees the surface and not
             * the particle's own displacement. */
            double gn = sqrt(gw[0] * gw[0] + gw[1] * gw[1] + gw[2] * gw[2]);
            if (gn > 0) {
                double nrm[3] = {gw[0] / gn, gw[1] / gn, gw[2] / gn};
                double sn = s[0] * nrm[0] + s[1] * nrm[1] + s[2] * nrm[2];
                for (int a = 0; a < 3; a++) s[a] -= sn * nrm[a];
            }
        }
        double sl = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        if (sl > cap) {
            for (int a = 0; a < 3; a++) s[a] *= cap / sl;
            sl = cap;
        }
        if (sl > smax) smax = sl;
        sx[i] = (pfsph_real)s[0];
        sy[i] = (pfsph_real)s[1];
        sz[i] = (pfsph_real)s[2];
    }
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        f->x[i] += sx[i];
        f->y[i] += sy[i];
        if (ctx->dim == 3) f->z[i] += sz[i];
    }
    return smax;
}
