/* Unit tests of the pair forces and the anisotropic filter (src/physics/pairwise.c) on
 * hand-made particle sets: the sign and range of Eq. 3/6 on two particles, T = I on lattices,
 * the anisotropy of a half-space, exact momentum balance with the filter off, the grid loops
 * against an O(N^2) oracle, thread-count independence; two-phase film particles (PF Eq. 24):
 * the pair coefficient against the formula, and momentum and thread independence with them; the
 * density summed in the pair walk (pfsph_pairwise_apply_density) against the density pass. */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/film.h"
#include "pfsph/pairwise.h"
#include "pfsph/sim.h"
#include "pfsph/eigen.h"
#include "physics/density.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

/* A scene, particle sets, grids and a context built by hand, as the core would. */
typedef struct world {
    pfsph_scene *scene;
    pfsph_particles fluid, boundary;
    pfsph_grid grid, bgrid;
    pfsph_ctx ctx;
    double d, h;
} world;

static void world_init(world *w, int dim, double d, int nphases, const double *rho, const int *kinds)
{
    memset(w, 0, sizeof(*w));
    w->scene = calloc(1, sizeof(pfsph_scene));
    assert_non_null(w->scene);
    pfsph_scene *s = w->scene;
    s->dim = dim;
    s->nphases = nphases;
    for (int a = 0; a < nphases; a++) {
        snprintf(s->phases[a].name, sizeof s->phases[a].name, "p%d", a);
        s->phases[a].kind = kinds ? kinds[a] : PFSPH_PHASE_FLUID;
        s->phases[a].rest_density = rho[a];
    }
    pfsph_pairwise_defaults(&s->pairwise);
    s->pairwise.enabled = true;
    w->d = d;
    w->h = 2 * d;
    assert_int_equal(pfsph_particles_init(&w->fluid, 64), PFSPH_OK);
    assert_int_equal(pfsph_particles_init(&w->boundary, 64), PFSPH_OK);
}

static void add(pfsph_particles *ps, double x, double y, double z, int phase)
{
    const pfsph_real p[3] = {(pfsph_real)x, (pfsph_real)y, (pfsph_real)z};
    assert_true(pfsph_particles_push(ps, p, NULL, (uint8_t)phase) >= 0);
}

/* Grids over the bounding box of all particles, cells of k*h; sorts both sets. */
static void world_finish(world *w)
{
    pfsph_scene *s = w->scene;
    int dim = s->dim;
    pfsph_real lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    pfsph_particles *sets[2] = {&w->fluid, &w->boundary};
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < sets[k]->n; i++) {
            const pfsph_real p[3] = {sets[k]->x[i], sets[k]->y[i], sets[k]->z[i]};
            for (int a = 0; a < 3; a++) {
                if (p[a] < lo[a]) lo[a] = p[a];
                if (p[a] > hi[a]) hi[a] = p[a];
            }
        }
    for (int a = 0; a < 3; a++) {
        lo[a] -= (pfsph_real)w->d;
        hi[a] += (pfsph_real)w->d;
    }
    pfsph_real cell = pfsph_pairwise_radius(s, (pfsph_real)w->h);
    if (cell < (pfsph_real)w->h) cell = (pfsph_real)w->h;
    assert_int_equal(pfsph_grid_init(&w->grid, dim, lo, hi, cell), PFSPH_OK);
    assert_int_equal(pfsph_grid_init(&w->bgrid, dim, lo, hi, cell), PFSPH_OK);
    size_t removed = 0;
    assert_int_equal(pfsph_grid_sort(&w->grid, &w->fluid, &removed), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(&w->bgrid, &w->boundary, &removed), PFSPH_OK);
    assert_int_equal(removed, 0);
    pfsph_ctx *c = &w->ctx;
    c->dim = dim;
    c->spacing = (pfsph_real)w->d;
    c->h = (pfsph_real)w->h;
    c->V0 = (pfsph_real)pow(w->d, dim);
    c->nd0 = 1 / c->V0;
    pfsph_kernel_init(&c->kern, dim, c->h);
    c->fluid = &w->fluid;
    c->boundary = &w->boundary;
    c->grid = &w->grid;
    c->bgrid = &w->bgrid;
    for (int a = 0; a < s->nphases; a++) {
        c->rest_density[a] = (pfsph_real)s->phases[a].rest_density;
        c->mass[a] = (pfsph_real)(s->phases[a].rest_density * pow(w->d, dim));
    }
    size_t n = w->fluid.n ? w->fluid.n : 1;
    c->ax = calloc(n, sizeof(pfsph_real));
    c->ay = calloc(n, sizeof(pfsph_real));
    c->az = calloc(n, sizeof(pfsph_real));
    assert_true(c->ax && c->ay && c->az);
    pfsph_ctx_set_model(c, s);
}

static void zero_acc(world *w)
{
    memset(w->ctx.ax, 0, w->fluid.n * sizeof(pfsph_real));
    memset(w->ctx.ay, 0, w->fluid.n * sizeof(pfsph_real));
    memset(w->ctx.az, 0, w->fluid.n * sizeof(pfsph_real));
}

