/* The artist's pipeline in the real tools (label "tools", issue 14): ParaView's pvpython opens a
 * run's .pvd collections as time series with the point arrays (a 2D run's outline too); Blender (background mode) runs the
 * loader on a small run (object count, frame range, the mesh face counts of the PLY files) and the
 * render script writes a PNG. Each test is skipped when its program is not installed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 3, \"particle_radius\": 0.01, \"gravity\": [0, -9.81, 0],\n"
    " \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [0.7, 0.6, 0.3]},\n"
    " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"end\": 0.1, \"fps\": 20},\n"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.2, 0.3, 0.2], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.6, 0.5, 0.2], \"open_top\": true,\n"
    "             \"phase\": \"wall\"}],\n"
    " \"output\": {\"formats\": [\"vtp\", \"ply\"], \"surface\": %s}}\n";

static char g_run[1200], g_points[1200], g_bodies[1200];

/* a ball (r 5 cm, 600 kg/m^3) dropped beside the water column, meshes on */
static const char *SCENE_BODIES =
    "{\"dimension\": 3, \"particle_radius\": 0.01, \"gravity\": [0, -9.81, 0],\n"
    " \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [0.7, 0.6, 0.3]},\n"
    " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"end\": 0.1, \"fps\": 20},\n"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"},\n"
    "            {\"name\": \"wood\", \"kind\": \"solid\", \"rest_density\": 600}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.2, 0.3, 0.2], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.6, 0.5, 0.2], \"open_top\": true,\n"
    "             \"phase\": \"wall\"}],\n"
    " \"bodies\": [{\"name\": \"ball\", \"shape\": \"sphere\", \"radius\": 0.05, \"position\": [0.4, 0.1, 0.1],\n"
    "             \"density\": 600, \"phase\": \"wood\"}],\n"
    " \"output\": {\"formats\": [\"vtp\", \"ply\"], \"surface\": true}}\n";

static int have(const char *prog)
{
    char cmd[256], out[256];
    snprintf(cmd, sizeof cmd, "command -v %s", prog);
    return tu_run(cmd, out, sizeof out) == 0;
}

static int make_run(char *dir, size_t cap, const char *name, const char *surface)
{
    char scene[1400], text[2048], cmd[4096], out[4096];
    snprintf(scene, sizeof scene, "%s/%s.json", tu_tmpdir(), name);
    snprintf(dir, cap, "%s/%s", tu_tmpdir(), name);
    if (surface) snprintf(text, sizeof text, SCENE, surface);
    else snprintf(text, sizeof text, "%s", SCENE_BODIES);
    if (tu_write_file(scene, text)) return -1;
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet", tu_pfsph_bin(), scene, dir);
    return tu_run(cmd, out, sizeof out);
}

static int setup(void **state)
{
    (void)state;
    if (make_run(g_run, sizeof g_run, "meshed", "true")) return -1;
    if (make_run(g_bodies, sizeof g_bodies, "bodies", NULL)) return -1;
    return make_run(g_points, sizeof g_points, "points", "false");
}

/* the JSON line after `tag` in out, or NULL */
static const char *json_after(const char *out, const char *tag)
{
    const char *p = strstr(out, tag);
    return p ? p + strlen(tag) : NULL;
}

