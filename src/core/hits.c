/* SIMD candidate filter of the neighbour passes (hits.h): AVX-512 and AVX2 variants compiled
 * with function target attributes, so the build still targets x86-64-v2 and the variant is
 * picked at run time. This file is compiled with -ffp-contract=off: an AVX-512 target enables
 * FMA, and a fused dx dx + dy dy would round differently from the scalar code. */
#include "core/hits.h"

#include <stdlib.h>
#include <string.h>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(PFSPH_DOUBLE)
#define PFSPH__X86 1
#include <immintrin.h>
#else
#define PFSPH__X86 0
#endif

static void hits_scalar(pfsph_hits *h, const pfsph_real *tx, const pfsph_real *ty, const pfsph_real *tz, uint32_t b,
                        uint32_t e, pfsph_real x, pfsph_real y, pfsph_real z, pfsph_real h2, uint32_t skip)
{
    int n = h->n;
    for (uint32_t j = b; j < e; j++) {
        pfsph_real dx = x - tx[j], dy = y - ty[j], dz = z - tz[j];
        pfsph_real r2 = dx * dx + dy * dy + dz * dz;
        if (r2 < h2 && j != skip) {
            h->j[n] = j;
            h->dx[n] = dx;
            h->dy[n] = dy;
            h->dz[n] = dz;
            h->r2[n] = r2;
            n++;
        }
    }
    h->n = n;
}

#if PFSPH__X86
__attribute__((target("avx512f"))) static void hits_avx512(pfsph_hits *h, const float *tx, const float *ty,
                                                           const float *tz, uint32_t b, uint32_t e, float x, float y,
                                                           float z, float h2, uint32_t skip)
{
    const __m512 X = _mm512_set1_ps(x), Y = _mm512_set1_ps(y), Z = _mm512_set1_ps(z), H2 = _mm512_set1_ps(h2);
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    int n = h->n;
    for (uint32_t j = b; j < e; j += 16) {
        const __mmask16 live = e - j >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << (e - j)) - 1);
        const __m512 dx = _mm512_sub_ps(X, _mm512_maskz_loadu_ps(live, tx + j));
        const __m512 dy = _mm512_sub_ps(Y, _mm512_maskz_loadu_ps(live, ty + j));
        const __m512 dz = _mm512_sub_ps(Z, _mm512_maskz_loadu_ps(live, tz + j));
        const __m512 r2 =
            _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
        unsigned m = _mm512_mask_cmp_ps_mask(live, r2, H2, _CMP_LT_OQ);
        if (skip - j < 16) m &= ~(1u << (skip - j));
        if (!m) continue;
        const __mmask16 k = (__mmask16)m;
        _mm512_storeu_si512(h->j + n,
                            _mm512_maskz_compress_epi32(k, _mm512_add_epi32(_mm512_set1_epi32((int)j), lane)));
        _mm512_storeu_ps(h->dx + n, _mm512_maskz_compress_ps(k, dx));
        _mm512_storeu_ps(h->dy + n, _mm512_maskz_compress_ps(k, dy));
        _mm512_storeu_ps(h->dz + n, _mm512_maskz_compress_ps(k, dz));
        _mm512_storeu_ps(h->r2 + n, _mm512_maskz_compress_ps(k, r2));
        n += __builtin_popcount(m);
    }
    h->n = n;
}

/* AVX2 has no compress: lane indices of the set bits of each 8-bit mask, one byte each */
static uint64_t compress8[256];

__attribute__((constructor)) static void compress8_init(void)
{
    for (unsigned m = 0; m < 256; m++) {
        uint64_t v = 0;
        int k = 0;
        for (unsigned l = 0; l < 8; l++)
            if (m >> l & 1) v |= (uint64_t)l << (8 * k++);
        compress8[m] = v;
    }
}

__attribute__((target("avx2"))) static void hits_avx2(pfsph_hits *h, const float *tx, const float *ty, const float *tz,
                                                      uint32_t b, uint32_t e, float x, float y, float z, float h2,
                                                      uint32_t skip)
{
    const __m256 X = _mm256_set1_ps(x), Y = _mm256_set1_ps(y), Z = _mm256_set1_ps(z), H2 = _mm256_set1_ps(h2);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    int n = h->n;
    for (uint32_t j = b; j < e; j += 8) {
        const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32((int)(e - j < 8 ? e - j : 8)), lane);
        const __m256 dx = _mm256_sub_ps(X, _mm256_maskload_ps(tx + j, live));
        const __m256 dy = _mm256_sub_ps(Y, _mm256_maskload_ps(ty + j, live));
        const __m256 dz = _mm256_sub_ps(Z, _mm256_maskload_ps(tz + j, live));
        const __m256 r2 =
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
        unsigned m =
            (unsigned)_mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(r2, H2, _CMP_LT_OQ), _mm256_castsi256_ps(live)));
        if (skip - j < 8) m &= ~(1u << (skip - j));
        if (!m) continue;
        const __m256i p = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)compress8[m]));
        _mm256_storeu_si256((__m256i *)(h->j + n),
                            _mm256_permutevar8x32_epi32(_mm256_add_epi32(_mm256_set1_epi32((int)j), lane), p));
        _mm256_storeu_ps(h->dx + n, _mm256_permutevar8x32_ps(dx, p));
        _mm256_storeu_ps(h->dy + n, _mm256_permutevar8x32_ps(dy, p));
        _mm256_storeu_ps(h->dz + n, _mm256_permutevar8x32_ps(dz, p));
        _mm256_storeu_ps(h->r2 + n, _mm256_permutevar8x32_ps(r2, p));
        n += __builtin_popcount(m);
    }
    h->n = n;
}
#endif

pfsph_hits_fn pfsph_hits_variant(int level)
{
    if (level == 0) return hits_scalar;
#if PFSPH__X86
    __builtin_cpu_init();
    if (level == 1 && __builtin_cpu_supports("avx2")) return hits_avx2;
    if (level == 2 && __builtin_cpu_supports("avx512f")) return hits_avx512;
#endif
    return NULL;
}

static int chosen = -1;

static int choose(void)
{
    int c = __atomic_load_n(&chosen, __ATOMIC_RELAXED);
    if (c >= 0) return c;
    int cap = 2;
    const char *s = getenv("PFSPH_SIMD");
    if (s && !strcmp(s, "scalar")) cap = 0;
    else if (s && !strcmp(s, "avx2")) cap = 1;
    c = cap;
    while (c > 0 && !pfsph_hits_variant(c)) c--;
    __atomic_store_n(&chosen, c, __ATOMIC_RELAXED);
    return c;
}

pfsph_hits_fn pfsph_hits_select(void) { return pfsph_hits_variant(choose()); }

const char *pfsph_hits_level_name(void)
{
    static const char *const names[] = {"scalar", "avx2", "avx512"};
    return names[choose()];
}
