/* Uniform-grid neighbour search. A dense grid over the scene domain; particles are sorted by
 * cell (counting sort, row-major cell order, x fastest) and the particle arrays permuted into
 * that order, so that the three cells of a row along x form one contiguous index range: a
 * neighbour query is 3 ranges in 2D and 9 in 3D, walked in memory order. The cell size is the
 * largest radius in use (k*h with pairwise forces), so both h and k*h queries use one grid;
 * callers filter by distance. */
#ifndef PFSPH_GRID_H
#define PFSPH_GRID_H

#include <math.h>

#include "pfsph/particles.h"

typedef struct pfsph_grid {
    int dim;
    pfsph_real lo[3], hi[3];           /* extent of the cells [m] */
    pfsph_real keep_lo[3], keep_hi[3]; /* particles outside this box are removed by sort
                                        * (defaults to the cell extent) */
    pfsph_real cell, inv_cell;
    int reach;     /* a query walks reach cells each way: it covers reach * cell (h) */
    int reach_far; /* the same for the far queries (k h of the pair forces), <= 3 */
    int nc[3];     /* cells per axis (nc[2] == 1 in 2D) */
    size_t ncells;
    uint32_t *start;   /* ncells + 1 entries: cell c holds [start[c], start[c+1]) */
    uint32_t *key;     /* scratch, per particle */
    uint32_t *perm;    /* scratch, per particle */
    void *tmp;         /* scratch for the permutation */
    int want_near;     /* set by the owner: pfsph_grid_sort fills near */
    uint8_t *near;     /* ncells entries (or NULL): 0 iff no cell within reach of c holds a
                         * particle (pfsph_grid_near) */
    uint8_t *near_far; /* the same for reach_far (pfsph_grid_near_far), when reach_far > reach */
    size_t cap;
} pfsph_grid;

typedef struct pfsph_ranges {
    uint32_t b[49], e[49]; /* (2 reach + 1)^(dim - 1) rows, reach <= 3 */
    int n;
} pfsph_ranges;

/* Grid over [lo, hi] with cells of edge `cell`; queries reach one cell each way (set
 * g->reach = 2 after init for cells of half the query radius). */
int pfsph_grid_init(pfsph_grid *g, int dim, const pfsph_real lo[3], const pfsph_real hi[3], pfsph_real cell);
void pfsph_grid_free(pfsph_grid *g);

/* Remove particles outside the domain (or with non-finite positions; count added to *removed
 * if not NULL), sort the rest by cell and fill g->start. Deterministic for any thread count. */
int pfsph_grid_sort(pfsph_grid *g, pfsph_particles *ps, size_t *removed);
/* The same with the caller's scratch (each at least ps->n elements of 4 bytes, tmp ps->n reals):
 * the simulation lends the step's arrays, which hold nothing while the grid sorts, instead of
 * keeping three more arrays per particle alive (docs/benchmarks.md, issue 28). */
int pfsph_grid_sort_in(pfsph_grid *g, pfsph_particles *ps, size_t *removed, uint32_t *key, uint32_t *perm, void *tmp);
/* Free the grid's own sort scratch (a set sorted once, such as static walls, needs it no more). */
void pfsph_grid_release_scratch(pfsph_grid *g);

/* Index ranges (into the sorted set) of the cells around a point; the union covers every
 * particle within distance R * g->cell of (x, y, z) (R <= 3). The point may lie outside the
 * domain. */
static inline void pfsph_grid_ranges_reach(const pfsph_grid *g, pfsph_real x, pfsph_real y, pfsph_real z, int R,
                                           pfsph_ranges *r)
{
    int c[3];
    const pfsph_real p[3] = {x, y, z};
    for (int a = 0; a < 3; a++) {
        pfsph_real t = (p[a] - g->lo[a]) * g->inv_cell;
        c[a] = t < 0 ? -1 : (t >= (pfsph_real)g->nc[a] ? g->nc[a] : (int)t);
    }
    r->n = 0;
    int x0 = c[0] - R < 0 ? 0 : c[0] - R;
    int x1 = c[0] + R >= g->nc[0] ? g->nc[0] - 1 : c[0] + R;
    if (x0 > x1) return;
    int zlo = g->dim == 3 ? c[2] - R : 0, zhi = g->dim == 3 ? c[2] + R : 0;
    for (int cz = zlo; cz <= zhi; cz++) {
        if (cz < 0 || cz >= g->nc[2]) continue;
        for (int cy = c[1] - R; cy <= c[1] + R; cy++) {
            if (cy < 0 || cy >= g->nc[1]) continue;
            size_t row = ((size_t)cz * (size_t)g->nc[1] + (size_t)cy) * (size_t)g->nc[0];
            uint32_t b = g->start[row + (size_t)x0], e = g->start[row + (size_t)x1 + 1];
            if (b < e) {
                r->b[r->n] = b;
                r->e[r->n] = e;
                r->n++;
            }
        }
    }
}

static inline void pfsph_grid_ranges(const pfsph_grid *g, pfsph_real x, pfsph_real y, pfsph_real z, pfsph_ranges *r)
{
    pfsph_grid_ranges_reach(g, x, y, z, g->reach, r);
}

