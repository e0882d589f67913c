/* Scene loader: valid scenes parse with the expected values and defaults; every kind of bad
 * input fails with "<file>: <JSON path>: <reason>" and PFSPH_EINPUT; every shipped scene parses. */
#include <glob.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/checkpoint.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "scene/shapes.h"
#include "testutil.h"

/* A minimal valid 3D scene body: domain plus one small fluid box. */
#define DOM3 "\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]}"
#define BOX3 "{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}"
#define FLUID3 "\"fluid\":[" BOX3 "]"
#define SCENE3(extra) "{\"particle_radius\":0.01," DOM3 "," FLUID3 extra "}"

static pfsph_scene g_scene; /* large; keep off the stack */

static int parse(const char *json, pfsph_error *err)
{
    memset(err, 0, sizeof *err);
    return pfsph_scene_parse(&g_scene, json, "dir/bad.json", err);
}

static void expect_ok(const char *json)
{
    pfsph_error err;
    int rc = parse(json, &err);
    if (rc != PFSPH_OK) fail_msg("unexpected error: %s", err.msg);
}

/* ---------------------------------------------------------------------------------------- */

static void test_full_scene(void **state)
{
    (void)state;
    const char *json = "{\"name\":\"t\",\"dimension\":3,\"particle_radius\":0.02,\"support_factor\":2.5,"
                       "\"gravity\":[0,-10,1],\"domain\":{\"min\":[-1,-1,-1],\"max\":[2,3,4]},"
                       "\"solver\":{\"type\":\"wcsph\",\"tolerance\":0.01,\"min_iterations\":2,"
                       "\"max_iterations\":20,\"sound_speed\":30,\"gamma\":3},"
                       "\"time\":{\"end\":2.5,\"fps\":30,\"cfl\":0.3,\"dt_min\":1e-5,\"dt_max\":0.002},"
                       "\"seed\":42,\"threads\":2,"
                       "\"phases\":[{\"name\":\"water\",\"kind\":\"fluid\",\"rest_density\":1000,"
                       "\"viscosity\":1e-4,\"color\":[0.1,0.2,0.3]},"
                       "{\"name\":\"air\",\"kind\":\"gas\"},{\"name\":\"wall\",\"kind\":\"solid\"}],"
                       "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.5,0.5,0.5],\"phase\":\"water\","
                       "\"velocity\":[1,0,0]},"
                       "{\"shape\":\"sphere\",\"center\":[1.5,1.5,1.5],\"radius\":0.2,\"phase\":\"air\"},"
                       "{\"shape\":\"cylinder\",\"center\":[1.5,0.5,3],\"radius\":0.1,\"height\":0.4,"
                       "\"axis\":\"z\"}],"
                       "\"solids\":[{\"shape\":\"container\",\"min\":[-0.5,-0.5,-0.5],\"max\":[1.9,2.9,3.9],"
                       "\"open_top\":true,\"layers\":3,\"phase\":\"wall\"},"
                       "{\"shape\":\"plane\",\"point\":[0,-0.9,0],\"normal\":[0,2,0]},"
                       "{\"shape\":\"cylinder\",\"center\":[1,2,1],\"radius\":0.1,\"height\":0.5,\"axis\":\"x\"}],"
                       "\"output\":{\"directory\":\"out/x\",\"formats\":[\"ply\"],\"fields\":[\"id\",\"speed\"],"
                       "\"boundary\":false,\"frame_interval\":2},"
                       "\"camera\":{\"eye\":[0,1,5],\"target\":[0,1,0],\"up\":[0,1,0],\"fov\":50,"
                       "\"width\":640,\"height\":480,\"color_by\":\"speed\"}}";
    expect_ok(json);
    const pfsph_scene *s = &g_scene;
    assert_string_equal(s->name, "t");
    assert_string_equal(s->source, "dir/bad.json");
    assert_int_equal(s->dim, 3);
    assert_true(s->particle_radius == 0.02);
    assert_true(s->support_factor == 2.5);
    assert_true(s->gravity[1] == -10 && s->gravity[2] == 1);
    assert_true(s->domain_min[0] == -1 && s->domain_max[2] == 4);
    assert_string_equal(s->solver, "wcsph");
    /* other solvers' keys are accepted (switching "type" is one word) but WCSPH keeps none */
    assert_true(isnan(pfsph_scene_solver_setting(s, "tolerance")));
    assert_true(s->sound_speed == 30 && s->gamma == 3);
    assert_true(s->end_time == 2.5 && s->fps == 30 && s->cfl == 0.3);
    assert_true(s->dt_min == 1e-5 && s->dt_max == 0.002);
    assert_true(s->seed == 42);
    assert_int_equal(s->threads, 2);
    assert_int_equal(s->nphases, 3);
    assert_int_equal(s->phases[1].kind, PFSPH_PHASE_GAS);
    assert_true(fabs(s->phases[1].rest_density - 1.2) < 1e-12); /* gas default */
    assert_int_equal(s->phases[2].kind, PFSPH_PHASE_SOLID);
    assert_true(s->phases[0].viscosity == 1e-4);
    assert_true(fabsf(s->phases[0].color[2] - 0.3f) < 1e-6f);
    assert_int_equal(s->nblocks, 3);
    assert_int_equal(s->blocks[0].shape, PFSPH_SHAPE_BOX);
    assert_true(s->blocks[0].velocity[0] == 1);
    assert_int_equal(s->blocks[1].shape, PFSPH_SHAPE_SPHERE);
    assert_int_equal(s->blocks[1].phase, 1);
    assert_true(s->blocks[1].radius == 0.2);
    /* sphere bounding box filled */
    assert_true(fabs(s->blocks[1].min[0] - 1.3) < 1e-12 && fabs(s->blocks[1].max[2] - 1.7) < 1e-12);
    assert_int_equal(s->blocks[2].shape, PFSPH_SHAPE_CYLINDER);
    assert_int_equal(s->blocks[2].axis, 2);
    assert_int_equal(s->blocks[2].phase, 0); /* default: first fluid phase */
    assert_true(s->blocks[2].height == 0.4);
    assert_int_equal(s->nsolids, 3);
    assert_int_equal(s->solids[0].shape, PFSPH_SHAPE_CONTAINER);
    assert_true(s->solids[0].open_top);
    assert_int_equal(s->solids[0].layers, 3);
    assert_int_equal(s->solids[0].phase, 2);
    assert_int_equal(s->solids[1].shape, PFSPH_SHAPE_PLANE);
    assert_true(fabs(s->solids[1].normal[1] - 1.0) < 1e-12); /* normalised */
    assert_true(s->solids[1].center[1] == -0.9);
    assert_int_equal(s->solids[1].phase, 2); /* default: first solid phase */
    assert_int_equal(s->solids[1].layers, 2);
    assert_int_equal(s->solids[2].axis, 0);
    assert_string_equal(s->output.dir, "out/x");
    assert_false(s->output.vtp);
    assert_true(s->output.ply);
    assert_false(s->output.write_boundary);
    assert_int_equal(s->output.fields, PFSPH_OUT_ID | PFSPH_OUT_SPEED);
    assert_int_equal(s->output.frame_interval, 2);
    assert_true(s->camera.set);
    assert_true(s->camera.eye[2] == 5 && s->camera.fov_deg == 50);
    assert_int_equal(s->camera.width, 640);
    assert_int_equal(s->camera.height, 480);
    assert_string_equal(s->camera.color_by, "speed");
    assert_int_equal(pfsph_scene_phase_index(s, "air"), 1);
    assert_int_equal(pfsph_scene_phase_index(s, "nope"), -1);
}

