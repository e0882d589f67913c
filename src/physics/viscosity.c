/* Gravity plus Morris 1997 viscosity, with Akinci 2012 wall friction (per solid: no slip with
 * the fluid's or the solid's own viscosity, or free slip). */
#include "physics/viscosity.h"

#include "core/nlist.h"
#include "pfsph/thermostat.h"

/* particle i as its fluid pairs see it */
typedef struct visc_i {
    pfsph_real x, y, z, vx, vy, vz, nu;
    double m, nd;
    uint32_t id;
    int phase;
} visc_i;

typedef struct visc_acc {
    pfsph_real ax, ay, az; /* viscosity sum */
    double fx, fy, fz;     /* thermostat */
} visc_acc;

/* Fluid neighbour j's Morris viscosity term (and with thermo its thermostat force) on i, added
 * to acc; x_ij = (dx, dy, dz), r2 = |x_ij|^2 < h^2, dwr = pfsph_kernel_dw_r(|x_ij|). */
static inline void visc_pair(const pfsph_ctx *ctx, const visc_i *I, uint32_t j, pfsph_real dx, pfsph_real dy,
                             pfsph_real dz, pfsph_real r2, pfsph_real dwr, pfsph_real eps, const int thermo,
                             double amp, const double ts[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES], uint64_t key,
                             visc_acc *acc)
{
    const pfsph_particles *f = ctx->fluid;
    pfsph_real nu = (pfsph_real)0.5 * (I->nu + ctx->nu[f->phase[j]]);
    pfsph_real vdx = (I->vx - f->vx[j]) * dx + (I->vy - f->vy[j]) * dy + (I->vz - f->vz[j]) * dz;
    pfsph_real s = nu / ctx->nd[j] * vdx / (r2 + eps) * dwr;
    acc->ax += s * dx;
    acc->ay += s * dy;
    acc->az += s * dz;
    if (thermo) {
        const int pb = f->phase[j];
        const double nud = 0.5 * ((double)I->nu + (double)ctx->nu[pb]);
        if (nud > 0 && r2 > 0) {
            const double rd = sqrt((double)r2);
            /* dwr, not dw_r((real) rd): (real) sqrt((double) r2) is pfsph_sqrt(r2), so the same bits */
            const double t = pfsph__thermo_fluid(amp * ts[I->phase][pb], nud, I->m, (double)ctx->mass[pb], I->nd,
                                                 (double)ctx->nd[j], (double)r2, (double)dwr, (double)eps, rd,
                                                 pfsph_thermo_theta(key, I->id, f->id[j]));
            acc->fx += t * (double)dx;
            acc->fy += t * (double)dy;
            acc->fz += t * (double)dz;
        }
    }
}

/* Boundary particle j's Akinci 2012 friction term on i (and with thermo the thermostat's wall
 * force, of amplitude ampw), added to acc; x_ij = (dx, dy, dz), r2 < h^2, dwr its kernel
 * derivative. The friction sum is scaled by the fluid's viscosity by the caller unless the
 * wall table is in use (ctx.h). */
static inline void wall_pair(const pfsph_ctx *ctx, const visc_i *I, uint32_t j, pfsph_real dx, pfsph_real dy,
                             pfsph_real dz, pfsph_real r2, pfsph_real dwr, pfsph_real eps, const int thermo, double ampw,
                             uint64_t wkey, visc_acc *acc)
{
    const pfsph_particles *b = ctx->boundary;
    const int mixed = ctx->nwalls > 1;
    pfsph_real vdx = (I->vx - b->vx[j]) * dx + (I->vy - b->vy[j]) * dy + (I->vz - b->vz[j]) * dz;
    /* the boundary particle's volume V_b plays the role of m_j / rho_j */
    pfsph_real s = b->aux[j] * vdx / (r2 + eps) * dwr;
    if (mixed) s *= ctx->wall_scale[b->wall[j]] * I->nu + ctx->wall_nu[b->wall[j]];
    acc->ax += s * dx;
    acc->ay += s * dy;
    acc->az += s * dz;
    if (thermo && r2 > 0) {
        const double rd = sqrt((double)r2);
        const double nuw = mixed ? (double)ctx->wall_scale[b->wall[j]] * (double)I->nu + (double)ctx->wall_nu[b->wall[j]]
                                 : (double)I->nu;
        /* dwr, not dw_r((real) rd): (real) sqrt((double) r2) is pfsph_sqrt(r2), so the same bits */
        const double t = pfsph__thermo_wall(ampw, nuw, I->m, (double)b->aux[j], (double)r2, (double)dwr, (double)eps, rd,
                                            pfsph_thermo_theta(wkey, I->id, b->id[j]));
        acc->fx += t * (double)dx;
        acc->fy += t * (double)dy;
        acc->fz += t * (double)dz;
    }
}

/* thermo: also the thermostat's random forces (thermostat.h), fused into this pass so that the
 * neighbours within h are walked once; the same expressions as pfsph_thermostat_apply, so the
 * same bits. Specialised at compile time (two call sites with a constant). */
