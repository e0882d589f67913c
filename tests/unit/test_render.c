/* PNG previews: a hand-made run directory (scene.json + frames written with the frame writers)
 * is rendered; the images must have the requested size, show particles where they project and
 * leave the corners as background. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/colormap.h"
#include "pfsph/io.h"
#include "pfsph/render.h"
#include "pfsph/scene.h"
#include "testutil.h"

typedef tu_img img;

static const unsigned char *px(const img *m, int x, int y)
{
    assert_true(x >= 0 && y >= 0 && x < m->w && y < m->h);
    return m->rgb + 3 * ((size_t)y * m->w + x);
}

static int is_background_top(const unsigned char *p)
{
    /* The renderer's background at the top row: (0.945, 0.950, 0.965). */
    return abs(p[0] - 241) <= 2 && abs(p[1] - 242) <= 2 && abs(p[2] - 246) <= 2;
}

static int bluish(const unsigned char *p) { return p[2] > p[0] + 40; }

static void write_or_fail(const char *path, const pfsph_particles *ps, const pfsph_io_opts *o)
{
    pfsph_error err;
    if (pfsph_write_vtp(path, ps, o, &err) != PFSPH_OK) fail_msg("%s", err.msg);
}

static void block(pfsph_particles *ps, double x0, double y0, double z0, int nx, int ny, int nz, double dx,
                  uint8_t phase, double vx)
{
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                pfsph_real x[3] = {(pfsph_real)(x0 + i * dx), (pfsph_real)(y0 + j * dx), (pfsph_real)(z0 + k * dx)};
                pfsph_real v[3] = {(pfsph_real)(vx * i), 0, 0};
                long id = pfsph_particles_push(ps, x, v, phase);
                assert_true(id >= 0);
                ps->rho[id] = (pfsph_real)(1000 + j);
            }
}

static const char *make_run(const char *name, const char *scene_json)
{
    static char run[512];
    snprintf(run, sizeof run, "%s/%s", tu_tmpdir(), name);
    assert_int_equal(mkdir(run, 0755), 0);
    char p[600];
    snprintf(p, sizeof p, "%s/frames", run);
    assert_int_equal(mkdir(p, 0755), 0);
    snprintf(p, sizeof p, "%s/scene.json", run);
    assert_int_equal(tu_write_file(p, scene_json), 0);
    return run;
}

static const char SCENE_2D[] =
    "{\n"
    "  \"name\": \"render test 2d\", \"dimension\": 2, \"particle_radius\": 0.01,\n"
    "  \"gravity\": [0, -9.81],\n"
    "  \"domain\": {\"min\": [0, 0], \"max\": [1, 1]},\n"
    "  \"time\": {\"end\": 0.1, \"fps\": 10},\n"
    "  \"phases\": [\n"
    "    {\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3,\n"
    "     \"color\": [0.1, 0.3, 0.9]},\n"
    "    {\"name\": \"wall\", \"kind\": \"solid\"}\n"
    "  ],\n"
    "  \"fluid\": [{\"shape\": \"box\", \"min\": [0.1, 0.1], \"max\": [0.4, 0.4]}],\n"
    "  \"solids\": [{\"shape\": \"container\", \"min\": [0.02, 0.02], \"max\": [0.98, 0.98],\n"
    "              \"layers\": 1, \"phase\": \"wall\"}]\n"
    "}\n";

/* Output pixel of a world point for the 2D view: the domain [0,1]^2 fills 94 % of the shorter
 * image side, centred. */
static void to_px(int w, int h, double x, double y, int *ix, int *iy)
{
    double s = 0.94 * (w < h ? w : h);
    *ix = (int)(0.5 * w + (x - 0.5) * s);
    *iy = (int)(0.5 * h - (y - 0.5) * s);
}

