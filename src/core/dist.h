/* The step's view of a distributed run (pfsph/dist.h): the owned range, global sums, halo
 * refreshes. Without a decomposition each helper is exactly the serial code. */
#ifndef PFSPH_CORE_DIST_H
#define PFSPH_CORE_DIST_H

#include "core/reduce.h"
#include "pfsph/ctx.h"
#include "pfsph/dist.h"

/* The fluid indices this process owns: all of them in a serial run. */
static inline void pfsph__owned(const pfsph_ctx *c, size_t *lo, size_t *hi)
{
    *lo = c->dist ? c->dist->own_lo : 0;
    *hi = c->dist ? c->dist->own_hi : c->fluid->n;
}

/* Fluid particles of the whole run. */
static inline size_t pfsph__fluid_count(const pfsph_ctx *c) { return c->dist ? c->dist->nglobal : c->fluid->n; }

/* pfsph__sum over the whole run's fluid (a per fluid particle). */
static inline double pfsph__fluid_sum(const pfsph_ctx *c, const pfsph_real *a)
{
    return c->dist ? c->dist->sum(c->dist, a) : pfsph__sum(a, c->fluid->n);
}

/* k counters of the owned particles summed over the whole run (serial: as they are). */
static inline void pfsph__count_sum(const pfsph_ctx *c, long *v, int k)
{
    if (c->dist) c->dist->count(c->dist, v, k);
}

/* The halo copies of k per-fluid-particle arrays refreshed from their owners (serial: nothing). */
static inline void pfsph__halo(const pfsph_ctx *c, pfsph_real *const *a, int k)
{
    if (c->dist) c->dist->halo(c->dist, a, k);
}

#endif
