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
    assert_true(found >= 3); /* wcsph, pcisph, dfsph at least */
    assert_null(pfsph_solver_find("sph2000"));
    assert_null(pfsph_solver_find(NULL));
    assert_null(pfsph_solver_at(-1));
}

/* Every registry row is complete: its keys fit the scene, their defaults lie in their ranges and
 * pass its own check, an eos comes with its report, and the defaults are what the scene takes. */
static void rows_are_complete(void **state)
{
    (void)state;
    for (int i = 0; pfsph_solver_at(i); i++) {
        const pfsph_solver_ops *ops = pfsph_solver_at(i);
        assert_non_null(ops->name);
        assert_true(strlen(ops->name) > 0 && strlen(ops->name) < PFSPH_NAME_LEN);
        assert_true(ops->nkeys >= 0 && ops->nkeys <= PFSPH_SOLVER_MAX_KEYS);
        assert_non_null(ops->create);
        assert_non_null(ops->solve);
        assert_non_null(ops->dt_limit);
        assert_non_null(ops->speed_bound);
        assert_non_null(ops->hint);
        if (ops->eos) assert_non_null(ops->report);
        double v[PFSPH_SOLVER_MAX_KEYS] = {0};
        for (int k = 0; k < ops->nkeys; k++) {
            const pfsph_solver_key *key = &ops->keys[k];
            assert_true(key->min <= key->def && key->def <= key->max);
            if (key->integer) assert_true(key->def == floor(key->def));
            assert_int_equal(pfsph_solver_key_index(ops, key->name), k);
            v[k] = key->def;
        }
        char msg[256];
        const char *bad = NULL;
        if (ops->check) assert_int_equal(ops->check(v, &bad, msg, sizeof msg), 0);
        static pfsph_scene s;
        pfsph_scene_defaults(&s);
        assert_int_equal(pfsph_scene_set_solver(&s, ops->name), PFSPH_OK);
        for (int k = 0; k < ops->nkeys; k++) assert_true(pfsph_scene_solver_setting(&s, ops->keys[k].name) == v[k]);
    }
    static pfsph_scene s;
    assert_int_equal(pfsph_scene_set_solver(&s, "sph2000"), PFSPH_EINPUT);
}

static void dt_limits(void **state)
{
    const pfsph_solver_ops *wc = pfsph_solver_find("wcsph"), *pc = pfsph_solver_find("pcisph");
    (void)state;
    pfsph_ctx c;
    memset(&c, 0, sizeof c);
    c.dim = 2;
    c.spacing = 0.02f;
    const double settings[] = {0.005, 3, 50}; /* PCISPH's tolerance, min and max iterations */
    pfsph_solver_config cfg = {.sound_speed = 20, .c_fast = 30, .gamma = 7, .settings = settings, .cfl = 0.4};
    pfsph_error err;
    const double d = (double)c.spacing, v = 2, a = 9.81, anp = 4;
    void *w = NULL, *p = NULL;
    assert_int_equal(wc->create(&w, &c, &cfg, &err), PFSPH_OK);
    assert_int_equal(pc->create(&p, &c, &cfg, &err), PFSPH_OK);
    /* WCSPH: min(cfl d / (v + c_fast), 0.25 sqrt(d / a)) with the total acceleration */
    double want = fmin(0.4 * d / (v + 30), 0.25 * sqrt(d / a));
    assert_true(fabs(wc->dt_limit(w, &c, v, a, anp) - want) <= 1e-12 * want);
    assert_true(wc->speed_bound(w, &c) == 20);
    /* PCISPH: min(cfl d / v, 0.25 sqrt(d / a_np), 0.2 sqrt(tol d / a_np)) */
    want = fmin(fmin(0.4 * d / v, 0.25 * sqrt(d / anp)), 0.2 * sqrt(0.005 * d / anp));
    assert_true(fabs(pc->dt_limit(p, &c, v, a, anp) - want) <= 1e-12 * want);
    assert_true(pc->speed_bound(p, &c) == 400);
    c.dt = 1e-8; /* a tiny step: the bound follows half a spacing per step (issue 15 item 5) */
    assert_true(fabs(pc->speed_bound(p, &c) - 0.5 * d / 1e-8) <= 1e-6 * 0.5 * d / 1e-8);
    c.dt = 0;
    /* at rest and without forces a solver sets no limit of its own */
    assert_true(isinf(pc->dt_limit(p, &c, 0, 0, 0)));
    wc->destroy(w);
    pc->destroy(p);
    pc->destroy(NULL);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(every_scene_solver_runs), cmocka_unit_test(rows_are_complete),
                                       cmocka_unit_test(dt_limits)};
    return tu_run_group(tests, NULL, NULL);
}