static void test_render_2d(void **state)
{
    (void)state;
    const char *run = make_run("run2d", SCENE_2D);
    char p[700];
    pfsph_particles fl, bd, df;
    pfsph_io_opts o = {.dim = 2, .write_speed = true};
    /* Frame 0: a block in the lower left; frame 1: the block moved right; boundary only at
     * frame 0 (frame 1 must reuse it); diffuse particles at frame 1. */
    for (int f = 0; f < 2; f++) {
        assert_int_equal(pfsph_particles_init(&fl, 64), PFSPH_OK);
        block(&fl, 0.1 + 0.4 * f, 0.1, 0, 16, 16, 1, 0.02, 0, 0.1);
        o.time = 0.1 * f;
        snprintf(p, sizeof p, "%s/frames/fluid_%05d.vtp", run, f);
        write_or_fail(p, &fl, &o);
        pfsph_particles_free(&fl);
    }
    assert_int_equal(pfsph_particles_init(&bd, 64), PFSPH_OK);
    block(&bd, 0.02, 0.02, 0, 49, 1, 1, 0.02, 1, 0); /* floor */
    block(&bd, 0.02, 0.04, 0, 1, 48, 1, 0.02, 1, 0); /* left wall */
    block(&bd, 0.98, 0.04, 0, 1, 48, 1, 0.02, 1, 0); /* right wall */
    o.aux_name = "volume";
    snprintf(p, sizeof p, "%s/frames/boundary_00000.vtp", run);
    write_or_fail(p, &bd, &o);
    pfsph_particles_free(&bd);
    assert_int_equal(pfsph_particles_init(&df, 8), PFSPH_OK);
    block(&df, 0.7, 0.8, 0, 3, 1, 1, 0.05, 2, 0);
    o.aux_name = "lifetime";
    snprintf(p, sizeof p, "%s/frames/diffuse_00001.vtp", run);
    write_or_fail(p, &df, &o);
    pfsph_particles_free(&df);

    pfsph_render_opts ro = {.width = 320, .height = 180, .color_by = "phase", .last = -1, .quiet = true};
    pfsph_error err = {0};
    int count = -1;
    int rc = pfsph_render_run(run, &ro, &count, &err);
    if (rc) fail_msg("%s", err.msg);
    assert_int_equal(count, 2);
    for (int f = 0; f < 2; f++) {
        snprintf(p, sizeof p, "%s/png/frame_%05d.png", run, f);
        img m = tu_read_png(p);
        assert_int_equal(m.w, 320);
        assert_int_equal(m.h, 180);
        int ix, iy;
        /* A particle near the middle of the fluid block: water colour (blue). */
        to_px(m.w, m.h, 0.26 + 0.4 * f, 0.26, &ix, &iy);
        const unsigned char *c = px(&m, ix, iy);
        assert_false(is_background_top(c));
        assert_true(bluish(c));
        /* Where the block was in frame 0 is empty in frame 1. */
        to_px(m.w, m.h, 0.26, 0.26, &ix, &iy);
        if (f == 1) assert_false(bluish(px(&m, ix, iy)));
        /* Floor (from boundary_00000 in both frames): grey, not blue. */
        to_px(m.w, m.h, 0.8, 0.02, &ix, &iy);
        c = px(&m, ix, iy);
        assert_true(c[0] < 235 && abs(c[0] - c[2]) < 30);
        /* Corners are background. */
        assert_true(is_background_top(px(&m, 0, 0)));
        assert_true(is_background_top(px(&m, m.w - 1, 0)));
        free(m.rgb);
    }
    /* A frame range renders only that frame; colour by speed works. */
    ro.first = ro.last = 1;
    ro.color_by = "speed";
    assert_int_equal(pfsph_render_run(run, &ro, &count, &err), PFSPH_OK);
    assert_int_equal(count, 1);
    /* Unknown colouring is an input error. */
    ro.color_by = "temperature";
    assert_int_equal(pfsph_render_run(run, &ro, &count, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "temperature"));
}

static const char SCENE_3D[] =
    "{\n"
    "  \"name\": \"render test 3d\", \"dimension\": 3, \"particle_radius\": 0.02,\n"
    "  \"gravity\": [0, -9.81, 0],\n"
    "  \"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},\n"
    "  \"time\": {\"end\": 0.1, \"fps\": 10},\n"
    "  \"phases\": [{\"name\": \"water\", \"kind\": \"fluid\", \"color\": [0.1, 0.3, 0.9]}],\n"
    "  \"fluid\": [{\"shape\": \"box\", \"min\": [0.3, 0.3, 0.3], \"max\": [0.7, 0.7, 0.7]}]\n"
    "  %s\n"
    "}\n";

