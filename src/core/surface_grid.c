/* The surface reconstruction's spatial lookups (surface_mesh_internal.h): a flat sorted cell
 * list of points, for the neighbour searches, and an open-addressing hash of block keys. */
#include <stdlib.h>
#include <string.h>

#include "core/surface_mesh_internal.h"

void pfsph__surface_grid_free(grid *g)
{
    free(g->idx);
    free(g->start);
    free(g->ukey);
    free(g->ustart);
    free(g->ucell);
    memset(g, 0, sizeof *g);
}

int pfsph__surface_grid_build(grid *g, const int32_t *cell, size_t n)
{
    memset(g, 0, sizeof *g);
    g->idx = malloc((n ? n : 1) * sizeof *g->idx);
    g->ustart = malloc((n + 1) * sizeof *g->ustart);
    g->ucell = malloc(3 * (n ? n : 1) * sizeof *g->ucell);
    if (!g->idx || !g->ustart || !g->ucell) return PFSPH_ENOMEM;
    g->ustart[0] = 0;
    if (!n) return PFSPH_OK;
    int32_t hi[3];
    for (int u = 0; u < 3; u++) g->lo[u] = hi[u] = cell[u];
    for (size_t i = 0; i < n; i++)
        for (int u = 0; u < 3; u++) {
            if (cell[3 * i + u] < g->lo[u]) g->lo[u] = cell[3 * i + u];
            if (cell[3 * i + u] > hi[u]) hi[u] = cell[3 * i + u];
        }
    for (int u = 0; u < 3; u++) g->ext[u] = (int64_t)hi[u] - g->lo[u] + 1;
    double cells = (double)g->ext[0] * (double)g->ext[1] * (double)g->ext[2];
    if (cells <= 4.0 * (double)n + 4096) {
        size_t nc = (size_t)cells;
        g->dense = 1;
        g->start = calloc(nc + 1, sizeof *g->start);
        uint32_t *cid = malloc(n * sizeof *cid);
        if (!g->start || !cid) {
            free(cid);
            return PFSPH_ENOMEM;
        }
        for (size_t i = 0; i < n; i++) {
            cid[i] = (uint32_t)(((cell[3 * i] - g->lo[0]) * g->ext[1] + (cell[3 * i + 1] - g->lo[1])) * g->ext[2] +
                                (cell[3 * i + 2] - g->lo[2]));
            g->start[cid[i] + 1]++;
        }
        for (size_t c = 0; c < nc; c++) g->start[c + 1] += g->start[c];
        for (size_t i = 0; i < n; i++) g->idx[g->start[cid[i]]++] = (uint32_t)i; /* stable */
        memmove(g->start + 1, g->start, nc * sizeof *g->start);
        g->start[0] = 0;
        for (size_t c = 0; c < nc; c++)
            if (g->start[c + 1] > g->start[c]) {
                uint32_t i = g->idx[g->start[c]];
                memcpy(g->ucell + 3 * g->nu, cell + 3 * (size_t)i, 3 * sizeof *cell);
                g->ustart[++g->nu] = g->start[c + 1];
            }
        free(cid);
        return PFSPH_OK;
    }
    /* sparse: LSD radix sort of (key, index), 16 bits a pass, stable */
    uint64_t *k0 = malloc(n * sizeof *k0), *k1 = malloc(n * sizeof *k1);
    uint32_t *i1 = malloc(n * sizeof *i1), *cnt = malloc(65536 * sizeof *cnt);
    g->ukey = malloc(n * sizeof *g->ukey);
    int rc = PFSPH_ENOMEM;
    if (!k0 || !k1 || !i1 || !cnt || !g->ukey) goto out;
    for (size_t i = 0; i < n; i++) {
        k0[i] = (uint64_t)pack3(cell[3 * i], cell[3 * i + 1], cell[3 * i + 2]);
        g->idx[i] = (uint32_t)i;
    }
    for (int pass = 0; pass < 4; pass++) {
        int sh = 16 * pass;
        memset(cnt, 0, 65536 * sizeof *cnt);
        for (size_t i = 0; i < n; i++) cnt[(k0[i] >> sh) & 0xffff]++;
        uint32_t s = 0;
        for (int c = 0; c < 65536; c++) {
            uint32_t t = cnt[c];
            cnt[c] = s;
            s += t;
        }
        for (size_t i = 0; i < n; i++) {
            uint32_t at = cnt[(k0[i] >> sh) & 0xffff]++;
            k1[at] = k0[i];
            i1[at] = g->idx[i];
        }
        uint64_t *tk = k0;
        k0 = k1;
        k1 = tk;
        memcpy(g->idx, i1, n * sizeof *i1);
    }
    for (size_t i = 0; i < n; i++)
        if (i == 0 || k0[i] != k0[i - 1]) {
            g->ukey[g->nu] = (int64_t)k0[i];
            memcpy(g->ucell + 3 * g->nu, cell + 3 * (size_t)g->idx[i], 3 * sizeof *cell);
            g->ustart[g->nu++] = (uint32_t)i;
            g->ustart[g->nu] = (uint32_t)(i + 1);
        } else g->ustart[g->nu] = (uint32_t)(i + 1);
    rc = PFSPH_OK;
out:
    free(k0);
    free(k1);
    free(i1);
    free(cnt);
    return rc;
}

