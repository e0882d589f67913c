/* Neighbour candidates filtered in SIMD: the targets of one grid range within a radius of a
 * point, appended in range order to a small buffer (index, x_ij, |x_ij|^2), so that a pass
 * computes its pair terms only for the ~15 % of the grid candidates that lie within h. The
 * test runs in AVX-512, AVX2 or scalar code, chosen once at run time from the CPU
 * (docs/architecture.md, dispatch); every variant rounds as the scalar expressions do, so
 * the hits and their x_ij, r2 are the same bits whatever the CPU. */
#ifndef PFSPH_HITS_H
#define PFSPH_HITS_H

#include "pfsph/grid.h"

/* Room in a buffer: a pass flushes (evaluates and empties) it before a range could overflow
 * it; the arrays have PFSPH_HITS_PAD more entries for full-vector stores. */
#define PFSPH_HITS_CAP 512
#define PFSPH_HITS_PAD 16

typedef struct pfsph_hits {
    int n;
    uint32_t j[PFSPH_HITS_CAP + PFSPH_HITS_PAD];
    pfsph_real dx[PFSPH_HITS_CAP + PFSPH_HITS_PAD], dy[PFSPH_HITS_CAP + PFSPH_HITS_PAD],
        dz[PFSPH_HITS_CAP + PFSPH_HITS_PAD], r2[PFSPH_HITS_CAP + PFSPH_HITS_PAD];
    /* per-hit scratch for the passes' terms (physics/pair_terms.h) */
    pfsph_real t0[PFSPH_HITS_CAP + PFSPH_HITS_PAD], t1[PFSPH_HITS_CAP + PFSPH_HITS_PAD],
        t2[PFSPH_HITS_CAP + PFSPH_HITS_PAD], t3[PFSPH_HITS_CAP + PFSPH_HITS_PAD];
} pfsph_hits;

/* Pads the hits to a multiple of 16 (the widest vector of floats) with harmless entries (j = 0,
 * x_ij = 0, r2 = 0) and returns that count, so that the vector loops of a pass over them run
 * whole vectors, not a scalar tail (for ~30 hits the tail was most of a loop's time); the
 * pass still sums only the first h->n. */
static inline int pfsph_hits_pad16(pfsph_hits *h)
{
    const int m = (h->n + 15) & ~15;
    for (int e = h->n; e < m; e++) {
        h->j[e] = 0;
        h->dx[e] = h->dy[e] = h->dz[e] = h->r2[e] = 0;
    }
    return m;
}

/* Appends the targets j in [b, e) with r2 = |x - x_j|^2 < h2 and j != skip, in order, with
 * dx = x - x_j etc. computed as (x - x_j) and r2 as dx dx + dy dy + dz dz. Requires
 * h->n + (e - b) <= PFSPH_HITS_CAP. */
typedef void (*pfsph_hits_fn)(pfsph_hits *h, const pfsph_real *tx, const pfsph_real *ty, const pfsph_real *tz,
                              uint32_t b, uint32_t e, pfsph_real x, pfsph_real y, pfsph_real z, pfsph_real h2,
                              uint32_t skip);

/* The variant for this CPU (resolved once; PFSPH_SIMD=scalar|avx2|avx512 in the environment
 * caps it, for tests and A/B measurements). */
pfsph_hits_fn pfsph_hits_select(void);
/* A given variant: 0 scalar, 1 AVX2, 2 AVX-512; NULL when this CPU or build lacks it. */
pfsph_hits_fn pfsph_hits_variant(int level);
/* Name of the variant pfsph_hits_select chose ("avx512", "avx2", "scalar"). */
const char *pfsph_hits_level_name(void);

/* Walks the grid ranges r of a query, appending their hits to h and calling FLUSH (a
 * statement that evaluates h's n entries in order) whenever a range might not fit, and once at
 * the end; the hits are then in grid-walk order across flushes. */
#define PFSPH_HITS_WALK(fn, h, r, tx, ty, tz, x, y, z, h2, skip, FLUSH)           \
    do {                                                                          \
        (h)->n = 0;                                                               \
        for (int q_ = 0; q_ < (r).n; q_++)                                        \
            for (uint32_t b_ = (r).b[q_]; b_ < (r).e[q_];) {                      \
                if ((h)->n > PFSPH_HITS_CAP - 64) {                               \
                    FLUSH;                                                        \
                    (h)->n = 0;                                                   \
                }                                                                 \
                uint32_t room_ = (uint32_t)(PFSPH_HITS_CAP - (h)->n);             \
                uint32_t e_ = (r).e[q_] - b_ > room_ ? b_ + room_ : (r).e[q_];    \
                (fn)((h), (tx), (ty), (tz), b_, e_, (x), (y), (z), (h2), (skip)); \
                b_ = e_;                                                          \
            }                                                                     \
        FLUSH;                                                                    \
    } while (0)

#endif
