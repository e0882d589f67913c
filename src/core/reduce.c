/* Deterministic reductions: fixed blocks, combined serially. */
#include "core/reduce.h"

double pfsph__sum(const pfsph_real *a, size_t n)
{
    enum { BLOCK = PFSPH_SUM_BLOCK };
    size_t nb = (n + BLOCK - 1) / BLOCK;
    double total = 0;
    /* Small fixed-size stack buffer of partials per chunk of blocks keeps this allocation free. */
    enum { CHUNK = 256 };
    double part[CHUNK];
    for (size_t b0 = 0; b0 < nb; b0 += CHUNK) {
        size_t b1 = b0 + CHUNK < nb ? b0 + CHUNK : nb;
#pragma omp parallel for schedule(static)
        for (size_t b = b0; b < b1; b++) {
            size_t lo = b * BLOCK, hi = lo + BLOCK < n ? lo + BLOCK : n;
            double s = 0;
            for (size_t i = lo; i < hi; i++) s += (double)a[i];
            part[b - b0] = s;
        }
        for (size_t b = b0; b < b1; b++) total += part[b - b0];
    }
    return total;
}