static void apply(world *w)
{
    pfsph_pairwise *pw = NULL;
    pfsph_error err = {0};
    assert_int_equal(pfsph_pairwise_create(&pw, &w->ctx, &err), PFSPH_OK);
    zero_acc(w);
    pfsph_pairwise_apply(pw, &w->ctx);
    pfsph_pairwise_destroy(pw);
}

static void world_free(world *w)
{
    free(w->ctx.ax);
    free(w->ctx.ay);
    free(w->ctx.az);
    pfsph_grid_free(&w->grid);
    pfsph_grid_free(&w->bgrid);
    pfsph_particles_free(&w->fluid);
    pfsph_particles_free(&w->boundary);
    free(w->scene);
}

static void test_shape(void **state)
{
    (void)state;
    const double R = 1.0;
    assert_true(pfsph_pairwise_shape(0.0, R) == 1.0);
    assert_true(pfsph_pairwise_shape(0.3, R) > 0);
    assert_true(fabs(pfsph_pairwise_shape(R / 3, R)) < 1e-15);
    assert_true(pfsph_pairwise_shape(0.34, R) < 0);
    assert_true(pfsph_pairwise_shape(0.99, R) < 0);
    assert_true(fabs(pfsph_pairwise_shape(R, R)) < 1e-15);
    assert_true(pfsph_pairwise_shape(1.01, R) == 0);
    assert_true(fabs(cbrt(80.0 / 30.0) - 1.3867) < 1e-4); /* Eq. 5 */
}

/* Two particles of different phases and masses: sign, magnitude, range, action-reaction. */
static void test_two_particles(void **state)
{
    (void)state;
    const double rho[2] = {1000, 400};
    const double d = 0.01;
    const double R = cbrt(80.0 / 30.0) * 2 * d;
    const double frac[] = {0.1, 0.3, 0.34, 0.5, 0.8, 0.99, 1.01, 1.5};
    for (int dim = 2; dim <= 3; dim++)
        for (size_t t = 0; t < sizeof frac / sizeof frac[0]; t++) {
            world w;
            world_init(&w, dim, d, 2, rho, NULL);
            w.scene->pairwise.filter = false;
            w.scene->pairwise.c[0][1] = w.scene->pairwise.c[1][0] = 3.0e4;
            double r = frac[t] * R;
            /* along a skew direction so that every component is exercised */
            double e[3] = {0.6, 0.8, 0.0};
            if (dim == 3) {
                e[0] = 0.48;
                e[1] = 0.6;
                e[2] = 0.64;
            }
            add(&w.fluid, 0, 0, 0, 0);
            add(&w.fluid, r * e[0], r * e[1], r * e[2], 1);
            world_finish(&w);
            apply(&w);
            size_t i = tu_nearest(&w.fluid, 0, 0, 0), j = 1 - i;
            double m0 = w.ctx.mass[0], m1 = w.ctx.mass[1];
            double a0[3] = {w.ctx.ax[i], w.ctx.ay[i], w.ctx.az[i]};
            double a1[3] = {w.ctx.ax[j], w.ctx.ay[j], w.ctx.az[j]};
            double rr = sqrt(pow(w.fluid.x[j] - w.fluid.x[i], 2) + pow(w.fluid.y[j] - w.fluid.y[i], 2) +
                             pow(w.fluid.z[j] - w.fluid.z[i], 2));
            /* |F| = c m_i m_j f(r), along r_ij = r_0 - r_1 = -r e */
            double f = 3.0e4 * m0 * m1 * (rr < R ? cos(1.5 * PI * rr / R) : 0.0);
            for (int a = 0; a < 3; a++) {
                double F0 = m0 * a0[a], F1 = m1 * a1[a];
                double expect = -f * e[a];
                assert_true(fabs(F0 - expect) <= 1e-5 * fabs(f) + 1e-30);
                assert_true(fabs(F0 + F1) <= 1e-6 * fabs(f) + 1e-30); /* f_ji = -f_ij */
            }
            /* repulsive below R/3: particle 0 pushed away from particle 1 (along -e) */
            double proj = a0[0] * e[0] + a0[1] * e[1] + a0[2] * e[2];
            if (frac[t] < 1.0 / 3) assert_true(proj < 0);
            else if (frac[t] < 1.0) assert_true(proj > 0);
            else assert_true(proj == 0);
            /* virial r_ij . F_ji = c m0 m1 f(r) r */
            double vir[2];
            pfsph_pairwise_diagnose(NULL, &w.ctx, vir, NULL);
            assert_true(fabs(vir[i] - f * rr) <= 1e-5 * fabs(f * rr) + 1e-30);
            assert_true(fabs(vir[j] - f * rr) <= 1e-5 * fabs(f * rr) + 1e-30);
            world_free(&w);
        }
}

