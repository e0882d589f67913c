/* The pressure-solver interface (src/physics/solver.h): every solver name a scene accepts has
 * a solver in the table and the simulation runs it; the table has no entry without a scene
 * name; each solver's time-step limit follows its own rule (WCSPH: acoustic CFL with the
 * fastest sound speed; PCISPH: flow CFL and its compression cap) on a hand-built context. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "physics/solver.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"domain\": {\"min\": [-0.1, -0.1], \"max\": [0.5, 0.5]},"
    " \"solver\": {\"type\": \"%s\", \"sound_speed\": 20}, \"time\": {\"end\": 0.01, \"cfl\": 0.4},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.1, 0.1], \"phase\": \"water\"}]}";

static void every_scene_solver_runs(void **state)
{
    (void)state;
    int found = 0;
    for (int i = 0; pfsph_solver_at(i); i++) {
        const pfsph_solver_ops *ops = pfsph_solver_at(i);
        char json[1024];
        snprintf(json, sizeof json, SCENE, ops->name);
        static pfsph_scene s;
        pfsph_error err = {0};
        int rc = pfsph_scene_parse(&s, json, "solver", &err);
        if (rc) fprintf(stderr, "%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK); /* the scene accepts the table's name */
        assert_string_equal(pfsph_scene_solver_name(&s), ops->name);
        assert_ptr_equal(pfsph_solver_find(pfsph_scene_solver_name(&s)), ops);
        pfsph_sim *sim;
        assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
        assert_int_equal(pfsph_sim_advance(sim, 0.01, &err), PFSPH_OK);
        assert_true(pfsph_sim_steps(sim) > 0);
        pfsph_sim_destroy(sim);
        /* the program names the solver from the same list (it once printed "wcsph" for any
         * solver that was not PCISPH) */
        char path[1024], cmd[2300], out[4096], want[64];
        snprintf(path, sizeof path, "%s/solver_%s.json", tu_tmpdir(), ops->name);
        assert_int_equal(tu_write_file(path, json), 0);
        snprintf(cmd, sizeof cmd, "'%s' check '%s'", tu_pfsph_bin(), path);
        assert_int_equal(tu_run(cmd, out, sizeof out), 0);
        snprintf(want, sizeof want, "solver %s,", ops->name);
        if (!strstr(out, want)) fprintf(stderr, "%s\n", out);
        assert_non_null(strstr(out, want));
        found++;
    }
    assert_int_equal(found, 3); /* wcsph, pcisph, dfsph */
    assert_null(pfsph_solver_find("iisph"));
    assert_null(pfsph_solver_find(NULL));
    assert_null(pfsph_solver_at(-1));
}

static void dt_limits(void **state)
{
    (void)state;
    pfsph_ctx c;
    memset(&c, 0, sizeof c);
    c.dim = 2;
    c.spacing = 0.02f;
    pfsph_solver_config cfg = {
        .sound_speed = 20, .c_fast = 30, .gamma = 7, .tolerance = 0.005, .min_iter = 3, .max_iter = 50, .cfl = 0.4};
    pfsph_error err;
    const double d = (double)c.spacing, v = 2, a = 9.81, anp = 4;
    void *w = NULL, *p = NULL;
    assert_int_equal(pfsph_solver_wcsph.create(&w, &c, &cfg, &err), PFSPH_OK);
    assert_int_equal(pfsph_solver_pcisph.create(&p, &c, &cfg, &err), PFSPH_OK);
    /* WCSPH: min(cfl d / (v + c_fast), 0.25 sqrt(d / a)) with the total acceleration */
    double want = fmin(0.4 * d / (v + 30), 0.25 * sqrt(d / a));
    assert_true(fabs(pfsph_solver_wcsph.dt_limit(w, &c, v, a, anp) - want) <= 1e-12 * want);
    assert_true(pfsph_solver_wcsph.speed_bound(w, &c) == 20);
    /* PCISPH: min(cfl d / v, 0.25 sqrt(d / a_np), 0.2 sqrt(tol d / a_np)) */
    want = fmin(fmin(0.4 * d / v, 0.25 * sqrt(d / anp)), 0.2 * sqrt(0.005 * d / anp));
    assert_true(fabs(pfsph_solver_pcisph.dt_limit(p, &c, v, a, anp) - want) <= 1e-12 * want);
    assert_true(pfsph_solver_pcisph.speed_bound(p, &c) == 400);
    c.dt = 1e-8; /* a tiny step: the bound follows half a spacing per step (issue 15 item 5) */
    assert_true(fabs(pfsph_solver_pcisph.speed_bound(p, &c) - 0.5 * d / 1e-8) <= 1e-6 * 0.5 * d / 1e-8);
    c.dt = 0;
    /* at rest and without forces a solver sets no limit of its own */
    assert_true(isinf(pfsph_solver_pcisph.dt_limit(p, &c, 0, 0, 0)));
    pfsph_solver_wcsph.destroy(w);
    pfsph_solver_pcisph.destroy(p);
    pfsph_solver_pcisph.destroy(NULL);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(every_scene_solver_runs), cmocka_unit_test(dt_limits)};
    return tu_run_group(tests, NULL, NULL);
}