/* use_ply: the frame exists only as .ply (runs that write PLY alone render too). */
static void run_3d(const char *name, const char *camera, int use_ply)
{
    char json[2048];
    snprintf(json, sizeof json, SCENE_3D, camera);
    const char *run = make_run(name, json);
    pfsph_particles fl;
    assert_int_equal(pfsph_particles_init(&fl, 1000), PFSPH_OK);
    block(&fl, 0.32, 0.32, 0.32, 10, 10, 10, 0.04, 0, 0);
    char p[700];
    snprintf(p, sizeof p, "%s/frames/fluid_00000.%s", run, use_ply ? "ply" : "vtp");
    pfsph_io_opts o = {.dim = 3};
    pfsph_error werr;
    if ((use_ply ? pfsph_write_ply : pfsph_write_vtp)(p, &fl, &o, &werr)) fail_msg("%s", werr.msg);
    pfsph_particles_free(&fl);
    pfsph_render_opts ro = {.width = 200, .height = 150, .last = -1, .quiet = true};
    pfsph_error err = {0};
    int count = 0;
    if (pfsph_render_run(run, &ro, &count, &err)) fail_msg("%s", err.msg);
    assert_int_equal(count, 1);
    snprintf(p, sizeof p, "%s/png/frame_00000.png", run);
    img m = tu_read_png(p);
    assert_int_equal(m.w, 200);
    assert_int_equal(m.h, 150);
    /* Both cameras look at the centre of the cube of particles. */
    const unsigned char *c = px(&m, 100, 75);
    assert_true(bluish(c));
    assert_true(is_background_top(px(&m, 0, 0)));
    assert_true(is_background_top(px(&m, m.w - 1, 0)));
    /* Shading: the sphere surfaces are not one flat colour. */
    int lo = 255, hi = 0;
    for (int y = 50; y < 100; y++)
        for (int x = 75; x < 125; x++) {
            int b = px(&m, x, y)[2];
            lo = b < lo ? b : lo;
            hi = b > hi ? b : hi;
        }
    assert_true(hi - lo > 30);
    free(m.rgb);
}

/* A solid phase with a "color" draws its walls in that colour; without one they stay grey
 * (test_render_2d checks the grey floor). */
static void test_render_wall_color(void **state)
{
    (void)state;
    char scene[sizeof SCENE_2D + 64];
    const char *from = "{\"name\": \"wall\", \"kind\": \"solid\"}";
    const char *at = strstr(SCENE_2D, from);
    assert_non_null(at);
    snprintf(scene, sizeof scene, "%.*s{\"name\": \"wall\", \"kind\": \"solid\", \"color\": [0.9, 0.1, 0.1]}%s",
             (int)(at - SCENE_2D), SCENE_2D, at + strlen(from));
    const char *run = make_run("runwall", scene);
    char p[700];
    pfsph_particles bd;
    pfsph_io_opts o = {.dim = 2, .aux_name = "volume"};
    assert_int_equal(pfsph_particles_init(&bd, 64), PFSPH_OK);
    block(&bd, 0.02, 0.02, 0, 49, 1, 1, 0.02, 1, 0); /* floor, phase 1 = wall */
    snprintf(p, sizeof p, "%s/frames/boundary_00000.vtp", run);
    write_or_fail(p, &bd, &o);
    pfsph_particles fl;
    assert_int_equal(pfsph_particles_init(&fl, 64), PFSPH_OK);
    block(&fl, 0.1, 0.1, 0, 4, 4, 1, 0.02, 0, 0.1);
    o.aux_name = NULL;
    snprintf(p, sizeof p, "%s/frames/fluid_00000.vtp", run);
    write_or_fail(p, &fl, &o);
    pfsph_particles_free(&fl);
    pfsph_particles_free(&bd);
    pfsph_render_opts ro = {.width = 320, .height = 180, .color_by = "phase", .last = -1, .quiet = true};
    pfsph_error err = {0};
    int count = -1;
    if (pfsph_render_run(run, &ro, &count, &err)) fail_msg("%s", err.msg);
    snprintf(p, sizeof p, "%s/png/frame_00000.png", run);
    img m = tu_read_png(p);
    int ix, iy;
    to_px(m.w, m.h, 0.8, 0.02, &ix, &iy);
    const unsigned char *c = px(&m, ix, iy);
    assert_true(c[0] > c[1] + 60 && c[0] > c[2] + 60); /* red */
    free(m.rgb);
}

