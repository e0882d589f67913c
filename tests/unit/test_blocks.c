/* Fluid blocks on the one scene lattice (issue 11): later blocks replace earlier ones where
 * they overlap, every shape samples the same sites (k + 1/2) d, counts without sampling equal
 * the walk's, and a scene of 100 blocks loads. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pfsph/ctx.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "scene/shapes.h"
#include "testutil.h"

static pfsph_scene g_scene; /* large; keep off the stack */

static void parse_ok(const char *json)
{
    pfsph_error err = {0};
    if (pfsph_scene_parse(&g_scene, json, "blocks.json", &err) != PFSPH_OK) fail_msg("%s", err.msg);
}

static double urand(unsigned *st)
{
    *st = *st * 1103515245u + 12345u;
    return (double)((*st >> 8) & 0xffffff) / (double)0x1000000;
}

/* Smallest distance between two particles, by brute force. */
static double min_distance(const pfsph_particles *f)
{
    double m = INFINITY;
    for (size_t i = 0; i < f->n; i++)
        for (size_t j = i + 1; j < f->n; j++) {
            double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j], dz = (double)f->z[i] - f->z[j];
            double r = sqrt(dx * dx + dy * dy + dz * dz);
            if (r < m) m = r;
        }
    return m;
}

/* A gas disc in a water tank, two lines: the tank keeps its lattice count, the disc takes the
 * lattice points inside it, and nothing is doubled. */
static void test_disc_in_tank(void **state)
{
    (void)state;
    const double d = 0.02, cx = 0.2, cy = 0.15, R = 0.073;
    char json[1024];
    snprintf(json, sizeof json,
             "{\"dimension\":2,\"particle_radius\":0.01,\"domain\":{\"min\":[0,0],\"max\":[0.4,0.4]},"
             "\"phases\":[{\"name\":\"water\"},{\"name\":\"gas\",\"kind\":\"gas\"}],"
             "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[0.4,0.3],\"phase\":\"water\"},"
             "{\"shape\":\"sphere\",\"center\":[%g,%g],\"radius\":%g,\"phase\":\"gas\"}]}",
             cx, cy, R);
    parse_ok(json);
    long inside = 0; /* lattice points (k + 1/2) d inside the disc, counted here */
    for (int i = 0; i < 20; i++)
        for (int j = 0; j < 15; j++) {
            double x = (i + 0.5) * d - cx, y = (j + 0.5) * d - cy;
            inside += x * x + y * y <= R * R;
        }
    assert_true(inside > 40);
    pfsph_sim *sim = NULL;
    pfsph_error err = {0};
    assert_int_equal(pfsph_sim_create(&sim, &g_scene, &err), PFSPH_OK);
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    long gas = 0;
    for (size_t i = 0; i < f->n; i++) gas += f->phase[i] == 1;
    printf("tank %zu particles (lattice 300), gas %ld (lattice points in the disc %ld), closest pair %.4f d\n", f->n,
           gas, inside, min_distance(f) / d);
    assert_int_equal(f->n, 20 * 15);
    assert_int_equal(gas, inside);
    assert_true(min_distance(f) >= 0.99 * d);
    size_t nf = 0;
    assert_int_equal(pfsph_scene_estimate(&g_scene, &nf, NULL, NULL, &err), PFSPH_OK);
    assert_int_equal(nf, f->n);
    pfsph_sim_destroy(sim);
}

/* Box, sphere and cylinder blocks (off-lattice centres and faces) sample the same lattice. */
static void test_one_lattice(void **state)
{
    (void)state;
    parse_ok(
        "{\"particle_radius\":0.01,\"domain\":{\"min\":[-1,-1,-1],\"max\":[1,1,1]},\"fluid\":["
        "{\"shape\":\"box\",\"min\":[-0.513,0.0037,0.2],\"max\":[-0.3,0.2,0.41]},"
        "{\"shape\":\"sphere\",\"center\":[0.1234,0.0567,-0.0891],\"radius\":0.101},"
        "{\"shape\":\"cylinder\",\"center\":[0.5011,-0.3,0.3333],\"radius\":0.07,\"height\":0.13,\"axis\":\"x\"}]}");
    const double d = 0.02;
    pfsph_particles ps;
    assert_int_equal(pfsph_particles_init(&ps, 1024), PFSPH_OK);
    double worst = 0;
    for (int b = 0; b < 3; b++) {
        ps.n = 0;
        assert_true(pfsph__sample_scene_block(&g_scene, b, d, &ps) > 100);
        const pfsph_real *q[3] = {ps.x, ps.y, ps.z};
        for (size_t i = 0; i < ps.n; i++)
            for (int a = 0; a < 3; a++) {
                double k = (double)q[a][i] / d - 0.5, off = fabs(k - round(k));
                if (off > worst) worst = off;
            }
    }
    printf("largest distance from a lattice site: %.2e d\n", worst);
    assert_true(worst < 1e-4); /* single precision positions of |x| < 1 m */
    pfsph_particles_free(&ps);
}

