/* The cut from the occupied cells only: round 1 reduces a histogram of at most `buckets`
 * coarse buckets of w cells (w = 1 on grids that small: the dense cut, one reduction); round 2
 * counts exactly, cell by cell, the windows of at most 2 w cells in which a cut, or a halo bound
 * off cells from it, can fall. Each rank counts its keys radix-sorted, so its work is its own
 * particles plus the windows, never the whole grid. The cut is the first cell with q / size of
 * the particles' weight before it, exactly as the dense histogram gives it (pfsph_cut_dense).
 * Weights are integers summed in integers: the same cut on every rank in any reduction order. */
#include "mpi/cut.h"

#include <stdlib.h>
#include <string.h>

#include "pfsph.h"

/* The exact cut from the cells' prefix counts pre[0..nc] (pre[k]: particles before cell k) and
 * weights wpre (the same array in the count cut): rank q starts at the first cell whose weight
 * prefix reaches q / size of the total; its global offset and its halo window's local bounds, off
 * cells either side. */
static void cut_from_prefix(pfsph_cut *C, const uint64_t *pre, const uint64_t *wpre, size_t nc, int size, size_t off)
{
    const uint64_t total = pre[nc], wtotal = wpre[nc], P = (uint64_t)size;
    C->cut[0] = 0;
    int q = 1;
    for (size_t k = 0; k <= nc && q < size; k++)
        while (q < size && wpre[k] * P >= (uint64_t)q * wtotal) C->cut[q++] = (uint32_t)k;
    C->cut[size] = (uint32_t)nc;
    for (q = 0; q < size; q++) {
        const size_t a = C->cut[q] > off ? C->cut[q] - off : 0;
        const size_t b = C->cut[q + 1] + off < nc ? C->cut[q + 1] + off : nc;
        C->gofs[q] = pre[C->cut[q]];
        C->lofs[q] = pre[a];
        C->lend[q] = pre[b];
    }
    C->gofs[size] = total;
}

/* A window of cells [s, e) counted exactly: F(k), the particles before cell k, for k in [s, e];
 * the cut's own window also their weight, W(k) (wcnt the same as cnt in the count cut). */
typedef struct window {
    uint64_t s, e, Fs, Ws;
    uint64_t *cnt, *wcnt;
} window;

int pfsph_cut_init(pfsph_cut *C, int size, uint64_t buckets)
{
    memset(C, 0, sizeof *C);
    C->buckets = buckets ? buckets : (uint64_t)1 << 17;
    const size_t P = (size_t)size;
    C->cut = calloc(P + 1, sizeof(uint32_t));
    C->gofs = calloc(P + 1, sizeof(uint64_t));
    C->lofs = calloc(P, sizeof(uint64_t));
    C->lend = calloc(P, sizeof(uint64_t));
    /* round 1 always fits, weighted or not: a failure later is then agreed through it */
    C->cnt_cap = 2 * (size_t)C->buckets + 2;
    C->cnt = malloc(C->cnt_cap * sizeof(uint64_t));
    C->pre = malloc(((size_t)C->buckets + 1) * sizeof(uint64_t));
    C->wpre = malloc(((size_t)C->buckets + 1) * sizeof(uint64_t));
    C->win = calloc(3 * P, sizeof(window));
    C->a_q = calloc(P, sizeof(uint64_t));
    C->b_q = calloc(P, sizeof(uint64_t));
    if (!C->cut || !C->gofs || !C->lofs || !C->lend || !C->cnt || !C->pre || !C->wpre || !C->win || !C->a_q || !C->b_q)
        return PFSPH_ENOMEM;
    return PFSPH_OK;
}

void pfsph_cut_free(pfsph_cut *C)
{
    free(C->cut);
    free(C->gofs);
    free(C->lofs);
    free(C->lend);
    free(C->cnt);
    free(C->pre);
    free(C->wpre);
    free(C->win);
    free(C->a_q);
    free(C->b_q);
    free(C->sorted);
    free(C->tmp);
    memset(C, 0, sizeof *C);
}

/* LSD radix sort, 3 passes of 11 bits; returns the array that holds the result (a or t). */
static uint32_t *radix(uint32_t *a, uint32_t *t, size_t m)
{
    for (int sh = 0; sh < 33; sh += 11) {
        size_t c[2049] = {0};
        for (size_t i = 0; i < m; i++) c[((a[i] >> sh) & 2047u) + 1]++;
        for (int k = 0; k < 2048; k++) c[k + 1] += c[k];
        for (size_t i = 0; i < m; i++) t[c[(a[i] >> sh) & 2047u]++] = a[i];
        uint32_t *s = a;
        a = t;
        t = s;
    }
    return a;
}