static inline void nonpressure(const pfsph_ctx *ctx, pfsph_real *const noise[3], const int thermo)
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
    const pfsph_nlist *nl = ctx->nlist, *bl = ctx->nlist_b; /* the step's lists, when the solver built them */
    const pfsph_real wall_nu_max = ctx->wall_nu_max;
    double amp = 0, ts[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    uint64_t key = 0, wkey = 0;
    if (thermo) {
        amp = pfsph__thermo_amp(ctx);
        for (int a = 0; a < ctx->nphases; a++)
            for (int c = 0; c < ctx->nphases; c++)
                ts[a][c] = fmin(pfsph_thermostat_scale(ctx, a), pfsph_thermostat_scale(ctx, c));
        key = pfsph_thermo_step_key(ctx->seed, ctx->step, 0);
        wkey = pfsph_thermo_step_key(ctx->seed, ctx->step, PFSPH_THERMO_SALT_WALL);
    }
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        const pfsph_real vxi = f->vx[i], vyi = f->vy[i], vzi = f->vz[i];
        const int pa = f->phase[i];
        const pfsph_real nui = ctx->nu[pa];
        const double mi = (double)ctx->mass[pa], ndi = thermo ? (double)ctx->nd[i] : 0;
        const uint32_t idi = f->id[i];
        double fx = 0, fy = 0, fz = 0; /* thermostat */
        pfsph_real ax = 0, ay = 0, az = 0;
        pfsph_ranges r;
        /* the same terms in the same order from a list or a grid walk: the same bits */
        const visc_i vi = {xi, yi, zi, vxi, vyi, vzi, nui, mi, ndi, idi, pa};
        visc_acc acc = {0, 0, 0, 0, 0, 0};
        if (nl) {
            for (uint32_t e = nl->start[i]; e < nl->start[i + 1]; e++) {
                const uint32_t j = nl->idx[e];
                pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                visc_pair(ctx, &vi, j, dx, dy, dz, dx * dx + dy * dy + dz * dz, nl->dw[e], eps, thermo, amp, ts, key,
                          &acc);
            }
        } else {
            pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2 || j == i) continue;
                    visc_pair(ctx, &vi, j, dx, dy, dz, r2, pfsph_kernel_dw_r(k, pfsph_sqrt(r2)), eps, thermo, amp, ts,
                              key, &acc);
                }
        }
        ax = acc.ax, ay = acc.ay, az = acc.az, fx = acc.fx, fy = acc.fy, fz = acc.fz;
        /* Akinci 2012 boundary friction, with the fluid's own viscosity unless the solid
         * says otherwise (ctx wall tables: free slip, its own viscosity); static walls rest,
         * body particles move. With only default walls the table is skipped and the sum is
         * the one of a single viscosity, nui times the sum. */
        if (b->n && (nui > 0 || (mixed && wall_nu_max > 0))) {
            /* the same terms in the same order from the step's boundary list or a grid walk */
            visc_acc w = {0, 0, 0, fx, fy, fz};
            const double ampw = thermo ? amp * ts[pa][pa] : 0;
            if (bl) {
                for (uint32_t e = bl->start[i]; e < bl->start[i + 1]; e++) {
                    const uint32_t j = bl->idx[e];
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    wall_pair(ctx, &vi, j, dx, dy, dz, dx * dx + dy * dy + dz * dz, bl->dw[e], eps, thermo, ampw, wkey,
                              &w);
                }
            } else {
                pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
                for (int q = 0; q < r.n; q++)
                    for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                        pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                        pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                        if (r2 >= h2) continue;
                        wall_pair(ctx, &vi, j, dx, dy, dz, r2, pfsph_kernel_dw_r(k, pfsph_sqrt(r2)), eps, thermo, ampw,
                                  wkey, &w);
                    }
            }
            fx = w.fx, fy = w.fy, fz = w.fz;
            const pfsph_real nub = mixed ? (pfsph_real)1 : nui;
            ax += nub * w.ax;
            ay += nub * w.ay;
            az += nub * w.az;
        }
        ctx->ax[i] = gx + visc_c * ax;
        ctx->ay[i] = gy + visc_c * ay;
        ctx->az[i] = gz + visc_c * az;
        if (thermo) {
            const pfsph_real nx = (pfsph_real)(fx / mi), ny = (pfsph_real)(fy / mi), nz = (pfsph_real)(fz / mi);
            noise[0][i] = nx;
            noise[1][i] = ny;
            noise[2][i] = nz;
            ctx->ax[i] += nx;
            ctx->ay[i] += ny;
            ctx->az[i] += nz;
        }
    }
}

void pfsph__nonpressure(const pfsph_ctx *ctx) { nonpressure(ctx, NULL, 0); }

void pfsph__nonpressure_thermo(const pfsph_ctx *ctx, pfsph_real *const noise[3])
{
    if (pfsph_thermostat_kT(ctx) > 0 && ctx->dt > 0) nonpressure(ctx, noise, 1);
    else nonpressure(ctx, NULL, 0);
}
