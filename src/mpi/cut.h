/* The step's cut of the cell-key order into one range per rank, from the occupied cells only
 * (docs/cluster.md): a coarse global histogram, then an exact count in the few windows where a
 * cut or a halo bound falls. The same cuts as a dense histogram of every cell. */
#ifndef PFSPH_MPI_CUT_H
#define PFSPH_MPI_CUT_H

#include <mpi.h>
#include <stddef.h>
#include <stdint.h>

/* What the cut gives every rank: rank q owns cells [cut[q], cut[q + 1]) and global indices
 * [gofs[q], gofs[q + 1]), and holds [lofs[q], lend[q]) with its halo (cells within off of
 * its own); removed: particles of every rank that left the domain (key UINT32_MAX). */
typedef struct pfsph_cut {
    uint32_t *cut;           /* size + 1 */
    uint64_t *gofs;          /* size + 1 */
    uint64_t *lofs, *lend;   /* size */
    uint64_t removed, total; /* total: particles that stay */
    uint32_t *sorted, *tmp;  /* scratch: this rank's keys, radix-sorted */
    uint32_t *cnt;           /* scratch: the histograms */
    uint64_t *pre;           /* scratch: the coarse prefix, buckets + 1 */
    void *win;               /* scratch: the 3 (size - 1) windows of round 2 (cut.c) */
    uint64_t *a_q, *b_q;     /* scratch: each cut's bucket, size */
    size_t sorted_cap, cnt_cap;
    uint64_t buckets;       /* the coarse histogram's size (a power of 2) */
    uint64_t hist_counters; /* counters of the last cut's reductions (figures) */
    int rounds;             /* collective reductions of the last cut: 1 or 2 */
} pfsph_cut;

/* Arrays for `size` ranks, buckets coarse counters (0: 2^17). */
int pfsph_cut_init(pfsph_cut *C, int size, uint64_t buckets);
void pfsph_cut_free(pfsph_cut *C);

/* The cut from the m keys of the particles this rank sends (UINT32_MAX: leaving the domain),
 * over nc cells. Collective. Returns 0 or PFSPH_ENOMEM (on any rank: every rank gets it). */
int pfsph_cut_compute(pfsph_cut *C, MPI_Comm comm, const uint32_t *key, size_t m, size_t nc, size_t off);

/* The same from one Allreduce of a dense histogram of every cell (the first slice's cut): tests
 * and PFSPH_MPI_CHECK_CUT=1 compare the two. */
int pfsph_cut_dense(pfsph_cut *C, MPI_Comm comm, const uint32_t *key, size_t m, size_t nc, size_t off);

#endif