static void test_paraview(void **state)
{
    (void)state;
    if (!have("pvpython")) tu_skip("no pvpython (ParaView)");
    char cmd[4096], out[16384];
    snprintf(cmd, sizeof cmd, "pvpython '%s/tools/paraview/pfsph_pvd_info.py' '%s/fluid.pvd'", tu_source_dir(), g_run);
    int st = tu_run(cmd, out, sizeof out);
    printf("%s", out);
    assert_int_equal(st, 0);
    const char *j = json_after(out, "pfsph_pvd_info: ");
    assert_non_null(j);
    assert_non_null(strstr(j, "\"steps\": 3"));
    assert_non_null(
        strstr(j, "\"point_arrays\": [\"density\", \"phase\", \"pressure\", \"surface_layer\", \"velocity\"]"));
    assert_non_null(strstr(j, "\"times\": [0.0, 0.05, 0.1]"));
    assert_non_null(strstr(j, "\"points\": 1500"));
    snprintf(cmd, sizeof cmd, "pvpython '%s/tools/paraview/pfsph_pvd_info.py' '%s/liquid.pvd'", tu_source_dir(), g_run);
    st = tu_run(cmd, out, sizeof out);
    printf("%s", out);
    assert_int_equal(st, 0);
    j = json_after(out, "pfsph_pvd_info: ");
    assert_non_null(j);
    assert_non_null(strstr(j, "\"steps\": 3"));
    assert_non_null(strstr(j, "\"cell_arrays\": [\"phase\"]"));
    assert_non_null(strstr(j, "\"point_arrays\": [\"Normals\", \"velocity\"]"));
}

/* a 2D run's outline (liquid.pvd of VTP polylines): a time series with Normals and phase, as many
 * line cells as points (closed curves) */
static void test_paraview_2d(void **state)
{
    (void)state;
    if (!have("pvpython")) tu_skip("no pvpython (ParaView)");
    char scene[1400], run[1400], cmd[4096], out[16384];
    snprintf(scene, sizeof scene, "%s/outline.json", tu_tmpdir());
    snprintf(run, sizeof run, "%s/outline", tu_tmpdir());
    assert_int_equal(
        tu_write_file(
            scene,
            "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, -9.81],\n"
            " \"domain\": {\"min\": [-0.1, -0.1], \"max\": [0.7, 0.6]}, \"time\": {\"end\": 0.1, \"fps\": 20},\n"
            " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}],\n"
            " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.2, 0.3], \"phase\": \"water\"}],\n"
            " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.5], \"open_top\": true,\n"
            "             \"phase\": \"wall\"}],\n"
            " \"output\": {\"formats\": [\"vtp\"], \"surface\": true}}\n"),
        0);
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet", tu_pfsph_bin(), scene, run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd, "pvpython '%s/tools/paraview/pfsph_pvd_info.py' '%s/liquid.pvd'", tu_source_dir(), run);
    int st = tu_run(cmd, out, sizeof out);
    printf("%s", out);
    assert_int_equal(st, 0);
    const char *j = json_after(out, "pfsph_pvd_info: ");
    assert_non_null(j);
    assert_non_null(strstr(j, "\"steps\": 3"));
    assert_non_null(strstr(j, "\"cell_arrays\": [\"phase\"]"));
    assert_non_null(strstr(j, "\"point_arrays\": [\"Normals\"]"));
    long pts = -1, cells = -2;
    const char *p = strstr(j, "\"points\": "), *c = strstr(j, "\"cells\": ");
    assert_true(p && c && sscanf(p, "\"points\": %ld", &pts) == 1 && sscanf(c, "\"cells\": %ld", &cells) == 1);
    assert_true(pts > 50);
    assert_int_equal(cells, pts);
}

static long ply_faces(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    char line[256];
    long n = -1;
    while (fgets(line, sizeof line, f) && strncmp(line, "end_header", 10))
        if (sscanf(line, "element face %ld", &n) == 1) break;
    fclose(f);
    return n;
}

