/* Rigid bodies: the "bodies" scene block (errors name the JSON path), bad OBJ files through
 * `pfsph check` (exit status 2, the file named), and keyframed bodies following their keys. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/bodies.h"
#include "pfsph/sim.h"
#include "testutil.h"

#define M_PI 3.14159265358979323846

static const char *BASE =
    "{\"dimension\": %d, \"particle_radius\": 0.02, \"gravity\": [0, -9.81%s],"
    " \"domain\": {\"min\": [-0.1, -0.1%s], \"max\": [1.1, 1.1%s]},"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"},"
    "              {\"name\": \"wood\", \"kind\": \"solid\", \"rest_density\": 600}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0%s], \"max\": [0.1, 0.1%s], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0%s], \"max\": [1, 1%s], \"phase\": \"wall\"}],"
    " \"bodies\": [%s]}";

static int parse(int dim, const char *bodies, pfsph_scene *s, pfsph_error *err)
{
    char json[8192];
    const char *z0 = dim == 3 ? ", 0" : "", *z1 = dim == 3 ? ", 1" : "", *zm = dim == 3 ? ", -0.1" : "",
               *zM = dim == 3 ? ", 1.1" : "", *zb = dim == 3 ? ", 0.1" : "";
    snprintf(json, sizeof json, BASE, dim, dim == 3 ? ", 0" : "", zm, zM, z0, zb, z0, z1, bodies);
    memset(err, 0, sizeof *err);
    return pfsph_scene_parse(s, json, "bodies.json", err);
}

static void expect_error(int dim, const char *bodies, const char *path, const char *words)
{
    static pfsph_scene s;
    pfsph_error err;
    int rc = parse(dim, bodies, &s, &err);
    if (rc != PFSPH_EINPUT || !strstr(err.msg, path) || !strstr(err.msg, words))
        fprintf(stderr, "bodies %s: got rc %d, \"%s\"; expected %s ... %s\n", bodies, rc, err.msg, path, words);
    assert_int_equal(rc, PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "bodies.json"));
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, words));
}

static void test_parse_ok(void **st)
{
    (void)st;
    static pfsph_scene s;
    pfsph_error err;
    int rc = parse(3,
                   "{\"name\": \"lid\", \"shape\": \"box\", \"half_extents\": [0.1, 0.05, 0.1],"
                   " \"position\": [0.5, 0.5, 0.5], \"rotation\": [0, 45, 0], \"phase\": \"wood\"},"
                   "{\"shape\": \"cylinder\", \"radius\": 0.05, \"height\": 0.2, \"axis\": \"x\","
                   " \"position\": [0.3, 0.3, 0.3], \"mass\": 2, \"kinematic\": true,"
                   " \"keyframes\": [{\"t\": 0}, {\"t\": 1, \"position\": [0.4, 0.3, 0.3]}]}",
                   &s, &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    assert_int_equal(s.nbodies, 2);
    assert_string_equal(s.bodies[0].name, "lid");
    assert_true(s.bodies[0].density == 600); /* from the phase */
    assert_int_equal(s.bodies[0].layers, 2);
    assert_string_equal(s.bodies[1].name, "body1");
    assert_int_equal(s.bodies[1].axis, 0);
    assert_int_equal(s.bodies[1].nkeys, 2);
    assert_true(s.bodies[1].keys[0].position[0] == 0.3); /* the body's own position */
    assert_true(s.bodies[1].keys[1].position[0] == 0.4);
}

static void test_parse_errors(void **st)
{
    (void)st;
    expect_error(2, "{\"position\": [0.5, 0.5]}", "$.bodies[0].shape", "missing");
    expect_error(2, "{\"shape\": \"cone\", \"position\": [0.5, 0.5]}", "$.bodies[0].shape", "one of");
    expect_error(2, "{\"shape\": \"sphere\", \"position\": [0.5, 0.5]}", "$.bodies[0].radius", "missing");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": -1, \"position\": [0.5, 0.5]}", "$.bodies[0].radius",
                 "out of range");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"phase\": \"water\"}",
                 "$.bodies[0].phase", "not a solid phase");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"phase\": \"steel\"}",
                 "$.bodies[0].phase", "phase");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"mass\": 1, \"density\": 2}",
                 "$.bodies[0].mass", "not both");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [5, 0.5]}", "$.bodies[0].position",
                 "outside the domain");
    expect_error(2, "{\"shape\": \"mesh\", \"file\": \"a.obj\", \"position\": [0.5, 0.5]}", "$.bodies[0].shape", "3D");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"keyframes\": [{\"t\": 0}]}",
                 "$.bodies[0].keyframes", "kinematic");
    expect_error(2,
                 "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"kinematic\": true,"
                 " \"keyframes\": [{\"t\": 1}, {\"t\": 0.5}]}",
                 "$.bodies[0].keyframes[1].t", "increase");
    expect_error(2,
                 "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"kinematic\": true,"
                 " \"keyframes\": [{\"t\": 0}, {\"t\": 1, \"position\": [3, 0.5]}]}",
                 "$.bodies[0].keyframes[1].position", "outside the domain");
    expect_error(2, "{\"name\": \"a,b\", \"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5]}",
                 "$.bodies[0].name", "letters");
    expect_error(2,
                 "{\"name\": \"a\", \"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5]},"
                 "{\"name\": \"a\", \"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.2, 0.5]}",
                 "$.bodies[1].name", "used by");
    expect_error(3, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5, 0.5], \"inertia\": [1, 1, 3]}",
                 "$.bodies[0].inertia", "sum of");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"inertia\": 0}",
                 "$.bodies[0].inertia", "> 0");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"colour\": 1}", "$.bodies[0]",
                 "colour");
}

