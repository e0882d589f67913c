/* Unit tests of particle shifting (src/physics/shifting.c): no shift on a perfect lattice, a
 * displaced particle is moved back towards its site, free-surface particles keep no normal
 * shift, the per-step cap, wall particles stop fluid from being shifted into a wall, velocities
 * untouched, the concentration against an O(N^2) oracle, thread-count independence, and the
 * scene keys of the "shifting" block. */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/pairwise.h"
#include "pfsph/shifting.h"
#include "pfsph/sim.h"
#include "testutil.h"

typedef struct world {
    pfsph_scene *scene;
    pfsph_particles fluid, boundary;
    pfsph_grid grid, bgrid;
    pfsph_ctx ctx;
    double d, h;
} world;

static void world_init(world *w, int dim, double d)
{
    memset(w, 0, sizeof(*w));
    w->scene = calloc(1, sizeof(pfsph_scene));
    assert_non_null(w->scene);
    w->scene->dim = dim;
    w->scene->nphases = 1;
    w->scene->phases[0].rest_density = 1000;
    pfsph_pairwise_defaults(&w->scene->pairwise);
    w->scene->pairwise.enabled = true;
    w->d = d;
    w->h = 2 * d;
    assert_int_equal(pfsph_particles_init(&w->fluid, 64), PFSPH_OK);
    assert_int_equal(pfsph_particles_init(&w->boundary, 64), PFSPH_OK);
}

static void add(pfsph_particles *ps, double x, double y, double z)
{
    const pfsph_real p[3] = {(pfsph_real)x, (pfsph_real)y, (pfsph_real)z};
    assert_true(pfsph_particles_push(ps, p, NULL, 0) >= 0);
}

static void world_finish(world *w)
{
    int dim = w->scene->dim;
    pfsph_real lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    if (dim == 2) lo[2] = hi[2] = 0;
    pfsph_real cell = (pfsph_real)(w->scene->pairwise.k * w->h);
    assert_int_equal(pfsph_grid_init(&w->grid, dim, lo, hi, cell), PFSPH_OK);
    assert_int_equal(pfsph_grid_init(&w->bgrid, dim, lo, hi, cell), PFSPH_OK);
    size_t removed = 0;
    assert_int_equal(pfsph_grid_sort(&w->grid, &w->fluid, &removed), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(&w->bgrid, &w->boundary, &removed), PFSPH_OK);
    for (size_t i = 0; i < w->boundary.n; i++) w->boundary.aux[i] = (pfsph_real)pow(w->d, dim);
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
    c->mass[0] = (pfsph_real)(1000 * c->V0);
    pfsph_ctx_set_model(c, w->scene);
}

static void world_free(world *w)
{
    pfsph_grid_free(&w->grid);
    pfsph_grid_free(&w->bgrid);
    pfsph_particles_free(&w->fluid);
    pfsph_particles_free(&w->boundary);
    free(w->scene);
}

/* One shifting step; the shifts in s[3][n] (caller frees), returns the largest. */
static double shift(world *w, const pfsph_shift_params *p, double dt, pfsph_real **s)
{
    size_t n = w->fluid.n;
    for (int a = 0; a < 3; a++) {
        s[a] = calloc(n, sizeof(pfsph_real));
        assert_non_null(s[a]);
    }
    return pfsph_shift_apply(&w->ctx, p, dt, w->scene->pairwise.k * w->h, s[0], s[1], s[2]);
}

static void free3(pfsph_real **s)
{
    for (int a = 0; a < 3; a++) free(s[a]);
}

/* Interior of a square (2D) and cubic (3D) lattice: grad C = 0, no shift; a particle displaced
 * by 0.2 d is moved back towards its site, and only it and its neighbours move. */
