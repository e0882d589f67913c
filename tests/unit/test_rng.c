/* Counter-based generator (Philox-4x32-10): known-answer vectors of the reference
 * implementation (Random123 kat_vectors), reproducibility, uniformity (chi-square), independence
 * of neighbouring counters and streams (correlation, bit agreement). */
#include <math.h>
#include <string.h>

#include "pfsph/rng.h"
#include "testutil.h"

/* Philox4x32-10 of Random123: counter {c0, c1, c2, c3}, key {k0, k1}. Our counter is
 * {id, step lo, step hi, stream} and key {seed lo, seed hi}. */
static void test_known_answers(void **state)
{
    (void)state;
    uint32_t o[4];
    pfsph_rng_u32x4(0, 0, 0, 0, o);
    assert_int_equal(o[0], 0x6627e8d5u);
    assert_int_equal(o[1], 0xe169c58du);
    assert_int_equal(o[2], 0xbc57ac4cu);
    assert_int_equal(o[3], 0x9b00dbd8u);
    pfsph_rng_u32x4(0xffffffffffffffffull, 0xffffffffu, 0xffffffffffffffffull, 0xffffffffu, o);
    assert_int_equal(o[0], 0x408f276du);
    assert_int_equal(o[1], 0x41c83b0eu);
    assert_int_equal(o[2], 0xa20bc7c6u);
    assert_int_equal(o[3], 0x6d5451fdu);
    pfsph_rng_u32x4(((uint64_t)0x299f31d0u << 32) | 0xa4093822u, 0x243f6a88u,
                    ((uint64_t)0x13198a2eu << 32) | 0x85a308d3u, 0x03707344u, o);
    assert_int_equal(o[0], 0xd16cfe09u);
    assert_int_equal(o[1], 0x94fdccebu);
    assert_int_equal(o[2], 0x5001e420u);
    assert_int_equal(o[3], 0x24126ea1u);
}

static void test_reproducible(void **state)
{
    (void)state;
    double a[4], b[4], c[4];
    pfsph_rng_uniform4(42, 17, 123456789012ull, 3, a);
    pfsph_rng_uniform4(42, 17, 123456789012ull, 3, b);
    assert_memory_equal(a, b, sizeof a);
    for (int k = 0; k < 4; k++) assert_true(a[k] >= 0 && a[k] < 1);
    /* every key component changes the block */
    pfsph_rng_uniform4(43, 17, 123456789012ull, 3, c);
    assert_memory_not_equal(a, c, sizeof a);
    pfsph_rng_uniform4(42, 18, 123456789012ull, 3, c);
    assert_memory_not_equal(a, c, sizeof a);
    pfsph_rng_uniform4(42, 17, 123456789013ull, 3, c);
    assert_memory_not_equal(a, c, sizeof a);
    pfsph_rng_uniform4(42, 17, 123456789012ull + (1ull << 32), 3, c);
    assert_memory_not_equal(a, c, sizeof a);
    pfsph_rng_uniform4(42, 17, 123456789012ull, 4, c);
    assert_memory_not_equal(a, c, sizeof a);
    assert_true(pfsph_rng_to_unit(0xffffffffu) < 1.0);
}

/* Chi-square over 64 bins of 4 x 100000 draws along consecutive ids (the pattern of one step's
 * emitters): the 0.999 quantile of chi2(63) is 103.4. */
static void test_uniformity(void **state)
{
    (void)state;
    enum { BINS = 64, N = 100000 };
    long h[BINS];
    memset(h, 0, sizeof h);
    double mean = 0;
    for (uint32_t i = 0; i < N; i++) {
        double u[4];
        pfsph_rng_uniform4(2024, i, 5, 0, u);
        for (int k = 0; k < 4; k++) {
            h[(int)(u[k] * BINS)]++;
            mean += u[k];
        }
    }
    double e = 4.0 * N / BINS, chi = 0;
    for (int b = 0; b < BINS; b++) chi += (h[b] - e) * (h[b] - e) / e;
    mean /= 4.0 * N;
    print_message("chi2(63) = %.1f, mean = %.5f\n", chi, mean);
    assert_true(chi < 103.4);
    assert_true(fabs(mean - 0.5) < 5 * sqrt(1.0 / 12 / (4.0 * N)));
}

/* Neighbouring streams, steps and ids: correlation of paired draws near 0 (|r| < 5 / sqrt(N))
 * and each output bit agreeing half of the time. */
static void test_independence(void **state)
{
    (void)state;
    enum { N = 50000 };
    const int kinds = 3;
    for (int kind = 0; kind < kinds; kind++) {
        double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
        long agree[32];
        memset(agree, 0, sizeof agree);
        for (uint32_t i = 0; i < N; i++) {
            uint32_t a[4], b[4];
            pfsph_rng_u32x4(99, i, 7, 1, a);
            if (kind == 0) pfsph_rng_u32x4(99, i, 7, 2, b);      /* next stream */
            else if (kind == 1) pfsph_rng_u32x4(99, i, 8, 1, b); /* next step */
            else pfsph_rng_u32x4(99, i + 1, 7, 1, b);            /* next id */
            double x = pfsph_rng_to_unit(a[0]), y = pfsph_rng_to_unit(b[0]);
            sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y;
            uint32_t same = ~(a[1] ^ b[1]);
            for (int k = 0; k < 32; k++) agree[k] += (same >> k) & 1u;
        }
        double cov = sxy / N - sx / N * sy / N;
        double r = cov / sqrt((sxx / N - sx * sx / N / N) * (syy / N - sy * sy / N / N));
        assert_true(fabs(r) < 5 / sqrt((double)N));
        for (int k = 0; k < 32; k++) assert_true(fabs(agree[k] - N / 2.0) < 5 * sqrt(N / 4.0));
        /* within one block, the four words are uncorrelated too */
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_answers),
        cmocka_unit_test(test_reproducible),
        cmocka_unit_test(test_uniformity),
        cmocka_unit_test(test_independence),
    };
    return tu_run_group(tests, NULL, NULL);
}