static void test_filter_matrix(void **state)
{
    (void)state;
    double T[3][3];
    const double iso[3][3] = {{2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
    pfsph_pairwise_filter_matrix(3, iso, 0.2, 0.5, T);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) assert_true(fabs(T[a][b] - (a == b)) < 1e-15);
    /* C = diag(1, 0.7, 0.1): e = (1, 0.7, 0.5) -> G/|G| = diag(0.5, 0.5/0.7, 1) */
    const double an[3][3] = {{1, 0, 0}, {0, 0.7, 0}, {0, 0, 0.1}};
    pfsph_pairwise_filter_matrix(3, an, 0.2, 0.5, T);
    assert_true(fabs(T[0][0] - (0.8 + 0.2 * 0.5)) < 1e-14);
    assert_true(fabs(T[1][1] - (0.8 + 0.2 * 0.5 / 0.7)) < 1e-14);
    assert_true(fabs(T[2][2] - 1.0) < 1e-14);
    assert_true(fabs(T[0][1]) < 1e-14 && fabs(T[1][2]) < 1e-14);
    /* scale invariance and eta = 0 */
    const double an2[3][3] = {{3, 0, 0}, {0, 2.1, 0}, {0, 0, 0.3}};
    double T2[3][3];
    pfsph_pairwise_filter_matrix(3, an2, 0.2, 0.5, T2);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) assert_true(fabs(T[a][b] - T2[a][b]) < 1e-14);
    pfsph_pairwise_filter_matrix(3, an, 0.0, 0.5, T);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) assert_true(T[a][b] == (a == b));
    /* 2D, rotated by 30 degrees: C = R diag(1, 0.2) R^T; normal (small variance) axis kept */
    double c = cos(PI / 6), s = sin(PI / 6);
    const double r2[3][3] = {
        {c * c + 0.2 * s * s, (1 - 0.2) * c * s, 0}, {(1 - 0.2) * c * s, s * s + 0.2 * c * c, 0}, {0, 0, 0}};
    pfsph_pairwise_filter_matrix(2, r2, 0.2, 0.5, T);
    double n[2] = {-s, c}, t[2] = {c, s};
    double Tn = n[0] * (T[0][0] * n[0] + T[0][1] * n[1]) + n[1] * (T[1][0] * n[0] + T[1][1] * n[1]);
    double Tt = t[0] * (T[0][0] * t[0] + T[0][1] * t[1]) + t[1] * (T[1][0] * t[0] + T[1][1] * t[1]);
    assert_true(fabs(Tn - 1.0) < 1e-14);
    assert_true(fabs(Tt - 0.9) < 1e-14);
    assert_true(T[2][2] == 1.0 && T[0][2] == 0.0);
    /* empty neighbourhood */
    const double z[3][3] = {{0}};
    pfsph_pairwise_filter_matrix(3, z, 0.2, 0.5, T);
    assert_true(T[0][0] == 1 && T[1][1] == 1 && T[2][2] == 1);
    /* random covariances, clamped or not (the unclamped take w_min C^-1, the others the
     * eigenvectors), nearly isotropic ones included: against Eqs. 8-12 from Jacobi's
     * eigen-decomposition, to float precision */
    uint64_t st = 777;
    double worst = 0;
    for (int t = 0; t < 20000; t++) {
        double g[3][3], Cr[3][3];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                st = st * 6364136223846793005ULL + 1442695040888963407ULL;
                g[a][b] = (double)(st >> 11) / 9007199254740992.0 - 0.5;
            }
        const double iso = t % 3 == 0 ? 1.0 : (t % 3 == 1 ? 0.05 : 1e-6); /* spread of the spectrum */
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                Cr[a][b] = a == b ? 1.0 : 0.0;
                for (int k = 0; k < 3; k++) Cr[a][b] += iso * g[a][k] * g[b][k] * 10.0;
            }
        double w[3], v[3][3], Tref[3][3];
        pfsph_eigen_sym3(Cr, w, v);
        double e[3], emin = 1;
        for (int k = 0; k < 3; k++) {
            e[k] = fmax(w[k] / w[0], 0.5);
            emin = fmin(emin, e[k]);
        }
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double gg = 0;
                for (int k = 0; k < 3; k++) gg += v[a][k] * v[b][k] * emin / e[k];
                Tref[a][b] = (a == b ? 0.8 : 0.0) + 0.2 * gg;
            }
        pfsph_pairwise_filter_matrix(3, Cr, 0.2, 0.5, T);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) worst = fmax(worst, fabs(T[a][b] - Tref[a][b]));
    }
    print_message("filter matrix against Jacobi: largest difference %.3g\n", worst);
    assert_true(worst < 1e-8);
}

/* T = I and zero net force for an interior particle of square, hexagonal and cubic lattices. */
static void test_lattice_isotropic(void **state)
{
    (void)state;
    const double rho[1] = {1000};
    const double d = 0.01;
    for (int kind = 0; kind < 3; kind++) {
        world w;
        int dim = kind == 2 ? 3 : 2;
        world_init(&w, dim, d, 1, rho, NULL);
        w.scene->pairwise.c[0][0] = 1e4;
        int N = dim == 2 ? 8 : 5;
        for (int i = -N; i <= N; i++)
            for (int j = -N; j <= N; j++)
                for (int k = (dim == 3 ? -N : 0); k <= (dim == 3 ? N : 0); k++) {
                    if (kind == 1) /* hexagonal: rows sqrt(3)/2 d apart, odd rows shifted */
                        add(&w.fluid, (i + 0.5 * (abs(j) % 2)) * d, j * d * sqrt(3) / 2, 0, 0);
                    else add(&w.fluid, i * d, j * d, k * d, 0);
                }
        world_finish(&w);
        size_t c = tu_nearest(&w.fluid, 0, 0, 0);
        double *T = calloc(9 * w.fluid.n, sizeof(double));
        pfsph_pairwise_diagnose(NULL, &w.ctx, NULL, T);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) assert_true(fabs(T[9 * c + 3 * a + b] - (a == b)) < 2e-6);
        apply(&w);
        double m = w.ctx.mass[0];
        double scale = 1e4 * m; /* one neighbour's acceleration at f = 1 */
        assert_true(fabs(w.ctx.ax[c]) < 1e-4 * scale && fabs(w.ctx.ay[c]) < 1e-4 * scale &&
                    fabs(w.ctx.az[c]) < 1e-4 * scale);
        free(T);
        world_free(&w);
    }
}

