/* Pressure acceleration (PF Eq. 4 in the number-density form of Solenthaler & Pajarola
 * 2008) with the Akinci 2012 boundary term. */
#include "physics/pressure.h"

#include "core/hits.h"
#include "physics/pair_terms.h"

void pfsph__pressure_accel(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y, const pfsph_real *z,
                           const pfsph_real *nd, const pfsph_real *p, pfsph_real *apx, pfsph_real *apy, pfsph_real *apz)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = f->n;
    const pfsph_hits_fn hits = pfsph_hits_select();
#pragma omp parallel
    {
        pfsph_hits H;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real xi = x[i], yi = y[i], zi = z[i];
            const pfsph_real pi = p[i] / (nd[i] * nd[i]);
            pfsph_real ax = 0, ay = 0, az = 0;
            pfsph_ranges r;
            pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
            /* the pairs within h of the grid walk, in its order: the same bits */
            PFSPH_HITS_WALK(
                hits, &H, r, x, y, z, xi, yi, zi, h2, (uint32_t)i, pfsph__terms_dwr(k, H.n, H.r2, H.t0);
                for (int e = 0; e < H.n; e++) {
                    const uint32_t j = H.j[e];
                    pfsph_real s = (pi + p[j] / (nd[j] * nd[j])) * H.t0[e];
                    ax += s * H.dx[e];
                    ay += s * H.dy[e];
                    az += s * H.dz[e];
                });
            if (b->n && pi > 0) {
                pfsph_real bx = 0, by = 0, bz = 0;
                /* with pair forces most of the bulk is under pressure, far from any wall: the
                 * empty walk was 20 % of this pass (docs/benchmarks.md) */
                if (pfsph_grid_near(ctx->bgrid, xi, yi, zi)) {
                    pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
                    PFSPH_HITS_WALK(
                        hits, &H, r, b->x, b->y, b->z, xi, yi, zi, h2, UINT32_MAX, pfsph__terms_dwr(k, H.n, H.r2, H.t0);
                        for (int e = 0; e < H.n; e++) {
                            pfsph_real s = b->aux[H.j[e]] * H.t0[e];
                            bx += s * H.dx[e];
                            by += s * H.dy[e];
                            bz += s * H.dz[e];
                        });
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
}