/* The key (issue 33 item 13): coloured by phase, a legend at the top left with a swatch of each
 * phase's colour (water, gas, the walls) and of each diffuse kind drawn, and their names; a
 * scale bar of 0.2 m at the bottom right, exactly as long as 0.2 m of the picture (2D); coloured
 * by speed, the colour bar's name and unit above it; --no-legend: none of it. The gas (near-white
 * grey) is drawn unlike the walls, which turn slate. */
static const char SCENE_KEY[] =
    "{\n"
    "  \"name\": \"render key 2d\", \"dimension\": 2, \"particle_radius\": 0.01,\n"
    "  \"gravity\": [0, -9.81],\n"
    "  \"domain\": {\"min\": [0, 0], \"max\": [1, 1]},\n"
    "  \"time\": {\"end\": 0.1, \"fps\": 10},\n"
    "  \"phases\": [\n"
    "    {\"name\": \"water\", \"kind\": \"fluid\", \"color\": [0.1, 0.3, 0.9]},\n"
    "    {\"name\": \"gas\", \"kind\": \"gas\", \"color\": [0.95, 0.95, 0.95]},\n"
    "    {\"name\": \"wall\", \"kind\": \"solid\"}\n"
    "  ],\n"
    "  \"fluid\": [{\"shape\": \"box\", \"min\": [0.1, 0.1], \"max\": [0.4, 0.4], \"phase\": \"water\"}],\n"
    "  \"solids\": [{\"shape\": \"container\", \"min\": [0.02, 0.02], \"max\": [0.98, 0.98],\n"
    "              \"layers\": 1, \"phase\": \"wall\"}]\n"
    "}\n";

static int near(const unsigned char *p, const uint8_t c[3])
{
    return abs(p[0] - c[0]) <= 1 && abs(p[1] - c[1]) <= 1 && abs(p[2] - c[2]) <= 1;
}

static const uint8_t INK[3] = {55, 58, 66};

/* Pixels of colour c in [x0, x1) x [y0, y1). */
static int count_in(const img *m, int x0, int y0, int x1, int y1, const uint8_t c[3])
{
    int n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) n += near(px(m, x, y), c);
    return n;
}

static void rgb8(const float f[3], uint8_t c[3])
{
    for (int k = 0; k < 3; k++) c[k] = (uint8_t)lrintf(f[k] * 255.0f);
}

