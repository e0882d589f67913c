/* 2D dam break: mass is conserved, no particle reaches a wall's boundary particles (or gets a
 * quarter spacing past its face), the average density error stays below 1%, for each solver;
 * and the same scene gives identical bits with 1 and 2 threads. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/sim.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"%s\"}, \"time\": {\"end\": 1, \"fps\": 20},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 2e-4},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"},"
    "   {\"shape\": \"box\", \"min\": [0.35, 0], \"max\": [0.4, 0.06], \"phase\": \"wall\"}]}";

static pfsph_sim *make(const char *solver)
{
    char json[2048];
    snprintf(json, sizeof json, SCENE, solver);
    static pfsph_scene s;
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(&s, json, "dam break", &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    pfsph_sim *sim = NULL;
    assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
    return sim;
}

static void run(const char *solver, double limit)
{
    pfsph_sim *sim = make(solver);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    size_t n0 = c->fluid->n;
    double mass0 = n0 * (double)c->mass[0];
    double err_sum = 0, err_max = 0, outside = 0, maxpen = -1;
    int frames = 0;
    pfsph_error err = {0};
    for (int k = 1; k <= 16; k++) {
        int rc = pfsph_sim_advance(sim, 0.05 * k, &err);
        if (rc) fprintf(stderr, "%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        const pfsph_particles *f = c->fluid;
        for (size_t i = 0; i < f->n; i++) {
            /* depth past the solid faces (container inner faces, obstacle box); the first
             * layer of boundary particles sits d/2 behind a face */
            double pen = fmax(fmax(-f->x[i], f->x[i] - 0.6), -f->y[i]);
            if (f->x[i] > 0.35 && f->x[i] < 0.4 && f->y[i] < 0.06)
                pen = fmax(pen, fmin(fmin(f->x[i] - 0.35, 0.4 - f->x[i]), 0.06 - f->y[i]));
            if (pen > maxpen) maxpen = pen;
            outside += pen >= 0.5 * c->spacing; /* reached the wall's particles: passed it */
        }
        double e = pfsph_sim_stats(sim)->density_err_avg;
        err_sum += e;
        if (e > err_max) err_max = e;
        frames++;
    }
    double mass = c->fluid->n * (double)c->mass[0];
    printf("%s: %zu particles, %llu steps, mass %.6g -> %.6g, particles past a wall %.0f, "
           "deepest %.4f m, average density error %.3f%% (max over frames %.3f%%)\n",
           solver, n0, (unsigned long long)pfsph_sim_steps(sim), mass0, mass, outside, maxpen, 100 * err_sum / frames,
           100 * err_max);
    assert_true(mass == mass0);
    assert_true(outside == 0);
    /* and no fluid centre gets further than a quarter spacing past a face */
    assert_true(maxpen < 0.25 * c->spacing);
    assert_true(err_sum / frames < limit);
    pfsph_sim_destroy(sim);
}

static void test_wcsph(void **state)
{
    (void)state;
    run("wcsph", 0.01);
}
static void test_pcisph(void **state)
{
    (void)state;
    run("pcisph", 0.01);
}
static void test_dfsph(void **state)
{
    (void)state;
    run("dfsph", 0.01);
}

static void test_threads_identical(void **state)
{
    (void)state;
    const char *solvers[3] = {"wcsph", "pcisph", "dfsph"};
    for (int s = 0; s < 3; s++) {
        pfsph_sim *a, *b;
        pfsph_error err = {0};
        omp_set_num_threads(1);
        a = make(solvers[s]);
        assert_int_equal(pfsph_sim_advance(a, 0.2, &err), PFSPH_OK);
        omp_set_num_threads(2);
        b = make(solvers[s]);
        assert_int_equal(pfsph_sim_advance(b, 0.2, &err), PFSPH_OK);
        const pfsph_particles *fa = pfsph_sim_ctx(a)->fluid, *fb = pfsph_sim_ctx(b)->fluid;
        assert_int_equal(fa->n, fb->n);
        assert_int_equal(pfsph_sim_steps(a), pfsph_sim_steps(b));
        for (int k = 0; k < PFSPH_NFIELDS; k++) assert_memory_equal(fa->f[k], fb->f[k], fa->n * sizeof(pfsph_real));
        assert_memory_equal(fa->id, fb->id, fa->n * sizeof(uint32_t));
        pfsph_sim_destroy(a);
        pfsph_sim_destroy(b);
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_wcsph), cmocka_unit_test(test_pcisph),
                                       cmocka_unit_test(test_dfsph), cmocka_unit_test(test_threads_identical)};
    return tu_run_group(tests, NULL, NULL);
}