/* A particle on the flat surface of a half-space (square lattice, y <= 0). */
static void test_half_space(void **state)
{
    (void)state;
    const double rho[1] = {1000};
    const double d = 0.01, eta = 0.2;
    double txx_edge[2] = {0, 0};
    for (int center = 0; center < 2; center++) {
        world w;
        world_init(&w, 2, d, 1, rho, NULL);
        w.scene->pairwise.c[0][0] = 1e4;
        w.scene->pairwise.center = center;
        for (int i = -10; i <= 10; i++)
            for (int j = -10; j <= 0; j++) add(&w.fluid, i * d, j * d, 0, 0);
        world_finish(&w);
        double *T = calloc(9 * w.fluid.n, sizeof(double));
        pfsph_pairwise_diagnose(NULL, &w.ctx, NULL, T);
        const double R = w.scene->pairwise.k * w.h;
        pfsph_kernel kk;
        pfsph_kernel_init(&kk, 2, (pfsph_real)R);
        for (int depth = 0; depth <= 1; depth++) {
            size_t c = tu_nearest(&w.fluid, 0, -depth * d, 0);
            /* independent covariance in double over the lattice (Eq. 7, self included) */
            double sw = kk.sigma, sx = 0, sy = 0, sxx = 0, syy = 0;
            for (int i = -10; i <= 10; i++)
                for (int j = -10; j <= 0; j++) {
                    double dx = i * d, dy = (j + depth) * d, r = hypot(dx, dy);
                    if (r == 0 || r >= R) continue;
                    double wt = pfsph_kernel_w(&kk, (pfsph_real)r);
                    sw += wt;
                    sx += wt * dx;
                    sy += wt * dy;
                    sxx += wt * dx * dx;
                    syy += wt * dy * dy;
                }
            double cxx = sxx / sw, cyy = syy / sw;
            if (center == PFSPH_PW_CENTER_MEAN) {
                cxx -= (sx / sw) * (sx / sw);
                cyy -= (sy / sw) * (sy / sw);
            }
            const double *Tc = T + 9 * c;
            assert_true(fabs(Tc[1]) < 1e-6 && fabs(Tc[3]) < 1e-6);
            /* expected: the normal (y, smaller spread) keeps factor 1, the tangent gets
             * (1 - eta) + eta * max(cyy / cxx, 0.5) */
            assert_true(cyy < cxx);
            double en = cyy / cxx > 0.5 ? cyy / cxx : 0.5;
            double Txx = (1 - eta) + eta * en;
            print_message("centre %s, depth %d: C_yy/C_xx = %.4f, T_xx = %.5f (expect %.5f), T_yy = %.5f\n",
                          center ? "particle" : "mean", depth, cyy / cxx, Tc[0], Txx, Tc[4]);
            assert_true(fabs(Tc[0] - Txx) < 1e-5);
            assert_true(fabs(Tc[4] - 1.0) < 1e-6);
            assert_true(Tc[0] < 1.0 - 1e-3);
            if (depth == 0) txx_edge[center] = Tc[0];
        }
        /* the surface is pulled into the liquid: net force on an edge particle points down */
        apply(&w);
        size_t c = tu_nearest(&w.fluid, 0, 0, 0);
        assert_true(w.ctx.ay[c] < 0);
        assert_true(fabs(w.ctx.ax[c]) < 1e-4 * fabs(w.ctx.ay[c]));
        free(T);
        world_free(&w);
    }
    /* about x_i (Eq. 7 as written) second moments are even in the normal in the continuum
     * limit; on the lattice the surface row still makes the edge anisotropic, but less so
     * than about the weighted mean */
    assert_true(1.0 - txx_edge[PFSPH_PW_CENTER_PARTICLE] < 1.0 - txx_edge[PFSPH_PW_CENTER_MEAN]);
}

static uint64_t g_rng = 987654321;
static double urand(void)
{
    g_rng = g_rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(g_rng >> 11) * (1.0 / 9007199254740992.0);
}

