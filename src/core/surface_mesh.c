/* Surface reconstruction (Yu & Turk 2013, "Reconstructing surfaces of particle-based fluids using
 * anisotropic kernels"): weighted PCA per particle, smoothed kernel centres, a volume-fraction
 * colour field on sparse blocks grown along the surface, marching cubes with every cube split into
 * six tetrahedra (Kuhn), vertices welded by edge ownership. docs/surfaces.md gives the choices.
 *
 * Speed (docs/benchmarks.md#surface-meshes): the neighbour searches use flat sorted cell lists
 * (one counting sort, contiguous columns of cells), the PCA and the field are single-precision
 * loops the compiler vectorises, the field is splatted kernel by kernel into rows of eight nodes,
 * and marching cubes reads a case table built once per call from the tetrahedral split, with
 * vertices numbered through a per-block edge table (no hashing, no sorting of vertices).
 *
 * This file grows the blocks along the surface, welds the blocks' triangles into one mesh and
 * smooths it; surface_mesh_internal.h lists the other pieces. */
#include "pfsph/surface_mesh.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/surface_mesh_internal.h"

static int block_cmp(const void *a, const void *b)
{
    int64_t x = ((const block *)a)->key, y = ((const block *)b)->key;
    return x < y ? -1 : (x > y);
}

/* Taubin lambda|mu smoothing over the welded mesh's vertex graph */
int pfsph__surface_taubin(pfsph_surface_mesh *m, size_t v0, size_t t0, int iters)
{
    size_t nv = m->nverts - v0, nt = m->ntris - t0;
    if (!nv || iters <= 0) return PFSPH_OK;
    int64_t *e = malloc(6 * nt * sizeof *e);
    uint32_t *start = calloc(nv + 1, sizeof *start), *adj = NULL;
    double *tmp = malloc(3 * nv * sizeof *tmp);
    int rc = PFSPH_ENOMEM;
    if (!e || !start || !tmp) goto out;
    size_t ne = 0;
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int64_t a = m->tri[3 * (t0 + t) + k] - v0, b = m->tri[3 * (t0 + t) + (k + 1) % 3] - v0;
            e[ne++] = (a << 32) | b;
            e[ne++] = (b << 32) | a;
        }
    qsort(e, ne, sizeof *e, i64_cmp);
    size_t u = 0;
    for (size_t i = 0; i < ne; i++)
        if (!u || e[i] != e[u - 1]) e[u++] = e[i];
    adj = malloc((u ? u : 1) * sizeof *adj);
    if (!adj) goto out;
    for (size_t i = 0; i < u; i++) {
        start[(e[i] >> 32) + 1]++;
        adj[i] = (uint32_t)(e[i] & 0xffffffff);
    }
    for (size_t i = 0; i < nv; i++) start[i + 1] += start[i];
    for (int it = 0; it < 2 * iters; it++) {
        double f = it % 2 ? -0.53 : 0.5;
        double *v = m->v + 3 * v0;
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < nv; i++) {
            double s[3] = {0, 0, 0};
            uint32_t k0 = start[i], k1 = start[i + 1];
            for (uint32_t k = k0; k < k1; k++)
                for (int a = 0; a < 3; a++) s[a] += v[3 * adj[k] + a];
            for (int a = 0; a < 3; a++)
                tmp[3 * i + a] = k1 > k0 ? v[3 * i + a] + f * (s[a] / (k1 - k0) - v[3 * i + a]) : v[3 * i + a];
        }
        memcpy(v, tmp, 3 * nv * sizeof *tmp);
    }
    rc = PFSPH_OK;
out:
    free(e);
    free(start);
    free(adj);
    free(tmp);
    return rc;
}

static int append(pfsph_surface_mesh *m, size_t nv, size_t nt)
{
    double *v = realloc(m->v, 3 * (m->nverts + nv) * sizeof *v + 1);
    if (!v) return PFSPH_ENOMEM;
    m->v = v;
    float *n = realloc(m->n, 3 * (m->nverts + nv) * sizeof *n + 1);
    if (!n) return PFSPH_ENOMEM;
    m->n = n;
    uint32_t *t = realloc(m->tri, 3 * (m->ntris + nt) * sizeof *t + 1);
    if (!t) return PFSPH_ENOMEM;
    m->tri = t;
    uint8_t *p = realloc(m->phase, m->ntris + nt + 1);
    if (!p) return PFSPH_ENOMEM;
    m->phase = p;
    return PFSPH_OK;
}

static long block_find(const block *bl, size_t nb, int64_t key)
{
    size_t lo = 0, hi = nb;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (bl[mid].key < key) lo = mid + 1;
        else hi = mid;
    }
    return lo < nb && bl[lo].key == key ? (long)lo : -1;
}

