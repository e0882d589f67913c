/* Neighbour lists: the fluid neighbours j != i within a radius of every fluid particle, built
 * once per step after the grid sort and walked by every later pass of that step whose positions
 * have not moved (DFSPH's factor, divergence and density iterations, the viscosity). A grid
 * query tests ~190 candidates in 3D for ~30 neighbours within h (docs/benchmarks.md); a list
 * holds only the ~30. Each particle's list is in the order of the grid walk, so a pass over the
 * list adds the same terms in the same order as the grid walk did: the same bits.
 *
 * Built with a kernel, each entry also keeps the kernel derivative of the pair, the same bits
 * as the passes computed (pfsph_kernel_dw_r of sqrt(r2)): the passes then need no square root,
 * division or branch of the kernel per pair.
 *
 * Memory: 4 bytes per particle for the offsets plus 4 bytes per neighbour (32-bit indices) and
 * 4 (float) for the kernel derivative, with 1/8 slack when the list grows: about
 * 4 + 9 * 33 = 301 bytes per fluid particle in 3D at h = 2 d, 4 + 9 * 13 = 121 in 2D. */
#ifndef PFSPH_NLIST_H
#define PFSPH_NLIST_H

#include "pfsph/grid.h"
#include "pfsph/kernel.h"

/* What lists are built over: n query points (qx, qy, qz) and the targets (tx, ty, tz) sorted
 * in grid g (its reach covers r2); self: queries and targets are one set (the fluid: j == i
 * left out), else two (fluid points, boundary targets); k: NULL, or the kernel whose
 * derivative each entry keeps (dw). */
typedef struct pfsph_nlist_sets {
    const pfsph_grid *g;
    const pfsph_real *tx, *ty, *tz;
    const pfsph_real *qx, *qy, *qz;
    size_t n;
    int self;
    pfsph_real r2;
    const pfsph_kernel *k;
} pfsph_nlist_sets;

#define PFSPH_NLIST_MAX_THREADS 256 /* threads a one-walk build plans for (more: two walks) */

typedef struct pfsph_nlist {
    size_t n;        /* particles listed */
    size_t cap_n;    /* entries allocated in start, minus one */
    uint32_t *start; /* n + 1: particle i's neighbours are idx[start[i] .. start[i + 1]) */
    uint32_t *idx;   /* neighbour indices into the sorted set */
    pfsph_real *dw;  /* per entry: pfsph_kernel_dw_r(k, |x_ij|) (grad W_ij = dw x_ij), when built
                      * with a kernel; else NULL */
    size_t cap;      /* entries allocated in idx */
    /* One-walk builds (pfsph_nlist_plan / _finish): thread t of nthreads writes its particles'
     * lists into idx[rbeg[t] .. rbeg[t + 1]); used[t] entries it needed, for n_t particles. */
    int nthreads;
    size_t rbeg[PFSPH_NLIST_MAX_THREADS + 1], used[PFSPH_NLIST_MAX_THREADS], n_t[PFSPH_NLIST_MAX_THREADS];
} pfsph_nlist;

/* Builds the lists of S's query points: the targets j with |x_i - x_j|^2 < r2 (j != i for one
 * set). Two grid walks (count, then fill) so that each list is contiguous and in grid-walk
 * order for any thread count. Grows its arrays only when a step needs more (by 1/8 over the
 * need). Returns PFSPH_OK or PFSPH_ENOMEM (the list is then empty). */
int pfsph_nlist_build(pfsph_nlist *l, const pfsph_nlist_sets *S);

/* Two steps, for a caller whose own grid walk counts the neighbours (the density pass): the
 * array of n counts to fill (cnt[i]: neighbours j != i of i with |x_i - x_j|^2 < r2), NULL when
 * out of memory; then pfsph_nlist_fill walks the grid again to list them (PFSPH_EINPUT if the
 * counts were not those of this walk; nothing is written out of bounds). */
uint32_t *pfsph_nlist_counts(pfsph_nlist *l, size_t n);
int pfsph_nlist_fill(pfsph_nlist *l, const pfsph_nlist_sets *S);

/* One walk, for a caller whose own grid walk finds the neighbours (the density pass): plan
 * gives each of nthreads threads, taking particles [n t / nthreads, n (t + 1) / nthreads) in
 * order, a region of idx and dw (rbeg) sized from the same thread's need last time (1/8 more,
 * plus 256; guess neighbours per particle for a thread that had none); returns PFSPH_ENOMEM,
 * or PFSPH_EINPUT when it cannot plan: the first build for this many threads (then every
 * region is empty, so the walk only counts, and finish fills by a second walk), or more than
 * PFSPH_NLIST_MAX_THREADS threads. The caller then
 * writes each particle's count to cnt = start + 1 and its entries at the thread's next free
 * place while they fit, and sets used[t]. finish compacts the regions and sets the offsets,
 * or, when a region overflowed, fills the lists by a second walk from the counts. */
int pfsph_nlist_plan(pfsph_nlist *l, size_t n, int nthreads, double guess);
int pfsph_nlist_finish(pfsph_nlist *l, int overflow, const pfsph_nlist_sets *S);

/* Frees the arrays; the struct may be built again. NULL is a no-op. */
void pfsph_nlist_free(pfsph_nlist *l);

/* Bytes per particle the lists of about `neighbours` neighbours each hold at most (estimate),
 * with_dw: built with a kernel. */
double pfsph_nlist_bytes_per_particle(double neighbours, int with_dw);

#endif