/* Random cloud of two phases with different masses (and optionally boundary particles). */
static void random_cloud(world *w, int dim, int n, int nb)
{
    const double rho[3] = {1000, 250, 2000};
    const int kinds[3] = {PFSPH_PHASE_FLUID, PFSPH_PHASE_FLUID, PFSPH_PHASE_SOLID};
    const double d = 0.01;
    world_init(w, dim, d, 3, rho, kinds);
    pfsph_pairwise_params *pp = &w->scene->pairwise;
    pp->c[0][0] = 1.0e4;
    pp->c[1][1] = 2.0e4;
    pp->c[0][1] = pp->c[1][0] = 3.0e3;
    pp->c[0][2] = pp->c[2][0] = 5.0e3;
    pp->c[1][2] = pp->c[2][1] = 1.0e3;
    double L = dim == 2 ? sqrt((double)n) * d : cbrt((double)n) * d;
    for (int i = 0; i < n; i++)
        add(&w->fluid, urand() * L, urand() * L, dim == 3 ? urand() * L : 0, urand() < 0.6 ? 0 : 1);
    for (int i = 0; i < nb; i++) add(&w->boundary, urand() * L, -urand() * 3 * d, dim == 3 ? urand() * L : 0, 2);
    world_finish(w);
}

/* With the filter off (or eta = 0) the interaction forces sum to zero (NOTES item 5). */
static void test_momentum(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++)
        for (int mode = 0; mode < 3; mode++) {
            world w;
            random_cloud(&w, dim, dim == 2 ? 400 : 1000, 0);
            w.scene->pairwise.filter = mode == 1 ? false : true;
            w.scene->pairwise.eta = mode == 0 ? 0.0 : 0.2;
            apply(&w);
            double sum[3] = {0, 0, 0}, mag = 0;
            for (size_t i = 0; i < w.fluid.n; i++) {
                double m = w.ctx.mass[w.fluid.phase[i]];
                const double F[3] = {m * w.ctx.ax[i], m * w.ctx.ay[i], m * w.ctx.az[i]};
                for (int a = 0; a < 3; a++) {
                    sum[a] += F[a];
                    mag += fabs(F[a]);
                }
            }
            double rel = (fabs(sum[0]) + fabs(sum[1]) + fabs(sum[2])) / mag;
            print_message("dim %d, %s: |sum F| / sum |F| = %.3g\n", dim,
                          mode == 0       ? "filter on, eta 0"
                              : mode == 1 ? "filter off"
                                          : "filter on, eta 0.2",
                          rel);
            /* float storage of each acceleration rounds at ~6e-8 */
            double tol = sizeof(pfsph_real) == 4 ? 2e-6 : 1e-13;
            if (mode < 2) assert_true(rel < tol);
            else assert_true(rel > 10 * tol); /* Eq. 12 does not conserve momentum */
            world_free(&w);
        }
}

/* The grid loops against an O(N^2) evaluation in double, fluid and boundary neighbours, filter
 * on; also the same bits for 1 and 2 threads. */
static void test_brute_force(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        world w;
        random_cloud(&w, dim, dim == 2 ? 300 : 600, dim == 2 ? 60 : 200);
        w.scene->pairwise.center = dim == 2 ? PFSPH_PW_CENTER_MEAN : PFSPH_PW_CENTER_PARTICLE;
        const pfsph_pairwise_params *pp = &w.scene->pairwise;
        omp_set_num_threads(1);
        apply(&w);
        size_t n = w.fluid.n;
        pfsph_real *a1 = malloc(3 * n * sizeof(pfsph_real));
        memcpy(a1, w.ctx.ax, n * sizeof(pfsph_real));
        memcpy(a1 + n, w.ctx.ay, n * sizeof(pfsph_real));
        memcpy(a1 + 2 * n, w.ctx.az, n * sizeof(pfsph_real));
        omp_set_num_threads(2);
        apply(&w);
        assert_memory_equal(a1, w.ctx.ax, n * sizeof(pfsph_real));
        assert_memory_equal(a1 + n, w.ctx.ay, n * sizeof(pfsph_real));
        assert_memory_equal(a1 + 2 * n, w.ctx.az, n * sizeof(pfsph_real));
        free(a1);
        const double R = pp->k * w.h;
        pfsph_kernel kk;
        pfsph_kernel_init(&kk, dim, (pfsph_real)R);
        double maxerr = 0, maxmag = 0;
        for (size_t i = 0; i < n; i++) {
            double acc[3] = {0, 0, 0}, sw = kk.sigma, sx[3] = {0, 0, 0}, sxx[3][3] = {{0}};
            const pfsph_particles *sets[2] = {&w.fluid, &w.boundary};
            for (int k = 0; k < 2; k++)
                for (size_t j = 0; j < sets[k]->n; j++) {
                    if (k == 0 && j == i) continue;
                    double dx[3] = {(double)w.fluid.x[i] - sets[k]->x[j], (double)w.fluid.y[i] - sets[k]->y[j],
                                    (double)w.fluid.z[i] - sets[k]->z[j]};
                    double r = sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
                    if (r >= R || r == 0) continue;
                    int pa = w.fluid.phase[i], pb = sets[k]->phase[j];
                    double s = pp->c[pa][pb] * w.ctx.mass[pb] * pfsph_pairwise_shape(r, R) / r;
                    double wt = pfsph_kernel_w(&kk, (pfsph_real)r);
                    sw += wt;
                    for (int a = 0; a < 3; a++) {
                        acc[a] += s * dx[a];
                        sx[a] -= wt * dx[a];
                        for (int b = 0; b < 3; b++) sxx[a][b] += wt * dx[a] * dx[b];
                    }
                }
            double C[3][3], T[3][3];
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    C[a][b] = sxx[a][b] / sw - (pp->center == PFSPH_PW_CENTER_MEAN ? sx[a] * sx[b] / (sw * sw) : 0);
            pfsph_pairwise_filter_matrix(dim, C, pp->eta, pp->eps_min, T);
            const double got[3] = {w.ctx.ax[i], w.ctx.ay[i], w.ctx.az[i]};
            for (int a = 0; a < 3; a++) {
                double e = T[a][0] * acc[0] + T[a][1] * acc[1] + T[a][2] * acc[2];
                maxerr = fmax(maxerr, fabs(got[a] - e));
                maxmag = fmax(maxmag, fabs(e));
            }
        }
        print_message("dim %d: max |a - a_brute| = %.3g of max |a| = %.3g\n", dim, maxerr, maxmag);
        assert_true(maxerr <= 1e-4 * maxmag);
        world_free(&w);
    }
}