static long edge_find(const block *b, uint32_t E)
{
    size_t lo = 0, hi = b->nv;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (b->ve[mid] < E) lo = mid + 1;
        else hi = mid;
    }
    return lo < b->nv && b->ve[lo] == E ? (long)lo : -1;
}

static void blocks_free(block *bl, size_t nb)
{
    for (size_t i = 0; bl && i < nb; i++) {
        free(bl[i].f);
        free(bl[i].ve);
        free(bl[i].vp);
        free(bl[i].vn);
        free(bl[i].tri);
    }
    free(bl);
}

/* one phase's points into m (appended) */
static int reconstruct_one(const double *x, size_t n, uint8_t phase, const pfsph_surface_opts *o, float iso,
                           double drop, const mc_table *T, pfsph_surface_mesh *m, pfsph_error *err)
{
    const double cellw = o->cell * o->spacing;
    kern *K = malloc((n ? n : 1) * sizeof *K);
    uint8_t *surf = malloc(n ? n : 1);
    int32_t *kc = malloc(3 * (n ? n : 1) * sizeof *kc);
    block *bl = NULL;
    size_t nb = 0, cb = 0, kept = 0;
    bmap map = {0};
    grid kg = {0};
    int64_t *pend = NULL;
    uint32_t *need = NULL;
    int32_t *src = NULL; /* 3 per block: the blocks at +y, +z, +y+z that hold its face rows, or -1 */
    size_t *voff = NULL, *toff = NULL;
    int rc = PFSPH_ENOMEM;
    if (!K || !surf || !kc) goto out;
    float rmax;
    double w0 = omp_get_wtime();
    if ((rc = pfsph__surface_kernels(x, n, o, drop, K, surf, &rmax))) goto out;
    double w1 = omp_get_wtime();
    m->seconds[0] += w1 - w0;
    /* the kernels by block: a block reads the block cells within R of its own */
    for (size_t i = 0; i < n; i++)
        for (int u = 0; u < 3; u++) kc[3 * i + u] = floordiv(K[i].I[u], BS);
    if ((rc = pfsph__surface_grid_build(&kg, kc, n))) goto out;
    rc = PFSPH_ENOMEM;
    const int R = (int)floorf(rmax / BS) + 1;
    /* seeds: the blocks of the particles near the surface; growth finds the rest */
    size_t np = 0, cp = 1024;
    pend = malloc(cp * sizeof *pend);
    if (!pend) goto out;
    for (size_t i = 0; i < n; i++) {
        if (!surf[i]) continue;
        m->surface_particles++;
        if (np == cp) {
            int64_t *t = realloc(pend, 2 * cp * sizeof *t);
            if (!t) goto out;
            pend = t;
            cp *= 2;
        }
        pend[np++] = pack3(kc[3 * i], kc[3 * i + 1], kc[3 * i + 2]);
    }
    size_t live = 0, peak = 0;
    while (np) {
        qsort(pend, np, sizeof *pend, i64_cmp);
        size_t u = 0;
        for (size_t i = 0; i < np; i++)
            if ((!u || pend[i] != pend[u - 1]) && pfsph__surface_bmap_find(&map, pend[i]) < 0) pend[u++] = pend[i];
        np = u;
        if (!np) break;
        size_t first = nb;
        if (nb + np > cb) {
            size_t nc = cb ? cb : 256;
            while (nc < nb + np) nc *= 2;
            block *t = realloc(bl, nc * sizeof *t);
            uint32_t *tn = realloc(need, nc * sizeof *tn);
            int32_t *ts = realloc(src, 3 * nc * sizeof *ts);
            if (t) bl = t;
            if (tn) need = tn;
            if (ts) src = ts;
            if (!t || !tn || !ts) goto out;
            cb = nc;
        }
        for (size_t i = 0; i < np; i++) {
            block *b = bl + nb;
            memset(b, 0, sizeof *b);
            b->key = pend[i];
            unpack3(pend[i], b->b);
            b->f = malloc(BNODES * sizeof *b->f);
            nb++;
            if (!b->f || pfsph__surface_bmap_put(&map, pend[i], (int32_t)(nb - 1))) goto out;
        }
        live += np;
        if (live > peak) peak = live;
        /* The node rows on a block's +y and +z faces are the first rows of the blocks there: taken
         * from those blocks where they exist (from earlier generations or this one), computed
         * otherwise. Either way the same bits (a node's sum is the same in every block). */
        static const int NB_OFF[3][3] = {{0, 1, 0}, {0, 0, 1}, {0, 1, 1}};
        uint64_t *rows = malloc((nb - first) * sizeof *rows);
        if (!rows) goto out;
        for (size_t i = first; i < nb; i++) {
            uint64_t m = 0;
            for (int c = 0; c < BS; c++) m |= (uint64_t)0x7f << (BN * c); /* own rows: b, c < BS */
            for (int g = 0; g < 3; g++) {
                int j = pfsph__surface_bmap_find(&map,
                                                 pack3((int64_t)bl[i].b[0] + NB_OFF[g][0],
                                                       (int64_t)bl[i].b[1] + NB_OFF[g][1],
                                                       (int64_t)bl[i].b[2] + NB_OFF[g][2]));
                src[3 * i + g] = j >= 0 && bl[j].f ? j : -1;
                if (src[3 * i + g] >= 0) continue;
                if (g == 0)
                    for (int c = 0; c < BS; c++) m |= (uint64_t)1 << (BS + BN * c);
                else if (g == 1) m |= (uint64_t)0x7f << (BN * BS);
                else m |= (uint64_t)1 << (BS + BN * BS);
            }
            rows[i - first] = m;
        }
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t i = first; i < nb; i++) pfsph__surface_block_field(bl + i, K, &kg, R, rows[i - first]);
        free(rows);
#pragma omp parallel for schedule(dynamic, 4)
        for (size_t i = first; i < nb; i++) {
            float *f = bl[i].f;
            if (src[3 * i] >= 0)
                for (int c = 0; c < BS; c++)
                    memcpy(f + NIDX(0, BS, c), bl[src[3 * i]].f + NIDX(0, 0, c), BN * sizeof *f);
            if (src[3 * i + 1] >= 0)
                for (int b = 0; b < BS; b++)
                    memcpy(f + NIDX(0, b, BS), bl[src[3 * i + 1]].f + NIDX(0, b, 0), BN * sizeof *f);
            if (src[3 * i + 2] >= 0) memcpy(f + NIDX(0, BS, BS), bl[src[3 * i + 2]].f + NIDX(0, 0, 0), BN * sizeof *f);
            int any;
            need[i] = pfsph__surface_block_needs(f, iso, &any);
            if (!any) need[i] |= 1u << 31; /* not crossed: not kept */
        }
        /* crossed cells on a block's rim call for the blocks of their neighbour cells */
        np = 0;
        for (size_t i = first; i < nb; i++) {
            for (int s = 0; s < 27; s++) {
                if (!(need[i] >> s & 1)) continue;
                if (np + 1 > cp) {
                    int64_t *t = realloc(pend, 2 * cp * sizeof *t);
                    if (!t) goto out;
                    pend = t;
                    cp *= 2;
                }
                pend[np++] = pack3((int64_t)bl[i].b[0] + s % 3 - 1, (int64_t)bl[i].b[1] + s / 3 % 3 - 1,
                                   (int64_t)bl[i].b[2] + s / 9 - 1);
            }
            if (need[i] >> 31) {
                free(bl[i].f);
                bl[i].f = NULL;
                live--;
            }
        }
    }
    /* compact and sort the kept blocks: the order of the output */
    for (size_t i = 0; i < nb; i++)
        if (bl[i].f) bl[kept++] = bl[i];
    nb = kept;
    qsort(bl, kept, sizeof *bl, block_cmp);
    m->blocks += kept;
    if (peak > m->blocks_peak) m->blocks_peak = peak;
    if (peak * BNODES * sizeof(float) > m->grid_bytes) m->grid_bytes = peak * BNODES * sizeof(float);
    double w2 = omp_get_wtime();
    m->seconds[1] += w2 - w1;
    int fail = 0;
