/* Non-pressure accelerations: gravity and viscosity (fluid and walls). */
#ifndef PFSPH_VISCOSITY_H
#define PFSPH_VISCOSITY_H

#include "pfsph/ctx.h"

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