/* Random overlapping blocks: each block's count without sampling equals its walk, and all
 * blocks together hold exactly the lattice sites of their union (each once). */
static void test_carving_counts(void **state)
{
    (void)state;
    unsigned seed = 777;
    pfsph_particles ps;
    assert_int_equal(pfsph_particles_init(&ps, 1024), PFSPH_OK);
    int cases = 0;
    for (int dim = 2; dim <= 3; dim++)
        for (int t = 0; t < 60; t++) {
            pfsph_scene *s = &g_scene;
            parse_ok(dim == 2 ? "{\"dimension\":2,\"domain\":{\"min\":[-2,-2],\"max\":[2,2]},"
                                "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[0.1,0.1]}]}"
                              : "{\"domain\":{\"min\":[-2,-2,-2],\"max\":[2,2,2]},"
                                "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.1,0.1,0.1]}]}");
            const double d = dim == 2 ? 0.02 : 0.04;
            s->nblocks = 2 + t % 4;
            for (int i = 0; i < s->nblocks; i++) {
                pfsph_block *b = &s->blocks[i];
                memset(b, 0, sizeof *b);
                b->shape = (t + i) % 3;
                for (int a = 0; a < dim; a++) {
                    b->min[a] = -0.3 + 0.5 * urand(&seed);
                    b->max[a] = b->min[a] + 0.1 + 0.4 * urand(&seed);
                    b->center[a] = -0.1 + 0.3 * urand(&seed);
                }
                b->radius = (t + i) % 5 == 0 ? d * (2 + t % 3) : 0.05 + 0.2 * urand(&seed);
                b->height = 0.05 + 0.3 * urand(&seed);
                b->axis = dim == 2 ? 2 : (t + i) % 3;
                b->jitter = i % 2 ? 0.2 : 0;
            }
            long total = 0;
            for (int i = 0; i < s->nblocks; i++) {
                ps.n = 0;
                long walked = pfsph__sample_scene_block(s, i, d, &ps);
                long counted = pfsph__sample_scene_block(s, i, d, NULL);
                if (walked != counted || (long)ps.n != walked)
                    fail_msg("dim %d case %d block %d: walk %ld, count %ld", dim, t, i, walked, counted);
                total += walked;
            }
            /* the union, site by site, with each block's own (uncarved) walk as the oracle */
            long uni = 0;
            const long K = dim == 2 ? 40 : 20;
            pfsph_particles one;
            assert_int_equal(pfsph_particles_init(&one, 1024), PFSPH_OK);
            char *mark = calloc((size_t)(2 * K) * (size_t)(2 * K) * (size_t)(dim == 3 ? 2 * K : 1), 1);
            assert_non_null(mark);
            for (int i = 0; i < s->nblocks; i++) {
                pfsph_block b = s->blocks[i];
                b.jitter = 0;
                one.n = 0;
                assert_true(pfsph__sample_block(s, &b, d, &one) >= 0);
                for (size_t j = 0; j < one.n; j++) {
                    long k[3] = {lround(one.x[j] / d - 0.5) + K, lround(one.y[j] / d - 0.5) + K,
                                 dim == 3 ? lround(one.z[j] / d - 0.5) + K : 0};
                    for (int a = 0; a < dim; a++) assert_true(k[a] >= 0 && k[a] < 2 * K);
                    char *m = &mark[(k[2] * 2 * K + k[1]) * 2 * K + k[0]];
                    uni += !*m;
                    *m = 1;
                }
            }
            free(mark);
            pfsph_particles_free(&one);
            if (total != uni)
                fail_msg("dim %d case %d: blocks hold %ld particles, their union %ld sites", dim, t, total, uni);
            cases++;
        }
    printf("%d random block sets: counts equal walks, totals equal the union's sites\n", cases);
    pfsph_particles_free(&ps);
}

/* 100 blocks (more than the former limit of 64), overlapping: they load, build, and no two
 * particles start closer than the spacing. */
