/* Counting-sort uniform grid (see grid.h for the layout and why). */
#include "pfsph/grid.h"

#include "core/stage.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int pfsph_grid_init(pfsph_grid *g, int dim, const pfsph_real lo[3], const pfsph_real hi[3], pfsph_real cell)
{
    memset(g, 0, sizeof(*g));
    g->dim = dim;
    g->cell = cell;
    g->reach = 1;
    g->reach_far = 1;
    g->inv_cell = (pfsph_real)1 / cell;
    g->ncells = 1;
    for (int a = 0; a < 3; a++) {
        g->lo[a] = lo[a];
        g->hi[a] = hi[a];
        g->keep_lo[a] = lo[a];
        g->keep_hi[a] = hi[a];
        if (a == 2 && dim == 2) {
            g->nc[a] = 1;
            continue;
        }
        double n = ceil((double)(hi[a] - lo[a]) / (double)cell);
        if (n < 1) n = 1;
        if (n > 1e7) return PFSPH_ENOMEM;
        g->nc[a] = (int)n;
        g->ncells *= (size_t)n;
    }
    if (g->ncells > ((size_t)1 << 31)) return PFSPH_ENOMEM;
    g->start = calloc(g->ncells + 1, sizeof(uint32_t));
    return g->start ? PFSPH_OK : PFSPH_ENOMEM;
}

void pfsph_grid_free(pfsph_grid *g)
{
    if (!g) return;
    free(g->near);
    free(g->near_far);
    free(g->start);
    free(g->key);
    free(g->perm);
    free(g->tmp);
    memset(g, 0, sizeof(*g));
}

/* *dst: the occupied cells dilated by R cells along x, then y, then z (a box dilation is
 * separable), so (*dst)[c] = 0 exactly when a walk of reach R from a point in c finds no
 * particle. Out of memory: *dst = NULL, and the queries answer 1 (walk). */
static void mark_near(pfsph_grid *g, int R, uint8_t **dst_)
{
    const size_t nc = g->ncells;
    uint8_t *a = *dst_ ? *dst_ : malloc(nc), *t = malloc(nc);
    if (!a || !t) {
        free(a);
        free(t);
        *dst_ = NULL;
        return;
    }
    *dst_ = a;
    /* cell by cell in parallel: each byte depends on the pass's source only (2.7e8 cells in the
     * 128 m cube of the diffuse paper's table 1) */
#pragma omp parallel for schedule(static)
    for (size_t c = 0; c < nc; c++) a[c] = g->start[c + 1] > g->start[c];
    const size_t n0 = (size_t)g->nc[0], n1 = (size_t)g->nc[1], n2 = (size_t)g->nc[2];
    const size_t stride[3] = {1, n0, n0 * n1}, len[3] = {n0, n1, n2};
    for (int ax = 0; ax < (g->dim == 3 ? 3 : 2); ax++) {
        uint8_t *src = ax % 2 ? t : a, *dst = ax % 2 ? a : t;
        const size_t s = stride[ax], L = len[ax];
#pragma omp parallel for schedule(static)
        for (size_t c = 0; c < nc; c++) {
            const size_t k = c / s % L; /* c's index along ax */
            const size_t lo = k >= (size_t)R ? k - (size_t)R : 0, hi = k + (size_t)R < L ? k + (size_t)R : L - 1;
            uint8_t v = 0;
            for (size_t q = lo; q <= hi; q++) v |= src[c + q * s - k * s];
            dst[c] = v;
        }
    }
    if (g->dim == 3) memcpy(a, t, nc); /* three passes ended in t */
    free(t);
}

static int ensure(pfsph_grid *g, size_t n)
{
    if (n <= g->cap) return PFSPH_OK;
    size_t cap = n + n / 4 + 64;
    uint32_t *k = realloc(g->key, cap * sizeof(uint32_t));
    if (!k) return PFSPH_ENOMEM;
    g->key = k;
    uint32_t *p = realloc(g->perm, cap * sizeof(uint32_t));
    if (!p) return PFSPH_ENOMEM;
    g->perm = p;
    void *t = realloc(g->tmp, cap * sizeof(pfsph_real));
    if (!t) return PFSPH_ENOMEM;
    g->tmp = t;
    g->cap = cap;
    return PFSPH_OK;
}

