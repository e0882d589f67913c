/* Cubic spline kernel (kernel.h): normalisation in 2D and 3D (radial quadrature and a Cartesian
 * lattice sum), positivity, compact support, monotonicity, derivative, gradient antisymmetry. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "pfsph/kernel.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;
static const pfsph_real H = (pfsph_real)0.1;

/* Fixed-seed LCG (Knuth MMIX constants): no dependence on libc rand. */
static uint64_t lcg_state = 12345;
static double lcg_uniform(void)
{
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
}

/* int_0^h S(r) W(r) dr with S = 2 pi r (2D) or 4 pi r^2 (3D); composite Simpson in double on
 * each of the two polynomial pieces [0, h/2], [h/2, h], so the rule is nearly exact. */
static double radial_integral(const pfsph_kernel *k, int n)
{
    double sum = 0;
    for (int piece = 0; piece < 2; piece++) {
        double a = piece * 0.5 * (double)k->h, b = a + 0.5 * (double)k->h;
        double dr = (b - a) / n;
        for (int i = 0; i <= n; i++) {
            double r = a + i * dr;
            double w = (double)pfsph_kernel_w(k, (pfsph_real)r);
            double s = k->dim == 2 ? 2 * PI * r : 4 * PI * r * r;
            double c = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
            sum += c * s * w * dr / 3;
        }
    }
    return sum;
}

/* Sum of W over a fine cubic lattice times the cell volume (brute-force Cartesian integral). */
static double lattice_integral(const pfsph_kernel *k, int m)
{
    double d = (double)k->h / m, sum = 0;
    int zr = k->dim == 3 ? m : 0;
    for (int iz = -zr; iz <= zr; iz++)
        for (int iy = -m; iy <= m; iy++)
            for (int ix = -m; ix <= m; ix++) {
                double r = d * sqrt((double)ix * ix + (double)iy * iy + (double)iz * iz);
                sum += (double)pfsph_kernel_w(k, (pfsph_real)r);
            }
    return sum * pow(d, k->dim);
}

static void test_normalisation(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        pfsph_kernel k;
        pfsph_kernel_init(&k, dim, H);
        double rad = radial_integral(&k, 2000);
        double lat = lattice_integral(&k, dim == 2 ? 400 : 80);
        printf("%dD: radial integral of W = %.8f (err %.2e), lattice sum = %.8f (err %.2e)\n", dim, rad, fabs(rad - 1),
               lat, fabs(lat - 1));
        assert_true(fabs(rad - 1) < 1e-3);
        assert_true(fabs(lat - 1) < 1e-3);
    }
}

static void test_shape(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        pfsph_kernel k;
        pfsph_kernel_init(&k, dim, H);
        assert_true(pfsph_kernel_w0(&k) == pfsph_kernel_w(&k, 0));
        /* compact support: exactly zero at and beyond h */
        assert_true(pfsph_kernel_w(&k, H) == 0);
        assert_true(pfsph_kernel_w(&k, H * (pfsph_real)1.0001) == 0);
        assert_true(pfsph_kernel_w(&k, 10 * H) == 0);
        assert_true(pfsph_kernel_dw_r(&k, H) == 0);
        assert_true(pfsph_kernel_dw_r(&k, 2 * H) == 0);
        /* non-negative and non-increasing; tolerance: a few float ulps of W(0) */
        const int n = 20000;
        double prev = (double)pfsph_kernel_w(&k, 0), worst_rise = 0;
        for (int i = 1; i <= n + 100; i++) {
            pfsph_real r = (pfsph_real)((double)H * i / n);
            double w = (double)pfsph_kernel_w(&k, r);
            assert_true(w >= 0);
            if (w - prev > worst_rise) worst_rise = w - prev;
            prev = w;
        }
        printf("%dD: largest rise of W between neighbouring samples %.3e (W(0) = %.4e)\n", dim, worst_rise,
               (double)k.sigma);
        assert_true(worst_rise <= 4e-7 * (double)k.sigma);
        /* continuity of W at q = 1/2 (the two polynomial pieces meet) */
        double wl = (double)pfsph_kernel_w(&k, H * (pfsph_real)0.4999),
               wr = (double)pfsph_kernel_w(&k, H * (pfsph_real)0.5001);
        assert_true(fabs(wl - wr) < 1e-3 * (double)k.sigma);
    }
}

