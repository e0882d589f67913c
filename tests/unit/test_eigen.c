/* Unit tests of the small symmetric eigen-solvers (src/core/eigen.c): known spectra, residuals
 * and orthonormality on random matrices, degenerate cases. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "pfsph/eigen.h"
#include "testutil.h"

/* Small deterministic generator so failures reproduce. */
static uint64_t g_state = 12345;
static double urand(void)
{
    g_state = g_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(g_state >> 11) * (1.0 / 9007199254740992.0);
}

static void check3(const double a[3][3], const double w[3], const double v[3][3], double tol)
{
    double scale = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) scale = fmax(scale, fabs(a[i][j]));
    if (scale == 0) scale = 1;
    assert_true(w[0] >= w[1] && w[1] >= w[2]);
    for (int c = 0; c < 3; c++) {
        for (int r = 0; r < 3; r++) {
            double av = 0;
            for (int k = 0; k < 3; k++) av += a[r][k] * v[k][c];
            assert_true(fabs(av - w[c] * v[r][c]) <= tol * scale);
        }
        for (int d = 0; d < 3; d++) {
            double dot = 0;
            for (int k = 0; k < 3; k++) dot += v[k][c] * v[k][d];
            assert_true(fabs(dot - (c == d ? 1.0 : 0.0)) <= 1e-12);
        }
    }
}

static void test_sym2_known(void **state)
{
    (void)state;
    const double a[2][2] = {{2, 1}, {1, 2}};
    double w[2], v[2][2];
    pfsph_eigen_sym2(a, w, v);
    assert_true(fabs(w[0] - 3) < 1e-14 && fabs(w[1] - 1) < 1e-14);
    assert_true(fabs(fabs(v[0][0]) - sqrt(0.5)) < 1e-14 && fabs(v[0][0] - v[1][0]) < 1e-14);
    const double d[2][2] = {{1, 0}, {0, 5}};
    pfsph_eigen_sym2(d, w, v);
    assert_true(w[0] == 5 && w[1] == 1);
    assert_true(fabs(fabs(v[1][0]) - 1) < 1e-15); /* largest along y */
    const double iso[2][2] = {{4, 0}, {0, 4}};
    pfsph_eigen_sym2(iso, w, v);
    assert_true(w[0] == 4 && w[1] == 4);
    for (int t = 0; t < 1000; t++) {
        double p = urand() * 2 - 1, q = urand() * 2 - 1, r = urand() * 2 - 1;
        const double m[2][2] = {{p, q}, {q, r}};
        pfsph_eigen_sym2(m, w, v);
        assert_true(w[0] >= w[1]);
        for (int c = 0; c < 2; c++)
            for (int row = 0; row < 2; row++) {
                double av = m[row][0] * v[0][c] + m[row][1] * v[1][c];
                assert_true(fabs(av - w[c] * v[row][c]) < 1e-13);
            }
        assert_true(fabs(v[0][0] * v[0][1] + v[1][0] * v[1][1]) < 1e-15);
    }
}

static void test_sym3_known(void **state)
{
    (void)state;
    /* Second-difference matrix: eigenvalues 2 + sqrt(2), 2, 2 - sqrt(2). */
    const double a[3][3] = {{2, -1, 0}, {-1, 2, -1}, {0, -1, 2}};
    double w[3], v[3][3];
    int sweeps = pfsph_eigen_sym3(a, w, v);
    assert_true(sweeps < 32);
    assert_true(fabs(w[0] - (2 + sqrt(2))) < 1e-14);
    assert_true(fabs(w[1] - 2) < 1e-14);
    assert_true(fabs(w[2] - (2 - sqrt(2))) < 1e-14);
    check3(a, w, v, 1e-13);
    /* Identity and a two-fold degenerate diagonal. */
    const double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    pfsph_eigen_sym3(I, w, v);
    assert_true(w[0] == 1 && w[1] == 1 && w[2] == 1);
    check3(I, w, v, 1e-15);
    const double d[3][3] = {{1, 0, 0}, {0, 3, 0}, {0, 0, 1}};
    pfsph_eigen_sym3(d, w, v);
    assert_true(w[0] == 3 && w[1] == 1 && w[2] == 1 && fabs(v[1][0]) == 1);
    /* Zero matrix. */
    const double z[3][3] = {{0}};
    pfsph_eigen_sym3(z, w, v);
    assert_true(w[0] == 0 && w[2] == 0);
}