static void test_render_key(void **state)
{
    (void)state;
    const char *run = make_run("runkey", SCENE_KEY);
    char p[700];
    pfsph_particles fl, bd, df;
    pfsph_io_opts o = {.dim = 2, .write_speed = true};
    assert_int_equal(pfsph_particles_init(&fl, 64), PFSPH_OK);
    block(&fl, 0.1, 0.1, 0, 16, 16, 1, 0.02, 0, 0.1); /* water */
    block(&fl, 0.6, 0.1, 0, 10, 10, 1, 0.02, 1, 0);   /* gas */
    snprintf(p, sizeof p, "%s/frames/fluid_00000.vtp", run);
    write_or_fail(p, &fl, &o);
    pfsph_particles_free(&fl);
    assert_int_equal(pfsph_particles_init(&bd, 64), PFSPH_OK);
    block(&bd, 0.02, 0.02, 0, 49, 1, 1, 0.02, 2, 0); /* floor */
    o.aux_name = "volume";
    snprintf(p, sizeof p, "%s/frames/boundary_00000.vtp", run);
    write_or_fail(p, &bd, &o);
    pfsph_particles_free(&bd);
    assert_int_equal(pfsph_particles_init(&df, 8), PFSPH_OK);
    for (uint8_t t = 0; t < 3; t++) block(&df, 0.7 + 0.05 * t, 0.8, 0, 1, 1, 1, 0.05, t, 0); /* spray, foam, bubble */
    o.aux_name = "lifetime";
    snprintf(p, sizeof p, "%s/frames/diffuse_00000.vtp", run);
    write_or_fail(p, &df, &o);
    pfsph_particles_free(&df);

    pfsph_scene *sc = malloc(sizeof *sc);
    pfsph_error err = {0};
    snprintf(p, sizeof p, "%s/scene.json", run);
    if (pfsph_scene_load(sc, p, &err)) fail_msg("%s", err.msg);
    float wf[3];
    assert_int_equal(pfsph_wall_color(sc, 2, wf), 1); /* not the plain grey: the gas is grey */
    uint8_t water[3], gas[3], wall[3];
    rgb8(sc->phases[0].color, water);
    rgb8(sc->phases[1].color, gas);
    rgb8(wf, wall);
    free(sc);
    uint8_t spray[3], foam[3], bubble[3];
    rgb8(PFSPH__DIFFUSE_COL[0], spray);
    rgb8(PFSPH__DIFFUSE_COL[1], foam);
    rgb8(PFSPH__DIFFUSE_COL[2], bubble);
    /* foam was a light grey that read as the walls' (issue 33): at least 0.3 in some channel
     * from the plain and the slate wall colours, the spray and the bubbles */
    const float grey[3] = {0.78f, 0.78f, 0.80f}, slate[3] = {0.46f, 0.48f, 0.53f};
    const float *other[4] = {grey, slate, PFSPH__DIFFUSE_COL[0], PFSPH__DIFFUSE_COL[2]};
    for (int j = 0; j < 4; j++) {
        float d = 0;
        for (int k = 0; k < 3; k++) d = fmaxf(d, fabsf(PFSPH__DIFFUSE_COL[1][k] - other[j][k]));
        assert_true(d >= 0.3f);
    }

    pfsph_render_opts ro = {.width = 320, .height = 180, .color_by = "phase", .last = -1, .quiet = true};
    int count = -1;
    if (pfsph_render_run(run, &ro, &count, &err)) fail_msg("%s", err.msg);
    snprintf(p, sizeof p, "%s/png/frame_00000.png", run);
    img m = tu_read_png(p);
    /* the legend, top left: a swatch of each colour and the names' letters */
    const uint8_t *sw[] = {water, gas, wall, spray, foam, bubble};
    for (int i = 0; i < 6; i++) assert_true(count_in(&m, 0, 0, 110, 110, sw[i]) >= 16);
    assert_true(count_in(&m, 0, 0, 110, 110, INK) > 100);
    /* the gas is not drawn like the walls */
    int gx, gy, wx, wy;
    to_px(m.w, m.h, 0.7, 0.2, &gx, &gy);
    to_px(m.w, m.h, 0.8, 0.02, &wx, &wy);
    const unsigned char *g = px(&m, gx, gy), *w = px(&m, wx, wy);
    assert_true(abs(g[0] - w[0]) + abs(g[1] - w[1]) + abs(g[2] - w[2]) > 120);
    /* the scale bar, bottom right: 0.2 m is 0.2 * 0.94 * 180 = 33.8 pixels */
    int longest = 0;
    for (int y = 150; y < 180; y++) {
        int run_len = 0;
        for (int x = 200; x < 320; x++) {
            run_len = near(px(&m, x, y), INK) ? run_len + 1 : 0;
            if (run_len > longest) longest = run_len;
        }
    }
    assert_true(abs(longest - 34) <= 1);
    free(m.rgb);

    /* by speed: the colour bar's name and unit above the bar */
    ro.color_by = "speed";
    if (pfsph_render_run(run, &ro, &count, &err)) fail_msg("%s", err.msg);
    m = tu_read_png(p);
    assert_true(count_in(&m, 200, 30, 320, 58, INK) > 60);
    free(m.rgb);
    /* --no-legend: no key */
    ro.no_legend = true;
    if (pfsph_render_run(run, &ro, &count, &err)) fail_msg("%s", err.msg);
    m = tu_read_png(p);
    assert_int_equal(count_in(&m, 200, 30, 320, 58, INK), 0);
    assert_int_equal(count_in(&m, 0, 0, 110, 110, INK), 0);
    assert_int_equal(count_in(&m, 200, 140, 320, 180, INK), 0);
    free(m.rgb);
}