void pfsph_grid_release_scratch(pfsph_grid *g)
{
    free(g->key);
    free(g->perm);
    free(g->tmp);
    g->key = g->perm = NULL;
    g->tmp = NULL;
    g->cap = 0;
}

int pfsph_grid_sort(pfsph_grid *g, pfsph_particles *ps, size_t *removed)
{
    int rc = ensure(g, ps->n);
    if (rc) return rc;
    return pfsph_grid_sort_in(g, ps, removed, g->key, g->perm, g->tmp);
}

int pfsph_grid_sort_in(pfsph_grid *g, pfsph_particles *ps, size_t *removed, uint32_t *gkey, uint32_t *gperm, void *tmp)
{
    size_t n = ps->n;
    const uint32_t outside = UINT32_MAX;
    const pfsph_real *pos[3] = {ps->x, ps->y, ps->z};
    const int dim = g->dim;

#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        size_t lin = 0, stride = 1;
        uint32_t key = 0;
        for (int a = 0; a < dim; a++) {
            pfsph_real v = pos[a][i];
            /* written so that NaN fails the test */
            if (!(v >= g->keep_lo[a] && v <= g->keep_hi[a] && v >= g->lo[a] && v <= g->hi[a])) {
                key = outside;
                break;
            }
            int c = (int)((v - g->lo[a]) * g->inv_cell);
            if (c >= g->nc[a]) c = g->nc[a] - 1;
            lin += (size_t)c * stride;
            stride *= (size_t)g->nc[a];
        }
        if (key != outside) key = (uint32_t)lin;
        gkey[i] = key;
    }

    /* Counting sort, stable: the same order for any thread count. */
    memset(g->start, 0, (g->ncells + 1) * sizeof(uint32_t));
    size_t kept = 0;
    for (size_t i = 0; i < n; i++)
        if (gkey[i] != outside) {
            g->start[gkey[i] + 1]++;
            kept++;
        }
    for (size_t c = 0; c < g->ncells; c++) g->start[c + 1] += g->start[c];
    /* use start[c] as the running insertion cursor, then restore */
    for (size_t i = 0; i < n; i++) {
        uint32_t k = gkey[i];
        if (k != outside) gperm[g->start[k]++] = (uint32_t)i;
    }
    for (size_t c = g->ncells; c > 0; c--) g->start[c] = g->start[c - 1];
    g->start[0] = 0;

    if (removed) *removed += n - kept;
    if (g->want_near) {
        mark_near(g, g->reach, &g->near);
        if (g->reach_far > g->reach) mark_near(g, g->reach_far, &g->near_far);
    }
    return pfsph_particles_permute(ps, gperm, kept, tmp);
}

size_t pfsph_neighbors_brute(const pfsph_particles *ps, size_t i, pfsph_real radius, uint32_t *out, size_t max)
{
    size_t cnt = 0;
    double r2 = (double)radius * (double)radius;
    for (size_t j = 0; j < ps->n; j++) {
        if (j == i) continue;
        double dx = (double)ps->x[i] - ps->x[j], dy = (double)ps->y[i] - ps->y[j], dz = (double)ps->z[i] - ps->z[j];
        if (dx * dx + dy * dy + dz * dz < r2) {
            if (cnt < max) out[cnt] = (uint32_t)j;
            cnt++;
        }
    }
    return cnt;
}

/* The grid stage: the fluid sorted into its cells (particles that left the domain removed), in
 * the order every later walk of the step relies on. */
static int grid_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    st->removed_before = st->removed;
    /* the sort's keys, permutation and buffer in the accelerations' arrays: per-particle arrays
     * of the step hold nothing across the sort (it reorders the particles under them), and the
     * accelerations are written afresh after it (docs/benchmarks.md, issue 28: 12 B per particle) */
    pfsph_ctx *c = st->ctx;
    if (pfsph_grid_sort_in(c->grid, c->fluid, &st->removed, (uint32_t *)c->ax, (uint32_t *)c->ay, c->az))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sorting the fluid into the grid");
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_grid = {.name = "grid",
                                          .slot = PFSPH_STAGE_GRID,
                                          .reads = PFSPH_D_POS,
                                          .writes = PFSPH_D_ORDER | PFSPH_D_ACC, /* ACC: lent to the sort */
                                          .run = grid_run};