/* R diag(l) R^T with R a random rotation must give back l. */
static void test_sym3_random(void **state)
{
    (void)state;
    for (int t = 0; t < 2000; t++) {
        double a[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = i; j < 3; j++) a[i][j] = a[j][i] = urand() * 2 - 1;
        double w[3], v[3][3];
        int sweeps = pfsph_eigen_sym3(a, w, v);
        assert_true(sweeps <= 10);
        check3(a, w, v, 1e-13);
        double tr = a[0][0] + a[1][1] + a[2][2];
        assert_true(fabs(tr - (w[0] + w[1] + w[2])) < 1e-13);
    }
    for (int t = 0; t < 200; t++) {
        /* rotation from a random unit quaternion */
        double q[4], n = 0;
        for (int i = 0; i < 4; i++) {
            q[i] = urand() - 0.5;
            n += q[i] * q[i];
        }
        n = sqrt(n);
        for (int i = 0; i < 4; i++) q[i] /= n;
        double R[3][3] = {
            {1 - 2 * (q[2] * q[2] + q[3] * q[3]), 2 * (q[1] * q[2] - q[0] * q[3]), 2 * (q[1] * q[3] + q[0] * q[2])},
            {2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[1] * q[1] + q[3] * q[3]), 2 * (q[2] * q[3] - q[0] * q[1])},
            {2 * (q[1] * q[3] - q[0] * q[2]), 2 * (q[2] * q[3] + q[0] * q[1]), 1 - 2 * (q[1] * q[1] + q[2] * q[2])}};
        const double l[3] = {5.0, 1.0 + 1e-9 * (t % 2), 1.0}; /* nearly degenerate pair */
        double a[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                a[i][j] = 0;
                for (int k = 0; k < 3; k++) a[i][j] += R[i][k] * l[k] * R[j][k];
            }
        double w[3], v[3][3];
        pfsph_eigen_sym3(a, w, v);
        for (int k = 0; k < 3; k++) assert_true(fabs(w[k] - l[k]) < 1e-13);
        check3(a, w, v, 1e-13);
        /* the top eigenvector is the first column of R (up to sign) */
        double dot = R[0][0] * v[0][0] + R[1][0] * v[1][0] + R[2][0] * v[2][0];
        assert_true(fabs(fabs(dot) - 1) < 1e-12);
    }
}

/* The closed form (pfsph_eigen_sym3_fast) against Jacobi: known spectra, degenerate, zero and
 * scaled matrices, random ones, nearly double eigenvalues, and the matrix functions
 * sum_k f(w_k) v_k v_k^T the pair filter builds from them (well defined for a double eigenvalue
 * even where the eigenvectors are not). */
static void fn_matrix(const double w[3], const double v[3][3], double F[3][3])
{
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            F[a][b] = 0;
            for (int k = 0; k < 3; k++) F[a][b] += v[a][k] * v[b][k] * (w[2] / (w[k] > 0.5 * w[0] ? w[k] : 0.5 * w[0]));
        }
}