static void test_defaults(void **state)
{
    (void)state;
    expect_ok(SCENE3(""));
    const pfsph_scene *s = &g_scene;
    assert_string_equal(s->name, "bad"); /* file name without .json */
    assert_string_equal(s->output.dir, "runs/bad");
    assert_int_equal(s->dim, 3);
    assert_true(s->support_factor == 2.0);
    assert_true(s->gravity[0] == 0 && s->gravity[1] == -9.81 && s->gravity[2] == 0);
    assert_string_equal(s->solver, "pcisph");
    assert_true(pfsph_scene_solver_setting(s, "tolerance") == 0.005);
    assert_true(pfsph_scene_solver_setting(s, "min_iterations") == 3);
    assert_true(pfsph_scene_solver_setting(s, "max_iterations") == 50);
    assert_true(s->sound_speed == 0 && s->gamma == 7);
    assert_true(s->end_time == 1.0 && s->fps == 25 && s->cfl == 0.4);
    assert_true(s->dt_min == 1e-6 && s->dt_max == 0.005);
    assert_true(s->seed == 1);
    assert_int_equal(s->threads, 0);
    assert_int_equal(s->nphases, 1);
    assert_string_equal(s->phases[0].name, "water");
    assert_int_equal(s->phases[0].kind, PFSPH_PHASE_FLUID);
    assert_true(s->phases[0].rest_density == 1000);
    assert_true(s->phases[0].viscosity == 1e-3);
    assert_int_equal(s->nblocks, 1);
    assert_int_equal(s->blocks[0].phase, 0);
    assert_int_equal(s->nsolids, 0);
    assert_true(s->output.vtp);
    assert_false(s->output.ply);
    assert_true(s->output.write_boundary);
    assert_int_equal(s->output.fields, 0);
    assert_int_equal(s->output.frame_interval, 1);
    assert_false(s->camera.set);
    assert_true(s->camera.fov_deg == 40);
    assert_int_equal(s->camera.width, 960);
    assert_string_equal(s->camera.color_by, "phase");
    assert_true(s->camera.target[0] == 0.5); /* framed on the domain */
    assert_false(s->pairwise.enabled);
    assert_false(s->diffuse.enabled);

    /* pfsph_scene_defaults alone */
    pfsph_scene_defaults(&g_scene);
    assert_int_equal(g_scene.dim, 3);
    assert_true(g_scene.particle_radius == 0.01);
    assert_true(pfsph_scene_solver_setting(&g_scene, "tolerance") == 0.005);

    /* the chosen solver keeps its own keys, from its registry row */
    expect_ok("{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0."
              "1,0.1,0.1]}],"
              "\"solver\":{\"type\":\"pcisph\",\"tolerance\":0.01,\"min_"
              "iterations\":2,"
              "\"max_iterations\":20}}");
    assert_true(pfsph_scene_solver_setting(&g_scene, "tolerance") == 0.01);
    assert_true(pfsph_scene_solver_setting(&g_scene, "min_iterations") == 2);
    assert_true(pfsph_scene_solver_setting(&g_scene, "max_iterations") == 20);
    assert_true(isnan(pfsph_scene_solver_setting(&g_scene, "divergence_tolerance")));
    /* DFSPH's own defaults (tighter tolerance, one minimum correction) */
    expect_ok("{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0."
              "1,0.1,0.1]}],"
              "\"solver\":{\"type\":\"dfsph\"}}");
    assert_true(pfsph_scene_solver_setting(&g_scene, "tolerance") == 0.001);
    assert_true(pfsph_scene_solver_setting(&g_scene, "min_iterations") == 1);
    assert_true(pfsph_scene_solver_setting(&g_scene, "divergence_max_iterations") == 100);
}