static void test_render_3d_default_camera(void **state)
{
    (void)state;
    run_3d("run3d_auto", "", 0);
}

static void test_render_3d_scene_camera(void **state)
{
    (void)state;
    run_3d("run3d_cam",
           ", \"camera\": {\"eye\": [0.5, 1.5, 2.5], \"target\": [0.5, 0.5, 0.5], "
           "\"up\": [0, 1, 0], \"fov\": 35, \"width\": 64, \"height\": 64}",
           1);
}

static void test_render_errors(void **state)
{
    (void)state;
    pfsph_render_opts ro = {.last = -1, .quiet = true};
    pfsph_error err = {0};
    int count = 7;
    char run[512];
    snprintf(run, sizeof run, "%s/missing", tu_tmpdir());
    assert_int_not_equal(pfsph_render_run(run, &ro, &count, &err), PFSPH_OK);
    assert_int_equal(count, 0);
    assert_non_null(strstr(err.msg, "missing"));
    /* A run without frames. */
    const char *r = make_run("noframes", SCENE_2D);
    assert_int_equal(pfsph_render_run(r, &ro, &count, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "frames"));
    /* A corrupt frame is reported with its file name. */
    char p[700];
    snprintf(p, sizeof p, "%s/frames/fluid_00000.vtp", r);
    assert_int_equal(tu_write_file(p, "<VTKFile>garbage"), 0);
    assert_int_not_equal(pfsph_render_run(r, &ro, &count, &err), PFSPH_OK);
    assert_non_null(strstr(err.msg, "fluid_00000.vtp"));
}

static void test_render_video(void **state)
{
    (void)state;
    char out[256];
    if (tu_run("command -v ffmpeg", out, sizeof out) != 0) tu_skip("no ffmpeg");
    const char *run = make_run("video", SCENE_2D);
    char p[700];
    pfsph_io_opts o = {.dim = 2};
    for (int f = 0; f < 3; f++) {
        pfsph_particles fl;
        assert_int_equal(pfsph_particles_init(&fl, 64), PFSPH_OK);
        block(&fl, 0.1 + 0.1 * f, 0.1, 0, 8, 8, 1, 0.02, 0, 0);
        snprintf(p, sizeof p, "%s/frames/fluid_%05d.vtp", run, f);
        write_or_fail(p, &fl, &o);
        pfsph_particles_free(&fl);
    }
    pfsph_render_opts ro = {.width = 96, .height = 64, .video = true, .last = -1, .quiet = true};
    pfsph_error err = {0};
    int count = 0;
    if (pfsph_render_run(run, &ro, &count, &err)) fail_msg("%s", err.msg);
    assert_int_equal(count, 3);
    snprintf(p, sizeof p, "%s/frames.mp4", run);
    struct stat st;
    assert_int_equal(stat(p, &st), 0);
    assert_true(st.st_size > 100);
}

/* pf_wetting's five plates (uncoloured solid phases): the first stays grey, the other four get
 * colours of their own, all different (issue 33 item 13); a lone uncoloured solid stays grey */
static void test_wall_colors(void **state)
{
    (void)state;
    pfsph_scene *s = malloc(sizeof *s);
    pfsph_error err = {0};
    char path[1200];
    snprintf(path, sizeof path, "%s/scenes/pf_wetting.json", tu_source_dir());
    assert_int_equal(pfsph_scene_load(s, path, &err), 0);
    float c[6][3];
    int coloured = 0;
    for (int p = 1; p <= 5; p++) coloured += pfsph_wall_color(s, p, c[p]);
    assert_int_equal(coloured, 4);
    assert_true(c[1][0] == 0.78f && c[1][1] == 0.78f);
    for (int p = 2; p <= 5; p++)
        for (int q = 1; q < p; q++) assert_memory_not_equal(c[p], c[q], sizeof c[p]);
    assert_int_equal(pfsph_wall_color(s, 0, c[0]), 0); /* not a solid: plain grey, no legend */
    s->nphases = 2;                                    /* one uncoloured solid phase: grey */
    assert_int_equal(pfsph_wall_color(s, 1, c[1]), 0);
    free(s);
}

