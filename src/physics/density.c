/* Number density delta_i (PF Eq. 23), fluid and boundary neighbours. */
#include "physics/density.h"

#include <omp.h>

#include "core/hits.h"
#include "core/nlist.h"
#include "physics/pair_terms.h"
#include "physics/solver.h"
#include "physics/stages.h"

void pfsph__number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y, const pfsph_real *z,
                           pfsph_real *nd)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_particles *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = ctx->fluid->n;
    const pfsph_hits_fn hits = pfsph_hits_select();
#pragma omp parallel
    {
        pfsph_hits H;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            pfsph_ranges r;
            const pfsph_real xi = x[i], yi = y[i], zi = z[i];
            pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
            pfsph_real s = 0;
            /* the terms of the grid walk in its order (the hits keep it): the same bits */
            PFSPH_HITS_WALK(hits, &H, r, x, y, z, xi, yi, zi, h2, UINT32_MAX, pfsph__terms_w(k, H.n, H.r2, H.t0);
                            for (int e = 0; e < H.n; e++) s += H.t0[e]);
            if (b->n) {
                pfsph_real sb = 0;
                pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
                PFSPH_HITS_WALK(hits, &H, r, b->x, b->y, b->z, xi, yi, zi, h2, UINT32_MAX,
                                pfsph__terms_w(k, H.n, H.r2, H.t0);
                                for (int e = 0; e < H.n; e++) sb += b->aux[H.j[e]] * H.t0[e]);
                s += sb * inv_v0;
            }
            nd[i] = s;
        }
    }
}

/* One thread's particles [i0, i1) of the one-walk build: densities (the terms of
 * pfsph__number_density in its order: the same bits), counts, and the entries while they fit in
 * [*pos, re) / [*bpos, bre) (fluid, boundary). The candidates are filtered and the kernel
 * values and derivatives computed in SIMD over each buffer of hits (core/hits.h,
 * physics/pair_terms.h), lane by lane the scalar expressions: the same bits as a scalar walk. */
static void density_list_block(const pfsph_ctx *ctx, pfsph_real *nd, pfsph_nlist *l, pfsph_nlist *lb, size_t i0,
                               size_t i1, size_t *pos_io, size_t re, size_t *bpos_io, size_t bre)
{
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h, inv_v0 = (pfsph_real)1 / ctx->V0;
    uint32_t *cnt = l->start + 1, *bcnt = lb->start + 1;
    uint32_t *restrict idx = l->idx, *restrict bidx = lb->idx;
    pfsph_real *restrict dw = l->dw, *restrict bdw = lb->dw;
    size_t pos = *pos_io, bpos = *bpos_io;
    const pfsph_hits_fn hits = pfsph_hits_select();
    pfsph_hits H;
    for (size_t i = i0; i < i1; i++) {
        pfsph_ranges r;
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        pfsph_real s = 0;
        const size_t p0 = pos;
        /* i itself is a hit (W(0) counts in delta_i) but no entry */
        PFSPH_HITS_WALK(
            hits, &H, r, f->x, f->y, f->z, xi, yi, zi, h2, UINT32_MAX, pfsph__terms_w(k, H.n, H.r2, H.t0);
            pfsph__terms_dwr(k, H.n, H.r2, H.t1); for (int e = 0; e < H.n; e++) {
                s += H.t0[e];
                if (H.j[e] != i) {
                    if (pos < re) {
                        idx[pos] = H.j[e];
                        dw[pos] = H.t1[e];
                    }
                    pos++;
                }
            });
        cnt[i] = (uint32_t)(pos - p0);
        const size_t b0 = bpos;
        if (b->n) {
            pfsph_real sb = 0;
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            PFSPH_HITS_WALK(
                hits, &H, r, b->x, b->y, b->z, xi, yi, zi, h2, UINT32_MAX, pfsph__terms_w(k, H.n, H.r2, H.t0);
                pfsph__terms_dwr(k, H.n, H.r2, H.t1); for (int e = 0; e < H.n; e++) {
                    sb += b->aux[H.j[e]] * H.t0[e];
                    if (bpos < bre) {
                        bidx[bpos] = H.j[e];
                        bdw[bpos] = H.t1[e];
                    }
                    bpos++;
                });
            s += sb * inv_v0;
        }
        bcnt[i] = (uint32_t)(bpos - b0);
        nd[i] = s;
    }
    *pos_io = pos;
    *bpos_io = bpos;
}