/* Each bad OBJ file makes `pfsph check` fail with status 2 and a message naming the file. */
static void test_bad_obj_cli(void **st)
{
    (void)st;
    static const char *const bad[] = {"missing_file.obj",    "bad_malformed.obj", "bad_open.obj",
                                      "bad_degenerate.obj",  "bad_index.obj",     "bad_empty.obj",
                                      "bad_nonmanifold.obj", "bad_nan.obj"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char body[2048], json[8192], scene[1100], cmd[2400], out[4096];
        snprintf(body, sizeof body,
                 "{\"name\": \"thing\", \"shape\": \"mesh\", \"file\": \"%s/tests/data/meshes/%s\","
                 " \"scale\": 0.1, \"position\": [0.5, 0.5, 0.5]}",
                 tu_source_dir(), bad[i]);
        snprintf(json, sizeof json, BASE, 3, ", 0", ", -0.1", ", 1.1", ", 0", ", 0.1", ", 0", ", 1", body);
        snprintf(scene, sizeof scene, "%s/bad_obj_%zu.json", tu_tmpdir(), i);
        assert_int_equal(tu_write_file(scene, json), 0);
        snprintf(cmd, sizeof cmd, "%s check %s", tu_pfsph_bin(), scene);
        int rc = tu_run(cmd, out, sizeof out);
        printf("%s: exit %d: %s", bad[i], rc, out);
        assert_int_equal(rc, 2);
        assert_non_null(strstr(out, bad[i]));
        assert_non_null(strstr(out, "thing"));
    }
    /* a good mesh passes */
    char body[2048], json[8192], scene[1100], cmd[2400], out[4096];
    snprintf(body, sizeof body,
             "{\"name\": \"ball\", \"shape\": \"mesh\", \"file\": \"%s/tests/data/meshes/icosphere.obj\","
             " \"scale\": 0.1, \"position\": [0.5, 0.5, 0.5]}",
             tu_source_dir());
    snprintf(json, sizeof json, BASE, 3, ", 0", ", -0.1", ", 1.1", ", 0", ", 0.1", ", 0", ", 1", body);
    snprintf(scene, sizeof scene, "%s/good_obj.json", tu_tmpdir());
    assert_int_equal(tu_write_file(scene, json), 0);
    snprintf(cmd, sizeof cmd, "%s check %s", tu_pfsph_bin(), scene);
    int rc = tu_run(cmd, out, sizeof out);
    if (rc) fprintf(stderr, "%s\n", out);
    assert_int_equal(rc, 0);
}

/* Tiny or absurdly light bodies (issue 33, item 3): a body's extents below the particle
 * spacing (0.04 m here) and densities outside 0.1..1e5 kg/m^3 are refused with the JSON path,
 * and a mass ODE would abort on (SIGABRT, "assertion dMassCheck(mass) failed") never reaches
 * it: each case is exit status 2, never a crash. */
