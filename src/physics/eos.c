/* Tait equation of state (DF Eq. 3, NOTES item 12). */
#include "physics/eos.h"

#include <math.h>

void pfsph__tait(const pfsph_ctx *ctx, const pfsph_real *nd, double B, double gamma, double rho_common, pfsph_real *p)
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
        } else pw = pow(ratio, gamma);
        /* rho_common > 0: one pressure scale for all phases (scene.h, pfsph_pressure_scale) */
        double rho0 = rho_common > 0 ? rho_common : (double)ctx->rest_density[f->phase[i]];
        double pr = ratio > 1 ? B * rho0 * (pw - 1) : 0;
        p[i] = (pfsph_real)pr;
    }
}
