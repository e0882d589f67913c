/* The SIMD candidate filter (src/core/hits.h) and the vectorised pair terms
 * (src/physics/pair_terms.h): every variant this CPU has (scalar, AVX2, AVX-512) finds the same
 * hits with the same bits of x_ij and r2 as the scalar code, over ranges of 0..70 targets
 * (masked tails) with and without the skipped index; the term loops give the bits of the scalar
 * kernel, viscosity and pressure expressions, kernel branches and r = 0 included. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/hits.h"
#include "physics/pair_terms.h"
#include "testutil.h"

static uint64_t lcg_state = 12345;
static double uni(void)
{
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
}

enum { NT = 400 };

static void test_variants(void **state)
{
    (void)state;
    static pfsph_real x[NT], y[NT], z[NT];
    const pfsph_real h = (pfsph_real)0.05, h2 = h * h;
    for (int j = 0; j < NT; j++) {
        x[j] = (pfsph_real)(0.12 * uni());
        y[j] = (pfsph_real)(0.12 * uni());
        z[j] = (pfsph_real)(0.12 * uni());
    }
    x[7] = x[8], y[7] = y[8], z[7] = z[8]; /* a coincident pair: r2 = 0 is a hit */
    static pfsph_hits ref, got;
    pfsph_hits_fn scalar = pfsph_hits_variant(0);
    assert_non_null(scalar);
    /* the scalar filter against the definition (r^2 < h^2, j != skip): the reference of the
     * SIMD variants, and the only filter of a double-precision build */
    int brute_hits = 0;
    for (int t = 0; t < 300; t++) {
        const uint32_t b = (uint32_t)(uni() * 300), e = b + (uint32_t)(uni() * 71);
        const int qi = (int)(uni() * NT);
        const uint32_t skip = t % 2 ? UINT32_MAX : (uint32_t)qi;
        ref.n = 0;
        scalar(&ref, x, y, z, b, e, x[qi], y[qi], z[qi], h2, skip);
        int k = 0;
        for (uint32_t j = b; j < e; j++) {
            const pfsph_real dx = x[qi] - x[j], dy = y[qi] - y[j], dz = z[qi] - z[j];
            if (dx * dx + dy * dy + dz * dz < h2 && j != skip) {
                assert_true(k < ref.n);
                assert_int_equal(ref.j[k], j);
                k++;
            }
        }
        assert_int_equal(k, ref.n);
        brute_hits += k;
    }
    assert_true(brute_hits > 100);
    int tested = 0, hits = 0;
    for (int level = 1; level <= 2; level++) {
        pfsph_hits_fn fn = pfsph_hits_variant(level);
        if (!fn) continue;
        tested++;
        for (int t = 0; t < 300; t++) {
            const uint32_t b = (uint32_t)(uni() * 300), e = b + (uint32_t)(uni() * 71);
            const int qi = (int)(uni() * NT);
            const uint32_t skip = t % 3 == 0 ? UINT32_MAX : t % 3 == 1 ? (uint32_t)qi : b + (uint32_t)(uni() * 20);
            ref.n = got.n = 3; /* appending after earlier hits */
            scalar(&ref, x, y, z, b, e, x[qi], y[qi], z[qi], h2, skip);
            fn(&got, x, y, z, b, e, x[qi], y[qi], z[qi], h2, skip);
            assert_int_equal(ref.n, got.n);
            const size_t m = (size_t)(ref.n - 3);
            hits += (int)m;
            assert_memory_equal(ref.j + 3, got.j + 3, m * sizeof(uint32_t));
            assert_memory_equal(ref.dx + 3, got.dx + 3, m * sizeof(pfsph_real));
            assert_memory_equal(ref.dy + 3, got.dy + 3, m * sizeof(pfsph_real));
            assert_memory_equal(ref.dz + 3, got.dz + 3, m * sizeof(pfsph_real));
            assert_memory_equal(ref.r2 + 3, got.r2 + 3, m * sizeof(pfsph_real));
        }
    }
    print_message("hits: scalar against the definition (%d hits), %d SIMD variant(s) checked (chosen here: %s), "
                  "%d hits\n",
                  brute_hits, tested, pfsph_hits_level_name(), hits);
    if (tested) assert_true(hits > 100); /* none in a double-precision build: the filter is scalar there */
}