static void test_tiny_bodies(void **st)
{
    (void)st;
    expect_error(3, "{\"shape\": \"sphere\", \"radius\": 1e-300, \"position\": [0.5, 0.5, 0.5]}", "$.bodies[0].radius",
                 "particle spacing");
    expect_error(2, "{\"shape\": \"cylinder\", \"radius\": 1e-20, \"position\": [0.5, 0.5]}", "$.bodies[0].radius",
                 "particle spacing");
    expect_error(3, "{\"shape\": \"cylinder\", \"radius\": 1e-300, \"height\": 0.2, \"position\": [0.5, 0.5, 0.5]}",
                 "$.bodies[0].radius", "particle spacing");
    expect_error(3, "{\"shape\": \"cylinder\", \"radius\": 0.1, \"height\": 1e-20, \"position\": [0.5, 0.5, 0.5]}",
                 "$.bodies[0].height", "particle spacing");
    expect_error(2, "{\"shape\": \"box\", \"half_extents\": [0.1, 0.019], \"position\": [0.5, 0.5]}",
                 "$.bodies[0].half_extents", "particle spacing");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5], \"density\": 1e-300}",
                 "$.bodies[0].density", "outside");
    expect_error(
        3, "{\"shape\": \"box\", \"half_extents\": [0.1, 0.1, 0.1], \"position\": [0.5, 0.5, 0.5], \"mass\": 1e-300}",
        "$.bodies[0].mass", "density of");
    expect_error(2, "{\"shape\": \"sphere\", \"radius\": 0.02, \"position\": [0.5, 0.5], \"mass\": 1e6}",
                 "$.bodies[0].mass", "density of");
    /* given moments of inertia that underflow: refused when the simulation is built */
    static pfsph_scene s;
    pfsph_error err;
    assert_int_equal(
        parse(3,
              "{\"name\": \"speck\", \"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.5, 0.5, 0.5],"
              " \"inertia\": [1e-300, 1e-300, 1e-300]}",
              &s, &err),
        PFSPH_OK);
    pfsph_sim *sim = NULL;
    int rc = pfsph_sim_create(&sim, &s, &err);
    printf("inertia 1e-300: %s\n", err.msg);
    assert_int_equal(rc, PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "$.bodies[0]"));
    assert_non_null(strstr(err.msg, "speck"));
    /* mesh bodies, checked once the file is read: through `pfsph check` (it aborted) */
    static const char *const mesh[][3] = {{"\"scale\": 1e-300", "$.bodies[0].scale", "icosphere.obj"},
                                          {"\"scale\": 1e-20", "$.bodies[0].scale", "icosphere.obj"},
                                          {"\"scale\": 1000", "$.bodies[0].scale", "icosphere.obj"},
                                          {"\"scale\": 0.1, \"mass\": 1e-300", "$.bodies[0].mass", "density of"},
                                          {"\"scale\": 0.1, \"density\": 1e-300", "$.bodies[0].density", "outside"}};
    for (size_t i = 0; i < sizeof mesh / sizeof mesh[0]; i++) {
        char body[2048], json[8192], scene[1100], cmd[2400], out[4096];
        snprintf(body, sizeof body,
                 "{\"name\": \"ball\", \"shape\": \"mesh\", \"file\": \"%s/tests/data/meshes/icosphere.obj\","
                 " %s, \"position\": [0.5, 0.5, 0.5]}",
                 tu_source_dir(), mesh[i][0]);
        snprintf(json, sizeof json, BASE, 3, ", 0", ", -0.1", ", 1.1", ", 0", ", 0.1", ", 0", ", 1", body);
        snprintf(scene, sizeof scene, "%s/tiny_%zu.json", tu_tmpdir(), i);
        assert_int_equal(tu_write_file(scene, json), 0);
        snprintf(cmd, sizeof cmd, "%s check %s", tu_pfsph_bin(), scene);
        rc = tu_run(cmd, out, sizeof out);
        printf("%s: exit %d: %s", mesh[i][0], rc, out);
        assert_int_equal(rc, 2);
        assert_non_null(strstr(out, scene));
        assert_non_null(strstr(out, mesh[i][1]));
        assert_non_null(strstr(out, mesh[i][2]));
    }
}

/* A kinematic body is where its keyframes put it: linear in position, slerp in rotation, the
 * last key held; its particles move with it at the keyed velocity. */
/* Overlapping bodies are refused with both JSON paths (issue 15 item 15: they were pushed
 * apart at 0.5 m/s each); bodies that only touch, and keyframed bodies, are accepted. */
