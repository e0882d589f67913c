/* Non-pressure accelerations: gravity and viscosity (fluid and walls). */
#ifndef PFSPH_VISCOSITY_H
#define PFSPH_VISCOSITY_H

#include "pfsph/ctx.h"

/* The kinematic viscosity of the Morris friction on a particle of phase a from one of phase b.
 * Within a phase nu_a, as 0.5 (nu_a + nu_a) was (the same bits). Across phases the dynamic
 * viscosity of the pair is the harmonic mean mu_ab = 2 mu_a mu_b / (mu_a + mu_b), mu = rho nu
 * (Morris et al. 1997 with Cleary's mean; Hu & Adams 2006), applied as mu_ab / rho_a with the
 * pair's mean number density (viscosity.c): the force on i, m_i mu_ab / rho_a 2 / (delta_i +
 * delta_j) = V0 mu_ab 2 / (delta_i + delta_j), and the reaction on j are equal and opposite to
 * round-off, so the pair conserves momentum and the interface carries the stress of two
 * viscosities in series. The
 * arithmetic mean of nu applied per particle gave a water-gas pair (rho 1000 / 100, mu 10 / 1)
 * a friction of mu 10 on the water and mu 1 on the gas (docs/validation.md, "Hysing case 1:
 * what holds the bubble back"). A phase without a rest density (a hand-made context) keeps the
 * arithmetic mean of nu. */
static inline pfsph_real pfsph__visc_pair_nu(const pfsph_ctx *c, int pa, int pb)
{
    if (pa == pb) return (pfsph_real)0.5 * (c->nu[pa] + c->nu[pb]);
    const double ra = (double)c->rest_density[pa], rb = (double)c->rest_density[pb];
    if (!(ra > 0 && rb > 0)) return (pfsph_real)0.5 * (c->nu[pa] + c->nu[pb]);
    const double ma = ra * (double)c->nu[pa], mb = rb * (double)c->nu[pb];
    return ma + mb > 0 ? (pfsph_real)(2 * ma * mb / (ma + mb) / ra) : 0;
}

/* The viscosity that the thermostat's noise (pfsph__thermo_fluid: nu 2 m_i m_j / (m_i delta_i +
 * m_j delta_j)) needs so that its friction is the pair's Morris friction (pfsph__visc_pair_nu
 * with 2 / (delta_i + delta_j), viscosity.c): within a phase 0.5 (nu_a + nu_b) in double as
 * before; across phases mu_ab (rho_a delta_i + rho_b delta_j) / (rho_a rho_b (delta_i +
 * delta_j)), whose friction is V0 mu_ab 2 / (delta_i + delta_j) (fluctuation-dissipation per
 * pair, exact since the friction itself takes the pair's mean delta). */
static inline double pfsph__visc_noise_nu(const pfsph_ctx *c, int pa, int pb, double ndi, double ndj)
{
    if (pa == pb) return 0.5 * ((double)c->nu[pa] + (double)c->nu[pb]);
    const double ra = (double)c->rest_density[pa], rb = (double)c->rest_density[pb];
    if (!(ra > 0 && rb > 0)) return 0.5 * ((double)c->nu[pa] + (double)c->nu[pb]);
    const double ma = ra * (double)c->nu[pa], mb = rb * (double)c->nu[pb];
    if (!(ma + mb > 0)) return 0;
    return 2 * ma * mb / (ma + mb) * (ra * ndi + rb * ndj) / (ra * rb * (ndi + ndj));
}

/* ctx->ax.. = gravity + viscosity (fluid-fluid and fluid-boundary). */
void pfsph__nonpressure(const pfsph_ctx *ctx);
/* The same plus the thermostat's random forces (pfsph_thermostat_apply, same bits), stored
 * alone in noise[0..2] as accelerations; without a temperature the plain pass. */
void pfsph__nonpressure_thermo(const pfsph_ctx *ctx, pfsph_real *const noise[3]);

/* ctx->ax.. as pfsph__nonpressure_thermo (noise may be NULL: no thermostat) and, in the same
 * neighbour walk, the pressure acceleration of pfsph__pressure_accel at the fluid's positions
 * from ctx->nd and the pressure p into ap[0..2]: for a solver whose pressure follows from the
 * density alone (WCSPH). The same bits as the separate passes. */
void pfsph__forces_and_pressure(const pfsph_ctx *ctx, pfsph_real *const noise[3], const pfsph_real *p,
                                pfsph_real *const ap[3]);

#endif
