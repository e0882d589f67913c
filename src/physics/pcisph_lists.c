/* PCISPH's density and pressure walks over once-per-step neighbour lists (pcisph_lists.h): a
 * grid walk at radius h tests ~190 candidates in 3D for ~30 neighbours, and the correction loop
 * walked twice per iteration; the profile of the interactive wetting scene had the candidate
 * tests (hits) at 43 % of the step (docs/interactive.md, "Profile"). */
#include "physics/pcisph_lists.h"

#include <omp.h>
#include <stdlib.h>

#include "core/hits.h"
#include "physics/pair_terms.h"

/* one thread's particles [i0, i1): their fluid and boundary neighbours within h, written from
 * *pos / *bpos while they fit before re / bre; the counts in the lists' start + 1 */
static void build_block(const pfsph_ctx *ctx, pfsph_nlist *l, pfsph_nlist *lb, size_t i0, size_t i1, size_t *pos_io,
                        size_t re, size_t *bpos_io, size_t bre)
{
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = ctx->kern.h * ctx->kern.h;
    uint32_t *cnt = l->start + 1, *bcnt = lb->start + 1;
    size_t pos = *pos_io, bpos = *bpos_io;
    const pfsph_hits_fn hits = pfsph_hits_select();
    pfsph_hits H;
    for (size_t i = i0; i < i1; i++) {
        pfsph_ranges r;
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        const size_t p0 = pos;
        PFSPH_HITS_WALK(
            hits, &H, r, f->x, f->y, f->z, xi, yi, zi, h2, (uint32_t)i, for (int e = 0; e < H.n; e++) {
                if (pos < re) l->idx[pos] = H.j[e];
                pos++;
            });
        cnt[i] = (uint32_t)(pos - p0);
        const size_t b0 = bpos;
        if (b->n && pfsph_grid_near(ctx->bgrid, xi, yi, zi)) {
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            PFSPH_HITS_WALK(
                hits, &H, r, b->x, b->y, b->z, xi, yi, zi, h2, UINT32_MAX, for (int e = 0; e < H.n; e++) {
                    if (bpos < bre) lb->idx[bpos] = H.j[e];
                    bpos++;
                });
        }
        bcnt[i] = (uint32_t)(bpos - b0);
    }
    *pos_io = pos;
    *bpos_io = bpos;
}

int pfsph__pcisph_lists(const pfsph_ctx *ctx, pfsph_nlist *l, pfsph_nlist *lb)
{
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = ctx->kern.h * ctx->kern.h;
    const size_t n = f->n;
    int T = omp_get_max_threads();
    if (T > PFSPH_NLIST_MAX_THREADS) T = PFSPH_NLIST_MAX_THREADS;
    const double q = (double)ctx->h / (double)ctx->spacing;
    const double guess = 1.25 * (ctx->dim == 2 ? 3.14159 * q * q : 4.18879 * q * q * q);
    int rc = pfsph_nlist_plan(l, n, T, guess), rcb = pfsph_nlist_plan(lb, n, T, guess / 4);
    if (rc == PFSPH_ENOMEM || rcb == PFSPH_ENOMEM) return PFSPH_ENOMEM;
    int over = rc != PFSPH_OK, bover = rcb != PFSPH_OK;
#pragma omp parallel num_threads(T) reduction(| : over, bover)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const size_t i0 = n * (size_t)t / (size_t)nt, i1 = n * (size_t)(t + 1) / (size_t)nt;
        const size_t rb = l->rbeg[t], re = nt == T ? l->rbeg[t + 1] : rb;
        const size_t brb = lb->rbeg[t], bre = nt == T ? lb->rbeg[t + 1] : brb;
        size_t pos = rb, bpos = brb;
        build_block(ctx, l, lb, i0, i1, &pos, re, &bpos, bre);
        if (nt != T || pos > re) over = 1;
        else l->used[t] = pos - rb;
        if (nt != T || bpos > bre) bover = 1;
        else lb->used[t] = bpos - brb;
    }
    /* no kernel: the lists' dw is not read (the predicted positions move the pairs) */
    const pfsph_nlist_sets S = {ctx->grid, f->x, f->y, f->z, f->x, f->y, f->z, n, 1, h2, NULL};
    const pfsph_nlist_sets SB = {ctx->bgrid, b->x, b->y, b->z, f->x, f->y, f->z, n, 0, h2, NULL};
    rc = pfsph_nlist_finish(l, over, &S);
    return rc ? rc : pfsph_nlist_finish(lb, bover, &SB);
}

/* The listed targets idx[*e .. end) of point (x, y, z) within h2 into H (x_ij, r2), as many as
 * fit; *e moves past those taken. */
