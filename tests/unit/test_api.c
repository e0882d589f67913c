/* The embedding API (include/pfsph.h): status texts, scene errors as the loader words them, and
 * the field accessors against the simulation's own arrays (count, stride, type, the very
 * pointers), bad names, writing fluid velocities between steps, frames as the program writes them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.45, 0.4]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.02, \"fps\": 100, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3},"
    "  {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.1, 0.12], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.4, 0.3], \"open_top\": true,"
    "  \"phase\": \"wall\"}]}";

static pfsph_sim *make(void)
{
    pfsph_error err = {0};
    pfsph_scene *s = NULL;
    if (pfsph_scene_new_json(&s, SCENE, "<api>", &err)) fail_msg("%s", err.msg);
    assert_int_equal(pfsph_scene_dim(s), 2);
    assert_true(fabs(pfsph_scene_end_time(s) - 0.02) < 1e-12);
    assert_true(fabs(pfsph_scene_fps(s) - 100) < 1e-12);
    pfsph_sim *sim = NULL;
    if (pfsph_sim_new(&sim, s, &err)) fail_msg("%s", err.msg);
    pfsph_scene_free(s); /* the simulation has its own copy */
    return sim;
}

static void test_strerror(void **state)
{
    (void)state;
    const int codes[] = {PFSPH_OK, PFSPH_EINPUT, PFSPH_EUNSTABLE, PFSPH_EINTR, PFSPH_EIO, PFSPH_ENOMEM};
    const int n = (int)(sizeof codes / sizeof codes[0]);
    for (int i = 0; i < n; i++) {
        const char *t = pfsph_strerror(codes[i]);
        assert_non_null(t);
        assert_true(strlen(t) > 3);
        assert_string_not_equal(t, "unknown error");
        for (int j = 0; j < i; j++) assert_string_not_equal(t, pfsph_strerror(codes[j]));
    }
    assert_string_equal(pfsph_strerror(PFSPH_OK), "success");
    assert_string_equal(pfsph_strerror(PFSPH_ENOMEM), "out of memory");
    assert_string_equal(pfsph_strerror(1), "unknown error");
    assert_string_equal(pfsph_strerror(-6), "unknown error");
    assert_string_equal(pfsph_version(), PFSPH_VERSION);
    assert_int_equal(pfsph_real_type(), PFSPH_REAL_TYPE);
    assert_int_equal(sizeof(pfsph_real), PFSPH_REAL_TYPE == PFSPH_FLOAT64 ? 8 : 4);
    assert_true(pfsph_threads(0) >= 1);
}