static void test_sym3_fast(void **state)
{
    (void)state;
    double w[3], v[3][3], wj[3], vj[3][3];
    const double a[3][3] = {{2, -1, 0}, {-1, 2, -1}, {0, -1, 2}};
    pfsph_eigen_sym3_fast(a, w, v);
    assert_true(fabs(w[0] - (2 + sqrt(2))) < 1e-14);
    assert_true(fabs(w[1] - 2) < 1e-14);
    assert_true(fabs(w[2] - (2 - sqrt(2))) < 1e-14);
    check3(a, w, v, 1e-13);
    const double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    pfsph_eigen_sym3_fast(I, w, v);
    assert_true(w[0] == 1 && w[1] == 1 && w[2] == 1);
    check3(I, w, v, 1e-15);
    const double I7[3][3] = {{7e-9, 0, 0}, {0, 7e-9, 0}, {0, 0, 7e-9}};
    pfsph_eigen_sym3_fast(I7, w, v);
    assert_true(w[0] == 7e-9 && w[2] == 7e-9 && v[0][0] == 1 && v[1][1] == 1 && v[2][2] == 1);
    /* a double eigenvalue: acos near 1 costs half the digits there (eigen.h) */
    const double d[3][3] = {{1, 0, 0}, {0, 3, 0}, {0, 0, 1}};
    pfsph_eigen_sym3_fast(d, w, v);
    assert_true(fabs(w[0] - 3) < 1e-15 && fabs(w[1] - 1) < 1e-7 && fabs(w[2] - 1) < 1e-7);
    assert_true(fabs(fabs(v[1][0]) - 1) < 1e-15);
    check3(d, w, v, 1e-7);
    const double d2[3][3] = {{2, 0, 0}, {0, 2, 0}, {0, 0, -5}}; /* double eigenvalue on top */
    pfsph_eigen_sym3_fast(d2, w, v);
    assert_true(fabs(w[0] - 2) < 1e-7 && fabs(w[1] - 2) < 1e-7 && fabs(w[2] + 5) < 1e-14);
    check3(d2, w, v, 1e-7);
    const double z[3][3] = {{0}};
    pfsph_eigen_sym3_fast(z, w, v);
    assert_true(w[0] == 0 && w[1] == 0 && w[2] == 0 && v[0][0] == 1 && v[1][1] == 1 && v[2][2] == 1);
    /* rank one and rank two (a particle with one or two neighbour directions) */
    const double r1[3][3] = {{1, 2, 3}, {2, 4, 6}, {3, 6, 9}};
    pfsph_eigen_sym3_fast(r1, w, v);
    assert_true(fabs(w[0] - 14) < 1e-13 && fabs(w[1]) < 1e-7 && fabs(w[2]) < 1e-7);
    check3(r1, w, v, 1e-7);
    const double r2[3][3] = {{1, 0, 0}, {0, 1e-3, 0}, {0, 0, 0}};
    pfsph_eigen_sym3_fast(r2, w, v);
    assert_true(fabs(w[0] - 1) < 1e-14 && fabs(w[1] - 1e-3) < 1e-13 && fabs(w[2]) < 1e-13);
    check3(r2, w, v, 1e-13);
    double worst_w = 0, worst_r = 0;
    for (int t = 0; t < 20000; t++) {
        double m[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = i; j < 3; j++) m[i][j] = m[j][i] = urand() * 2 - 1;
        if (t % 4 == 1) /* covariance-like: positive definite, nearly isotropic */
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) m[i][j] = (i == j) + 1e-6 * (t % 8) * m[i][j];
        pfsph_eigen_sym3_fast(m, w, v);
        pfsph_eigen_sym3(m, wj, vj);
        double sc = fmax(fabs(wj[0]), fabs(wj[2]));
        for (int k = 0; k < 3; k++) worst_w = fmax(worst_w, fabs(w[k] - wj[k]) / sc);
        check3(m, w, v, 1e-7);
        double F[3][3], Fj[3][3];
        if (wj[2] > 0) {
            fn_matrix(w, v, F);
            fn_matrix(wj, vj, Fj);
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) worst_r = fmax(worst_r, fabs(F[a][b] - Fj[a][b]));
        }
    }
    for (int t = 0; t < 2000; t++) { /* nearly double eigenvalues, in either position */
        double q[4], n = 0;
        for (int i = 0; i < 4; i++) {
            q[i] = urand() - 0.5;
            n += q[i] * q[i];
        }
        n = sqrt(n);
        for (int i = 0; i < 4; i++) q[i] /= n;
        double R[3][3] = {
            {1 - 2 * (q[2] * q[2] + q[3] * q[3]), 2 * (q[1] * q[2] - q[0] * q[3]), 2 * (q[1] * q[3] + q[0] * q[2])},
            {2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[1] * q[1] + q[3] * q[3]), 2 * (q[2] * q[3] - q[0] * q[1])},
            {2 * (q[1] * q[3] - q[0] * q[2]), 2 * (q[2] * q[3] + q[0] * q[1]), 1 - 2 * (q[1] * q[1] + q[2] * q[2])}};
        const double gap = pow(10.0, -(double)(t % 14));
        const double l[3] = {t % 2 ? 3.0 : 3.0 + gap, t % 2 ? 1.0 + gap : 1.0, t % 2 ? 1.0 : 0.2};
        double m[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                m[i][j] = 0;
                for (int k = 0; k < 3; k++) m[i][j] += R[i][k] * l[k] * R[j][k];
            }
        pfsph_eigen_sym3_fast(m, w, v);
        pfsph_eigen_sym3(m, wj, vj);
        for (int k = 0; k < 3; k++) worst_w = fmax(worst_w, fabs(w[k] - wj[k]) / 3.0);
        check3(m, w, v, 1e-7);
        double F[3][3], Fj[3][3];
        fn_matrix(w, v, F);
        fn_matrix(wj, vj, Fj);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) worst_r = fmax(worst_r, fabs(F[a][b] - Fj[a][b]));
    }
    print_message("closed form against Jacobi: eigenvalues %.3g of the largest, filter matrix %.3g\n", worst_w,
                  worst_r);
    assert_true(worst_w < 1e-7);
    assert_true(worst_r < 1e-7);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sym2_known),
        cmocka_unit_test(test_sym3_known),
        cmocka_unit_test(test_sym3_random),
        cmocka_unit_test(test_sym3_fast),
    };
    return tu_run_group(tests, NULL, NULL);
}
