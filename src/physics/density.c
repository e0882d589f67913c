/* Number density delta_i (PF Eq. 23), fluid and boundary neighbours. */
#include "physics/density.h"

#include <omp.h>

/* SSE (every x86-64 has it; the build targets x86-64-v2) for the candidate test of the one
 * grid walk a step makes with lists; single precision only. Elsewhere: the scalar loop. */
#if defined(__SSE2__) && !defined(PFSPH_DOUBLE) && defined(__GNUC__)
#include <immintrin.h>
#define PFSPH__SSE 1
#else
#define PFSPH__SSE 0
#endif

#include "core/nlist.h"

/* cnt: NULL, or where to count each particle's fluid neighbours j != i within h (the lists'
 * counts, src/core/nlist.h): the walk is the density's own, so counting costs a compare. */
static inline void number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                                  const pfsph_real *z, pfsph_real *nd, uint32_t *cnt)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_particles *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = ctx->fluid->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        pfsph_ranges r;
        const pfsph_real xi = x[i], yi = y[i], zi = z[i];
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        pfsph_real s = 0;
        uint32_t c = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - x[j], dy = yi - y[j], dz = zi - z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 < h2) {
                    s += pfsph_kernel_w(k, pfsph_sqrt(r2));
                    c++;
                }
            }
        if (cnt) cnt[i] = c - 1; /* less i itself */
        if (b->n) {
            pfsph_real sb = 0;
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 < h2) sb += b->aux[j] * pfsph_kernel_w(k, pfsph_sqrt(r2));
                }
            s += sb * inv_v0;
        }
        nd[i] = s;
    }
}

void pfsph__number_density(const pfsph_ctx *ctx, const pfsph_real *x, const pfsph_real *y,
                           const pfsph_real *z, pfsph_real *nd)
{
    number_density(ctx, x, y, z, nd, NULL);
}

/* The boundary part (1/V0) sum_b V_b W_ib of particle i at (xi, yi, zi). */
static inline pfsph_real boundary_density(const pfsph_ctx *ctx, pfsph_real xi, pfsph_real yi, pfsph_real zi)
{
    const pfsph_particles *b = ctx->boundary;
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    pfsph_ranges r;
    pfsph_real sb = 0;
    pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
    for (int q = 0; q < r.n; q++)
        for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
            pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
            pfsph_real r2 = dx * dx + dy * dy + dz * dz;
            if (r2 < h2) sb += b->aux[j] * pfsph_kernel_w(k, pfsph_sqrt(r2));
        }
    return sb * ((pfsph_real)1 / ctx->V0);
}

int pfsph__number_density_list(const pfsph_ctx *ctx, pfsph_real *nd, pfsph_nlist *l, double guess)
{
    const pfsph_particles *f = ctx->fluid;
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const size_t n = f->n;
    const int T = omp_get_max_threads();
    int rc = pfsph_nlist_plan(l, n, T, guess), over = 0;
    if (rc == PFSPH_ENOMEM) return rc;
    uint32_t *cnt = pfsph_nlist_counts(l, n);
    if (!cnt) return PFSPH_ENOMEM;
    if (rc) { /* no plan: count in the density walk, then fill by a second walk */
        number_density(ctx, f->x, f->y, f->z, nd, cnt);
        over = 1;
    } else {
#pragma omp parallel num_threads(T) reduction(| : over)
        {
            /* the particles of this thread as the plan has them: contiguous, in order */
            const int t = omp_get_thread_num(), nt = omp_get_num_threads();
            const size_t i0 = n * (size_t)t / (size_t)nt, i1 = n * (size_t)(t + 1) / (size_t)nt;
            const size_t rb = l->rbeg[t], re = nt == T ? l->rbeg[t + 1] : rb; /* fewer threads: no room */
            size_t pos = rb;
            for (size_t i = i0; i < i1; i++) {
                pfsph_ranges r;
                const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
                pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
#if PFSPH__SSE
                const __m128 X = _mm_set1_ps(xi), Y = _mm_set1_ps(yi), Z = _mm_set1_ps(zi), H2 = _mm_set1_ps(h2);
#endif
                pfsph_real s = 0;
                const size_t p0 = pos;
                /* the terms of number_density in its order (the same bits), and the list */
#define PFSPH__HIT(j_, r2_)                                                                    \
    do {                                                                                       \
        const uint32_t jh = (j_);                                                              \
        const pfsph_real rr = pfsph_sqrt(r2_);                                                 \
        s += pfsph_kernel_w(k, rr);                                                            \
        if (jh != i) {                                                                         \
            if (pos < re) {                                                                    \
                l->idx[pos] = jh;                                                              \
                l->dw[pos] = pfsph_kernel_dw_r(k, rr);                                         \
            }                                                                                  \
            pos++;                                                                             \
        }                                                                                      \
    } while (0)
                for (int q = 0; q < r.n; q++) {
                    uint32_t j = r.b[q];
#if PFSPH__SSE
                    /* four candidates at a time: ~85 % of them lie beyond h (docs/benchmarks.md),
                     * and the scalar loop's branch on r2 < h2 mispredicts often. r2 is rounded
                     * as the scalar expression rounds it, so the hits are the same. */
                    for (; j + 4 <= r.e[q]; j += 4) {
                        const __m128 dx = _mm_sub_ps(X, _mm_loadu_ps(f->x + j));
                        const __m128 dy = _mm_sub_ps(Y, _mm_loadu_ps(f->y + j));
                        const __m128 dz = _mm_sub_ps(Z, _mm_loadu_ps(f->z + j));
                        const __m128 r2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)),
                                                     _mm_mul_ps(dz, dz));
                        unsigned m = (unsigned)_mm_movemask_ps(_mm_cmplt_ps(r2, H2));
                        if (!m) continue;
                        float r2s[4];
                        _mm_storeu_ps(r2s, r2);
                        for (; m; m &= m - 1) {
                            const unsigned b = (unsigned)__builtin_ctz(m);
                            PFSPH__HIT(j + b, r2s[b]);
                        }
                    }
#endif
                    for (; j < r.e[q]; j++) {
                        pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                        pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                        if (r2 < h2) PFSPH__HIT(j, r2);
                    }
                }
#undef PFSPH__HIT
                cnt[i] = (uint32_t)(pos - p0);
                if (ctx->boundary->n) s += boundary_density(ctx, xi, yi, zi);
                nd[i] = s;
            }
            if (nt != T || pos > re) over = 1;
            else l->used[t] = pos - rb;
        }
    }
    return pfsph_nlist_finish(l, over, ctx->grid, f->x, f->y, f->z, n, h2, k);
}

void pfsph__number_density_rate(const pfsph_ctx *ctx, const pfsph_real *vx, const pfsph_real *vy,
                                const pfsph_real *vz, pfsph_real *rate)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_real h2 = k->h * k->h;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const size_t n = f->n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        pfsph_ranges r;
        const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
        const pfsph_real vxi = vx[i], vyi = vy[i], vzi = vz[i];
        pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
        pfsph_real s = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2 || j == i) continue;
                pfsph_real vd = (vxi - vx[j]) * dx + (vyi - vy[j]) * dy + (vzi - vz[j]) * dz;
                s += vd * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
            }
        if (b->n) {
            pfsph_real sb = 0;
            pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= h2) continue;
                    pfsph_real vd = (vxi - b->vx[j]) * dx + (vyi - b->vy[j]) * dy + (vzi - b->vz[j]) * dz;
                    sb += b->aux[j] * vd * pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                }
            s += sb * inv_v0;
        }
        rate[i] = s;
    }
}