static void test_lattice(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        const double d = 0.01;
        const int m = dim == 2 ? 8 : 5;
        for (int pass = 0; pass < 2; pass++) {
            world w;
            world_init(&w, dim, d);
            for (int i = -m; i <= m; i++)
                for (int j = -m; j <= m; j++)
                    for (int k = (dim == 3 ? -m : 0); k <= (dim == 3 ? m : 0); k++)
                        add(&w.fluid, i * d + (pass && !i && !j && !k ? 0.2 * d : 0), j * d, k * d);
            world_finish(&w);
            pfsph_shift_params p;
            pfsph_shift_defaults(&p);
            p.D = 1e-3;
            p.max_frac = 0.25;
            size_t c = tu_nearest(&w.fluid, pass ? 0.2 * d : 0, 0, 0);
            double g[3];
            double C = pfsph_shift_concentration(&w.ctx, c, g);
            pfsph_real *s[3];
            const double dt = 1e-3;
            shift(&w, &p, dt, s);
            print_message("dim %d, %s: C = %.5f, shift of the centre particle %.3g d\n", dim,
                          pass ? "displaced 0.2 d" : "lattice", C, s[0][c] / d);
            if (!pass) {
                assert_true(fabs(C - 1.0) < 0.01); /* the cubic spline sums to ~1 on a lattice */
                assert_true(fabs(s[0][c]) + fabs(s[1][c]) + fabs(s[2][c]) < 1e-9 * d);
                assert_true(fabs(g[0]) + fabs(g[1]) + fabs(g[2]) < 1e-6 / d);
            } else {
                assert_true(s[0][c] < -1e-4 * d); /* back towards x = 0 */
                assert_true(fabs(s[1][c]) < 1e-6 * fabs(s[0][c]));
                /* the shift is -D dt grad C */
                assert_true(fabs(s[0][c] + p.D * dt * g[0]) < 1e-5 * fabs(s[0][c]) + 1e-12);
                /* far particles are untouched */
                size_t far = tu_nearest(&w.fluid, -5 * d, -5 * d, 0);
                assert_true(fabs(s[0][far]) + fabs(s[1][far]) < 1e-4 * fabs(s[0][c]));
            }
            free3(s);
            world_free(&w);
        }
    }
}

/* A flat free surface (2D half-space): the surface row has C < surface threshold and a
 * concentration gradient along the normal; it gets no normal shift (Lind et al. 2012).
 * Switching the threshold off would push it out. */
static void test_free_surface(void **state)
{
    (void)state;
    const double d = 0.01;
    world w;
    world_init(&w, 2, d);
    for (int i = -12; i <= 12; i++)
        for (int j = -10; j <= 0; j++) add(&w.fluid, i * d + (j == 0 && i == 0 ? 0.2 * d : 0), j * d, 0);
    world_finish(&w);
    size_t c = tu_nearest(&w.fluid, 0.2 * d, 0, 0);
    double g[3];
    double C = pfsph_shift_concentration(&w.ctx, c, g);
    print_message("surface particle: C = %.3f, grad C = (%.3g, %.3g) 1/m\n", C, g[0], g[1]);
    assert_true(C < 0.9 && C > 0.5);
    pfsph_shift_params p;
    pfsph_shift_defaults(&p);
    p.D = 1e-3;
    p.max_frac = 0.25;
    pfsph_real *s[3];
    shift(&w, &p, 1e-3, s);
    print_message("shift of the displaced surface particle: (%.3g, %.3g) d\n", s[0][c] / d, s[1][c] / d);
    /* the tangential part pulls it back to its site; the normal part is (nearly) removed */
    assert_true(s[0][c] < -1e-4 * d);
    assert_true(s[1][c] <= 0 && fabs(s[1][c]) < 0.2 * fabs(s[0][c])); /* never outwards */
    /* a surface particle on the lattice does not move at all */
    size_t e = tu_nearest(&w.fluid, 5 * d, 0, 0);
    print_message("lattice surface particle: shift (%.3g, %.3g) d\n", s[0][e] / d, s[1][e] / d);
    assert_true(fabs(s[0][e]) + fabs(s[1][e]) < 1e-4 * fabs(s[0][c]));
    free3(s);
    /* without the correction (threshold 0) the surface row is pushed outwards */
    world_free(&w);
    world_init(&w, 2, d);
    for (int i = -12; i <= 12; i++)
        for (int j = -10; j <= 0; j++) add(&w.fluid, i * d, j * d, 0);
    world_finish(&w);
    p.surface = 0;
    shift(&w, &p, 1e-3, s);
    e = tu_nearest(&w.fluid, 0, 0, 0);
    assert_true(s[1][e] > 1e-4 * d);
    free3(s);
    world_free(&w);
}