/* A scene error reads as the loader (and so the program) words it: file and JSON path. */
static void test_scene_errors(void **state)
{
    (void)state;
    const char *bad = "{\"dimension\": 2, \"particle_radius\": -1}";
    pfsph_error e1 = {0}, e2 = {0};
    pfsph_scene *s = (pfsph_scene *)&e1; /* set to NULL on error */
    assert_int_equal(pfsph_scene_new_json(&s, bad, "bad.json", &e1), PFSPH_EINPUT);
    assert_null(s);
    assert_int_equal(e1.code, PFSPH_EINPUT);
    pfsph_scene *ref = malloc(sizeof *ref);
    assert_non_null(ref);
    assert_int_equal(pfsph_scene_parse(ref, bad, "bad.json", &e2), PFSPH_EINPUT);
    free(ref);
    assert_string_equal(e1.msg, e2.msg);
    assert_non_null(strstr(e1.msg, "bad.json: "));
    assert_non_null(strstr(e1.msg, "particle_radius"));

    char path[1200];
    snprintf(path, sizeof path, "%s/no_such_scene.json", tu_tmpdir());
    s = (pfsph_scene *)&e1;
    assert_int_equal(pfsph_scene_new_file(&s, path, &e1), PFSPH_EIO);
    assert_null(s);
    assert_non_null(strstr(e1.msg, path));
    /* a file that loads */
    snprintf(path, sizeof path, "%s/api.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, SCENE), 0);
    assert_int_equal(pfsph_scene_new_file(&s, path, NULL), PFSPH_OK);
    assert_non_null(s);
    assert_string_equal(pfsph_scene_name(s), "api");
    pfsph_scene_free(s);
    pfsph_scene_free(NULL);
    pfsph_sim_free(NULL);
}

/* Every listed field of a set against the particle set it views. */
static void check_set(const pfsph_sim *sim, const char *set, const pfsph_particles *ps)
{
    pfsph_error err = {0};
    size_t n = 99;
    assert_int_equal(pfsph_sim_count(sim, set, &n, &err), PFSPH_OK);
    assert_int_equal(n, ps ? ps->n : 0);
    int nf = 0;
    for (const char *name; (name = pfsph_field_name(set, nf)); nf++) {
        pfsph_field f;
        if (pfsph_sim_field(sim, set, name, &f, &err)) fail_msg("%s", err.msg);
        assert_int_equal(f.count, n);
        assert_int_equal(f.stride, f.itemsize);
        assert_int_equal(f.writable, 0);
        assert_non_null(f.unit);
        assert_true(f.components == 1 || f.components == 3);
        for (int k = f.components; k < 3; k++) assert_null(f.data[k]);
        if (!n) {
            for (int k = 0; k < 3; k++) assert_null(f.data[k]);
            continue;
        }
        const void *want[3] = {NULL, NULL, NULL};
        size_t size = sizeof(pfsph_real);
        int type = PFSPH_REAL_TYPE;
        if (!strcmp(name, "position")) want[0] = ps->x, want[1] = ps->y, want[2] = ps->z;
        else if (!strcmp(name, "velocity")) want[0] = ps->vx, want[1] = ps->vy, want[2] = ps->vz;
        else if (!strcmp(name, "density")) want[0] = ps->rho;
        else if (!strcmp(name, "pressure")) want[0] = ps->p;
        else if (!strcmp(name, "film")) want[0] = ps->film;
        else if (!strcmp(name, "volume") || !strcmp(name, "lifetime")) want[0] = ps->aux;
        else if (!strcmp(name, "id")) want[0] = ps->id, size = 4, type = PFSPH_UINT32;
        else {
            size = 1, type = PFSPH_UINT8;
            if (!strcmp(name, "phase") || !strcmp(name, "type")) want[0] = ps->phase;
            else if (!strcmp(name, "wall")) want[0] = ps->wall;
            else if (!strcmp(name, "bubble")) want[0] = ps->bubble;
            else fail_msg("%s: unexpected field %s", set, name);
        }
        assert_int_equal(f.type, type);
        assert_int_equal(f.itemsize, size);
        assert_int_equal(f.components, want[1] ? 3 : 1);
        for (int k = 0; k < f.components; k++) {
            assert_ptr_equal(f.data[k], want[k]);
            assert_memory_equal(f.data[k], want[k], n * size);
        }
    }
    assert_true(nf >= 5);
    assert_null(pfsph_field_name(set, -1));
}

static void test_fields(void **state)
{
    (void)state;
    pfsph_sim *sim = make();
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    assert_true(c->fluid->n >= 30);
    /* primed as `pfsph run` primes its frame 0: densities summed before any step */
    for (size_t i = 0; i < c->fluid->n; i++) assert_true(c->fluid->rho[i] > 500);
    assert_int_equal(pfsph_sim_steps(sim), 0);
    assert_true(pfsph_sim_dt(sim) == 0);
    for (int pass = 0; pass < 2; pass++) {
        check_set(sim, "fluid", c->fluid);
        check_set(sim, "boundary", c->boundary);
        check_set(sim, "diffuse", NULL); /* off in this scene: empty, not an error */
        pfsph_error err = {0};
        if (pfsph_sim_advance(sim, 0.01, &err)) fail_msg("%s", err.msg);
    }
    assert_true(fabs(pfsph_sim_time(sim) - 0.01) < 1e-12);
    assert_true(pfsph_sim_steps(sim) >= 5);
    assert_int_equal(pfsph_sim_dim(sim), 2);
    pfsph_stats st;
    pfsph_sim_stats_get(sim, &st);
    assert_int_equal(st.n_fluid, c->fluid->n);
    assert_int_equal(st.n_boundary, c->boundary->n);
    assert_int_equal(st.n_diffuse, 0);
    assert_true(st.dt > 0 && st.dt == pfsph_sim_dt(sim));
    assert_int_equal(st.steps, pfsph_sim_steps(sim));
    assert_true(st.time == pfsph_sim_time(sim));
    pfsph_field f;
    pfsph_sim_field(sim, "boundary", "volume", &f, NULL);
    assert_string_equal(f.unit, "m^2");
    pfsph_sim_free(sim);
}

/* Bad names: PFSPH_EINPUT, a zeroed field, a message naming what was asked and what exists. */
static void test_bad_names(void **state)
{
    (void)state;
    pfsph_sim *sim = make();
    pfsph_error err = {0};
    pfsph_field f;
    memset(&f, 0xab, sizeof f);
    assert_int_equal(pfsph_sim_field(sim, "liquid", "position", &f, &err), PFSPH_EINPUT);
    assert_null(f.data[0]);
    assert_int_equal(f.count, 0);
    assert_non_null(strstr(err.msg, "'liquid'"));
    assert_non_null(strstr(err.msg, "fluid, boundary, diffuse"));
    memset(&f, 0xab, sizeof f);
    assert_int_equal(pfsph_sim_field(sim, "fluid", "temperature", &f, &err), PFSPH_EINPUT);
    assert_null(f.data[0]);
    assert_non_null(strstr(err.msg, "'temperature'"));
    assert_non_null(strstr(err.msg, "position, velocity, density"));
    assert_int_equal(pfsph_sim_field(sim, "diffuse", "volume", &f, NULL), PFSPH_EINPUT);
    assert_int_equal(pfsph_sim_field(sim, NULL, "id", &f, NULL), PFSPH_EINPUT);
    assert_int_equal(pfsph_sim_field(sim, "fluid", NULL, &f, NULL), PFSPH_EINPUT);
    size_t n = 7;
    assert_int_equal(pfsph_sim_count(sim, "solid", &n, NULL), PFSPH_EINPUT);
    assert_int_equal(n, 0);
    assert_null(pfsph_field_name("solid", 0));
    /* writing: the fluid's position and velocity only */
    assert_int_equal(pfsph_sim_field_write(sim, "fluid", "density", &f, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "not writable"));
    assert_int_equal(pfsph_sim_field_write(sim, "boundary", "position", &f, &err), PFSPH_EINPUT);
    /* bodies: none here */
    assert_int_equal(pfsph_sim_body_count(sim), 0);
    assert_null(pfsph_sim_body_name(sim, 0));
    double x[3];
    assert_int_equal(pfsph_sim_body_state(sim, 0, x, NULL, NULL, NULL), PFSPH_EINPUT);
    pfsph_sim_free(sim);
}

/* Velocities written between steps: checked, and the next time step follows them. */
static void test_write(void **state)
{
    (void)state;
    pfsph_sim *sim = make();
    pfsph_error err = {0};
    if (pfsph_sim_advance(sim, 0.004, &err)) fail_msg("%s", err.msg);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    pfsph_field v, x;
    assert_int_equal(pfsph_sim_field_write(sim, "fluid", "velocity", &v, &err), PFSPH_OK);
    assert_int_equal(pfsph_sim_field_write(sim, "fluid", "position", &x, &err), PFSPH_OK);
    assert_int_equal(v.writable, 1);
    assert_ptr_equal(v.data[0], c->fluid->vx);
    pfsph_real *vx = v.data[0], *vz = v.data[2], *xz = x.data[2];
    /* non-finite, and z in 2D: refused, naming the particle */
    vx[3] = NAN;
    assert_int_equal(pfsph_sim_fields_written(sim, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "fluid particle 3 (id "));
    vx[3] = 0;
    xz[2] = (pfsph_real)0.01;
    assert_int_equal(pfsph_sim_fields_written(sim, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "2D"));
    xz[2] = 0;
    (void)vz;
    /* a push of 2 m/s: the next dt is the CFL step of the new speed, not of the old one */
    for (size_t i = 0; i < v.count; i++) vx[i] += 2;
    assert_int_equal(pfsph_sim_fields_written(sim, &err), PFSPH_OK);
    pfsph_stats st;
    pfsph_sim_stats_get(sim, &st);
    double vmax = 0;
    for (size_t i = 0; i < c->fluid->n; i++)
        vmax = fmax(vmax, sqrt((double)c->fluid->vx[i] * c->fluid->vx[i] + (double)c->fluid->vy[i] * c->fluid->vy[i]));
    assert_true(fabs(st.vmax - vmax) <= 1e-9 * vmax);
    assert_true(st.vmax > 2);
    if (pfsph_sim_step(sim, 1.0, &err)) fail_msg("%s", err.msg);
    const pfsph_scene *sc = pfsph_sim_scene(sim);
    assert_true(pfsph_sim_dt(sim) <= sc->cfl * 2 * sc->particle_radius / vmax * (1 + 1e-6));
    /* the fluid moved on with its push */
    double mean = 0;
    for (size_t i = 0; i < c->fluid->n; i++) mean += c->fluid->vx[i];
    assert_true(mean / (double)c->fluid->n > 1.5);
    pfsph_sim_free(sim);
}

/* pfsph_sim_write_frame: the program's frame writer, so frames written by an embedder that
 * advances frame by frame are the program's files byte for byte (frame < 0: the current one). */
static void test_write_frame(void **state)
{
    (void)state;
    char scene[512], prog[512], mine[512], cmd[2048], out[4096];
    snprintf(scene, sizeof scene, "%s/frames.json", tu_tmpdir());
    snprintf(prog, sizeof prog, "%s/program_run", tu_tmpdir());
    snprintf(mine, sizeof mine, "%s/api_run/sub", tu_tmpdir());
    assert_int_equal(tu_write_file(scene, SCENE), 0);
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet", tu_pfsph_bin(), scene, prog);
    if (tu_run(cmd, out, sizeof out) != 0) fail_msg("%s: %s", cmd, out);
    pfsph_error err = {0};
    pfsph_scene *s = NULL;
    if (pfsph_scene_new_file(&s, scene, &err)) fail_msg("%s", err.msg);
    pfsph_sim *sim = NULL;
    if (pfsph_sim_new(&sim, s, &err)) fail_msg("%s", err.msg);
    pfsph_scene_free(s);
    /* frame 0 by number, then the frames of t = 0.01 and 0.02 s by the clock (dir made) */
    assert_int_equal(pfsph_sim_write_frame(sim, mine, 0, &err), PFSPH_OK);
    for (int k = 1; k <= 2; k++) {
        if (pfsph_sim_advance(sim, k / 100.0, &err)) fail_msg("%s", err.msg);
        if (pfsph_sim_write_frame(sim, mine, -1, &err)) fail_msg("%s", err.msg);
    }
    char a[600], b[600];
    snprintf(a, sizeof a, "%s/frames", prog);
    snprintf(b, sizeof b, "%s/frames", mine);
    tu_assert_same_file(a, b, "fluid_00000.vtp");
    tu_assert_same_file(a, b, "boundary_00000.vtp");
    tu_assert_same_file(a, b, "fluid_00001.vtp");
    tu_assert_same_file(a, b, "fluid_00002.vtp");
    tu_assert_same_file(prog, mine, "fluid.pvd");
    /* a directory that cannot be made: the writer's error */
    assert_int_equal(pfsph_sim_write_frame(sim, "/proc/no/such", 0, &err) != PFSPH_OK, 1);
    assert_int_equal(pfsph_sim_write_frame(sim, NULL, 0, &err), PFSPH_EINPUT);
    pfsph_sim_free(sim);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_strerror),  cmocka_unit_test(test_scene_errors), cmocka_unit_test(test_fields),
        cmocka_unit_test(test_bad_names), cmocka_unit_test(test_write),        cmocka_unit_test(test_write_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