static void test_create_checks_grid(void **state)
{
    (void)state;
    const double rho[1] = {1000};
    world w;
    world_init(&w, 2, 0.01, 1, rho, NULL);
    add(&w.fluid, 0, 0, 0, 0);
    world_finish(&w);
    w.grid.cell = (pfsph_real)w.h; /* pretend the core sized cells for h only */
    pfsph_pairwise *pw = NULL;
    pfsph_error err = {0};
    assert_int_equal(pfsph_pairwise_create(&pw, &w.ctx, &err), PFSPH_EINPUT);
    assert_null(pw);
    assert_non_null(strstr(err.msg, "k*h"));
    pfsph_pairwise_destroy(NULL);
    w.scene->pairwise.enabled = false;
    assert_true(pfsph_pairwise_radius(w.scene, 1.0f) == 0);
    world_free(&w);
}

/* PF Eq. 24: two gas particles of a bubble (phase beta = 1, rho 400) holding film fractions a and
 * b of the liquid alpha = 0 (rho 1000): the force on each is c~ m_i m_j f(r) with
 * c~ = a b c_aa + (a (1 - b) + (1 - a) b) c_ab + (1 - a)(1 - b) c_bb, opposite on the two
 * (symmetric in i, j), for a, b in {0, 0.3, 1}; a film particle against a solid (phase 2) and
 * against an ordinary liquid particle mixes the same matrix. */
static void test_film_eq24(void **state)
{
    (void)state;
    const double rho[3] = {1000, 400, 2000};
    const int kinds[3] = {PFSPH_PHASE_FLUID, PFSPH_PHASE_GAS, PFSPH_PHASE_SOLID};
    const double d = 0.01, caa = 2.0e4, cab = 5.0e3, cbb = 1.0e3, caw = 7.0e3, cbw = 3.0e3;
    const double fr[3] = {0, 0.3, 1};
    double maxrel = 0;
    for (int dim = 2; dim <= 3; dim++)
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++)
                for (int other = 0; other < 3; other++) { /* j: film particle, liquid, solid */
                    if (other && q) continue;             /* b is the film particle's only */
                    world w;
                    world_init(&w, dim, d, 3, rho, kinds);
                    pfsph_pairwise_params *pp = &w.scene->pairwise;
                    pp->filter = false;
                    pp->c[0][0] = caa;
                    pp->c[0][1] = pp->c[1][0] = cab;
                    pp->c[1][1] = cbb;
                    pp->c[0][2] = pp->c[2][0] = caw;
                    pp->c[1][2] = pp->c[2][1] = cbw;
                    pfsph_film_defaults(&w.scene->film);
                    w.scene->film.nbubbles = 1;
                    w.scene->film.film[1] = 0;
                    const double r = 0.7 * pp->k * 2 * d; /* attractive range */
                    const double e[3] = {0.48, 0.6, dim == 3 ? 0.64 : 0};
                    const double en = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
                    add(&w.fluid, 0, 0, 0, 1);
                    if (other == 2) add(&w.boundary, r * e[0] / en, r * e[1] / en, r * e[2] / en, 2);
                    else add(&w.fluid, r * e[0] / en, r * e[1] / en, r * e[2] / en, other == 1 ? 0 : 1);
                    world_finish(&w);
                    const size_t i = tu_nearest(&w.fluid, 0, 0, 0), j = 1 - i;
                    const double a = fr[p], b = fr[q];
                    w.fluid.film[i] = (pfsph_real)a;
                    if (other == 0) w.fluid.film[j] = (pfsph_real)b;
                    apply(&w);
                    double expect_c;
                    int pj;
                    if (other == 0) {
                        expect_c =
                            a * b * caa + (a * (1 - b) + (1 - a) * b) * cab + (1 - a) * (1 - b) * cbb; /* Eq. 24 */
                        pj = 1;
                    } else if (other == 1) {
                        expect_c = a * caa + (1 - a) * cab;
                        pj = 0;
                    } else {
                        expect_c = a * caw + (1 - a) * cbw;
                        pj = 2;
                    }
                    const pfsph_particles *sj = other == 2 ? &w.boundary : &w.fluid;
                    const size_t jj = other == 2 ? 0 : j;
                    /* the formula in the header, both orders */
                    const double c_ij = pfsph_film_pair_c((const double(*)[PFSPH_MAX_PHASES])pp->c, w.scene->film.film,
                                                          1, a, pj, other == 0 ? b : 0, false);
                    const double c_ji = pfsph_film_pair_c((const double(*)[PFSPH_MAX_PHASES])pp->c, w.scene->film.film,
                                                          pj, other == 0 ? b : 0, 1, a, false);
                    assert_true(fabs(c_ij - expect_c) <= 1e-12 * expect_c);
                    assert_true(c_ij == c_ji);
                    const double rr = sqrt(pow(sj->x[jj] - w.fluid.x[i], 2) + pow(sj->y[jj] - w.fluid.y[i], 2) +
                                           pow(sj->z[jj] - w.fluid.z[i], 2));
                    const double R = pp->k * 2 * d;
                    const double mi = w.ctx.mass[1], mj = w.ctx.mass[pj];
                    const double F = expect_c * mi * mj * cos(1.5 * PI * rr / R); /* Eq. 3, 6 */
                    const double Fi[3] = {mi * w.ctx.ax[i], mi * w.ctx.ay[i], mi * w.ctx.az[i]};
                    for (int k = 0; k < 3; k++) {
                        const double ex = (0 - (k == 0 ? sj->x[jj] : k == 1 ? sj->y[jj] : sj->z[jj])) / rr * F;
                        const double rel = fabs(Fi[k] - ex) / fabs(F);
                        maxrel = fmax(maxrel, rel);
                        assert_true(rel <= 1e-5);
                        if (other != 2) { /* action and reaction */
                            const double Fj = w.ctx.mass[pj] *
                                (k == 0       ? w.ctx.ax[j]
                                     : k == 1 ? w.ctx.ay[j]
                                              : w.ctx.az[j]);
                            assert_true(fabs(Fi[k] + Fj) <= 1e-6 * fabs(F));
                        }
                    }
                    world_free(&w);
                }
    print_message("Eq. 24: largest relative force error %.2g over a, b in {0, 0.3, 1}, film-film, film-liquid, "
                  "film-solid, 2D and 3D\n",
                  maxrel);
}

