/* Neighbour lists built from the sorted grid (nlist.h). */
#include "core/nlist.h"

#include <stdlib.h>
#include <string.h>

/* the neighbours of query point i (targets within r2; j != i when the sets are one), the first
 * `room` of them written to out when out is not NULL (and their kernel derivatives to dw when
 * it is not NULL); their count */
static inline uint32_t walk(const pfsph_nlist_sets *S, size_t i, uint32_t *out, pfsph_real *dw, uint32_t room)
{
    pfsph_ranges r;
    const pfsph_real xi = S->qx[i], yi = S->qy[i], zi = S->qz[i];
    const pfsph_real *x = S->tx, *y = S->ty, *z = S->tz;
    const size_t self = S->self ? i : SIZE_MAX;
    pfsph_grid_ranges(S->g, xi, yi, zi, &r);
    uint32_t c = 0;
    for (int q = 0; q < r.n; q++)
        for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
            pfsph_real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
            pfsph_real r2 = dx * dx + dy * dy + dz * dz;
            if (r2 < S->r2 && j != self) {
                if (out && c < room) {
                    out[c] = j;
                    if (dw) dw[c] = pfsph_kernel_dw_r(S->k, pfsph_sqrt(r2));
                }
                c++;
            }
        }
    return c;
}

uint32_t *pfsph_nlist_counts(pfsph_nlist *l, size_t n)
{
    l->n = 0;
    if (n > l->cap_n || !l->start) {
        size_t cap = n + n / 8 + 16;
        uint32_t *s = realloc(l->start, (cap + 1) * sizeof *s);
        if (!s) return NULL;
        l->start = s;
        l->cap_n = cap;
    }
    return l->start + 1;
}

int pfsph_nlist_fill(pfsph_nlist *l, const pfsph_nlist_sets *S)
{
    const size_t n = S->n;
    const pfsph_kernel *k = S->k;
    /* offsets, serially: a 64-bit total so that an overflow of the 32-bit offsets is caught */
    const uint32_t *cnt = l->start + 1;
    uint64_t total = 0;
    l->n = 0;
    l->start[0] = 0;
    for (size_t i = 0; i < n; i++) {
        total += cnt[i];
        if (total > UINT32_MAX) return PFSPH_ENOMEM;
        l->start[i + 1] = (uint32_t)total;
    }
    if (total > l->cap || !l->idx || (k && !l->dw)) {
        size_t cap = (size_t)total + (size_t)total / 8 + 64;
        uint32_t *p = realloc(l->idx, cap * sizeof *p);
        if (!p) return PFSPH_ENOMEM;
        l->idx = p;
        if (k) {
            pfsph_real *w = realloc(l->dw, cap * sizeof *w);
            if (!w) return PFSPH_ENOMEM;
            l->dw = w;
        }
        l->cap = cap;
    }
    pfsph_real *dw = k ? l->dw : NULL;
    int bad = 0;
#pragma omp parallel for schedule(static) reduction(| : bad)
    for (size_t i = 0; i < n; i++) {
        const uint32_t want = l->start[i + 1] - l->start[i];
        if (walk(S, i, l->idx + l->start[i], dw ? dw + l->start[i] : NULL, want) != want) bad = 1;
    }
    if (bad) return PFSPH_EINPUT; /* counts not those of this walk: a caller's bug */
    l->n = n;
    return PFSPH_OK;
}

int pfsph_nlist_build(pfsph_nlist *l, const pfsph_nlist_sets *S)
{
    const size_t n = S->n;
    uint32_t *cnt = pfsph_nlist_counts(l, n);
    if (!cnt) return PFSPH_ENOMEM;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) cnt[i] = walk(S, i, NULL, NULL, 0);
    return pfsph_nlist_fill(l, S);
}

