/* Neighbour lists: the fluid neighbours j != i within a radius of every fluid particle, built
 * once per step after the grid sort and walked by every later pass of that step whose positions
 * have not moved (DFSPH's factor, divergence and density iterations, the viscosity). A grid
 * query tests ~190 candidates in 3D for ~30 neighbours within h (docs/benchmarks.md); a list
 * holds only the ~30. Each particle's list is in the order of the grid walk, so a pass over the
 * list adds the same terms in the same order as the grid walk did: the same bits.
 *
 * Memory: 4 bytes per particle for the offsets plus 4 bytes per neighbour (32-bit indices),
 * with 1/8 slack when the list grows: about 4 + 4.5 * 33 = 153 bytes per fluid particle in 3D
 * at h = 2 d, 4 + 4.5 * 13 = 62 in 2D. */
#ifndef PFSPH_NLIST_H
#define PFSPH_NLIST_H

#include "pfsph/grid.h"

typedef struct pfsph_nlist {
    size_t n;        /* particles listed */
    size_t cap_n;    /* entries allocated in start, minus one */
    uint32_t *start; /* n + 1: particle i's neighbours are idx[start[i] .. start[i + 1]) */
    uint32_t *idx;   /* neighbour indices into the sorted set */
    size_t cap;      /* entries allocated in idx */
} pfsph_nlist;

/* Builds the lists of the n particles at (x, y, z), sorted in grid g (this step), for the
 * radius g->reach * g->cell covers: j != i with |x_i - x_j|^2 < r2. Two grid walks (count,
 * then fill) so that each list is contiguous and in grid-walk order for any thread count.
 * Grows its arrays only when a step needs more (by 1/8 over the need). Returns PFSPH_OK or
 * PFSPH_ENOMEM (the list is then empty). */
int pfsph_nlist_build(pfsph_nlist *l, const pfsph_grid *g, const pfsph_real *x, const pfsph_real *y,
                      const pfsph_real *z, size_t n, pfsph_real r2);

/* Two steps, for a caller whose own grid walk counts the neighbours (the density pass): the
 * array of n counts to fill (cnt[i]: neighbours j != i of i with |x_i - x_j|^2 < r2), NULL when
 * out of memory; then pfsph_nlist_fill walks the grid again to list them (PFSPH_EINPUT if the
 * counts were not those of this walk; nothing is written out of bounds). */
uint32_t *pfsph_nlist_counts(pfsph_nlist *l, size_t n);
int pfsph_nlist_fill(pfsph_nlist *l, const pfsph_grid *g, const pfsph_real *x, const pfsph_real *y,
                     const pfsph_real *z, size_t n, pfsph_real r2);

/* Frees the arrays; the struct may be built again. NULL is a no-op. */
void pfsph_nlist_free(pfsph_nlist *l);

/* Bytes per particle the lists of about `neighbours` neighbours each hold at most (estimate). */
double pfsph_nlist_bytes_per_particle(double neighbours);

#endif