static void test_blender_load(void **state)
{
    (void)state;
    if (!have("blender")) tu_skip("no blender");
    char cmd[4096], out[16384], want[256], path[1400];
    snprintf(cmd, sizeof cmd,
             "blender -b --factory-startup -noaudio -P '%s/tools/blender/pfsph_load.py' -- '%s' --save '%s/x.blend'",
             tu_source_dir(), g_run, g_run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    const char *j = json_after(out, "pfsph_load: ");
    assert_non_null(j);
    printf("meshed: %.700s\n", j ? j : "");
    assert_non_null(strstr(j, "\"frame_end\": 2, \"frame_start\": 0"));
    /* 3 liquid frames and the tank (RUN/solids.ply, issue 33 item 10), the liquid with velocities
     * (item 12); no factory cube, camera or light: the scene's own stage (item 9) */
    assert_non_null(strstr(j, "\"objects\": 4"));
    assert_non_null(strstr(j, "\"solids\": 1"));
    assert_non_null(strstr(j, "\"solid 0 container\": 60"));
    assert_non_null(strstr(j, "\"liquid_velocity\": true"));
    assert_non_null(strstr(j, "\"stage\": [\"pfsph camera\", \"pfsph floor\", \"pfsph sun\"]"));
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.ply", g_run, k);
        long n = ply_faces(path);
        assert_true(n > 1000);
        snprintf(want, sizeof want, "\"%d\": %ld", k, n);
        assert_non_null(strstr(j, want));
    }
    /* the saved file: what opening it shows */
    snprintf(cmd, sizeof cmd,
             "blender -b --factory-startup -noaudio '%s/x.blend' --python-expr \"import bpy; "
             "print('BLEND', bpy.context.scene.camera.name, sorted(o.name for o in bpy.data.objects "
             "if not o.name.startswith('liquid_')))\"",
             g_run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    const char *b0 = strstr(out, "BLEND ");
    assert_non_null(b0);
    printf("%.300s\n", b0);
    assert_non_null(strstr(b0, "BLEND pfsph camera ['pfsph camera', 'pfsph floor', 'pfsph sun', 'solid 0 container']"));
    /* without meshes: the particles as point clouds (one per frame, each with its instanced sphere) */
    snprintf(cmd, sizeof cmd, "blender -b --factory-startup -noaudio -P '%s/tools/blender/pfsph_load.py' -- '%s'",
             tu_source_dir(), g_points);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    j = json_after(out, "pfsph_load: ");
    assert_non_null(j);
    printf("points: %.400s\n", j ? j : "");
    assert_non_null(strstr(j, "\"fluid points\": 6"));
    assert_non_null(strstr(j, "\"objects\": 8")); /* and the tank */
    /* a rigid body: its own object, keyed every frame, falling (Blender's z is pfsph's y) */
    snprintf(cmd, sizeof cmd, "blender -b --factory-startup -noaudio -P '%s/tools/blender/pfsph_load.py' -- '%s'",
             tu_source_dir(), g_bodies);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    j = json_after(out, "pfsph_load: ");
    assert_non_null(j);
    printf("bodies: %.600s\n", j ? j : "");
    assert_non_null(strstr(j, "\"objects\": 5")); /* 3 liquid frames, the ball, the tank */
    const char *b = strstr(j, "\"body ball\": {");
    assert_non_null(b);
    double zf = 0, zl = 0;
    int faces = 0, keys = 0;
    assert_int_equal(sscanf(b, "\"body ball\": {\"faces\": %d, \"keys\": %d, \"z_first\": %lf, \"z_last\": %lf", &faces,
                            &keys, &zf, &zl),
                     4);
    assert_int_equal(keys, 3);
    assert_true(faces > 100);
    assert_true(fabs(zf - 0.1) < 1e-6);
    assert_true(zl < zf - 0.005);
}

static void test_blender_render(void **state)
{
    (void)state;
    if (!have("blender")) tu_skip("no blender");
    char cmd[4096], out[16384], png[1400];
    snprintf(cmd, sizeof cmd,
             "blender -b --factory-startup -noaudio -P '%s/tools/blender/pfsph_render.py' -- '%s' '%s/png' "
             "--size 160x90 --samples 4 --frames 2:2",
             tu_source_dir(), g_run, g_run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "pfsph_render: 1 PNG frames"));
    snprintf(png, sizeof png, "%s/png/frame_0002.png", g_run);
    FILE *f = fopen(png, "rb");
    assert_non_null(f);
    unsigned char sig[8];
    assert_int_equal(fread(sig, 1, 8, f), 8);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    assert_memory_equal(sig, "\x89PNG\r\n\x1a\n", 8);
    assert_true(size > 2000);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paraview),
        cmocka_unit_test(test_paraview_2d),
        cmocka_unit_test(test_blender_load),
        cmocka_unit_test(test_blender_render),
    };
    return tu_run_group(tests, setup, NULL);
}