static void test_hundred_blocks(void **state)
{
    (void)state;
    size_t cap = 64 * 1024, len = 0;
    char *json = malloc(cap);
    assert_non_null(json);
    len += (size_t)snprintf(json + len, cap - len,
                            "{\"dimension\":2,\"particle_radius\":0.005,\"domain\":{\"min\":[0,0],\"max\":[1,1]},"
                            "\"phases\":[{\"name\":\"a\"},{\"name\":\"b\",\"rest_density\":800}],\"fluid\":["
                            "{\"shape\":\"box\",\"min\":[0,0],\"max\":[1,0.5],\"phase\":\"a\"}");
    /* 99 discs on a grid of 0.08 m with radius 0.05 m: each overlaps its neighbours (and the
     * tank), none is covered */
    for (int i = 1; i < 100; i++)
        len += (size_t)snprintf(json + len, cap - len,
                                ",{\"shape\":\"%s\",\"center\":[%.4f,%.4f],\"radius\":0.05,\"phase\":\"%s\"}",
                                i % 2 ? "sphere" : "cylinder", 0.08 + 0.08 * ((i - 1) % 11),
                                0.06 + 0.08 * ((i - 1) / 11), i % 3 ? "b" : "a");
    snprintf(json + len, cap - len, "]}");
    parse_ok(json);
    free(json);
    assert_int_equal(g_scene.nblocks, 100);
    pfsph_sim *sim = NULL;
    pfsph_error err = {0};
    assert_int_equal(pfsph_sim_create(&sim, &g_scene, &err), PFSPH_OK);
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    size_t nf = 0;
    assert_int_equal(pfsph_scene_estimate(&g_scene, &nf, NULL, NULL, &err), PFSPH_OK);
    printf("100 blocks: %zu particles (estimate %zu), closest pair %.4f d\n", f->n, nf, min_distance(f) / 0.01);
    assert_int_equal(nf, f->n);
    /* the union of the blocks' lattice sites, from their geometry: each site once */
    size_t uni = 0;
    for (int i = 0; i < 100; i++)
        for (int j = 0; j < 100; j++) {
            double x = (i + 0.5) * 0.01, y = (j + 0.5) * 0.01;
            int in = y < 0.5;
            for (int b = 1; b < 100 && !in; b++) {
                const pfsph_block *q = &g_scene.blocks[b];
                in = (x - q->center[0]) * (x - q->center[0]) + (y - q->center[1]) * (y - q->center[1]) <=
                    q->radius * q->radius;
            }
            uni += in;
        }
    assert_int_equal(f->n, uni);
    assert_true(min_distance(f) >= 0.99 * 0.01);
    pfsph_sim_destroy(sim);
}

static double wall(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Counting a carved block costs rows, not sites: a tank of 1e9 sites with a sphere of 1.1e8
 * in it is counted exactly, and `pfsph check` loads and counts it in well under a second (timed
 * through the program, so that the figure means the same under valgrind). */
static void test_large_counts_fast(void **state)
{
    (void)state;
    const char *json = "{\"particle_radius\":0.0005,\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":["
                       "{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[1,1,1]},"
                       "{\"shape\":\"sphere\",\"center\":[0.5,0.5,0.5],\"radius\":0.3}]}";
    parse_ok(json);
    const double d = 0.001;
    long tank = pfsph__sample_scene_block(&g_scene, 0, d, NULL), ball = pfsph__sample_scene_block(&g_scene, 1, d, NULL);
    printf("tank %ld + ball %ld sites\n", tank, ball);
    assert_int_equal(tank + ball, 1000L * 1000 * 1000);
    assert_true(fabs((double)ball / (4.0 / 3 * 3.14159265358979 * 300 * 300 * 300) - 1) < 1e-3);
    char path[600], cmd[2048], out[4096];
    snprintf(path, sizeof path, "%s/large.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, json), 0);
    snprintf(cmd, sizeof cmd, "timeout 60 '%s' check '%s'", tu_pfsph_bin(), path);
    double t0 = wall();
    int st = tu_run(cmd, out, sizeof out);
    double secs = wall() - t0;
    printf("pfsph check: exit %d in %.3f s: %s", st, secs, out);
    assert_non_null(strstr(out, "particles: 1000000000 fluid"));
    assert_true(secs < 5);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_disc_in_tank),      cmocka_unit_test(test_one_lattice),
        cmocka_unit_test(test_carving_counts),    cmocka_unit_test(test_hundred_blocks),
        cmocka_unit_test(test_large_counts_fast),
    };
    return tu_run_group(tests, NULL, NULL);
}