/* dw_r * r == dW/dr, checked against a central difference of W (in double around float r). */
static void test_derivative(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        pfsph_kernel k;
        pfsph_kernel_init(&k, dim, H);
        double e = 1e-3 * (double)H, gmax = 1.5 * (double)k.gsigma, worst = 0;
        for (int i = 1; i < 1000; i++) {
            double r = (double)H * i / 1000.0;
            if (r - e <= 0 || r + e >= (double)H) continue;
            double fd =
                ((double)pfsph_kernel_w(&k, (pfsph_real)(r + e)) - (double)pfsph_kernel_w(&k, (pfsph_real)(r - e))) /
                (2 * e);
            double an = (double)pfsph_kernel_dw_r(&k, (pfsph_real)r) * r;
            if (fabs(fd - an) > worst) worst = fabs(fd - an);
            assert_true(an <= 0); /* W non-increasing */
        }
        printf("%dD: max |dW/dr - finite difference| / max|dW/dr| = %.2e\n", dim, worst / gmax);
        assert_true(worst < 2e-3 * gmax);
        /* the self term is skipped by callers: dw_r(0) must be 0, not NaN/inf */
        assert_true(pfsph_kernel_dw_r(&k, 0) == 0);
    }
}

static void test_gradient_antisymmetry(void **state)
{
    (void)state;
    lcg_state = 777;
    for (int dim = 2; dim <= 3; dim++) {
        pfsph_kernel k;
        pfsph_kernel_init(&k, dim, H);
        int nonzero = 0;
        for (int t = 0; t < 2000; t++) {
            pfsph_real xi[3] = {0, 0, 0}, xj[3] = {0, 0, 0};
            for (int a = 0; a < dim; a++) {
                xi[a] = (pfsph_real)(lcg_uniform() * (double)H * 1.5);
                xj[a] = (pfsph_real)(lcg_uniform() * (double)H * 1.5);
            }
            pfsph_real dij[3], dji[3];
            for (int a = 0; a < 3; a++) {
                dij[a] = xi[a] - xj[a];
                dji[a] = xj[a] - xi[a];
            }
            pfsph_real rij = pfsph_sqrt(dij[0] * dij[0] + dij[1] * dij[1] + dij[2] * dij[2]);
            pfsph_real rji = pfsph_sqrt(dji[0] * dji[0] + dji[1] * dji[1] + dji[2] * dji[2]);
            pfsph_real gij = pfsph_kernel_dw_r(&k, rij), gji = pfsph_kernel_dw_r(&k, rji);
            if (gij != 0) nonzero++;
            for (int a = 0; a < 3; a++) assert_true(gij * dij[a] == -(gji * dji[a]));
            /* W decreases with r, so grad_i W(x_ij) points from i towards j */
            assert_true(gij <= 0);
        }
        printf("%dD: %d of 2000 random pairs inside the support, antisymmetry exact\n", dim, nonzero);
        assert_true(nonzero > 200);
    }
}

/* On a regular lattice of spacing d = h/2, sum_j W(x_i - x_j) ~ 1/d^dim (the particle number
 * density), the SPH density estimate that sets rest density. */
static void test_lattice_sum(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        pfsph_kernel k;
        pfsph_kernel_init(&k, dim, H);
        double d = 0.5 * (double)H, sum = 0;
        int zr = dim == 3 ? 3 : 0;
        for (int iz = -zr; iz <= zr; iz++)
            for (int iy = -3; iy <= 3; iy++)
                for (int ix = -3; ix <= 3; ix++) {
                    double r = d * sqrt((double)ix * ix + (double)iy * iy + (double)iz * iz);
                    sum += (double)pfsph_kernel_w(&k, (pfsph_real)r);
                }
        double expect = 1.0 / pow(d, dim), rel = sum / expect - 1;
        /* not asserted: a point off the lattice (shifted by (d/3, d/5, d/7)) for information */
        double off[3] = {d / 3, d / 5, dim == 3 ? d / 7 : 0}, sum_off = 0;
        for (int iz = -zr; iz <= zr; iz++)
            for (int iy = -3; iy <= 3; iy++)
                for (int ix = -3; ix <= 3; ix++) {
                    double dx = ix * d - off[0], dy = iy * d - off[1], dz = iz * d - off[2];
                    sum_off += (double)pfsph_kernel_w(&k, (pfsph_real)sqrt(dx * dx + dy * dy + dz * dz));
                }
        printf("%dD: lattice sum at d = h/2: %.6f * 1/d^%d (rel err %.2e); off-lattice point %.4f\n", dim, sum / expect,
               dim, rel, sum_off / expect);
        assert_true(fabs(rel) < 0.01);
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_normalisation), cmocka_unit_test(test_shape),
        cmocka_unit_test(test_derivative),    cmocka_unit_test(test_gradient_antisymmetry),
        cmocka_unit_test(test_lattice_sum),
    };
    return tu_run_group(tests, NULL, NULL);
}