static void test_terms(void **state)
{
    (void)state;
    enum { N = 203 };
    pfsph_kernel k;
    pfsph_kernel_init(&k, 3, (pfsph_real)0.05);
    const pfsph_real h2 = k.h * k.h;
    static pfsph_real r2[N], w[N], dw[N], dw2[N], sv[N], sp[N], dx[N], dy[N], dz[N], nuj[N];
    static pfsph_real vx[N], vy[N], vz[N], nd[N], p[N];
    static uint32_t jj[N];
    for (int e = 0; e < N; e++) {
        dx[e] = (pfsph_real)(0.06 * (uni() - 0.5));
        dy[e] = (pfsph_real)(0.06 * (uni() - 0.5));
        dz[e] = (pfsph_real)(0.06 * (uni() - 0.5));
        r2[e] = dx[e] * dx[e] + dy[e] * dy[e] + dz[e] * dz[e];
        if (e % 17 == 0) r2[e] = 0;                     /* coincident */
        if (e % 19 == 0) r2[e] = h2 * (pfsph_real)0.25; /* q = 1/2, the branch point */
        if (e % 23 == 0) r2[e] = h2;                    /* q = 1 */
        vx[e] = (pfsph_real)uni(), vy[e] = (pfsph_real)uni(), vz[e] = (pfsph_real)uni();
        nd[e] = (pfsph_real)(7000 + 1000 * uni());
        p[e] = (pfsph_real)(1000 * uni());
        nuj[e] = e % 2 ? (pfsph_real)0.01 : (pfsph_real)0.003;
        jj[e] = (uint32_t)((e * 37) % N);
    }
    pfsph__terms_w(&k, N, r2, w);
    pfsph__terms_dwr(&k, N, r2, dw);
    const pfsph_pair_in in = {k,      vx, vy, vz, nd, p, nuj, 0.3f, -0.2f, 0.1f, 0.01f, 0.02f, (pfsph_real)0.01 * h2,
                              7500.0f};
    pfsph__terms_visc_pressure(&in, N, jj, dx, dy, dz, r2, dw2, sv, sp);
    for (int e = 0; e < N; e++) {
        const pfsph_real r = pfsph_sqrt(r2[e]), wr = pfsph_kernel_w(&k, r), dwr = pfsph_kernel_dw_r(&k, r);
        assert_memory_equal(&w[e], &wr, sizeof wr);
        assert_memory_equal(&dw[e], &dwr, sizeof dwr);
        assert_memory_equal(&dw2[e], &dwr, sizeof dwr);
        const uint32_t j = jj[e];
        const pfsph_real nu = nuj[e]; /* the pair's viscosity (viscosity.h, pfsph__visc_pair_nu) */
        const pfsph_real vdx = (in.vxi - vx[j]) * dx[e] + (in.vyi - vy[j]) * dy[e] + (in.vzi - vz[j]) * dz[e];
        const pfsph_real s = 2 * nu / (in.ndi + nd[j]) * vdx / (r2[e] + in.eps) * dwr;
        const pfsph_real t = (in.pi + p[j] / (nd[j] * nd[j])) * dwr;
        assert_memory_equal(&sv[e], &s, sizeof s);
        assert_memory_equal(&sp[e], &t, sizeof t);
    }
}

/* The pair forces' float cosine: within 2e-7 of cos over [0, 2 pi] (the pair force's argument
 * is 3 pi r / (2 k h) < 3 pi / 2), and the vector term loop gives the bits of the scalar
 * expression cos(U_R r) / r. */
static void test_cos_pair(void **state)
{
    (void)state;
    double worst = 0;
    for (int q = 0; q <= 2000000; q++) {
        const float x = (float)(6.283185307179586 * q / 2000000.0);
        const double d = fabs((double)pfsph__cos_pair(x) - cos((double)x));
        if (d > worst) worst = d;
    }
    print_message("cos_pair: largest error %.3g over [0, 2 pi]\n", worst);
    assert_true(worst < 2e-7);
    enum { N = 203 };
    static pfsph_real r2[N];
    static double cr[N];
    const double R = 0.0695, U_R = 1.5 * 3.141592653589793 / R;
    for (int e = 0; e < N; e++) r2[e] = (pfsph_real)(R * R * uni());
    pfsph__terms_pair_cos(U_R, N, r2, cr);
    for (int e = 0; e < N; e++) {
        const double r = sqrt((double)r2[e]), want = (double)pfsph__cos_pair((float)(U_R * r)) / r;
        assert_memory_equal(&cr[e], &want, sizeof want);
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_variants),
        cmocka_unit_test(test_terms),
        cmocka_unit_test(test_cos_pair),
    };
    return tu_run_group(tests, NULL, NULL);
}