static size_t lower_bound(const uint32_t *a, size_t m, uint64_t v)
{
    size_t lo = 0, hi = m;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (a[mid] < v) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

static uint64_t F_at(const window *W, uint64_t k)
{
    uint64_t F = W->Fs;
    for (uint64_t x = W->s; x < k; x++) F += W->cnt[x - W->s];
    return F;
}

static uint64_t W_at(const window *W, uint64_t k)
{
    uint64_t F = W->Ws;
    for (uint64_t x = W->s; x < k; x++) F += W->wcnt[x - W->s];
    return F;
}

int pfsph_cut_compute(pfsph_cut *C, MPI_Comm comm, const uint32_t *key, size_t m, size_t nc, size_t off, uint64_t wt)
{
    int rank, size;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    const uint64_t P = (uint64_t)size, B = C->buckets;
    const uint64_t w = nc <= B ? 1 : (nc + B - 1) / B;
    const size_t nb = (size_t)((nc + w - 1) / w);
    const int weighted = wt > 0;
    /* round 2: 3 count windows per cut, and the cut's own window's weights */
    const size_t win = (size_t)(2 * w + 2), nwin = 3 * (size_t)(size - 1),
                 need = nwin * win + (weighted ? (size_t)(size - 1) * win : 0);
    uint32_t fail = 0;
    if (w > 1 && need > C->cnt_cap) {
        uint64_t *p = realloc(C->cnt, need * sizeof(uint64_t));
        if (p) {
            C->cnt = p;
            C->cnt_cap = need;
        } else {
            fail = 1;
        }
    }
    if (!fail && w > 1 && m > C->sorted_cap) {
        uint32_t *a = realloc(C->sorted, m * sizeof(uint32_t)), *t = a ? realloc(C->tmp, m * sizeof(uint32_t)) : NULL;
        if (a) C->sorted = a;
        if (t) C->tmp = t;
        if (a && t) C->sorted_cap = m;
        else fail = 1;
    }
    /* round 1: the coarse histogram, the particles leaving the domain, any rank's failure, then
     * (weighted) each bucket's weight: this rank's particles all weigh wt */
    uint64_t *h = C->cnt;
    const size_t nh = nb + 2 + (weighted ? nb : 0);
    memset(h, 0, nh * sizeof(uint64_t));
    for (size_t i = 0; i < m; i++) {
        if (key[i] == UINT32_MAX) h[nb]++;
        else h[key[i] / w]++;
    }
    h[nb + 1] = fail;
    if (weighted)
        for (size_t j = 0; j < nb; j++) h[nb + 2 + j] = h[j] * wt;
    MPI_Allreduce(MPI_IN_PLACE, h, (int)nh, MPI_UINT64_T, MPI_SUM, comm);
    if (h[nb + 1]) return PFSPH_ENOMEM;
    C->removed = h[nb];
    uint64_t *pre = C->pre, *wpre = weighted ? C->wpre : C->pre; /* pre[j]: particles before cell j w */
    pre[0] = 0;
    for (size_t j = 0; j < nb; j++) pre[j + 1] = pre[j] + h[j];
    if (weighted) {
        wpre[0] = 0;
        for (size_t j = 0; j < nb; j++) wpre[j + 1] = wpre[j] + h[nb + 2 + j];
    }
    const uint64_t total = pre[nb], wtotal = wpre[nb];
    C->total = total;
    C->wtotal = wtotal;
    C->weighted = weighted;
    C->rounds = 1;
    C->hist_counters = nh;
    C->cut[0] = 0;
    C->cut[size] = (uint32_t)nc;
    C->gofs[0] = 0;
    C->gofs[size] = total;
    if (total == 0) { /* every cut at cell 0, every slice empty */
        for (int q = 0; q < size; q++) C->cut[q] = 0, C->gofs[q] = C->lofs[q] = C->lend[q] = 0;
        return PFSPH_OK;
    }
    if (w == 1) { /* exact already: the dense cut */
        cut_from_prefix(C, pre, wpre, nc, size, off);
        return PFSPH_OK;
    }
    /* round 2: per cut q, the bucket (a, b] it falls in and the windows of its halo bounds */
    const uint32_t *s = m ? radix(memcpy(C->sorted, key, m * sizeof(uint32_t)), C->tmp, m) : NULL;
    window *W = C->win;
    uint64_t *a_q = C->a_q, *b_q = C->b_q;
    size_t j = 1;
    for (int q = 1; q < size; q++) {
        while (j < nb && wpre[j] * P < (uint64_t)q * wtotal) j++;
        const uint64_t a = (uint64_t)(j - 1) * w, b = (uint64_t)j * w < nc ? (uint64_t)j * w : nc;
        a_q[q] = a;
        b_q[q] = b;
        const uint64_t lo2 = a > off ? a - off : 0, hi3 = a + off < nc ? a + off : nc;
        window *X = &W[3 * (q - 1)];
        X[0].s = a;
        X[0].e = b;
        X[1].s = lo2 / w * w;
        X[1].e = b > off ? b - off : 0;
        X[2].s = hi3 / w * w;
        X[2].e = b + off < nc ? b + off : nc;
        for (int t = 0; t < 3; t++) {
            if (X[t].e < X[t].s) X[t].e = X[t].s;
            X[t].Fs = pre[X[t].s / w];
            X[t].cnt = C->cnt + (size_t)(3 * (q - 1) + t) * win;
            memset(X[t].cnt, 0, win * sizeof(uint64_t));
            for (size_t i = lower_bound(s, m, X[t].s); i < m && s[i] < X[t].e; i++) X[t].cnt[s[i] - X[t].s]++;
        }
        X[0].Ws = wpre[X[0].s / w];
        X[0].wcnt = X[0].cnt;
        if (weighted) {
            X[0].wcnt = C->cnt + nwin * win + (size_t)(q - 1) * win;
            for (size_t x = 0; x < win; x++) X[0].wcnt[x] = X[0].cnt[x] * wt;
        }
    }
    MPI_Allreduce(MPI_IN_PLACE, C->cnt, (int)need, MPI_UINT64_T, MPI_SUM, comm);
    C->rounds = 2;
    C->hist_counters += need;
    C->lofs[0] = 0;
    C->lend[size - 1] = total;
    for (int q = 1; q < size; q++) {
        const window *X = &W[3 * (q - 1)];
        uint64_t k = a_q[q] + 1, F = F_at(&X[0], k), Wk = W_at(&X[0], k);
        while (k < b_q[q] && Wk * P < (uint64_t)q * wtotal) {
            F += X[0].cnt[k - X[0].s];
            Wk += X[0].wcnt[k - X[0].s];
            k++;
        }
        C->cut[q] = (uint32_t)k;
        C->gofs[q] = F;
        C->lofs[q] = k > off ? F_at(&X[1], k - off) : 0;
        C->lend[q - 1] = k + off < nc ? F_at(&X[2], k + off) : total;
    }
    return PFSPH_OK;
}

int pfsph_cut_dense(pfsph_cut *C, MPI_Comm comm, const uint32_t *key, size_t m, size_t nc, size_t off, uint64_t wt)
{
    int size;
    MPI_Comm_size(comm, &size);
    const int weighted = wt > 0;
    const size_t nh = nc + 1 + (weighted ? nc : 0);
    uint64_t *hist = calloc(nh, sizeof(uint64_t));
    uint64_t *pre = malloc((nc + 1) * sizeof(uint64_t)), *wpre = weighted ? malloc((nc + 1) * sizeof(uint64_t)) : pre;
    if (!hist || !pre || !wpre) MPI_Abort(comm, 1); /* a test's or a check's allocation */
    for (size_t i = 0; i < m; i++) {
        if (key[i] == UINT32_MAX) hist[nc]++;
        else hist[key[i]]++;
    }
    if (weighted)
        for (size_t k = 0; k < nc; k++) hist[nc + 1 + k] = hist[k] * wt;
    MPI_Allreduce(MPI_IN_PLACE, hist, (int)nh, MPI_UINT64_T, MPI_SUM, comm);
    pre[0] = 0;
    for (size_t k = 0; k < nc; k++) pre[k + 1] = pre[k] + hist[k];
    if (weighted) {
        wpre[0] = 0;
        for (size_t k = 0; k < nc; k++) wpre[k + 1] = wpre[k] + hist[nc + 1 + k];
    }
    C->removed = hist[nc];
    C->total = pre[nc];
    C->wtotal = wpre[nc];
    C->weighted = weighted;
    cut_from_prefix(C, pre, wpre, nc, size, off);
    free(hist);
    free(pre);
    if (weighted) free(wpre);
    return PFSPH_OK;
}