static void test_2d(void **state)
{
    (void)state;
    expect_ok("{\"dimension\":2,\"particle_radius\":0.005,\"gravity\":[0,-9.81],"
              "\"domain\":{\"min\":[0,0],\"max\":[1,1]},"
              "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[0.3,0.5],\"velocity\":[1,2]},"
              "{\"shape\":\"cylinder\",\"center\":[0.7,0.7],\"radius\":0.1}],"
              "\"solids\":[{\"shape\":\"container\",\"min\":[0,0],\"max\":[1,1]},"
              "{\"shape\":\"cylinder\",\"center\":[0.5,0.2],\"radius\":0.05,\"axis\":\"z\"}]}");
    const pfsph_scene *s = &g_scene;
    assert_int_equal(s->dim, 2);
    assert_true(s->gravity[2] == 0 && s->gravity[1] == -9.81);
    assert_true(s->domain_min[2] == 0 && s->domain_max[2] == 0);
    assert_true(s->blocks[0].max[1] == 0.5 && s->blocks[0].max[2] == 0);
    assert_true(s->blocks[0].velocity[1] == 2 && s->blocks[0].velocity[2] == 0);
    assert_int_equal(s->blocks[1].axis, 2);
    assert_true(s->blocks[1].height == 0);
    /* a default solid phase "solid" is made for solids that name none */
    assert_int_equal(s->nphases, 2);
    assert_string_equal(s->phases[1].name, "solid");
    assert_int_equal(s->phases[1].kind, PFSPH_PHASE_SOLID);
    assert_int_equal(s->solids[0].phase, 1);
    assert_int_equal(s->solids[1].phase, 1);
}

/* "jitter" displaces lattice sites by at most jitter * spacing per axis, deterministically from
 * the seed; out-of-range values are errors. */
static void test_block_jitter(void **state)
{
    (void)state;
    pfsph_error err;
    assert_int_equal(parse("{\"particle_radius\":0.01," DOM3 ",\"fluid\":[{\"shape\":\"box\","
                           "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2],\"jitter\":0.6}]}",
                           &err),
                     PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "$.fluid[0].jitter"));
    static pfsph_scene a;
    pfsph_particles p0, p1, p2;
    const double d = 0.02;
    for (int k = 0; k < 3; k++) {
        expect_ok(k == 0 ? SCENE3("")
                         : "{\"particle_radius\":0.01," DOM3 ",\"fluid\":[{\"shape\":\"box\","
                           "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2],\"jitter\":0.25}]}");
        a = g_scene;
        pfsph_particles *p = k == 0 ? &p0 : k == 1 ? &p1 : &p2;
        assert_int_equal(pfsph_particles_init(p, 16), PFSPH_OK);
        assert_true(pfsph__sample_block(&a, &a.blocks[0], d, p) > 0);
    }
    assert_int_equal(p0.n, p1.n);
    assert_int_equal(p1.n, p2.n);
    double moved = 0;
    for (size_t i = 0; i < p0.n; i++) {
        const pfsph_real *q0[3] = {p0.x, p0.y, p0.z}, *q1[3] = {p1.x, p1.y, p1.z}, *q2[3] = {p2.x, p2.y, p2.z};
        for (int ax = 0; ax < 3; ax++) {
            double off = fabs((double)q1[ax][i] - (double)q0[ax][i]);
            assert_true(off <= 0.25 * d * (1 + 1e-5));
            assert_true(q1[ax][i] == q2[ax][i]); /* same seed, same positions */
            moved += off;
        }
    }
    assert_true(moved > 0.05 * d * (double)p0.n); /* it did move them (mean |u| is 1/8 d) */
    pfsph_particles_free(&p0);
    pfsph_particles_free(&p1);
    pfsph_particles_free(&p2);
}

static void test_touching_blocks_ok(void **state)
{
    (void)state;
    /* Boxes sharing a face, and a sphere touching a box, are fine (no doubled particles). */
    expect_ok("{\"particle_radius\":0.01," DOM3 ",\"fluid\":["
              "{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]},"
              "{\"shape\":\"box\",\"min\":[0.2,0,0],\"max\":[0.4,0.2,0.2]},"
              "{\"shape\":\"sphere\",\"center\":[0.1,0.3,0.1],\"radius\":0.1},"
              "{\"shape\":\"sphere\",\"center\":[0.3,0.3,0.1],\"radius\":0.1}]}");
    assert_int_equal(g_scene.nblocks, 4);
}

/* Regression: a container's walls are a shell `layers` spacings thick. Fluid in a second
 * container beside it (or anywhere beyond the shell) is kept; fluid inside the shell is not.
 * The first version treated every point outside a container as inside its walls, and two
 * side-by-side containers started with no fluid at all. */
static void test_two_containers_keep_fluid(void **state)
{
    (void)state;
    const char *json =
        "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
        " \"domain\": {\"min\": [-0.1, -0.1], \"max\": [0.7, 0.4]},"
        " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.2, 0.1]},"
        "             {\"shape\": \"box\", \"min\": [0.3, 0], \"max\": [0.5, 0.1]},"
        "             {\"shape\": \"box\", \"min\": [0.2, 0.2], \"max\": [0.3, 0.25]},"
        "             {\"shape\": \"box\", \"min\": [0.55, 0], \"max\": [0.65, 0.05]}],"
        " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.2, 0.3], \"layers\": 2},"
        "              {\"shape\": \"container\", \"min\": [0.3, 0], \"max\": [0.5, 0.3], \"layers\": 2}]}";
    pfsph_scene *s = malloc(sizeof *s);
    assert_non_null(s);
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(s, json, "two.json", &err), PFSPH_OK);
    pfsph_sim *sim = NULL;
    int rc = pfsph_sim_create(&sim, s, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    /* 20 x 10 in each container. The block over the gap (x 0.2-0.3) meets both walls'
     * shells (0.2-0.22 and 0.28-0.3): 2 columns at each side go, 6 columns x 5 rows stay.
     * The block at x 0.55-0.65 lies beyond the right shell (0.52): all 10 x 5 stay. */
    size_t n = pfsph_sim_ctx(sim)->fluid->n;
    print_message("fluid particles kept: %zu\n", n);
    assert_int_equal(n, 200 + 200 + 30 + 50);
    pfsph_sim_destroy(sim);
    free(s);
}

/* Issue 28: $.solver.neighbour_lists is true, false or "auto" (stored 1, -1, 0); "auto" is the
 * default and keeps the hash of a scene that does not name it (its checkpoints resume). */