/* points on a box's surface (a wall set) or filling it (a fluid), spacing 0.02 */
static void fill_box(pfsph_particles *ps, const double lo[3], const double hi[3], int shell)
{
    for (double x = lo[0]; x <= hi[0] + 1e-9; x += 0.02)
        for (double y = lo[1]; y <= hi[1] + 1e-9; y += 0.02)
            for (double z = lo[2]; z <= hi[2] + 1e-9; z += 0.02) {
                const int edge = fabs(x - lo[0]) < 1e-9 || fabs(x - hi[0]) < 1e-9 || fabs(y - lo[1]) < 1e-9 ||
                    fabs(z - lo[2]) < 1e-9 || fabs(z - hi[2]) < 1e-9;
                if (shell && !edge) continue;
                const pfsph_real p[3] = {(pfsph_real)x, (pfsph_real)y, (pfsph_real)z}, v[3] = {0, 0, 0};
                assert_true(pfsph_particles_push(ps, p, v, 0) >= 0);
            }
}

/* The cut-away of the walls facing the camera: on for a tank the fluid stands in, off for
 * drops on a plate (it would take the plate away whole), and it hides the near wall of the
 * tank only */
static void test_cutaway(void **state)
{
    (void)state;
    pfsph_scene *s = calloc(1, sizeof *s);
    s->dim = 3;
    s->particle_radius = 0.01;
    s->gravity[1] = -9.81;
    pfsph_particles walls, fluid;
    assert_int_equal(pfsph_particles_init(&walls, 64), 0);
    assert_int_equal(pfsph_particles_init(&fluid, 64), 0);
    const double tlo[3] = {0, 0, 0}, thi[3] = {1, 0.5, 0.5}, flo[3] = {0.1, 0.04, 0.1}, fhi[3] = {0.4, 0.3, 0.4};
    fill_box(&walls, tlo, thi, 1); /* an open tank: floor and four sides */
    fill_box(&fluid, flo, fhi, 0);
    pfsph_cutaway cw;
    pfsph_cutaway_init(&cw, s, &walls, &fluid);
    assert_true(cw.on);
    const double eye[3] = {0.5, 1.5, 3.0}, near[3] = {0.5, 0.25, 0.5}, far[3] = {0.5, 0.25, 0.0};
    assert_true(pfsph_cutaway_hides(&cw, eye, near));
    assert_false(pfsph_cutaway_hides(&cw, eye, far));
    /* a plate with a drop on it */
    walls.n = fluid.n = 0;
    const double plo[3] = {0, 0, 0}, phi[3] = {0.6, 0.04, 0.6}, dlo[3] = {0.2, 0.06, 0.2}, dhi[3] = {0.4, 0.2, 0.4};
    fill_box(&walls, plo, phi, 0);
    fill_box(&fluid, dlo, dhi, 0);
    pfsph_cutaway_init(&cw, s, &walls, &fluid);
    assert_false(cw.on);
    const double top[3] = {0.3, 0.04, 0.6};
    assert_false(pfsph_cutaway_hides(&cw, eye, top));
    pfsph_particles_free(&walls);
    pfsph_particles_free(&fluid);
    free(s);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_render_2d),
        cmocka_unit_test(test_render_wall_color),
        cmocka_unit_test(test_render_key),
        cmocka_unit_test(test_wall_colors),
        cmocka_unit_test(test_cutaway),
        cmocka_unit_test(test_render_3d_default_camera),
        cmocka_unit_test(test_render_3d_scene_camera),
        cmocka_unit_test(test_render_errors),
        cmocka_unit_test(test_render_video),
    };
    return tu_run_group(tests, NULL, NULL);
}
