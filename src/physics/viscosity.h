/* Non-pressure accelerations: gravity and viscosity (fluid and walls). */
#ifndef PFSPH_VISCOSITY_H
#define PFSPH_VISCOSITY_H

#include "pfsph/ctx.h"

/* ctx->ax.. = gravity + viscosity (fluid-fluid and fluid-boundary). */
void pfsph__nonpressure(const pfsph_ctx *ctx);

#endif