static void test_neighbour_lists_key(void **state)
{
    (void)state;
    static const char *const vals[] = {NULL, "\"auto\"", "true", "false"};
    static const double want[] = {0, 0, 1, -1};
    uint64_t h[4];
    for (int i = 0; i < 4; i++) {
        char json[512];
        snprintf(json, sizeof json, SCENE3(",\"solver\":{\"type\":\"dfsph\"%s%s}"),
                 vals[i] ? ",\"neighbour_lists\":" : "", vals[i] ? vals[i] : "");
        expect_ok(json);
        assert_true(pfsph_scene_solver_setting(&g_scene, "neighbour_lists") == want[i]);
        h[i] = pfsph_scene_hash(&g_scene);
    }
    assert_true(h[0] == h[1]);
    assert_true(h[2] != h[1] && h[3] != h[1] && h[2] != h[3]);
}

static void test_error_leaves_scene_unchanged(void **state)
{
    (void)state;
    expect_ok(SCENE3(""));
    pfsph_scene before = g_scene;
    pfsph_error err;
    assert_int_equal(parse("{\"particle_radius\":-1}", &err), PFSPH_EINPUT);
    assert_memory_equal(&before, &g_scene, sizeof before);
}

static void test_default_scene(void **state)
{
    (void)state;
    pfsph_error err;
    memset(&err, 0, sizeof err);
    int rc = pfsph_scene_parse(&g_scene, pfsph_scene_default_json(), "<embedded>", &err);
    if (rc) fail_msg("%s", err.msg);
    const pfsph_scene *s = &g_scene;
    assert_int_equal(s->dim, 3);
    assert_string_equal(s->solver, "wcsph"); /* the solver whose hydrostatic pressure is validated */
    assert_string_equal(s->output.dir, "pfsph_default_run");
    assert_true(s->output.vtp && s->output.ply);
    assert_true(s->fps == 25 && s->end_time >= 1.0 && s->end_time <= 1.5);
    /* 8k..15k fluid particles: count lattice cells of the boxes */
    double n = 0;
    for (int i = 0; i < s->nblocks; i++) {
        assert_int_equal(s->blocks[i].shape, PFSPH_SHAPE_BOX);
        double c = 1;
        for (int k = 0; k < 3; k++)
            c *= floor((s->blocks[i].max[k] - s->blocks[i].min[k]) / (2 * s->particle_radius) + 1e-6);
        n += c;
    }
    assert_true(n >= 8000 && n <= 15000);
}

static void test_load_file(void **state)
{
    (void)state;
    pfsph_error err;
    char path[512];
    snprintf(path, sizeof path, "%s/missing_scene.json", tu_tmpdir());
    assert_int_equal(pfsph_scene_load(&g_scene, path, &err), PFSPH_EIO);
    assert_non_null(strstr(err.msg, path));
    snprintf(path, sizeof path, "%s/typo.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, SCENE3(",\"tiem\":{}")), 0);
    assert_int_equal(pfsph_scene_load(&g_scene, path, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, "$.tiem"));
    assert_non_null(strstr(err.msg, "did you mean \"time\""));
    snprintf(path, sizeof path, "%s/good.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, SCENE3("")), 0);
    assert_int_equal(pfsph_scene_load(&g_scene, path, &err), PFSPH_OK);
    assert_string_equal(g_scene.source, path);
    assert_string_equal(g_scene.name, "good");
}

/* Every shipped scene parses. */
static void test_shipped_scenes(void **state)
{
    (void)state;
    char pattern[1024];
    snprintf(pattern, sizeof pattern, "%s/scenes/*.json", tu_source_dir());
    glob_t g;
    int rc = glob(pattern, 0, NULL, &g);
    assert_int_equal(rc, 0);
    assert_true(g.gl_pathc >= 5);
    for (size_t i = 0; i < g.gl_pathc; i++) {
        pfsph_error err;
        memset(&err, 0, sizeof err);
        if (pfsph_scene_load(&g_scene, g.gl_pathv[i], &err) != PFSPH_OK) {
            globfree(&g);
            fail_msg("%s", err.msg);
        }
        assert_true(g_scene.nblocks >= 1 || g_scene.nemitters >= 1); /* a poured scene may start empty */
    }
    globfree(&g);
}

/* A bubble's liquid_volume is checked against its surface (docs/film.md) when the simulation
 * is built: more than its surface particles hold, one particle thick, is an input error naming
 * file, path and the largest volume; the largest itself is accepted. */
