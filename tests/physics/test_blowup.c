/* A scene tuned to explode (WCSPH with a speed of sound below the free-fall speed of its column)
 * stops with exit status 3 and a diagnosis naming step, time, stage, particle and cause, and
 * leaves the last good frame behind as a checkpoint that loads; a squeezed state stops at the
 * density check. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "pfsph/checkpoint.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"wcsph\", \"sound_speed\": 1.5},"
    " \"time\": {\"end\": 1, \"fps\": 50},"
    " \"phases\": [{\"name\": \"water\", \"viscosity\": 2e-4}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}]}";

static void test_blowup_diagnosis(void **state)
{
    (void)state;
    char scene[512], run[512], cmd[2048], out[8192];
    snprintf(scene, sizeof scene, "%s/explode.json", tu_tmpdir());
    snprintf(run, sizeof run, "%s/explode_run", tu_tmpdir());
    assert_int_equal(tu_write_file(scene, SCENE), 0);
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet", tu_pfsph_bin(), scene, run);
    int st = tu_run(cmd, out, sizeof out);
    printf("exit %d: %s", st, out);
    assert_int_equal(st, 3);
    const char *must[] = {"unstable at step", "t = ",         "stage ",      "particle id",           "phase 'water'",
                          "position",         "likely cause", "sound_speed", "last good state (frame"};
    for (size_t k = 0; k < sizeof must / sizeof *must; k++)
        if (!strstr(out, must[k])) fail_msg("diagnosis lacks \"%s\"", must[k]);
    /* the kept checkpoint is the named frame and restores into the same scene */
    int frame = -1;
    const char *f = strstr(out, "last good state (frame ");
    assert_int_equal(sscanf(f, "last good state (frame %d)", &frame), 1);
    char cp[1024];
    pfsph_checkpoint_path(cp, sizeof cp, run, frame);
    struct stat sb;
    assert_int_equal(stat(cp, &sb), 0);
    /* it was the run's stash of the last good frame (on disk, not in memory), moved into place */
    char stash[1024];
    snprintf(stash, sizeof stash, "%s/.last_good.bin", run);
    assert_int_equal(stat(stash, &sb), -1);
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, SCENE, "explode", &err), PFSPH_OK);
    pfsph_sim *sim;
    assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
    pfsph_checkpoint_info info;
    int rc = pfsph_checkpoint_load(cp, sim, &info, &err);
    if (rc) fail_msg("%s", err.msg);
    assert_int_equal(info.frame, frame);
    pfsph_sim_destroy(sim);
}

/* A state squeezed to a quarter of its area (2D: four times the rest density) stops at the
 * density check, naming it. */
static void test_density_explosion(void **state)
{
    (void)state;
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, SCENE, "explode", &err), PFSPH_OK);
    pfsph_scene_set_solver(&s, "pcisph");
    pfsph_sim *sim;
    assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    pfsph_particles squeezed;
    assert_int_equal(pfsph_particles_init(&squeezed, f->n), PFSPH_OK);
    for (size_t i = 0; i < f->n; i++) {
        pfsph_real x[3] = {f->x[i] * (pfsph_real)0.5, f->y[i] * (pfsph_real)0.5, 0};
        assert_true(pfsph_particles_push(&squeezed, x, NULL, f->phase[i]) >= 0);
    }
    pfsph_sim_state st;
    pfsph_sim_get_state(sim, &st);
    assert_int_equal(pfsph_sim_restore(sim, &st, &squeezed, NULL, 0, 0, &err), PFSPH_OK);
    int rc = pfsph_sim_step(sim, 1.0, &err);
    printf("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_EUNSTABLE);
    assert_non_null(strstr(err.msg, "stage density"));
    assert_non_null(strstr(err.msg, "relative density error"));
    pfsph_particles_free(&squeezed);
    pfsph_sim_destroy(sim);
}

/* Issue 15 item 5: PCISPH with a time step far below the acoustic one (dt_max 1e-8 s) used to
 * report a blow-up at step 0 (its pressure removes the start's density error within one step,
 * so speeds grow as 1/dt) and advised lowering dt_max. It runs; a real blow-up at such a step
 * advises raising dt_max. */
static const char *TINY_DT =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.0001, \"fps\": 10000, \"dt_max\": 1e-8,"
    " \"dt_min\": 1e-9}, \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}]}";

static void test_pcisph_tiny_dt(void **state)
{
    (void)state;
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, TINY_DT, "tiny-dt", &err), PFSPH_OK);
    pfsph_sim *sim;
    assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
    int rc = pfsph_sim_advance(sim, 2e-5, &err); /* 2000 steps */
    if (rc) fail_msg("%s", err.msg);
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_true(pfsph_sim_stats(sim)->density_err_max < 0.01);
    /* a particle thrown at 1e7 m/s (0.1 m, five spacings, in one step) is a blow-up */
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    pfsph_particles p;
    assert_int_equal(pfsph_particles_init(&p, f->n), PFSPH_OK);
    for (size_t i = 0; i < f->n; i++) {
        pfsph_real x[3] = {f->x[i], f->y[i], 0}, v[3] = {i == 7 ? (pfsph_real)1e7 : 0, 0, 0};
        assert_true(pfsph_particles_push(&p, x, v, f->phase[i]) >= 0);
    }
    pfsph_sim_state st;
    pfsph_sim_get_state(sim, &st);
    assert_int_equal(pfsph_sim_restore(sim, &st, &p, NULL, 0, 0, &err), PFSPH_OK);
    rc = pfsph_sim_advance(sim, 3e-5, &err);
    printf("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_EUNSTABLE);
    assert_non_null(strstr(err.msg, "raise time.dt_max"));
    assert_null(strstr(err.msg, "lower time.cfl or dt_max"));
    pfsph_particles_free(&p);
    pfsph_sim_destroy(sim);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_blowup_diagnosis),
                                       cmocka_unit_test(test_density_explosion), cmocka_unit_test(test_pcisph_tiny_dt)};
    return tu_run_group(tests, NULL, NULL);
}
