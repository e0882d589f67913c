/* Non-pressure accelerations: gravity and viscosity (fluid and walls). */
#ifndef PFSPH_VISCOSITY_H
#define PFSPH_VISCOSITY_H

#include "pfsph/ctx.h"

/* ctx->ax.. = gravity + viscosity (fluid-fluid and fluid-boundary). */
void pfsph__nonpressure(const pfsph_ctx *ctx);
/* The same plus the thermostat's random forces (pfsph_thermostat_apply, same bits), stored
 * alone in noise[0..2] as accelerations; without a temperature the plain pass. */
void pfsph__nonpressure_thermo(const pfsph_ctx *ctx, pfsph_real *const noise[3]);

#endif