static inline void gather(pfsph_hits *H, const uint32_t *idx, uint32_t *e, uint32_t end, const pfsph_real *tx,
                          const pfsph_real *ty, const pfsph_real *tz, pfsph_real x, pfsph_real y, pfsph_real z,
                          pfsph_real h2)
{
    int m = H->n;
    uint32_t q = *e;
    for (; q < end && m < PFSPH_HITS_CAP; q++) {
        const uint32_t j = idx[q];
        const pfsph_real dx = x - tx[j], dy = y - ty[j], dz = z - tz[j];
        const pfsph_real r2 = dx * dx + dy * dy + dz * dz;
        H->j[m] = j;
        H->dx[m] = dx;
        H->dy[m] = dy;
        H->dz[m] = dz;
        H->r2[m] = r2;
        m += r2 < h2; /* kept only within h (branch-free) */
    }
    H->n = m;
    *e = q;
}

void pfsph__pcisph_density(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb, const pfsph_real *x,
                           const pfsph_real *y, const pfsph_real *z, pfsph_real *nd)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h, w0 = pfsph_kernel_w0(k);
    const pfsph_particles *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = ctx->fluid->n;
#pragma omp parallel
    {
        pfsph_hits H;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real xi = x[i], yi = y[i], zi = z[i];
            pfsph_real s = w0;
            for (uint32_t e = l->start[i], end = l->start[i + 1]; e < end;) {
                H.n = 0;
                gather(&H, l->idx, &e, end, x, y, z, xi, yi, zi, h2);
                pfsph__terms_w(k, H.n, H.r2, H.t0);
                for (int q = 0; q < H.n; q++) s += H.t0[q];
            }
            pfsph_real sb = 0;
            for (uint32_t e = lb->start[i], end = lb->start[i + 1]; e < end;) {
                H.n = 0;
                gather(&H, lb->idx, &e, end, b->x, b->y, b->z, xi, yi, zi, h2);
                pfsph__terms_w(k, H.n, H.r2, H.t0);
                for (int q = 0; q < H.n; q++) sb += b->aux[H.j[q]] * H.t0[q];
            }
            nd[i] = s + sb * inv_v0;
        }
    }
}

void pfsph__pcisph_pressure(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb, const pfsph_real *x,
                            const pfsph_real *y, const pfsph_real *z, const pfsph_real *nd, const pfsph_real *p,
                            pfsph_real *apx, pfsph_real *apy, pfsph_real *apz)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = f->n;
#pragma omp parallel
    {
        pfsph_hits H;
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real xi = x[i], yi = y[i], zi = z[i];
            const pfsph_real pi = p[i] / (nd[i] * nd[i]);
            pfsph_real ax = 0, ay = 0, az = 0;
            for (uint32_t e = l->start[i], end = l->start[i + 1]; e < end;) {
                H.n = 0;
                gather(&H, l->idx, &e, end, x, y, z, xi, yi, zi, h2);
                pfsph__terms_dwr(k, H.n, H.r2, H.t0);
                for (int q = 0; q < H.n; q++) {
                    const uint32_t j = H.j[q];
                    const pfsph_real s = (pi + p[j] / (nd[j] * nd[j])) * H.t0[q];
                    ax += s * H.dx[q];
                    ay += s * H.dy[q];
                    az += s * H.dz[q];
                }
            }
            if (pi > 0) {
                /* Akinci 2012: the wall pushes with p_i alone (pressure.c) */
                pfsph_real bx = 0, by = 0, bz = 0;
                for (uint32_t e = lb->start[i], end = lb->start[i + 1]; e < end;) {
                    H.n = 0;
                    gather(&H, lb->idx, &e, end, b->x, b->y, b->z, xi, yi, zi, h2);
                    pfsph__terms_dwr(k, H.n, H.r2, H.t0);
                    for (int q = 0; q < H.n; q++) {
                        const pfsph_real s = b->aux[H.j[q]] * H.t0[q];
                        bx += s * H.dx[q];
                        by += s * H.dy[q];
                        bz += s * H.dz[q];
                    }
                }
                const pfsph_real wb = pi * inv_v0;
                ax += wb * bx;
                ay += wb * by;
                az += wb * bz;
            }
            const pfsph_real inv_m = -(pfsph_real)1 / ctx->mass[f->phase[i]];
            apx[i] = inv_m * ax;
            apy[i] = inv_m * ay;
            apz[i] = inv_m * az;
        }
    }
}

int pfsph__pcisph_pairs_reserve(pfsph_pcisph_pairs *c, size_t m)
{
    m += 8; /* the eight-lane sums read up to 7 entries past the last (pair_terms.h) */
    if (m <= c->cap) return PFSPH_OK;
    const size_t cap = m + m / 8 + 64;
    pfsph_real **arr[4] = {&c->dx, &c->dy, &c->dz, &c->dw};
    for (int a = 0; a < 4; a++) {
        pfsph_real *q = realloc(*arr[a], cap * sizeof(pfsph_real));
        if (!q) return PFSPH_ENOMEM; /* the grown ones stay grown; cap unchanged */
        *arr[a] = q;
    }
    c->cap = cap;
    return PFSPH_OK;
}