/* Momentum (filter off or eta 0) and 1 vs 2 threads with two-phase particles: the cloud's
 * phase-1 particles are a bubble's gas, half of them film particles with fractions in (0, 1). */
static void test_film_momentum_threads(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++)
        for (int mode = 0; mode < 3; mode++) {
            world w;
            random_cloud(&w, dim, dim == 2 ? 400 : 1000, dim == 2 ? 60 : 200);
            w.scene->phases[1].kind = PFSPH_PHASE_GAS;
            pfsph_film_defaults(&w.scene->film);
            w.scene->film.nbubbles = 1;
            w.scene->film.film[1] = 0;
            size_t nfilm = 0;
            for (size_t i = 0; i < w.fluid.n; i++)
                if (w.fluid.phase[i] == 1 && urand() < 0.5) {
                    w.fluid.film[i] = (pfsph_real)(0.05 + 0.9 * urand());
                    w.fluid.bubble[i] = 1;
                    nfilm++;
                }
            w.scene->pairwise.filter = mode == 1 ? false : true;
            w.scene->pairwise.eta = mode == 0 ? 0.0 : 0.2;
            omp_set_num_threads(1);
            apply(&w);
            const size_t n = w.fluid.n;
            pfsph_real *a1 = malloc(3 * n * sizeof(pfsph_real));
            assert_non_null(a1);
            memcpy(a1, w.ctx.ax, n * sizeof(pfsph_real));
            memcpy(a1 + n, w.ctx.ay, n * sizeof(pfsph_real));
            memcpy(a1 + 2 * n, w.ctx.az, n * sizeof(pfsph_real));
            omp_set_num_threads(2);
            apply(&w);
            assert_memory_equal(a1, w.ctx.ax, n * sizeof(pfsph_real));
            assert_memory_equal(a1 + n, w.ctx.ay, n * sizeof(pfsph_real));
            assert_memory_equal(a1 + 2 * n, w.ctx.az, n * sizeof(pfsph_real));
            free(a1);
            if (mode < 2) { /* momentum: fluid-fluid pairs only (walls are static) */
                w.boundary.n = 0;
                apply(&w);
                double sum[3] = {0, 0, 0}, mag = 0;
                for (size_t i = 0; i < n; i++) {
                    const double m = w.ctx.mass[w.fluid.phase[i]];
                    const double F[3] = {m * w.ctx.ax[i], m * w.ctx.ay[i], m * w.ctx.az[i]};
                    for (int a = 0; a < 3; a++) {
                        sum[a] += F[a];
                        mag += fabs(F[a]);
                    }
                }
                const double rel = (fabs(sum[0]) + fabs(sum[1]) + fabs(sum[2])) / mag;
                print_message("dim %d, %zu film particles, %s: |sum F| / sum |F| = %.3g; 1 and 2 threads: same bits\n",
                              dim, nfilm, mode == 0 ? "filter on, eta 0" : "filter off", rel);
                assert_true(rel < (sizeof(pfsph_real) == 4 ? 2e-6 : 1e-13));
            }
            world_free(&w);
        }
}