#pragma omp parallel reduction(| : fail)
    {
        march_scratch *S = malloc(sizeof *S);
        if (!S) fail = 1;
        else
            for (int i = 0; i < NEDGE; i++) S->tab[i] = -1;
#pragma omp for schedule(dynamic, 1)
        for (size_t i = 0; i < kept; i++)
            if (!fail && pfsph__surface_march_block(S, bl + i, T, iso, cellw)) fail = 1;
        free(S);
    }
    if (fail) goto out;
    double w3 = omp_get_wtime();
    m->seconds[2] += w3 - w2;
    /* the mesh: blocks in key order, each its owned vertices in edge order */
    voff = malloc((kept + 1) * sizeof *voff);
    toff = malloc((kept + 1) * sizeof *toff);
    if (!voff || !toff) goto out;
    voff[0] = m->nverts;
    toff[0] = m->ntris;
    for (size_t i = 0; i < kept; i++) {
        voff[i + 1] = voff[i] + bl[i].nv;
        toff[i + 1] = toff[i] + bl[i].nt;
    }
    if (voff[kept] > UINT32_MAX) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "surface: more than 2^32 vertices");
        goto out;
    }
    if ((rc = append(m, voff[kept] - m->nverts, toff[kept] - m->ntris))) goto out;
    rc = PFSPH_ENOMEM;