/* the range in idx of the column of cells (i, j, k0..k1); b == e when empty */
void pfsph__surface_grid_col(const grid *g, int64_t i, int64_t j, int64_t k0, int64_t k1, uint32_t *b, uint32_t *e)
{
    *b = *e = 0;
    if (!g->nu) return;
    if (g->dense) {
        i -= g->lo[0];
        j -= g->lo[1];
        k0 -= g->lo[2];
        k1 -= g->lo[2];
        if (i < 0 || i >= g->ext[0] || j < 0 || j >= g->ext[1]) return;
        if (k0 < 0) k0 = 0;
        if (k1 >= g->ext[2]) k1 = g->ext[2] - 1;
        if (k0 > k1) return;
        size_t c = (size_t)((i * g->ext[1] + j) * g->ext[2]);
        *b = g->start[c + (size_t)k0];
        *e = g->start[c + (size_t)k1 + 1];
        return;
    }
    const int64_t lim = ((int64_t)1 << (COORD_BITS - 1)) - 1;
    if (i < -lim || i > lim || j < -lim || j > lim) return;
    if (k0 < -lim) k0 = -lim;
    if (k1 > lim) k1 = lim;
    if (k0 > k1) return;
    int64_t key0 = pack3(i, j, k0), key1 = pack3(i, j, k1);
    size_t lo = 0, hi = g->nu;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (g->ukey[mid] < key0) lo = mid + 1;
        else hi = mid;
    }
    size_t end = lo;
    while (end < g->nu && g->ukey[end] <= key1) end++;
    *b = g->ustart[lo];
    *e = g->ustart[end];
}

/* ---- sparse blocks: open-addressing hash of block keys (growth only) ---- */
static size_t hash64(int64_t k)
{
    uint64_t x = (uint64_t)k;
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    return (size_t)x;
}

int pfsph__surface_bmap_find(const bmap *m, int64_t key)
{
    if (!m->cap) return -1;
    size_t i = hash64(key) & (m->cap - 1);
    while (m->val[i] >= 0) {
        if (m->keys[i] == key) return m->val[i];
        i = (i + 1) & (m->cap - 1);
    }
    return -1;
}

int pfsph__surface_bmap_put(bmap *m, int64_t key, int32_t v)
{
    if (2 * (m->n + 1) > m->cap) {
        size_t nc = m->cap ? 2 * m->cap : 1024;
        int64_t *nk = malloc(nc * sizeof *nk);
        int32_t *nv = malloc(nc * sizeof *nv);
        if (!nk || !nv) {
            free(nk);
            free(nv);
            return PFSPH_ENOMEM;
        }
        for (size_t i = 0; i < nc; i++) nv[i] = -1;
        for (size_t i = 0; i < m->cap; i++)
            if (m->val[i] >= 0) {
                size_t j = hash64(m->keys[i]) & (nc - 1);
                while (nv[j] >= 0) j = (j + 1) & (nc - 1);
                nk[j] = m->keys[i];
                nv[j] = m->val[i];
            }
        free(m->keys);
        free(m->val);
        m->keys = nk;
        m->val = nv;
        m->cap = nc;
    }
    size_t i = hash64(key) & (m->cap - 1);
    while (m->val[i] >= 0) i = (i + 1) & (m->cap - 1);
    m->keys[i] = key;
    m->val[i] = v;
    m->n++;
    return PFSPH_OK;
}