static void test_bubble_volume_limit(void **state)
{
    (void)state;
    char json[1024];
    const char *fmt = "{\"dimension\":2,\"particle_radius\":0.01,\"domain\":{\"min\":[0,0],\"max\":[1,1]},"
                      "\"phases\":[{\"name\":\"soap\"},{\"name\":\"air\",\"kind\":\"gas\"}],"
                      "\"fluid\":[{\"shape\":\"sphere\",\"center\":[0.5,0.5],\"radius\":0.1,\"phase\":\"air\","
                      "\"bubble\":{\"film\":\"soap\",\"liquid_volume\":%g}}]}";
    pfsph_error err;
    snprintf(json, sizeof json, fmt, 1.0);
    assert_int_equal(parse(json, &err), PFSPH_OK);
    pfsph_sim *sim = NULL;
    assert_int_equal(pfsph_sim_create(&sim, &g_scene, &err), PFSPH_EINPUT);
    print_message("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "dir/bad.json: $.fluid[0].bubble.liquid_volume: 1 m^2 is more than"));
    /* the largest it names is accepted: N_s V0 */
    const char *at = strstr(err.msg, "hold (");
    assert_non_null(at);
    const double vmax = atof(at + 6);
    snprintf(json, sizeof json, fmt, 0.999 * vmax); /* %g prints it rounded */
    assert_int_equal(parse(json, &err), PFSPH_OK);
    assert_int_equal(pfsph_sim_create(&sim, &g_scene, &err), PFSPH_OK);
    pfsph_sim_destroy(sim);
}

/* ---------------------------------------------------------------------------------------- */
/* Bad inputs: each must fail with code EINPUT and a message naming file, path and reason. */

typedef struct bad_case {
    const char *name;
    const char *json;
    const char *path;   /* expected JSON path, as it must appear after "dir/bad.json: " */
    const char *reason; /* a substring of the reason */
} bad_case;

static const bad_case bad_cases[] = {
    {"invalid_json", "{\"dimension\": 3,\n  \"particle_radius\": 0.01,,\n}", "$", "invalid JSON at line 2, column 28"},
    {"truncated_json", "{\"dimension\": 3, \"domain\": {\"min\": [0,0,0]", "$", "unexpected end"},
    {"empty_text", "  \n", "$", "empty"},
    {"root_not_object", "[1, 2]", "$", "must be a JSON object"},
    {"unknown_key_top", SCENE3(",\"partcle_radius\":0.01"), "$.partcle_radius",
     "unknown key \"partcle_radius\" (did you mean \"particle_radius\"?)"},
    {"unknown_key_nested", SCENE3(",\"time\":{\"ends\":1}"), "$.time.ends", "did you mean \"end\""},
    {"unknown_key_far", SCENE3(",\"output\":{\"zzzzzzz\":1}"), "$.output.zzzzzzz", "valid keys: directory"},
    {"unknown_key_block", "{" DOM3 ",\"fluid\":[{\"shape\":\"sphere\",\"center\":[0.5,0.5,0.5],\"raduis\":0.1}]}",
     "$.fluid[0].raduis", "did you mean \"radius\""},
    {"key_wrong_shape",
     "{" DOM3 ",\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.2,0.2],"
     "\"radius\":0.1}]}",
     "$.fluid[0].radius", "unknown key"},
    {"duplicate_key", SCENE3(",\"seed\":1,\"seed\":2"), "$.seed", "duplicate key"},
    {"wrong_type_number", SCENE3(",\"support_factor\":\"2\""), "$.support_factor", "expected a number, got a string"},
    {"wrong_type_vector_elem", SCENE3(",\"gravity\":[0,\"down\",0]"), "$.gravity[1]", "expected a number"},
    {"wrong_vector_length", "{\"domain\":{\"min\":[0,0],\"max\":[1,1,1]}," FLUID3 "}", "$.domain.min",
     "expected 3 numbers, got 2"},
    {"wrong_vector_length_2d",
     "{\"dimension\":2,\"domain\":{\"min\":[0,0],\"max\":[1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2]}]}",
     "$.fluid[0].min", "expected 2 numbers, got 3"},
    {"wrong_type_bool",
     SCENE3(",\"solids\":[{\"shape\":\"container\",\"min\":[0,0,0],\"max\":[1,1,1],"
            "\"open_top\":\"yes\"}]"),
     "$.solids[0].open_top", "expected true or false"},
    {"wrong_type_int", SCENE3(",\"threads\":1.5"), "$.threads", "expected an integer"},
    {"wrong_type_array", SCENE3(",\"phases\":{\"name\":\"water\"}"), "$.phases", "expected an array"},
    {"out_of_range_radius", "{\"particle_radius\":-0.01," DOM3 "," FLUID3 "}", "$.particle_radius",
     "value -0.01 is out of range [1e-05, 10]"},
    {"out_of_range_density", SCENE3(",\"phases\":[{\"name\":\"w\",\"rest_density\":1e9}]"), "$.phases[0].rest_density",
     "value 1e+09 is out of range [0.01, 100000]"},
    {"out_of_range_color", SCENE3(",\"phases\":[{\"name\":\"w\",\"color\":[0,0,2]}]"), "$.phases[0].color[2]",
     "out of range [0, 1]"},
    {"out_of_range_layers",
     SCENE3(",\"solids\":[{\"shape\":\"container\",\"min\":[0,0,0],\"max\":[1,1,1],"
            "\"layers\":0}]"),
     "$.solids[0].layers", "out of range [1, 10]"},
    {"unknown_phase",
     "{" DOM3 ",\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.2,0.2],"
     "\"phase\":\"oil\"}]}",
     "$.fluid[0].phase", "unknown phase \"oil\""},
    {"unknown_solid_phase",
     SCENE3(",\"solids\":[{\"shape\":\"container\",\"min\":[0,0,0],\"max\":[1,1,1],"
            "\"phase\":\"steel\"}]"),
     "$.solids[0].phase", "unknown phase \"steel\""},
    {"duplicate_phase", SCENE3(",\"phases\":[{\"name\":\"water\"},{\"name\":\"oil\"},{\"name\":\"water\"}]"),
     "$.phases[2].name", "duplicate phase name \"water\""},
    {"empty_phase_name", SCENE3(",\"phases\":[{\"name\":\"\"}]"), "$.phases[0].name", "must not be empty"},
    {"fluid_with_solid_phase",
     "{" DOM3 ",\"phases\":[{\"name\":\"water\"},{\"name\":\"wall\",\"kind\":\"solid\"}],"
     "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.2,0.2],\"phase\":\"wall\"}]}",
     "$.fluid[0].phase", "is a solid phase"},
    {"solid_with_fluid_phase",
     SCENE3(",\"solids\":[{\"shape\":\"container\",\"min\":[0,0,0],\"max\":[1,1,1],"
            "\"phase\":\"water\"}]"),
     "$.solids[0].phase", "solids need a phase of kind \"solid\""},
    {"unknown_kind", SCENE3(",\"phases\":[{\"name\":\"w\",\"kind\":\"liquid\"}]"), "$.phases[0].kind",
     "unknown value \"liquid\""},
    {"too_many_phases",
     SCENE3(",\"phases\":[{\"name\":\"a\"},{\"name\":\"b\"},{\"name\":\"c\"},{\"name\":\"d\"},"
            "{\"name\":\"e\"},{\"name\":\"f\"},{\"name\":\"g\"},{\"name\":\"h\"},{\"name\":\"i\"},"
            "{\"name\":\"j\"},{\"name\":\"k\"},{\"name\":\"l\"},{\"name\":\"m\"},{\"name\":\"n\"},"
            "{\"name\":\"o\"},{\"name\":\"p\"},{\"name\":\"q\"}]"),
     "$.phases", "too many entries (17, at most 16)"},
    {"too_many_phases_with_default_solid",
     SCENE3(",\"phases\":[{\"name\":\"a\"},{\"name\":\"b\"},{\"name\":\"c\"},{\"name\":\"d\"},"
            "{\"name\":\"e\"},{\"name\":\"f\"},{\"name\":\"g\"},{\"name\":\"h\"},{\"name\":\"i\"},"
            "{\"name\":\"j\"},{\"name\":\"k\"},{\"name\":\"l\"},{\"name\":\"m\"},{\"name\":\"n\"},"
            "{\"name\":\"o\"},{\"name\":\"p\"}],"
            "\"solids\":[{\"shape\":\"container\",\"min\":[0,0,0],\"max\":[1,1,1]}]"),
     "$.phases", "too many phases"},
    {"too_many_blocks", NULL /* built at run time */, "$.fluid", "too many entries (1025, at most 1024)"},
    {"too_many_solids", NULL /* built at run time */, "$.solids", "too many entries (65, at most 64)"},
    {"domain_min_ge_max", "{\"domain\":{\"min\":[0,1,0],\"max\":[1,1,1]}," FLUID3 "}", "$.domain",
     "min[1] = 1 must be less than max[1] = 1"},
    {"missing_domain", "{" FLUID3 "}", "$.domain", "missing required key \"domain\""},
    {"missing_fluid", "{" DOM3 "}", "$.fluid", "at least one fluid block"},
    {"block_outside_domain", "{" DOM3 ",\"fluid\":[{\"shape\":\"box\",\"min\":[0.5,0.5,0.5],\"max\":[1.5,0.7,0.7]}]}",
     "$.fluid[0].max", "extends outside the domain"},
    {"block_below_domain", "{" DOM3 ",\"fluid\":[{\"shape\":\"box\",\"min\":[0.5,-0.5,0.5],\"max\":[0.7,0.7,0.7]}]}",
     "$.fluid[0].min", "extends outside the domain [0, 0, 0] .. [1, 1, 1] along y"},
    {"sphere_outside_domain", "{" DOM3 ",\"fluid\":[{\"shape\":\"sphere\",\"center\":[0.95,0.5,0.5],\"radius\":0.1}]}",
     "$.fluid[0].center", "extends outside the domain"},
    {"box_min_ge_max", "{" DOM3 ",\"fluid\":[{\"shape\":\"box\",\"min\":[0.5,0.5,0.5],\"max\":[0.4,0.7,0.7]}]}",
     "$.fluid[0].max", "max[0] = 0.4 must be greater than min[0] = 0.5"},
    /* issue 11: overlapping blocks carve (a later one replaces an earlier one); only an
     * earlier block that later ones cover wholly is refused */
    {"covered_box_by_box",
     "{" DOM3 ",\"fluid\":[{\"shape\":\"box\",\"min\":[0.1,0.1,0.1],\"max\":[0.2,0.2,0.2]},"
     "{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.3,0.3,0.3]}]}",
     "$.fluid[0]", "every particle of this block lies inside later blocks"},
    {"covered_sphere_by_box",
     "{" DOM3 ",\"fluid\":[{\"shape\":\"sphere\",\"center\":[0.5,0.5,0.5],\"radius\":0.1},"
     "{\"shape\":\"box\",\"min\":[0.2,0.2,0.2],\"max\":[0.8,0.8,0.8]}]}",
     "$.fluid[0]", "list it after the blocks it should replace"},
    {"covered_box_by_two",
     "{" DOM3 ",\"fluid\":[" BOX3 ",{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.1,0.2,0.2]},"
     "{\"shape\":\"box\",\"min\":[0.1,0,0],\"max\":[0.2,0.2,0.2]}]}",
     "$.fluid[0]", "lies inside later blocks"},
    {"overlap_solid_obstacle", SCENE3(",\"solids\":[{\"shape\":\"sphere\",\"center\":[0.2,0.2,0.2],\"radius\":0.1}]"),
     "$.fluid[0]", "overlaps the solid $.solids[0]"},
    {"block_crosses_container", SCENE3(",\"solids\":[{\"shape\":\"container\",\"min\":[0.1,0,0],\"max\":[1,1,1]}]"),
     "$.fluid[0]", "crosses the walls of the container $.solids[0]"},
    {"empty_box", "{" DOM3 ",\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.015,0.2]}]}",
     "$.fluid[0].max", "less than one particle spacing"},
    {"empty_sphere", "{" DOM3 ",\"fluid\":[{\"shape\":\"sphere\",\"center\":[0.5,0.5,0.5],\"radius\":0.015}]}",
     "$.fluid[0].radius", "less than one particle spacing"},
    {"end_time_zero", SCENE3(",\"time\":{\"end\":0}"), "$.time.end", "must be > 0"},
    {"end_time_negative", SCENE3(",\"time\":{\"end\":-1}"), "$.time.end", "value -1 is out of range: must be > 0"},
    {"fps_zero", SCENE3(",\"time\":{\"fps\":0}"), "$.time.fps", "must be > 0"},
    {"dt_min_gt_dt_max", SCENE3(",\"time\":{\"dt_min\":0.01,\"dt_max\":0.001}"), "$.time.dt_min",
     "dt_min (0.01 s) is greater than dt_max (0.001 s)"},
    {"solver_unknown", SCENE3(",\"solver\":{\"type\":\"sph2000\"}"), "$.solver.type",
     "unknown value \"sph2000\" (expected one of \"wcsph\", \"pcisph\", \"dfsph\", \"iisph\")"},
    {"solver_pressure_scale", SCENE3(",\"solver\":{\"pressure_scale\":\"water\"}"), "$.solver.pressure_scale",
     "unknown value"},
    {"solver_iterations", SCENE3(",\"solver\":{\"min_iterations\":10,\"max_iterations\":5}"), "$.solver.min_iterations",
     "greater than max_iterations"},
    {"solver_lists_number", SCENE3(",\"solver\":{\"type\":\"dfsph\",\"neighbour_lists\":1}"),
     "$.solver.neighbour_lists", "expected true, false or \"auto\", got a number"},
    {"solver_lists_string", SCENE3(",\"solver\":{\"type\":\"iisph\",\"neighbour_lists\":\"yes\"}"),
     "$.solver.neighbour_lists", "expected true, false or \"auto\", got \"yes\""},
    {"dimension_4", "{\"dimension\":4," DOM3 "," FLUID3 "}", "$.dimension", "must be 2 or 3"},
    {"dimension_string", "{\"dimension\":\"3d\"," DOM3 "," FLUID3 "}", "$.dimension", "must be 2 or 3"},
    {"shape_unknown", "{" DOM3 ",\"fluid\":[{\"shape\":\"cube\"}]}", "$.fluid[0].shape", "unknown value \"cube\""},
    {"shape_missing", "{" DOM3 ",\"fluid\":[{\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}]}", "$.fluid[0].shape",
     "missing required key"},
    {"cylinder_axis",
     "{" DOM3 ",\"fluid\":[{\"shape\":\"cylinder\",\"center\":[0.5,0.5,0.5],\"radius\":0.1,"
     "\"height\":0.2,\"axis\":\"w\"}]}",
     "$.fluid[0].axis", "unknown value \"w\""},
    {"cylinder_2d_height",
     "{\"dimension\":2,\"domain\":{\"min\":[0,0],\"max\":[1,1]},\"fluid\":[{\"shape\":"
     "\"cylinder\",\"center\":[0.5,0.5],\"radius\":0.1,\"height\":0.2}]}",
     "$.fluid[0].height", "not used in 2D"},
    {"plane_zero_normal", SCENE3(",\"solids\":[{\"shape\":\"plane\",\"point\":[0,0,0],\"normal\":[0,0,0]}]"),
     "$.solids[0].normal", "must not be zero"},
    {"solid_outside_domain", SCENE3(",\"solids\":[{\"shape\":\"sphere\",\"center\":[5,5,5],\"radius\":0.1}]"),
     "$.solids[0]", "outside the domain"},
    {"output_format", SCENE3(",\"output\":{\"formats\":[\"vtp\",\"bgeo\"]}"), "$.output.formats[1]", "unknown format"},
    {"output_field", SCENE3(",\"output\":{\"fields\":[\"vorticity\"]}"), "$.output.fields[0]", "unknown field"},
    {"camera_eye_target", SCENE3(",\"camera\":{\"eye\":[1,1,1],\"target\":[1,1,1]}"), "$.camera.target",
     "target equals eye"},
    {"camera_color_by", SCENE3(",\"camera\":{\"color_by\":\"vorticity\"}"), "$.camera.color_by", "unknown value"},
    /* The pairwise / diffuse sub-parsers are reached and report with the same format. */
    {"pairwise_unknown_key", SCENE3(",\"pairwise\":{\"zzzz_bogus\":1}"), "$.pairwise.zzzz_bogus", "unknown key"},
    {"pairwise_not_object", SCENE3(",\"pairwise\":true"), "$.pairwise", "expected an object"},
    {"diffuse_unknown_key", SCENE3(",\"diffuse\":{\"zzzz_bogus\":1}"), "$.diffuse.zzzz_bogus", "unknown key"},
    {"seed_fraction", SCENE3(",\"seed\":1.5"), "$.seed", "expected an integer"},
    {"huge_number", SCENE3(",\"support_factor\":1e999"), "$.support_factor", "not a finite number"},
/* bubbles in air (docs/film.md) */
#define BUB(b)                                                                                                 \
    "{\"particle_radius\":0.01," DOM3 ",\"phases\":[{\"name\":\"soap\"},{\"name\":\"air\",\"kind\":\"gas\"}]," \
    "\"fluid\":[{\"shape\":\"sphere\",\"center\":[0.5,0.5,0.5],\"radius\":0.1,\"phase\":\"air\",\"bubble\":" b "}]}"
    {"bubble_not_object", BUB("1"), "$.fluid[0].bubble", "expected an object"},
    {"bubble_no_film", BUB("{\"thickness\":0.01}"), "$.fluid[0].bubble.film", "missing required key"},
    {"bubble_film_unknown", BUB("{\"film\":\"soup\",\"thickness\":0.01}"), "$.fluid[0].bubble.film",
     "unknown phase \"soup\""},
    {"bubble_film_gas", BUB("{\"film\":\"air\",\"thickness\":0.01}"), "$.fluid[0].bubble.film", "a film is a liquid"},
    {"bubble_thickness_big", BUB("{\"film\":\"soap\",\"thickness\":0.03}"), "$.fluid[0].bubble.thickness",
     "value 0.03 is out of range [0, 0.02]"},
    {"bubble_thickness_zero", BUB("{\"film\":\"soap\",\"thickness\":0}"), "$.fluid[0].bubble.thickness",
     "must be above 0"},
    {"bubble_both", BUB("{\"film\":\"soap\",\"thickness\":0.01,\"liquid_volume\":1e-5}"), "$.fluid[0].bubble",
     "exactly one of"},
    {"bubble_neither", BUB("{\"film\":\"soap\"}"), "$.fluid[0].bubble", "exactly one of"},
    {"bubble_volume_neg", BUB("{\"film\":\"soap\",\"liquid_volume\":-1}"), "$.fluid[0].bubble.liquid_volume",
     "value -1 is out of range"},
    {"bubble_key", BUB("{\"film\":\"soap\",\"thickness\":0.01,\"thicknes\":1}"), "$.fluid[0].bubble.thicknes",
     "unknown key"},
    {"bubble_liquid_block",
     "{\"particle_radius\":0.01," DOM3 ",\"phases\":[{\"name\":\"soap\"}],\"fluid\":[{\"shape\":\"sphere\","
     "\"center\":[0.5,0.5,0.5],\"radius\":0.1,\"bubble\":{\"film\":\"soap\",\"thickness\":0.01}}]}",
     "$.fluid[0].phase", "a bubble's block is its gas"},
#undef BUB
};
#define NBAD (sizeof bad_cases / sizeof bad_cases[0])

/* JSON with n copies of an item under key (the "too many" cases). */
static char *make_many(const char *key, const char *item, int n)
{
    size_t cap = 256 + (size_t)n * (strlen(item) + 2);
    char *t = malloc(cap);
    assert_non_null(t);
    size_t len = (size_t)snprintf(t, cap, "{" DOM3 ",%s\"%s\":[", strcmp(key, "fluid") ? FLUID3 "," : "", key);
    for (int i = 0; i < n; i++) len += (size_t)snprintf(t + len, cap - len, "%s%s", i ? "," : "", item);
    snprintf(t + len, cap - len, "]}");
    return t;
}

/* Issue 33, item 6: text that is not a name (invalid UTF-8, a NUL, 10 MB) is refused with the
 * JSON path before it can reach summary.json or bodies.csv; valid UTF-8 passes. */
static void test_text_limits(void **state)
{
    (void)state;
    static const char *const bad[][2] = {
        {SCENE3(",\"name\":\"dam\xff\xfe\""), "$.name: the string is not valid UTF-8 (byte 0xff"},
        {SCENE3(",\"phases\":[{\"name\":\"wa\xc0\x80ter\"}]"), "$.phases[0].name: the string is not valid UTF-8"},
        {SCENE3(",\"name\":\"a\xed\xa0\x80\""), "$.name: the string is not valid UTF-8 (byte 0xed"},
        {SCENE3(",\"name\":\"a\xf4\x90\x80\x80\""), "$.name: the string is not valid UTF-8"},
        {SCENE3(",\"name\":\"a\\u0000b\""), "$: \"\\u0000\" (a NUL character) in a string at line 1"},
        {SCENE3(",\"comment\":{\"x\xff\":1}"), "$.comment.x\xff: the key is not valid UTF-8"},
    };
    pfsph_error err;
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        int rc = parse(bad[k][0], &err);
        if (rc != PFSPH_EINPUT || !strstr(err.msg, bad[k][1]))
            fail_msg("case %zu: rc %d, \"%s\"; expected \"%s\"", k, rc, err.msg, bad[k][1]);
        assert_non_null(strstr(err.msg, "dir/bad.json"));
    }
    /* a 10 MB comment */
    const size_t n = 10u << 20;
    char *big = malloc(n + 512);
    assert_non_null(big);
    int len = snprintf(big, 512, "{\"particle_radius\":0.01," DOM3 "," FLUID3 ",\"comment\":\"");
    memset(big + len, 'x', n);
    strcpy(big + len + n, "\"}");
    assert_int_equal(parse(big, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "$.comment: the string of 10485760 bytes, more than the 65536"));
    free(big);
    /* valid UTF-8 and an escaped backslash before u0000 are fine */
    expect_ok(SCENE3(",\"name\":\"D\xc3\xa4mm \xe2\x9c\x93 \xf0\x9f\x98\x80\",\"comment\":\"a\\\\u0000b\""));
}