static void test_overlap(void **st)
{
    (void)st;
    static const char *A =
        "{\"name\": \"a\", \"shape\": \"box\", \"half_extents\": [0.1, 0.1], \"position\": [0.5, 0.5],"
        " \"density\": 600, \"phase\": \"wood\"}";
    const struct {
        const char *b;
        int overlap;
    } cases[] = {
        {"{\"name\": \"b\", \"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.65, 0.5], \"density\": 600, "
         "\"phase\": \"wood\"}",
         1},
        {"{\"name\": \"b\", \"shape\": \"sphere\", \"radius\": 0.1, \"position\": [0.7, 0.5], \"density\": 600, "
         "\"phase\": \"wood\"}",
         0},
        {"{\"name\": \"b\", \"shape\": \"box\", \"half_extents\": [0.1, 0.1], \"position\": [0.5, 0.7], \"density\": "
         "600, \"phase\": \"wood\"}",
         0},
        {"{\"name\": \"b\", \"shape\": \"box\", \"half_extents\": [0.1, 0.1], \"position\": [0.5, 0.65], \"density\": "
         "600, \"phase\": \"wood\"}",
         1},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        char bodies[1024];
        snprintf(bodies, sizeof bodies, "%s, %s", A, cases[k].b);
        static pfsph_scene s;
        pfsph_error err;
        assert_int_equal(parse(2, bodies, &s, &err), PFSPH_OK);
        pfsph_sim *sim = NULL;
        int rc = pfsph_sim_create(&sim, &s, &err);
        if (cases[k].overlap) {
            if (rc != PFSPH_EINPUT) fprintf(stderr, "case %zu: rc %d\n", k, rc);
            assert_int_equal(rc, PFSPH_EINPUT);
            assert_non_null(strstr(err.msg, "bodies.json"));
            assert_non_null(strstr(err.msg, "$.bodies[0]"));
            assert_non_null(strstr(err.msg, "$.bodies[1]"));
            assert_non_null(strstr(err.msg, "overlap"));
        } else {
            if (rc) fprintf(stderr, "case %zu: %s\n", k, err.msg);
            assert_int_equal(rc, PFSPH_OK);
        }
        pfsph_sim_destroy(sim);
    }
}

static void test_keyframes(void **st)
{
    (void)st;
    static pfsph_scene s;
    pfsph_error err;
    int rc = parse(3,
                   "{\"name\": \"paddle\", \"shape\": \"box\", \"half_extents\": [0.05, 0.1, 0.02],"
                   " \"position\": [0.5, 0.5, 0.5], \"kinematic\": true, \"keyframes\": ["
                   "  {\"t\": 0, \"position\": [0.5, 0.5, 0.5], \"rotation\": [0, 0, 0]},"
                   "  {\"t\": 0.2, \"position\": [0.7, 0.5, 0.5], \"rotation\": [0, 0, 90]}]}",
                   &s, &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    pfsph_sim *sim;
    rc = pfsph_sim_create(&sim, &s, &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    pfsph_body_state bs;
    assert_int_equal(pfsph_sim_advance(sim, 0.1, &err), PFSPH_OK);
    pfsph_bodies_get_state(B, 0, &bs);
    printf("t = 0.1: x = %.9f, q = %.6f %.6f %.6f %.6f, v = %.6f, w = %.6f\n", bs.x[0], bs.q[0], bs.q[1], bs.q[2],
           bs.q[3], bs.v[0], bs.w[2]);
    assert_true(fabs(bs.x[0] - 0.6) < 1e-9);
    /* halfway between 0 and 90 degrees about z: 45 degrees */
    assert_true(fabs(bs.q[0] - cos(M_PI / 8)) < 1e-9 && fabs(bs.q[3] - sin(M_PI / 8)) < 1e-9);
    assert_true(fabs(bs.v[0] - 1.0) < 1e-6);            /* 0.2 m in 0.2 s */
    assert_true(fabs(bs.w[2] - M_PI / 2 / 0.2) < 1e-3); /* 90 degrees in 0.2 s */
    assert_int_equal(pfsph_sim_advance(sim, 0.3, &err), PFSPH_OK);
    pfsph_bodies_get_state(B, 0, &bs);
    assert_true(fabs(bs.x[0] - 0.7) < 1e-9);
    assert_true(fabs(bs.q[0] - cos(M_PI / 4)) < 1e-9);
    /* its particles: inside the rotated box's extent around the centre */
    const pfsph_particles *b = pfsph_sim_ctx(sim)->boundary;
    size_t n = 0;
    for (size_t j = 0; j < b->n; j++) {
        if (b->id[j] < pfsph_bodies_first_id(B)) continue;
        n++;
        /* rotated 90 degrees about z: the x half extent is now 0.1 */
        assert_true(fabs(b->x[j] - 0.7) < 0.1 + 1e-4 && fabs(b->y[j] - 0.5) < 0.05 + 1e-4);
    }
    assert_true(n > 0);
    pfsph_sim_destroy(sim);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_ok),  cmocka_unit_test(test_parse_errors), cmocka_unit_test(test_bad_obj_cli),
        cmocka_unit_test(test_keyframes), cmocka_unit_test(test_overlap),      cmocka_unit_test(test_tiny_bodies),
    };
    return tu_run_group(tests, NULL, NULL);
}
