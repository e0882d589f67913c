/* The random half of a smoothed-DPD thermostat whose dissipative half is the Morris viscosity
 * and Akinci wall friction of viscosity.c (fluctuation-dissipation: sigma_ij^2 = 2 kT Gamma_ij). */
#include "pfsph/thermostat.h"

#include "physics/viscosity.h"

#include <math.h>

void pfsph_thermostat_apply(const pfsph_ctx *ctx, pfsph_real *const noise[3])
{
    const double amp = pfsph__thermo_amp(ctx);
    if (!(amp > 0)) return;
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h, eps = (pfsph_real)0.01 * h2;
    /* viscosity.c's friction between i and j, as a force: m_i visc_c nu_ij / n_j r^2 |W'/r| /
     * (r^2 + eps) times (v_ij . e_ij) e_ij, visc_c = 2 (d + 2). The noise amplitude is
     * sqrt(2 kT Gamma / dt); the 2 kT / dt and visc_c are folded into amp. */
    /* one thermal speed for all phases: phase a at kT rho_a / rho_ref, a pair at the colder
     * of the two (a gas by a liquid must not be shaken at the liquid's temperature) */
    double ts[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    for (int a = 0; a < ctx->nphases; a++)
        for (int b = 0; b < ctx->nphases; b++)
            ts[a][b] = fmin(pfsph_thermostat_scale(ctx, a), pfsph_thermostat_scale(ctx, b));
    const uint64_t key = pfsph_thermo_step_key(ctx->seed, ctx->step, 0);
    const uint64_t wkey = pfsph_thermo_step_key(ctx->seed, ctx->step, PFSPH_THERMO_SALT_WALL);
    const size_t n = f->n;
    const int mixed = ctx->nwalls > 1;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        const int pa = f->phase[i];
        const double mi = (double)ctx->mass[pa], nui = (double)ctx->nu[pa], ndi = (double)ctx->nd[i];
        const uint32_t idi = f->id[i];
        double fx = 0, fy = 0, fz = 0;
        pfsph_ranges r;
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2 || j == i || r2 <= 0) continue;
                const int pb = f->phase[j];
                double nu = pfsph__visc_noise_nu(ctx, pa, pb, ndi, (double)ctx->nd[j]);
                if (!(nu > 0)) continue;
                double rr = sqrt((double)r2);
                double s = pfsph__thermo_fluid(amp * ts[pa][pb], nu, mi, (double)ctx->mass[pb], ndi, (double)ctx->nd[j],
                                               (double)r2, (double)pfsph_kernel_dw_r(k, (pfsph_real)rr), (double)eps,
                                               rr, pfsph_thermo_theta(key, idi, f->id[j]));
                fx += s * (double)dx;
                fy += s * (double)dy;
                fz += s * (double)dz;
            }
        if (b->n && (nui > 0 || (mixed && ctx->wall_nu_max > 0))) {
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2 || r2 <= 0) continue;
                    double rr = sqrt((double)r2);
                    /* nu_w: the wall's friction viscosity (viscosity.c: free slip 0, no slip nu_i
                     * or the solid's own) */
                    const double nuw =
                        mixed ? (double)ctx->wall_scale[b->wall[j]] * nui + (double)ctx->wall_nu[b->wall[j]] : nui;
                    double s = pfsph__thermo_wall(amp * ts[pa][pa], nuw, mi, (double)b->aux[j], (double)r2,
                                                  (double)pfsph_kernel_dw_r(k, (pfsph_real)rr), (double)eps, rr,
                                                  pfsph_thermo_theta(wkey, idi, b->id[j]));
                    fx += s * (double)dx;
                    fy += s * (double)dy;
                    fz += s * (double)dz;
                }
        }
        const pfsph_real nx = (pfsph_real)(fx / mi), ny = (pfsph_real)(fy / mi), nz = (pfsph_real)(fz / mi);
        noise[0][i] = nx;
        noise[1][i] = ny;
        noise[2][i] = nz;
        ctx->ax[i] += nx;
        ctx->ay[i] += ny;
        ctx->az[i] += nz;
    }
}

/* The two passes of the measure, each over [lo, hi) and continuing the running sums of the
 * particles before lo: a distributed run hands them on from rank to rank in the global order,
 * which gives the serial sums' bits (src/mpi/gather.c). */
void pfsph__thermostat_moments(const pfsph_particles *f, const pfsph_real *mass, size_t lo, size_t hi, double acc[4])
{
    double M = acc[0], P[3] = {acc[1], acc[2], acc[3]};
    for (size_t i = lo; i < hi; i++) {
        double m = (double)mass[f->phase[i]];
        M += m;
        P[0] += m * f->vx[i];
        P[1] += m * f->vy[i];
        P[2] += m * f->vz[i];
    }
    acc[0] = M;
    acc[1] = P[0];
    acc[2] = P[1];
    acc[3] = P[2];
}

double pfsph__thermostat_spread(const pfsph_particles *f, const pfsph_real *mass, int dim, size_t lo, size_t hi,
                                const double vc[3], double e)
{
    for (size_t i = lo; i < hi; i++) {
        double m = (double)mass[f->phase[i]];
        double ux = f->vx[i] - vc[0], uy = f->vy[i] - vc[1], uz = dim == 3 ? f->vz[i] - vc[2] : 0;
        e += m * (ux * ux + uy * uy + uz * uz);
    }
    return e;
}

double pfsph_thermostat_measure(const pfsph_particles *f, const pfsph_real *mass, int dim)
{
    const size_t n = f->n;
    if (n < 2) return 0;
    double acc[4] = {0, 0, 0, 0};
    pfsph__thermostat_moments(f, mass, 0, n, acc);
    const double vc[3] = {acc[1] / acc[0], acc[2] / acc[0], acc[3] / acc[0]};
    return pfsph__thermostat_spread(f, mass, dim, 0, n, vc, 0) / ((double)dim * (double)(n - 1));
}
