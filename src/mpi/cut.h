/* The step's cut of the cell-key order into one range per rank, from the occupied cells only
 * (docs/cluster.md): a coarse global histogram, then an exact count in the few windows where a
 * cut or a halo bound falls. The same cuts as a dense histogram of every cell. Each rank's share
 * is 1/size of the particles' total weight: an integer per rank (its measured cost, src/mpi/cost.c),
 * or 1 for every particle (the count cut). */
#ifndef PFSPH_MPI_CUT_H
#define PFSPH_MPI_CUT_H

#include <mpi.h>
#include <stddef.h>
#include <stdint.h>

/* What the cut gives every rank: rank q owns cells [cut[q], cut[q + 1]) and global indices
 * [gofs[q], gofs[q + 1]), and holds [lofs[q], lend[q]) with its halo (cells within off of
 * its own); removed: particles of every rank that left the domain (key UINT32_MAX). */
/* A weight's bound: the prefix comparisons w * size stay below 2^64 for up to 2^36 particles on
 * 2^16 ranks (2^12 * 2^36 * 2^16). */
#define PFSPH_CUT_WEIGHT_MAX 4096u

typedef struct pfsph_cut {
    uint32_t *cut;           /* size + 1 */
    uint64_t *gofs;          /* size + 1 */
    uint64_t *lofs, *lend;   /* size */
    uint64_t removed, total; /* total: particles that stay */
    uint64_t wtotal;         /* their total weight (total in the count cut) */
    uint32_t *sorted, *tmp;  /* scratch: this rank's keys, radix-sorted */
    uint64_t *cnt;           /* scratch: the histograms (counts, then weights) */
    uint64_t *pre, *wpre;    /* scratch: the coarse prefixes of counts and weights, buckets + 1 */
    void *win;               /* scratch: the 3 (size - 1) windows of round 2 (cut.c) */
    uint64_t *a_q, *b_q;     /* scratch: each cut's bucket, size */
    size_t sorted_cap, cnt_cap;
    uint64_t buckets;       /* the coarse histogram's size (a power of 2) */
    uint64_t hist_counters; /* counters of the last cut's reductions (figures) */
    int rounds;             /* collective reductions of the last cut: 1 or 2 */
    int weighted;           /* the last cut weighed the particles (wt > 0) */
} pfsph_cut;

/* Arrays for `size` ranks, buckets coarse counters (0: 2^17). */
int pfsph_cut_init(pfsph_cut *C, int size, uint64_t buckets);
void pfsph_cut_free(pfsph_cut *C);

/* The cut from the m keys of the particles this rank sends (UINT32_MAX: leaving the domain),
 * over nc cells, each particle weighing wt (1 .. PFSPH_CUT_WEIGHT_MAX; 0: the count cut, on every
 * rank or on none): rank q's first cell is the first with q / size of the total weight before it.
 * Collective. Returns 0 or PFSPH_ENOMEM (on any rank: every rank gets it). */
int pfsph_cut_compute(pfsph_cut *C, MPI_Comm comm, const uint32_t *key, size_t m, size_t nc, size_t off, uint64_t wt);

/* The same from one Allreduce of a dense histogram of every cell (the first slice's cut): tests
 * and PFSPH_MPI_CHECK_CUT=1 compare the two. */
int pfsph_cut_dense(pfsph_cut *C, MPI_Comm comm, const uint32_t *key, size_t m, size_t nc, size_t off, uint64_t wt);

#endif