static void test_bad(void **state)
{
    const bad_case *c = *state;
    char *owned = NULL;
    const char *json = c->json;
    if (!json && strcmp(c->name, "too_many_blocks") == 0)
        json = owned = make_many("fluid",
                                 "{\"shape\":\"sphere\",\"center\":[0.5,0.5,0.5],"
                                 "\"radius\":0.1}",
                                 PFSPH_MAX_BLOCKS + 1);
    if (!json && strcmp(c->name, "too_many_solids") == 0)
        json = owned = make_many("solids",
                                 "{\"shape\":\"sphere\",\"center\":[0.5,0.5,0.5],"
                                 "\"radius\":0.1}",
                                 PFSPH_MAX_SOLIDS + 1);
    pfsph_error err;
    int rc = parse(json, &err);
    free(owned);
    if (rc != PFSPH_EINPUT) fail_msg("%s: expected PFSPH_EINPUT, got %d (%s)", c->name, rc, err.msg);
    assert_int_equal(err.code, PFSPH_EINPUT);
    if (getenv("PFSPH_TEST_VERBOSE")) print_message("%s\n", err.msg);
    char head[256];
    snprintf(head, sizeof head, "dir/bad.json: %s: ", c->path);
    if (strncmp(err.msg, head, strlen(head)) != 0)
        fail_msg("%s: message \"%s\" does not start with \"%s\"", c->name, err.msg, head);
    if (!strstr(err.msg + strlen(head), c->reason))
        fail_msg("%s: message \"%s\" lacks \"%s\"", c->name, err.msg, c->reason);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    static const struct CMUnitTest fixed[] = {
        cmocka_unit_test(test_full_scene),
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_neighbour_lists_key),
        cmocka_unit_test(test_2d),
        cmocka_unit_test(test_touching_blocks_ok),
        cmocka_unit_test(test_two_containers_keep_fluid),
        cmocka_unit_test(test_block_jitter),
        cmocka_unit_test(test_bubble_volume_limit),
        cmocka_unit_test(test_error_leaves_scene_unchanged),
        cmocka_unit_test(test_default_scene),
        cmocka_unit_test(test_load_file),
        cmocka_unit_test(test_shipped_scenes),
        cmocka_unit_test(test_text_limits),
    };
    enum { NFIXED = sizeof fixed / sizeof fixed[0] };
    struct CMUnitTest tests[NFIXED + NBAD];
    memcpy(tests, fixed, sizeof fixed);
    for (size_t i = 0; i < NBAD; i++) {
        struct CMUnitTest t = {bad_cases[i].name, test_bad, NULL, NULL, (void *)&bad_cases[i]};
        tests[NFIXED + i] = t;
    }
    return tu_run_group(tests, NULL, NULL);
}
