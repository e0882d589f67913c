/* The solvers that walk the neighbours many times a step (DFSPH, IISPH) give the same bits with
 * neighbour lists and with grid walks ($.solver.neighbour_lists true / false, physics/neighbours.h):
 * every fluid array after some steps of a 2D and a 3D dam break, with viscosity and walls, and a
 * 2D one with pair forces and the thermostat; "auto" picks lists for these small scenes, and
 * without lists none are allocated. Docs: docs/solvers.md, "Neighbour lists". */
#include <stdio.h>
#include <string.h>

#include "core/nlist.h"
#include "core/stage.h"
#include "pfsph/sim.h"
#include "testutil.h"

#ifdef PFSPH_SANITIZED
#define SANITIZED 1 /* instrumented: shorter runs, the same assertions */
#else
#define SANITIZED 0
#endif

/* 2D: a 0.2 x 0.3 m column (600 particles) in a 0.6 m tank; %s the solver, %s the
 * neighbour_lists value, %s extra top-level keys */
static const char *DAM2 =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"%s\", \"neighbour_lists\": %s}, \"time\": {\"end\": 1, \"fps\": 100},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-3},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.2, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}]%s}";

/* 3D: a 0.12 x 0.16 x 0.12 m block (2,304 particles) in a 0.3 x 0.3 x 0.2 m tank */
static const char *DAM3 =
    "{\"dimension\": 3, \"particle_radius\": 0.005, \"gravity\": [0, -9.81, 0],"
    " \"domain\": {\"min\": [-0.05, -0.05, -0.05], \"max\": [0.35, 0.35, 0.25]},"
    " \"solver\": {\"type\": \"%s\", \"neighbour_lists\": %s}, \"time\": {\"end\": 1, \"fps\": 100},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-3},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.12, 0.16, 0.12], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.3, 0.3, 0.2], \"open_top\": true,"
    "              \"phase\": \"wall\"}]%s}";

static const char *PAIR = ", \"pairwise\": {\"coefficients\": [{\"phases\": [\"water\", \"water\"], \"c\": 1000}]}";

static pfsph_sim *run(const char *fmt, const char *solver, const char *lists, const char *extra, double t)
{
    char json[4096];
    snprintf(json, sizeof json, fmt, solver, lists, extra);
    pfsph_sim *sim = tu_sim_from_json(json, "nlist modes");
    tu_advance(sim, t);
    return sim;
}

/* a and b hold the same particles, bit for bit, after the same steps and iterations */
static void same_bits(pfsph_sim *a, pfsph_sim *b, const char *what)
{
    const pfsph_particles *fa = pfsph_sim_ctx(a)->fluid, *fb = pfsph_sim_ctx(b)->fluid;
    assert_int_equal(pfsph_sim_steps(a), pfsph_sim_steps(b));
    assert_int_equal(fa->n, fb->n);
    const pfsph_step *sa = pfsph_sim_step_state(a), *sb = pfsph_sim_step_state(b);
    assert_int_equal(sa->stats.iterations, sb->stats.iterations);
    assert_int_equal(sa->stats.div_iterations, sb->stats.div_iterations);
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        const int same = !memcmp(fa->f[k], fb->f[k], fa->n * sizeof(pfsph_real));
        if (!same) {
            size_t i = 0;
            while (i < fa->n && !memcmp(&fa->f[k][i], &fb->f[k][i], sizeof(pfsph_real))) i++;
            fprintf(stderr, "%s: field %d differs first at particle %zu: %.9g vs %.9g\n", what, k, i,
                    (double)fa->f[k][i], (double)fb->f[k][i]);
        }
        assert_true(same);
    }
    assert_memory_equal(fa->id, fb->id, fa->n * sizeof *fa->id);
    printf("%s: %zu particles, %llu steps, the same bits (last step %d + %d iterations)\n", what, fa->n,
           (unsigned long long)pfsph_sim_steps(a), sa->stats.iterations, sa->stats.div_iterations);
}

static void both_ways(const char *fmt, const char *solver, const char *extra, double t, const char *what)
{
    pfsph_sim *L = run(fmt, solver, "true", extra, t), *G = run(fmt, solver, "false", extra, t);
    const pfsph_step *sl = pfsph_sim_step_state(L), *sg = pfsph_sim_step_state(G);
    assert_int_equal(sl->lists, 1);
    assert_true(sl->nlist->cap > 0); /* the lists were built */
    assert_int_equal(sg->lists, 0);
    assert_true(sg->nlist->cap == 0 && sg->nlist_b->cap == 0); /* and here never */
    same_bits(L, G, what);
    /* "auto" takes lists for a scene this small */
    pfsph_sim *A = run(fmt, solver, "\"auto\"", extra, 0);
    assert_int_equal(pfsph_sim_step_state(A)->lists, 1);
    pfsph_sim_destroy(A);
    pfsph_sim_destroy(L);
    pfsph_sim_destroy(G);
}

static void dfsph_2d(void **state)
{
    (void)state;
    both_ways(DAM2, "dfsph", "", SANITIZED ? 0.03 : 0.15, "dfsph 2D");
}

static void dfsph_3d(void **state)
{
    (void)state;
    both_ways(DAM3, "dfsph", "", SANITIZED ? 0.01 : 0.05, "dfsph 3D");
}

static void iisph_2d(void **state)
{
    (void)state;
    both_ways(DAM2, "iisph", "", SANITIZED ? 0.03 : 0.15, "iisph 2D");
}

static void iisph_3d(void **state)
{
    (void)state;
    both_ways(DAM3, "iisph", "", SANITIZED ? 0.01 : 0.03, "iisph 3D");
}

/* pair forces with the thermostat: the viscosity's thermostat paths over lists and the grid */
static void dfsph_2d_pairwise(void **state)
{
    (void)state;
    both_ways(DAM2, "dfsph", PAIR, SANITIZED ? 0.01 : 0.05, "dfsph 2D pairwise");
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(dfsph_2d), cmocka_unit_test(dfsph_3d),
                                       cmocka_unit_test(iisph_2d), cmocka_unit_test(iisph_3d),
                                       cmocka_unit_test(dfsph_2d_pairwise)};
    return tu_run_group(tests, NULL, NULL);
}