/* The density and pair stages in one walk (pfsph_pairwise_apply_density, used by sim.c for
 * WCSPH and PCISPH): the accelerations are the bits pfsph_pairwise_apply adds, and the number
 * density is the density pass's (pfsph__number_density) up to the order of its float sum: a
 * sum of ~30-60 positive terms in float differs by a few ulp (6e-8 each) with the order, so
 * 1e-6 relative; checked also in double against an O(N^2) sum, 1 and 2 threads, and with the
 * pair forces switched off (zero forces, the same density). */
static void test_density_fused(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++)
        for (int on = 0; on <= 1; on++) {
            world w;
            random_cloud(&w, dim, dim == 2 ? 300 : 600, dim == 2 ? 60 : 200);
            w.scene->pairwise.enabled = on;
            for (size_t j = 0; j < w.boundary.n; j++) /* Akinci volumes around V0 */
                w.boundary.aux[j] = w.ctx.V0 * (pfsph_real)(0.5 + urand());
            const size_t n = w.fluid.n;
            pfsph_real *nd_ref = malloc(n * sizeof(pfsph_real)), *nd1 = malloc(n * sizeof(pfsph_real)),
                       *nd2 = malloc(n * sizeof(pfsph_real)), *acc = malloc(3 * n * sizeof(pfsph_real));
            assert_true(nd_ref && nd1 && nd2 && acc);
            pfsph__number_density(&w.ctx, w.fluid.x, w.fluid.y, w.fluid.z, nd_ref);
            pfsph_pairwise *pw = NULL;
            pfsph_error err = {0};
            assert_int_equal(pfsph_pairwise_create(&pw, &w.ctx, &err), PFSPH_OK);
            pfsph_real *const a[3] = {acc, acc + n, acc + 2 * n};
            for (size_t i = 0; i < 3 * n; i++) acc[i] = 12345; /* written, not added to */
            omp_set_num_threads(1);
            pfsph_pairwise_apply_density(pw, &w.ctx, nd1, a);
            zero_acc(&w);
            pfsph_pairwise_apply(pw, &w.ctx);
            assert_memory_equal(acc, w.ctx.ax, n * sizeof(pfsph_real));
            assert_memory_equal(acc + n, w.ctx.ay, n * sizeof(pfsph_real));
            assert_memory_equal(acc + 2 * n, w.ctx.az, n * sizeof(pfsph_real));
            double amag = 0;
            for (size_t i = 0; i < 3 * n; i++) amag = fmax(amag, fabs(acc[i]));
            assert_true(on ? amag > 0 : amag == 0);
            omp_set_num_threads(2);
            pfsph_pairwise_apply_density(pw, &w.ctx, nd2, a);
            assert_memory_equal(nd1, nd2, n * sizeof(pfsph_real));
            double rel = 0, relb = 0;
            for (size_t i = 0; i < n; i++) {
                rel = fmax(rel, fabs((double)nd1[i] - nd_ref[i]) / nd_ref[i]);
                double s = 0; /* Eq. 23 in double over all pairs: fluid, then walls (volume / V0) */
                const pfsph_particles *sets[2] = {&w.fluid, &w.boundary};
                for (int k = 0; k < 2; k++)
                    for (size_t j = 0; j < sets[k]->n; j++) {
                        const double r = sqrt(pow((double)w.fluid.x[i] - sets[k]->x[j], 2) +
                                              pow((double)w.fluid.y[i] - sets[k]->y[j], 2) +
                                              pow((double)w.fluid.z[i] - sets[k]->z[j], 2));
                        const double vol = k == 0 ? 1.0 : (double)sets[k]->aux[j] / (double)w.ctx.V0;
                        s += vol * pfsph_kernel_w(&w.ctx.kern, (pfsph_real)r);
                    }
                relb = fmax(relb, fabs((double)nd1[i] - s) / s);
            }
            print_message(
                "dim %d, pair forces %s: nd in the pair walk vs the density pass %.2g, vs O(N^2) in double %.2g "
                "(relative, largest); accelerations the same bits, 1 and 2 threads the same bits\n",
                dim, on ? "on" : "off", rel, relb);
            assert_true(rel <= 1e-6);
            assert_true(relb <= 1e-5);
            pfsph_pairwise_destroy(pw);
            free(nd_ref);
            free(nd1);
            free(nd2);
            free(acc);
            world_free(&w);
        }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shape),         cmocka_unit_test(test_two_particles),
        cmocka_unit_test(test_filter_matrix), cmocka_unit_test(test_lattice_isotropic),
        cmocka_unit_test(test_half_space),    cmocka_unit_test(test_momentum),
        cmocka_unit_test(test_brute_force),   cmocka_unit_test(test_create_checks_grid),
        cmocka_unit_test(test_film_eq24),     cmocka_unit_test(test_film_momentum_threads),
        cmocka_unit_test(test_density_fused),
    };
    return tu_run_group(tests, NULL, NULL);
}