void pfsph__pcisph_pairs_free(pfsph_pcisph_pairs *c)
{
    free(c->dx);
    free(c->dy);
    free(c->dz);
    free(c->dw);
    *c = (pfsph_pcisph_pairs){0};
}

void pfsph__pcisph_density_pairs(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb, const pfsph_real *x,
                                 const pfsph_real *y, const pfsph_real *z, pfsph_real *nd, pfsph_pcisph_pairs *cf,
                                 pfsph_pcisph_pairs *cb)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h, w0 = pfsph_kernel_w0(k);
    const pfsph_particles *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = ctx->fluid->n;
#pragma omp parallel
    {
        pfsph_real w[PFSPH_LIST_TERMS_MAX + 8]; /* pfsph__lanes_sum reads 7 past the end */
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real xi = x[i], yi = y[i], zi = z[i];
            /* the terms in eight lanes (pair_terms.h), zeros for the pairs beyond h */
            pfsph_real s = w0;
            for (uint32_t e = l->start[i], end = l->start[i + 1]; e < end;) {
                const uint32_t e1 = end - e > PFSPH_LIST_TERMS_MAX ? e + PFSPH_LIST_TERMS_MAX : end;
                const int m = (int)(e1 - e);
                pfsph__terms_list_wdw(k, h2, m, l->idx + e, x, y, z, xi, yi, zi, NULL, cf->dx + e, cf->dy + e,
                                      cf->dz + e, cf->dw + e, w);
                s += pfsph__lanes_sum(m, w);
                e = e1;
            }
            /* the walls' entries hold aux_j W and aux_j dW/r: the products both passes form */
            pfsph_real sb = 0;
            for (uint32_t e = lb->start[i], end = lb->start[i + 1]; e < end;) {
                const uint32_t e1 = end - e > PFSPH_LIST_TERMS_MAX ? e + PFSPH_LIST_TERMS_MAX : end;
                const int m = (int)(e1 - e);
                pfsph__terms_list_wdw(k, h2, m, lb->idx + e, b->x, b->y, b->z, xi, yi, zi, b->aux, cb->dx + e,
                                      cb->dy + e, cb->dz + e, cb->dw + e, w);
                sb += pfsph__lanes_sum(m, w);
                e = e1;
            }
            nd[i] = s + sb * inv_v0;
        }
    }
}

void pfsph__pcisph_pressure_pairs(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb,
                                  const pfsph_real *nd, const pfsph_real *p, const pfsph_pcisph_pairs *cf,
                                  const pfsph_pcisph_pairs *cb, pfsph_real *pn, pfsph_real *apx, pfsph_real *apy,
                                  pfsph_real *apz)
{
    const pfsph_particles *f = ctx->fluid;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = f->n;
    const pfsph_real *restrict cx = cf->dx, *restrict cy = cf->dy, *restrict cz = cf->dz, *restrict cw = cf->dw;
    const pfsph_real *restrict bxs = cb->dx, *restrict bys = cb->dy, *restrict bzs = cb->dz, *restrict bws = cb->dw;
#pragma omp parallel
    {
        /* p / delta^2 once per particle, not once per pair (a division each): the same value */
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) pn[i] = p[i] / (nd[i] * nd[i]);
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real pi = pn[i];
            /* the terms in eight lanes (pair_terms.h); a pair beyond h adds s = 0 times x_ij */
            const uint32_t e0 = l->start[i];
            pfsph_real a[3];
            pfsph__lanes_pressure((int)(l->start[i + 1] - e0), l->idx + e0, pn, pi, cw + e0, cx + e0, cy + e0, cz + e0,
                                  a);
            pfsph_real ax = a[0], ay = a[1], az = a[2];
            if (pi > 0) {
                const uint32_t b0 = lb->start[i];
                pfsph_real bs[3]; /* the walls' dw holds aux_j dW/r (pfsph__pcisph_density_pairs) */
                pfsph__lanes_sx((int)(lb->start[i + 1] - b0), bws + b0, bxs + b0, bys + b0, bzs + b0, bs);
                const pfsph_real wb = pi * inv_v0;
                ax += wb * bs[0];
                ay += wb * bs[1];
                az += wb * bs[2];
            }
            const pfsph_real inv_m = -(pfsph_real)1 / ctx->mass[f->phase[i]];
            apx[i] = inv_m * ax;
            apy[i] = inv_m * ay;
            apz[i] = inv_m * az;
        }
    }
}
