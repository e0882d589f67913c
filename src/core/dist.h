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

/* Whether this process computes what belongs to the point (x, y, z) (a boundary particle): the
 * rank that owns its grid cell (clamped into the grid), whose held fluid covers the point's
 * walks; always in a serial run. */
static inline int pfsph__owns_point(const pfsph_ctx *c, pfsph_real x, pfsph_real y, pfsph_real z)
{
    if (!c->dist) return 1;
    const pfsph_grid *g = c->grid;
    const pfsph_real p[3] = {x, y, z};
    size_t key = 0, stride = 1;
    for (int a = 0; a < g->dim; a++) {
        const pfsph_real t = (p[a] - g->lo[a]) * g->inv_cell;
        const int ca = !(t >= 0) ? 0 : t >= (pfsph_real)g->nc[a] ? g->nc[a] - 1 : (int)t;
        key += (size_t)ca * stride;
        stride *= (size_t)g->nc[a];
    }
    return key >= c->dist->cell_lo && key < c->dist->cell_hi;
}

/* v[0, n) whose entries each process computed for the points it owns (pfsph__owns_point) and
 * left +0 elsewhere: every entry from the process that computed it (serial: as they are). */
static inline void pfsph__merge(const pfsph_ctx *c, double *v, size_t n)
{
    if (c->dist) c->dist->merge(c->dist, v, n);
}

/* The halo copies of k per-fluid-particle arrays refreshed from their owners (serial: nothing). */
static inline void pfsph__halo(const pfsph_ctx *c, pfsph_real *const *a, int k)
{
    if (c->dist) c->dist->halo(c->dist, a, k);
}

#endif