/* The cap, the wall and velocities. */
static void test_cap_wall_velocity(void **state)
{
    (void)state;
    const double d = 0.01;
    world w;
    world_init(&w, 2, d);
    /* fluid over a 3-layer wall; one fluid particle pushed to 0.5 d above the wall's top layer */
    for (int i = -10; i <= 10; i++)
        for (int j = 1; j <= 8; j++)
            add(&w.fluid, i * d + (i == 0 && j == 1 ? 0.0 : 0), j * d - (i == 0 && j == 1 ? 0.5 * d : 0), 0);
    for (int i = -14; i <= 14; i++)
        for (int j = -2; j <= 0; j++) add(&w.boundary, i * d, j * d, 0);
    for (size_t i = 0; i < w.fluid.n; i++) w.fluid.vx[i] = (pfsph_real)(0.1 * (double)i);
    world_finish(&w);
    size_t c = tu_nearest(&w.fluid, 0, 0.5 * d, 0);
    pfsph_shift_params p;
    pfsph_shift_defaults(&p);
    p.D = 1.0; /* huge: the cap decides */
    pfsph_real vx[1024];
    assert_true(w.fluid.n < 1024);
    memcpy(vx, w.fluid.vx, w.fluid.n * sizeof(pfsph_real));
    double y0 = w.fluid.y[c];
    pfsph_real *s[3];
    double smax = shift(&w, &p, 1e-3, s);
    print_message("largest shift %.4g d (cap %.3g d); particle near the wall moved by %.3g d\n", smax / d, p.max_frac,
                  (w.fluid.y[c] - y0) / d);
    assert_true(smax <= p.max_frac * d * (1 + 1e-5));
    assert_true(smax >= 0.99 * p.max_frac * d);
    assert_true(w.fluid.y[c] > y0); /* away from the wall, not into it */
    assert_memory_equal(vx, w.fluid.vx, w.fluid.n * sizeof(pfsph_real));
    free3(s);
    world_free(&w);
}

/* Random cloud of 600 particles in an 8.5 d cube (fixed generator). */
static void cloud(world *w, double d)
{
    uint64_t rng = 12345;
    world_init(w, 3, d);
    for (int i = 0; i < 600; i++) {
        double q[3];
        for (int a = 0; a < 3; a++) {
            rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
            q[a] = (double)(rng >> 11) * (1.0 / 9007199254740992.0) * 8.5 * d;
        }
        add(&w->fluid, q[0], q[1], q[2]);
    }
    world_finish(w);
}