#pragma omp parallel for schedule(dynamic, 4) reduction(| : fail)
    for (size_t i = 0; i < kept; i++) {
        const block *b = bl + i;
        memcpy(m->v + 3 * voff[i], b->vp, 3 * b->nv * sizeof *b->vp);
        memcpy(m->n + 3 * voff[i], b->vn, 3 * b->nv * sizeof *b->vn);
        memset(m->phase + toff[i], phase, b->nt);
        uint32_t *t = m->tri + 3 * toff[i];
        for (uint32_t k = 0; k < 3 * b->nt; k++) {
            uint32_t r = b->tri[k];
            if (!(r & FOREIGN)) {
                t[k] = (uint32_t)(voff[i] + r);
                continue;
            }
            int o = (int)(r >> 12 & 7);
            long j = block_find(
                bl, kept,
                pack3((int64_t)b->b[0] + (o & 1), (int64_t)b->b[1] + (o >> 1 & 1), (int64_t)b->b[2] + (o >> 2)));
            long v = j < 0 ? -1 : edge_find(bl + j, r & 0xfff);
            if (v < 0) fail = 1; /* cannot happen: the owner holds every crossed edge of its cells */
            else t[k] = (uint32_t)(voff[j] + (size_t)v);
        }
    }
    if (fail) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "surface: internal error: a vertex without its block");
        goto out;
    }
    size_t v0 = m->nverts, t0 = m->ntris;
    m->nverts = voff[kept];
    m->ntris = toff[kept];
    rc = pfsph__surface_taubin(m, v0, t0, o->smooth_iters);
    m->seconds[3] += omp_get_wtime() - w3;
out:
    if (rc == PFSPH_ENOMEM && !err->msg[0]) pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    blocks_free(bl, nb);
    free(map.keys);
    free(map.val);
    free(pend);
    free(need);
    free(src);
    free(voff);
    free(toff);
    pfsph__surface_grid_free(&kg);
    free(K);
    free(surf);
    free(kc);
    return rc;
}

int pfsph_surface_reconstruct(const double *x, const uint8_t *phase, size_t n, const pfsph_surface_opts *in,
                              pfsph_surface_mesh *m, pfsph_error *err)
{
    memset(m, 0, sizeof *m);
    err->msg[0] = 0;
    pfsph_surface_opts o;
    int rc0 = pfsph__surface_resolve_checked(in, true, &o, err);
    if (rc0 != PFSPH_OK) return rc0;
    const double reach = (double)(1 << 18) * o.cell * o.spacing; /* the grid's integer coordinates */
    for (size_t i = 0; i < 3 * n; i++) {
        if (!isfinite(x[i]))
            return pfsph_fail(err, PFSPH_EINPUT, "surface: particle %zu has a non-finite position", i / 3);
        if (fabs(x[i]) > reach)
            return pfsph_fail(err, PFSPH_EINPUT,
                              "surface: particle %zu is %g m from the origin, beyond the meshing "
                              "grid's %g m (2^18 cells)",
                              i / 3, fabs(x[i]), reach);
    }
    const float iso = (float)(o.iso > 0 ? o.iso : pfsph_surface_calibrate_iso(&o));
    const double drop = pfsph__surface_drop_scale(&o, iso);
    mc_table *T = malloc(sizeof *T);
    if (!T) return pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    pfsph__surface_mc_table(T);
    int present[256] = {0};
    for (size_t i = 0; i < n; i++) present[phase ? phase[i] : 0]++;
    double *xs = malloc(3 * (n ? n : 1) * sizeof *xs);
    if (!xs) {
        free(T);
        return pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    }
    int rc = PFSPH_OK;
    for (int p = 0; p < 256 && !rc; p++) {
        if (!present[p]) continue;
        size_t k = 0;
        for (size_t i = 0; i < n; i++)
            if ((phase ? phase[i] : 0) == p) {
                memcpy(xs + 3 * k, x + 3 * i, 3 * sizeof *xs);
                k++;
            }
        rc = reconstruct_one(xs, k, (uint8_t)p, &o, iso, drop, T, m, err);
    }
    free(xs);
    free(T);
    if (rc) pfsph_surface_mesh_free(m);
    return rc;
}

void pfsph_surface_mesh_free(pfsph_surface_mesh *m)
{
    if (!m) return;
    free(m->v);
    free(m->n);
    free(m->tri);
    free(m->phase);
    free(m->vel);
    memset(m, 0, sizeof *m);
}