int pfsph_nlist_plan(pfsph_nlist *l, size_t n, int nthreads, double guess)
{
    if (nthreads < 1 || nthreads > PFSPH_NLIST_MAX_THREADS) return PFSPH_EINPUT;
    if (!pfsph_nlist_counts(l, n)) return PFSPH_ENOMEM;
    if (l->nthreads != nthreads) {
        /* no history for this many threads: regions of nothing, so that the caller's walk
         * only counts and finish fills by a second walk, which sizes the arrays exactly (a
         * guess would set the peak memory: 1.4x the need) */
        for (int t = 0; t <= nthreads; t++) l->rbeg[t] = 0;
        for (int t = 0; t < nthreads; t++) l->n_t[t] = 0;
        l->nthreads = nthreads;
        return PFSPH_EINPUT;
    }
    size_t off = 0;
    for (int t = 0; t < nthreads; t++) {
        const size_t i0 = n * (size_t)t / (size_t)nthreads, i1 = n * (size_t)(t + 1) / (size_t)nthreads;
        /* this thread's particles lie where its particles lay last step (the grid order changes
         * little from step to step), so its last need, per particle, predicts this one */
        double per = l->n_t[t] ? (double)l->used[t] / (double)l->n_t[t] : guess;
        l->rbeg[t] = off;
        off += (size_t)(1.125 * per * (double)(i1 - i0)) + 256;
        l->n_t[t] = i1 - i0;
    }
    l->rbeg[nthreads] = off;
    l->nthreads = nthreads;
    if (off > l->cap || !l->idx || !l->dw) {
        uint32_t *p = realloc(l->idx, off * sizeof *p);
        if (!p) return PFSPH_ENOMEM;
        l->idx = p;
        pfsph_real *w = realloc(l->dw, off * sizeof *w);
        if (!w) return PFSPH_ENOMEM;
        l->dw = w;
        l->cap = off;
    }
    return PFSPH_OK;
}

int pfsph_nlist_finish(pfsph_nlist *l, int overflow, const pfsph_nlist_sets *S)
{
    const size_t n = S->n;
    if (overflow) {
        int rc = pfsph_nlist_fill(l, S);
        for (int t = 0; t < l->nthreads && rc == PFSPH_OK; t++) { /* the next plan's sizes */
            const size_t i0 = n * (size_t)t / (size_t)l->nthreads, i1 = n * (size_t)(t + 1) / (size_t)l->nthreads;
            l->used[t] = l->start[i1] - l->start[i0];
            l->n_t[t] = i1 - i0;
        }
        return rc;
    }
    /* compact: each region moves left to follow the one before (in order, so a move never
     * overwrites entries still to move) */
    size_t to = l->used[0];
    for (int t = 1; t < l->nthreads; t++) {
        if (to != l->rbeg[t]) {
            memmove(l->idx + to, l->idx + l->rbeg[t], l->used[t] * sizeof *l->idx);
            memmove(l->dw + to, l->dw + l->rbeg[t], l->used[t] * sizeof *l->dw);
        }
        to += l->used[t];
    }
    const uint32_t *cnt = l->start + 1;
    uint64_t total = 0;
    l->start[0] = 0;
    for (size_t i = 0; i < n; i++) {
        total += cnt[i];
        if (total > UINT32_MAX) return PFSPH_ENOMEM;
        l->start[i + 1] = (uint32_t)total;
    }
    l->n = n;
    return total == to ? PFSPH_OK : PFSPH_EINPUT;
}

void pfsph_nlist_free(pfsph_nlist *l)
{
    if (!l) return;
    free(l->start);
    free(l->idx);
    free(l->dw);
    l->start = l->idx = NULL;
    l->dw = NULL;
    l->n = l->cap_n = l->cap = 0;
}

double pfsph_nlist_bytes_per_particle(double neighbours, int with_dw)
{
    return sizeof(uint32_t) * (1.0 + 1.125 * neighbours) + (with_dw ? sizeof(pfsph_real) * 1.125 * neighbours : 0) +
        0.5;
}