/* Concentration against O(N^2) in double on a random cloud; same bits for 1 and 2 threads. */
static void test_oracle_threads(void **state)
{
    (void)state;
    const double d = 0.01;
    world w;
    cloud(&w, d);
    const pfsph_particles *f = &w.fluid;
    double wd = pfsph_kernel_w(&w.ctx.kern, (pfsph_real)d);
    for (size_t i = 0; i < f->n; i += 37) {
        double C = 0, G[3] = {0, 0, 0};
        for (size_t j = 0; j < f->n; j++) {
            double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j], dz = (double)f->z[i] - f->z[j],
                   r = sqrt(dx * dx + dy * dy + dz * dz);
            double wv = pfsph_kernel_w(&w.ctx.kern, (pfsph_real)r);
            C += w.ctx.V0 * wv;
            if (j == i || r == 0) continue;
            double t = pow(wv / wd, 4);
            double s = w.ctx.V0 * (1 + 0.2 * t) * pfsph_kernel_dw_r(&w.ctx.kern, (pfsph_real)r);
            G[0] += s * dx;
            G[1] += s * dy;
            G[2] += s * dz;
        }
        double g[3];
        double c = pfsph_shift_concentration(&w.ctx, i, g);
        double gs = fabs(G[0]) + fabs(G[1]) + fabs(G[2]) + 1;
        assert_true(fabs(c - C) < 1e-4 * C);
        for (int a = 0; a < 3; a++) assert_true(fabs(g[a] - G[a]) < 1e-4 * gs);
    }
    /* the same cloud shifted with 1 and with 2 threads */
    pfsph_shift_params p;
    pfsph_shift_defaults(&p);
    p.D = 1e-2;
    pfsph_real *s1[3], *s2[3];
    omp_set_num_threads(1);
    shift(&w, &p, 1e-3, s1);
    world w2;
    cloud(&w2, d);
    omp_set_num_threads(2);
    shift(&w2, &p, 1e-3, s2);
    omp_set_num_threads(1);
    for (int a = 0; a < 3; a++) assert_memory_equal(s1[a], s2[a], w2.fluid.n * sizeof(pfsph_real));
    assert_memory_equal(w.fluid.x, w2.fluid.x, w2.fluid.n * sizeof(pfsph_real));
    free3(s1);
    free3(s2);
    world_free(&w);
    world_free(&w2);
}

/* The "shifting" block of the scene: defaults off, values read, bad keys and ranges refused. */
static void test_scene_keys(void **state)
{
    (void)state;
    const char *base = "{\"dimension\": 2, \"particle_radius\": 0.005, \"phases\": [{\"name\": \"w\"}],"
                       " \"domain\": {\"min\": [0, 0], \"max\": [1, 1]},"
                       " \"fluid\": [{\"shape\": \"box\", \"min\": [0.1, 0.1], \"max\": [0.2, 0.2]}],"
                       " \"pairwise\": {%s \"coefficients\": [{\"phases\": [\"w\", \"w\"], \"sigma\": 1}]}}";
    struct {
        const char *block;
        int rc;
        double D, surface, max_frac;
    } cases[] = {
        {"", PFSPH_OK, 0, 0.9, 0.05},
        {"\"shifting\": {\"diffusivity\": 0.002},", PFSPH_OK, 0.002, 0.9, 0.05},
        {"\"shifting\": {\"diffusivity\": 0.002, \"surface\": 0.8, \"max_step\": 0.1},", PFSPH_OK, 0.002, 0.8, 0.1},
        {"\"shifting\": {\"diffusivity\": -1},", PFSPH_EINPUT, 0, 0, 0},
        {"\"shifting\": {\"max_step\": 0.5},", PFSPH_EINPUT, 0, 0, 0},
        {"\"shifting\": {\"D\": 0.1},", PFSPH_EINPUT, 0, 0, 0},
        {"\"shifting\": 0.1,", PFSPH_EINPUT, 0, 0, 0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char json[2048];
        snprintf(json, sizeof json, base, cases[k].block);
        pfsph_scene *s = malloc(sizeof *s);
        pfsph_error err = {0};
        int rc = pfsph_scene_parse(s, json, "shift.json", &err);
        print_message("%s -> %d %s\n", cases[k].block, rc, rc ? err.msg : "");
        assert_int_equal(rc, cases[k].rc);
        if (rc == PFSPH_OK) {
            assert_true(s->pairwise.shift.D == cases[k].D);
            assert_true(s->pairwise.shift.surface == cases[k].surface);
            assert_true(s->pairwise.shift.max_frac == cases[k].max_frac);
        } else {
            assert_non_null(strstr(err.msg, "shifting"));
        }
        free(s);
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lattice),           cmocka_unit_test(test_free_surface),
        cmocka_unit_test(test_cap_wall_velocity), cmocka_unit_test(test_oracle_threads),
        cmocka_unit_test(test_scene_keys),
    };
    return tu_run_group(tests, NULL, NULL);
}