int pfsph__number_density_list(const pfsph_ctx *ctx, pfsph_real *nd, pfsph_nlist *l, pfsph_nlist *lb, double guess)
{
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = ctx->kern.h * ctx->kern.h;
    const size_t n = f->n;
    int T = omp_get_max_threads();
    if (T > PFSPH_NLIST_MAX_THREADS) T = PFSPH_NLIST_MAX_THREADS;
    /* a plan that cannot be made (the first build for T threads) leaves empty regions: the
     * walk then only counts, and finish fills by a second walk */
    int rc = pfsph_nlist_plan(l, n, T, guess), rcb = pfsph_nlist_plan(lb, n, T, guess / 4);
    if (rc == PFSPH_ENOMEM || rcb == PFSPH_ENOMEM) return PFSPH_ENOMEM;
    int over = rc != PFSPH_OK, bover = rcb != PFSPH_OK;
#pragma omp parallel num_threads(T) reduction(| : over, bover)
    {
        /* the particles of this thread as the plan has them: contiguous, in order */
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const size_t i0 = n * (size_t)t / (size_t)nt, i1 = n * (size_t)(t + 1) / (size_t)nt;
        /* fewer threads than planned: no room (count only) */
        const size_t rb = l->rbeg[t], re = nt == T ? l->rbeg[t + 1] : rb;
        const size_t brb = lb->rbeg[t], bre = nt == T ? lb->rbeg[t + 1] : brb;
        size_t pos = rb, bpos = brb;
        density_list_block(ctx, nd, l, lb, i0, i1, &pos, re, &bpos, bre);
        if (nt != T || pos > re) over = 1;
        else l->used[t] = pos - rb;
        if (nt != T || bpos > bre) bover = 1;
        else lb->used[t] = bpos - brb;
    }
    const pfsph_nlist_sets S = {ctx->grid, f->x, f->y, f->z, f->x, f->y, f->z, n, 1, h2, &ctx->kern};
    const pfsph_nlist_sets SB = {ctx->bgrid, b->x, b->y, b->z, f->x, f->y, f->z, n, 0, h2, &ctx->kern};
    rc = pfsph_nlist_finish(l, over, &S);
    return rc ? rc : pfsph_nlist_finish(lb, bover, &SB);
}

/* compression (rho / rho0 - 1) that stops a run as unstable */
#define PFSPH_DENSITY_ERROR_LIMIT 0.5

int pfsph__density_check(pfsph_step *st, pfsph_blowup *bad)
{
    pfsph_ctx *c = st->ctx;
    pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    pfsph_real ndmax = 0;
#pragma omp parallel for schedule(static) reduction(max : ndmax)
    for (size_t i = 0; i < n; i++) {
        f->rho[i] = c->mass[f->phase[i]] * c->nd[i];
        if (c->nd[i] > ndmax) ndmax = c->nd[i];
    }
    /* A particle compressed by half again its rest density means the pressure solve has lost
     * control (PCISPH aims at 0.5%, WCSPH at Mach 0.1 stays near 1%): stop before the pressure
     * solve turns it into NaN. */
    if ((double)ndmax / (double)c->nd0 - 1 > PFSPH_DENSITY_ERROR_LIMIT) {
        size_t wi = 0;
        for (size_t i = 1; i < n; i++)
            if (c->nd[i] > c->nd[wi]) wi = i;
        return pfsph__blowup(bad, wi, "relative density error", (double)ndmax / (double)c->nd0 - 1);
    }
    return PFSPH_OK;
}

/* Number density; with neighbour lists (solvers that walk the neighbours many times a step,
 * when they chose lists: st->lists) the density's walk also fills them: positions stay put
 * until the integration, and the loop drops the lists after any stage that writes positions or
 * the order. */
static int density_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    pfsph_ctx *c = st->ctx;
    pfsph_particles *f = c->fluid;
    c->nlist = c->nlist_b = NULL;
    if (st->lists) {
        const double q = (double)c->h / (double)c->spacing; /* a full neighbourhood, and a quarter */
        const double guess = 1.25 * (c->dim == 2 ? 3.14159 * q * q : 4.18879 * q * q * q);
        int rc = pfsph__number_density_list(c, c->nd, st->nlist, st->nlist_b, guess);
        if (rc)
            return pfsph_fail(err, rc, "cannot build the neighbour lists (%s)",
                              rc == PFSPH_ENOMEM ? "out of memory" : "internal error");
        c->nlist = st->nlist;
        c->nlist_b = st->nlist_b;
    } else {
        pfsph__number_density(c, f->x, f->y, f->z, c->nd);
    }
    return pfsph__density_check(st, bad);
}

const pfsph_stage_ops pfsph_stage_density = {.name = "density",
                                             .slot = PFSPH_STAGE_DENSITY,
                                             .reads = PFSPH_D_POS | PFSPH_D_ORDER,
                                             .writes = PFSPH_D_DENSITY | PFSPH_D_NLIST,
                                             .run = density_run};