/* The linear index of the cell holding (x, y, z), the point clamped into the grid (the spatial
 * sort's key of a set that is not sorted by the grid itself, and under MPI the cell whose owner
 * takes the point). */
static inline uint32_t pfsph_grid_cell_clamped(const pfsph_grid *g, pfsph_real x, pfsph_real y, pfsph_real z)
{
    const pfsph_real p[3] = {x, y, z};
    size_t c[3] = {0, 0, 0};
    for (int a = 0; a < g->dim; a++) {
        pfsph_real t = (p[a] - g->lo[a]) * g->inv_cell;
        c[a] = !(t > 0) ? 0 : (t >= (pfsph_real)g->nc[a] ? (size_t)g->nc[a] - 1 : (size_t)t);
    }
    return (uint32_t)((c[2] * (size_t)g->nc[1] + c[1]) * (size_t)g->nc[0] + c[0]);
}

static inline int pfsph__grid_flag(const pfsph_grid *g, const uint8_t *flags, pfsph_real x, pfsph_real y, pfsph_real z)
{
    if (!flags) return 1;
    const pfsph_real p[3] = {x, y, z};
    size_t idx = 0, mul = 1;
    for (int a = 0; a < (g->dim == 3 ? 3 : 2); a++) {
        const pfsph_real t = (p[a] - g->lo[a]) * g->inv_cell;
        if (!(t >= 0 && t < (pfsph_real)g->nc[a])) return 1;
        idx += (size_t)(int)t * mul;
        mul *= (size_t)g->nc[a];
    }
    return flags[idx];
}

/* 0 only if pfsph_grid_ranges from (x, y, z) would return no range (no particle within reach):
 * a pass may then skip the walk, with the same result. 1 without g->near or outside the
 * grid. For a sparse set (the boundary) that most fluid particles are far from. */
static inline int pfsph_grid_near(const pfsph_grid *g, pfsph_real x, pfsph_real y, pfsph_real z)
{
    return pfsph__grid_flag(g, g->near, x, y, z);
}

/* The same for the far queries (pfsph_grid_ranges_far, pfsph_grid_ranges_radius). */
static inline int pfsph_grid_near_far(const pfsph_grid *g, pfsph_real x, pfsph_real y, pfsph_real z)
{
    return pfsph__grid_flag(g, g->reach_far > g->reach ? g->near_far : g->near, x, y, z);
}

/* Ranges covering every particle within g->reach_far * g->cell (the pair forces' k h). */
static inline void pfsph_grid_ranges_far(const pfsph_grid *g, pfsph_real x, pfsph_real y, pfsph_real z, pfsph_ranges *r)
{
    pfsph_grid_ranges_reach(g, x, y, z, g->reach_far, r);
}

/* Ranges covering every particle within distance rad of (x, y, z), rad <= g->reach_far *
 * g->cell: per axis only the cells that [x - rad, x + rad] touches (with a margin of 1e-3 cell
 * for rounding), so that a radius of 1.39 cells walks 3-4 cells per axis instead of 5. The
 * rows and their order are those of pfsph_grid_ranges_reach, with some dropped and trimmed.
 * Only for particles at their sorted positions (a particle moved after the sort may sit in a
 * cell outside the band). */
static inline void pfsph_grid_ranges_radius(const pfsph_grid *g, pfsph_real x, pfsph_real y, pfsph_real z,
                                            pfsph_real rad, pfsph_ranges *r)
{
    int lo[3], hi[3];
    const pfsph_real p[3] = {x, y, z};
    const pfsph_real rc = rad * g->inv_cell + (pfsph_real)1e-3;
    const int R = g->reach_far;
    for (int a = 0; a < 3; a++) {
        pfsph_real t = (p[a] - g->lo[a]) * g->inv_cell;
        int c = t < 0 ? -1 : (t >= (pfsph_real)g->nc[a] ? g->nc[a] : (int)t);
        pfsph_real tl = t - rc, th = t + rc;
        /* floor, clamped to the reach box and to the grid */
        int l = tl < (pfsph_real)(c - R) ? c - R : (int)floor((double)tl);
        int u = th >= (pfsph_real)(c + R + 1) ? c + R : (int)floor((double)th);
        lo[a] = l < 0 ? 0 : l;
        hi[a] = u >= g->nc[a] ? g->nc[a] - 1 : u;
    }
    r->n = 0;
    if (lo[0] > hi[0]) return;
    if (g->dim != 3) lo[2] = hi[2] = 0;
    for (int cz = lo[2]; cz <= hi[2]; cz++)
        for (int cy = lo[1]; cy <= hi[1]; cy++) {
            size_t row = ((size_t)cz * (size_t)g->nc[1] + (size_t)cy) * (size_t)g->nc[0];
            uint32_t b = g->start[row + (size_t)lo[0]], e = g->start[row + (size_t)hi[0] + 1];
            if (b < e) {
                r->b[r->n] = b;
                r->e[r->n] = e;
                r->n++;
            }
        }
}

/* Test oracle: indices j != i of ps with |x_i - x_j| < radius, ascending; returns the count
 * (writes at most max). O(n). */
size_t pfsph_neighbors_brute(const pfsph_particles *ps, size_t i, pfsph_real radius, uint32_t *out, size_t max);

#endif
