/* `pfsph view` under a display (xvfb-run in CI, CMakeLists.txt): a live 2D scene drawn for 20
 * frames covers the pixels its particles' positions predict; replaying a run shows the frame
 * the PNG renderer shows (2D and 3D, same camera, walls cut away or not; a run with a rigid
 * body and liquid meshes drawn as meshes, and the mesh toggle); live 3D draws the liquid as a
 * surface, M (pressed with --press) and --particles go back to particles, and a surface too
 * slow for its budget falls back to particles; the walls' layer re-used while nothing moves
 * is the layer drawn afresh, and drawn again when the walls shown change; bad input. Skipped in builds without the viewer
 * or without a display. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/io.h"
#include "pfsph/render.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "testutil.h"

/* A 2D tank, 25 x 25 particles of water released against the right wall; a 320 x 240 camera. */
static const char *SCENE2D =
    "{\"name\": \"viewer test 2D\", \"dimension\": 2, \"particle_radius\": 0.006,"
    " \"gravity\": [0, -9.81], \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.75, 0.55]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.16, \"fps\": 25, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3,"
    "   \"color\": [0.2, 0.4, 0.9]}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.3, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.7, 0.5], \"open_top\": true,"
    "   \"layers\": 2, \"phase\": \"wall\"}],"
    " \"output\": {\"formats\": [\"vtp\"], \"boundary\": true},"
    " \"camera\": {\"width\": 320, \"height\": 240, \"color_by\": \"speed\"}}";

/* A small 3D tank (perspective camera, translucent walls). */
static const char *SCENE3D =
    "{\"name\": \"viewer test 3D\", \"dimension\": 3, \"particle_radius\": 0.02,"
    " \"gravity\": [0, -9.81, 0], \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [0.7, 0.6, 0.5]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.08, \"fps\": 25, \"dt_max\": 0.004},"
    " \"phases\": [{\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3,"
    "   \"color\": [0.2, 0.4, 0.9]}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.2, 0.24, 0.2], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.6, 0.4, 0.4], \"open_top\": true,"
    "   \"layers\": 2, \"phase\": \"wall\"}],"
    " \"output\": {\"formats\": [\"vtp\"], \"boundary\": true},"
    " \"camera\": {\"width\": 320, \"height\": 240}}";

/* A 3D tank with a wooden crate (a rigid body) beside a water column, meshed while it runs
 * (output.surface) and with PLY output, so that the run has frames/liquid_NNNNN.ply and
 * frames/surfaces_NNNNN.ply: replay draws both meshes, as `pfsph render` does. */
static const char *SCENE3D_MESH =
    "{\"name\": \"viewer test 3D meshes\", \"dimension\": 3, \"particle_radius\": 0.01,"
    " \"gravity\": [0, -9.81, 0], \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [0.5, 0.5, 0.4]},"
    " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"end\": 0.08, \"fps\": 25},"
    " \"phases\": [{\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3,"
    "   \"color\": [0.2, 0.4, 0.9]}, {\"name\": \"wall\", \"kind\": \"solid\"},"
    "   {\"name\": \"wood\", \"kind\": \"solid\", \"rest_density\": 600, \"color\": [0.85, 0.55, 0.2]}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.16, 0.2, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.4, 0.3, 0.3], \"open_top\": true,"
    "   \"layers\": 2, \"phase\": \"wall\"}],"
    " \"bodies\": [{\"name\": \"crate\", \"shape\": \"box\", \"half_extents\": [0.05, 0.04, 0.05],"
    "   \"position\": [0.28, 0.1, 0.15], \"rotation\": [0, 30, 0], \"density\": 600, \"phase\": \"wood\"}],"
    " \"output\": {\"formats\": [\"vtp\", \"ply\"], \"boundary\": true, \"surface\": true},"
    " \"camera\": {\"width\": 320, \"height\": 240}}";

/* A ball of liquid (about 900 particles) at rest in zero gravity, no walls; orange, so that
 * the water shading of a surface (blue) tells it from the particles (the phase's colour). */
static const char *SCENE3D_DROP =
    "{\"name\": \"viewer test 3D drop\", \"dimension\": 3, \"particle_radius\": 0.005,"
    " \"gravity\": [0, 0, 0], \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [0.1, 0.1, 0.1]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 100, \"fps\": 30, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"juice\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3,"
    "   \"color\": [0.95, 0.5, 0.1]}],"
    " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 0.06, \"phase\": \"juice\"}],"
    " \"camera\": {\"width\": 320, \"height\": 240, \"eye\": [0.1, 0.08, 0.25], \"target\": [0, 0, 0]}}";

typedef tu_img img;

/* Both front ends draw the same background: light grey, darker towards the bottom. A pixel
 * more than 14/255 away from it in some channel shows a particle. */
static unsigned char *mask_of(const img *m)
{
    unsigned char *k = calloc((size_t)m->w * m->h, 1);
    const double top[3] = {0.945, 0.950, 0.965}, bot[3] = {0.840, 0.850, 0.875};
    for (int y = 0; y < m->h; y++) {
        double t = (y + 0.5) / m->h;
        for (int x = 0; x < m->w; x++) {
            const unsigned char *p = m->rgb + 3 * ((size_t)y * m->w + x);
            int on = 0;
            for (int c = 0; c < 3; c++) on |= fabs(p[c] - 255.0 * ((1 - t) * top[c] + t * bot[c])) > 14;
            k[(size_t)y * m->w + x] = (unsigned char)on;
        }
    }
    return k;
}

static double iou(const unsigned char *a, const unsigned char *b, size_t n, size_t *na, size_t *nb)
{
    size_t i_ = 0, u = 0;
    *na = *nb = 0;
    for (size_t i = 0; i < n; i++) {
        i_ += a[i] && b[i];
        u += a[i] || b[i];
        *na += a[i] != 0;
        *nb += b[i] != 0;
    }
    return u ? (double)i_ / u : 1.0;
}

static bool viewer_available(void)
{
#ifndef PFSPH_HAVE_VIEWER
    print_message("this build has no viewer (GLFW or libepoxy missing): skipped\n");
    return false;
#else
    if (!getenv("DISPLAY") || !*getenv("DISPLAY")) {
        print_message("no display (DISPLAY unset; xvfb-run not found at configure time): skipped\n");
        return false;
    }
    return true;
#endif
}

static void write_scene(const char *dir, const char *name, const char *text, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", dir, name);
    assert_int_equal(tu_write_file(path, text), 0);
}

/* Live 2D, 20 frames: the screenshot's particle pixels against discs of the drawn radius
 * (1.3 r, the renderer's 2D fluid radius) at the positions the viewer dumped for the frame it
 * drew, projected with the renderer's camera of the initial state. Walls hidden, overlay off,
 * coloured by phase (blue on grey). Measured IoU 0.97; the tolerance, 0.9, leaves room for
 * the edges: a pixel half covered counts on one side or the other. */
static void test_live_2d(void **state)
{
    (void)state;
    if (!viewer_available()) tu_skip("no viewer in this build, or no display");
    const char *dir = tu_tmpdir();
    char scene[600], cmd[2400], out[4096], shot[600], dump[600], p[700];
    write_scene(dir, "live2d.json", SCENE2D, scene, sizeof scene);
    snprintf(shot, sizeof shot, "%s/live.png", dir);
    snprintf(dump, sizeof dump, "%s/dump", dir);
    snprintf(cmd, sizeof cmd,
             "%s view %s --screenshot %s --frames 20 --dump %s --no-overlay --hide walls "
             "--color-by phase --threads 2 --particles",
             tu_pfsph_bin(), scene, shot, dump);
    int st = tu_run(cmd, out, sizeof out);
    print_message("%s", out);
    assert_int_equal(st, 0);
    img m = tu_read_png(shot);
    assert_int_equal(m.w, 320);
    assert_int_equal(m.h, 240);

    pfsph_error err = {0};
    pfsph_particles fl = {0};
    double t = 0;
    snprintf(p, sizeof p, "%s/fluid.vtp", dump);
    assert_int_equal(pfsph_read_vtp(p, &fl, &t, &err), PFSPH_OK);
    print_message("frame drawn: t = %.4f s, %zu fluid particles\n", t, fl.n);
    assert_true(t > 0); /* it did step */
    /* the camera: the renderer's for the initial particles */
    pfsph_scene *sc = malloc(sizeof *sc);
    assert_int_equal(pfsph_scene_load(sc, scene, &err), PFSPH_OK);
    pfsph_sim *sim = NULL;
    assert_int_equal(pfsph_sim_create(&sim, sc, &err), PFSPH_OK);
    pfsph_render_camera cam;
    pfsph_render_camera_for(sc, pfsph_sim_ctx(sim)->fluid, pfsph_sim_ctx(sim)->boundary, m.w, m.h, &cam);
    assert_true(cam.ortho);
    unsigned char *pred = calloc((size_t)m.w * m.h, 1);
    const double rad = 1.3 * sc->particle_radius * cam.f;
    for (size_t i = 0; i < fl.n; i++) {
        double sx = 0.5 * m.w + (fl.x[i] - cam.cx) * cam.f, sy = 0.5 * m.h - (fl.y[i] - cam.cy) * cam.f;
        for (int y = (int)floor(sy - rad); y <= (int)ceil(sy + rad); y++)
            for (int x = (int)floor(sx - rad); x <= (int)ceil(sx + rad); x++) {
                if (x < 0 || y < 0 || x >= m.w || y >= m.h) continue;
                double dx = x + 0.5 - sx, dy = y + 0.5 - sy;
                if (dx * dx + dy * dy <= rad * rad) pred[(size_t)y * m.w + x] = 1;
            }
    }
    unsigned char *got = mask_of(&m);
    size_t na, nb;
    double q = iou(got, pred, (size_t)m.w * m.h, &na, &nb);
    print_message("live 2D: %zu particle pixels drawn, %zu predicted, IoU %.4f (at least 0.9)\n", na, nb, q);
    assert_true(nb > 2000);
    assert_true(q >= 0.9);
    free(pred);
    free(got);
    free(m.rgb);
    pfsph_particles_free(&fl);
    pfsph_sim_destroy(sim);
    free(sc);
}

/* The run of a scene (once per name, reused by later comparisons). */
static void make_run(const char *scene_text, const char *name, char *run, size_t cap)
{
    const char *dir = tu_tmpdir();
    char scene[600], cmd[2400], out[4096], probe[700];
    snprintf(run, cap, "%s/run_%s", dir, name);
    snprintf(probe, sizeof probe, "%s/scene.json", run);
    FILE *f = fopen(probe, "r");
    if (f) {
        fclose(f);
        return;
    }
    write_scene(dir, name, scene_text, scene, sizeof scene);
    snprintf(cmd, sizeof cmd, "%s run %s -o %s --quiet --threads 2", tu_pfsph_bin(), scene, run);
    int st = tu_run(cmd, out, sizeof out);
    if (st) print_message("%s", out);
    assert_int_equal(st, 0);
}

/* The viewer's screenshot of frame `frame` (extra options `vargs`) into shot. */
static void view_shot(const char *run, int frame, const char *vargs, const char *shot)
{
    char cmd[2400], out[4096];
    snprintf(cmd, sizeof cmd, "%s view %s --frame %d --screenshot %s --frames 3 --no-overlay %s", tu_pfsph_bin(), run,
             frame, shot, vargs);
    int st = tu_run(cmd, out, sizeof out);
    print_message("%s", out);
    assert_int_equal(st, 0);
}

/* Coarse masks: 4 x 4 pixel blocks (a block is on when half its pixels are), the renderer's
 * caption rows left out. */
#define BLK 4
static unsigned char *block_mask(const img *m)
{
    unsigned char *k = mask_of(m);
    const int bw = m->w / BLK, bh = (m->h - 20) / BLK; /* the caption sits in the last 13 rows */
    unsigned char *c = calloc((size_t)bw * bh, 1);
    for (int y = 0; y < bh; y++)
        for (int x = 0; x < bw; x++) {
            int sum = 0;
            for (int v = 0; v < BLK; v++)
                for (int u = 0; u < BLK; u++) sum += k[(size_t)(y * BLK + v) * m->w + (size_t)(x * BLK + u)];
            c[(size_t)y * bw + x] = sum * 2 >= BLK * BLK;
        }
    free(k);
    return c;
}

/* Mean colour difference (fraction of full scale) over the pixels both images call particles,
 * above the caption. */
static double colour_diff(const img *a, const img *b, size_t *both)
{
    unsigned char *ma = mask_of(a), *mb = mask_of(b);
    double diff = 0;
    *both = 0;
    for (int y = 0; y < a->h - 20; y++)
        for (int x = 0; x < a->w; x++) {
            size_t o = (size_t)y * a->w + x;
            if (!ma[o] || !mb[o]) continue;
            for (int c = 0; c < 3; c++) diff += fabs((double)a->rgb[3 * o + c] - b->rgb[3 * o + c]) / 255.0 / 3;
            (*both)++;
        }
    free(ma);
    free(mb);
    return *both ? diff / *both : 1;
}

/* Replay of frame `frame` of a run against the renderer's PNG of it (render options rargs,
 * viewer options vargs). Coarse: the block masks' IoU, and the mean colour difference over
 * pixels both call particles. Measured: IoU 1.0 and a difference of 0.0006 (2D) and 0.0004
 * (3D) of full scale; asked: IoU >= 0.98 (a block or two of 1,000 to 2,300 may tip) and at
 * most 0.02 (5 levels of 255). */
static void compare_replay(const char *scene_text, const char *name, int frame, const char *rargs, const char *vargs,
                           double min_iou, double max_diff)
{
    char run[600], cmd[2400], out[4096], shot[700], ref[700];
    make_run(scene_text, name, run, sizeof run);
    snprintf(cmd, sizeof cmd, "%s render %s --no-legend %s", tu_pfsph_bin(), run, rargs);
    int st = tu_run(cmd, out, sizeof out);
    if (st) print_message("%s", out);
    assert_int_equal(st, 0);
    snprintf(shot, sizeof shot, "%s/replay.png", run);
    view_shot(run, frame, vargs, shot);
    snprintf(ref, sizeof ref, "%s/png/frame_%05d.png", run, frame);
    img a = tu_read_png(ref), b = tu_read_png(shot);
    assert_int_equal(a.w, b.w);
    assert_int_equal(a.h, b.h);
    unsigned char *ca = block_mask(&a), *cb = block_mask(&b);
    size_t na, nb, both;
    double q = iou(ca, cb, (size_t)(a.w / BLK) * ((a.h - 20) / BLK), &na, &nb);
    double diff = colour_diff(&a, &b, &both);
    print_message("%s frame %d [render %s / view %s]: %zu blocks (renderer) / %zu (viewer), IoU %.4f (at least %.2f); "
                  "mean colour difference %.4f (at most %.2f) over %zu pixels\n",
                  name, frame, rargs, vargs, na, nb, q, min_iou, diff, max_diff, both);
    assert_true(na > 100);
    assert_true(q >= min_iou);
    assert_true(diff <= max_diff);
    free(ca);
    free(cb);
    free(a.rgb);
    free(b.rgb);
}

static void test_replay_2d(void **state)
{
    (void)state;
    if (!viewer_available()) tu_skip("no viewer in this build, or no display");
    compare_replay(SCENE2D, "replay2d.json", 3, "", "", 0.98, 0.02);
}

/* 3D: with the walls facing the camera cut away (the default of both, the decision shared:
 * pfsph_cutaway_*), and with every wall. */
static void test_replay_3d(void **state)
{
    (void)state;
    if (!viewer_available()) tu_skip("no viewer in this build, or no display");
    compare_replay(SCENE3D, "replay3d.json", 2, "", "", 0.98, 0.02);
    compare_replay(SCENE3D, "replay3d.json", 2, "--all-walls", "--all-walls", 0.98, 0.02);
}

/* A run with a rigid body and liquid meshes: replay draws the liquid as water and the crate as
 * its mesh, as the renderer does (IoU and colour as above); with --particles (the M key's other
 * state) both draw particles again and still agree; and the toggle changes the picture: the
 * share of the scene's pixels whose colour moves by more than 40/255 in some channel. */
static void test_replay_meshes(void **state)
{
    (void)state;
    if (!viewer_available()) tu_skip("no viewer in this build, or no display");
    compare_replay(SCENE3D_MESH, "replay_mesh.json", 2, "", "", 0.98, 0.02);
    compare_replay(SCENE3D_MESH, "replay_mesh.json", 2, "--particles", "--particles", 0.98, 0.02);
    char run[600], s1[700], s2[700];
    make_run(SCENE3D_MESH, "replay_mesh.json", run, sizeof run);
    snprintf(s1, sizeof s1, "%s/surface.png", run);
    snprintf(s2, sizeof s2, "%s/particles.png", run);
    view_shot(run, 2, "", s1);
    view_shot(run, 2, "--particles", s2);
    img a = tu_read_png(s1), b = tu_read_png(s2);
    unsigned char *ma = mask_of(&a), *mb = mask_of(&b);
    size_t scene_px = 0, changed = 0;
    for (size_t o = 0; o < (size_t)a.w * a.h; o++) {
        if (!ma[o] && !mb[o]) continue;
        scene_px++;
        int ch = 0;
        for (int c = 0; c < 3; c++) ch |= abs((int)a.rgb[3 * o + c] - (int)b.rgb[3 * o + c]) > 40;
        changed += ch;
    }
    double share = (double)changed / (double)scene_px;
    print_message("mesh toggle: %zu of %zu scene pixels change (%.3f; at least 0.10)\n", changed, scene_px, share);
    assert_true(share >= 0.10);
    free(ma);
    free(mb);
    free(a.rgb);
    free(b.rgb);
}

/* Live 3D with extra options: screenshot into dir/name, stdout into out; the exit status. */
static int live_shot(const char *scene, const char *args, const char *name, char *shot, size_t cap, char *out,
                     size_t ocap)
{
    char cmd[2400];
    snprintf(shot, cap, "%s/%s", tu_tmpdir(), name);
    snprintf(cmd, sizeof cmd, "%s view %s --screenshot %s --no-overlay --threads 2 %s", tu_pfsph_bin(), scene, shot,
             args);
    int st = tu_run(cmd, out, ocap);
    print_message("%s", out);
    return st;
}

/* Of the scene's pixels (mask_of): the share drawn in the water shading's blue (blue above red
 * by 40/255; the particles are orange), and the mean luminance step between neighbouring scene
 * pixels, in 1/255 (the particles' sphere shading makes steps at every particle's rim). */
static void liquid_stats(const img *m, double *blue, double *rough, size_t *npx)
{
    unsigned char *k = mask_of(m);
    size_t n = 0, nb = 0, pairs = 0;
    double steps = 0;
    for (int y = 0; y < m->h; y++)
        for (int x = 0; x < m->w; x++) {
            size_t o = (size_t)y * m->w + x;
            if (!k[o]) continue;
            const unsigned char *p = m->rgb + 3 * o;
            n++;
            nb += p[2] > p[0] + 40;
            double l = 0.3 * p[0] + 0.59 * p[1] + 0.11 * p[2];
            if (x + 1 < m->w && k[o + 1]) {
                const unsigned char *q = p + 3;
                steps += fabs(l - (0.3 * q[0] + 0.59 * q[1] + 0.11 * q[2]));
                pairs++;
            }
            if (y + 1 < m->h && k[o + m->w]) {
                const unsigned char *q = p + 3 * (size_t)m->w;
                steps += fabs(l - (0.3 * q[0] + 0.59 * q[1] + 0.11 * q[2]));
                pairs++;
            }
        }
    *npx = n;
    *blue = n ? (double)nb / (double)n : 0;
    *rough = pairs ? steps / (double)pairs : 0;
    free(k);
}

/* Live 3D surface: by default the liquid is drawn as the reconstructed surface (the report
 * names its triangles; the scene's pixels are the water shading's blue, and smooth); with
 * --particles, and after M is pressed (--press M: through the key handler), particles (orange,
 * a sphere per particle: rough); a surface budget of 1 us cannot be met at any cell: after
 * three rebuilds at the coarsest the viewer falls back to particles and says so. */
static void test_live_surface(void **state)
{
    (void)state;
    if (!viewer_available()) tu_skip("no viewer in this build, or no display");
    char scene[600], shot[700], out[4096];
    write_scene(tu_tmpdir(), "drop3d.json", SCENE3D_DROP, scene, sizeof scene);
    const char *args[4] = {"--frames 3", "--frames 3 --particles", "--frames 3 --press M",
                           "--frames 10 --surface-budget 0.001"};
    const char *names[4] = {"surface.png", "particles.png", "toggled.png", "budget.png"};
    const bool surf[4] = {true, false, false, false};
    for (int k = 0; k < 4; k++) {
        assert_int_equal(live_shot(scene, args[k], names[k], shot, sizeof shot, out, sizeof out), 0);
        const char *rep = strstr(out, "surface: ");
        assert_non_null(rep);
        size_t ntris = 0;
        if (surf[k]) {
            assert_int_equal(sscanf(rep, "surface: %zu triangles", &ntris), 1);
            assert_true(ntris > 1000);
        } else {
            assert_non_null(strstr(rep, k == 3 ? "particles drawn (too slow" : "particles drawn (off"));
        }
        img m = tu_read_png(shot);
        double blue, rough;
        size_t npx;
        liquid_stats(&m, &blue, &rough, &npx);
        print_message("%s: %zu triangles, %zu liquid pixels, %.3f of them water blue, mean step %.2f / 255\n", names[k],
                      ntris, npx, blue, rough);
        assert_true(npx > 5000);
        if (surf[k]) {
            assert_true(blue > 0.9);
            assert_true(rough < 3.0);
        } else {
            assert_true(blue < 0.1);
            assert_true(rough > 4.0);
        }
        free(m.rgb);
    }
    /* 2D: the outline (a band of triangles) over the particles; the particles alone without it */
    char scene2[600], shot2[700];
    write_scene(tu_tmpdir(), "live2d_outline.json", SCENE2D, scene2, sizeof scene2);
    assert_int_equal(
        live_shot(scene2, "--frames 3 --paused --hide walls", "outline.png", shot, sizeof shot, out, sizeof out), 0);
    size_t ntris = 0;
    assert_non_null(strstr(out, "surface: "));
    assert_int_equal(sscanf(strstr(out, "surface: "), "surface: %zu triangles", &ntris), 1);
    assert_int_equal(live_shot(scene2, "--frames 3 --paused --hide walls --particles", "outline_off.png", shot2,
                               sizeof shot2, out, sizeof out),
                     0);
    img a = tu_read_png(shot), b = tu_read_png(shot2);
    unsigned char *ma = mask_of(&a), *mb = mask_of(&b);
    size_t px = 0, changed = 0;
    for (size_t o = 0; o < (size_t)a.w * a.h; o++) {
        if (!ma[o] && !mb[o]) continue;
        px++;
        int ch = 0;
        for (int c = 0; c < 3; c++) ch |= abs((int)a.rgb[3 * o + c] - (int)b.rgb[3 * o + c]) > 40;
        changed += ch;
    }
    print_message("2D outline: %zu triangles; %zu of %zu scene pixels change with it (at least 3 %%)\n", ntris, changed,
                  px);
    assert_true(ntris > 100);
    assert_true(changed > 0.03 * (double)px);
    free(ma);
    free(mb);
    free(a.rgb);
    free(b.rgb);
}

/* Pixels (of w x h) whose colour differs between two screenshots of the same size. */
static size_t pixels_differing(const img *a, const img *b)
{
    assert_int_equal(a->w, b->w);
    assert_int_equal(a->h, b->h);
    size_t n = 0;
    for (size_t o = 0; o < (size_t)a->w * a->h; o++) n += memcmp(a->rgb + 3 * o, b->rgb + 3 * o, 3) != 0;
    return n;
}

/* The walls' layer is drawn once and re-used while its sprites and the camera stay the same
 * (draw.c): a paused frame drawn after two re-uses is the first frame, pixel for pixel; and a
 * change of the walls drawn (X: the cut-away on or off, pressed after the first frame) draws
 * the layer again, so the second frame is the picture a viewer started in that state draws. */
static void test_wall_layer(void **state)
{
    (void)state;
    if (!viewer_available()) tu_skip("no viewer in this build, or no display");
    char scene[600], out[4096], shot[5][700];
    write_scene(tu_tmpdir(), "walls3d.json", SCENE3D, scene, sizeof scene);
    const char *args[5] = {"--all-walls --frames 1", "--all-walls --frames 3", "--frames 2 --press X", "--frames 1",
                           "--all-walls --frames 2 --press X"};
    char name[32];
    for (int k = 0; k < 5; k++) {
        char a[200];
        snprintf(a, sizeof a, "--paused --particles %s", args[k]);
        snprintf(name, sizeof name, "walls_%d.png", k);
        assert_int_equal(live_shot(scene, a, name, shot[k], sizeof shot[k], out, sizeof out), 0);
    }
    img m[5];
    for (int k = 0; k < 5; k++) m[k] = tu_read_png(shot[k]);
    size_t cut = pixels_differing(&m[0], &m[3]), reused = pixels_differing(&m[0], &m[1]),
           to_all = pixels_differing(&m[0], &m[2]), to_cut = pixels_differing(&m[3], &m[4]);
    print_message("walls' layer: the cut-away changes %zu pixels; re-used twice: %zu differ; X to all walls: %zu, "
                  "X to the cut-away: %zu (all required 0)\n",
                  cut, reused, to_all, to_cut);
    assert_true(cut > 1000); /* the comparisons below could not see a stale layer otherwise */
    assert_int_equal(reused, 0);
    assert_int_equal(to_all, 0);
    assert_int_equal(to_cut, 0);
    for (int k = 0; k < 5; k++) free(m[k].rgb);
}

/* Bad input: exit status 2 and a message naming the problem, before any window opens. */
static void test_bad_input(void **state)
{
    (void)state;
    char cmd[1400], out[4096];
    snprintf(cmd, sizeof cmd, "%s view /nonexistent/scene.json --screenshot /tmp/x.png", tu_pfsph_bin());
    int st = tu_run(cmd, out, sizeof out);
#ifndef PFSPH_HAVE_VIEWER
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "this build has no viewer"));
    return;
#endif
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "/nonexistent/scene.json"));
    snprintf(cmd, sizeof cmd, "%s view --color-by vorticity --screenshot /tmp/x.png", tu_pfsph_bin());
    assert_int_equal(tu_run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "vorticity"));
    snprintf(cmd, sizeof cmd, "%s view --frames 0", tu_pfsph_bin());
    assert_int_equal(tu_run(cmd, out, sizeof out), 2);
    snprintf(cmd, sizeof cmd, "%s view --surface-budget 0", tu_pfsph_bin());
    assert_int_equal(tu_run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "--surface-budget"));
    snprintf(cmd, sizeof cmd, "%s view --max-fps -5", tu_pfsph_bin());
    assert_int_equal(tu_run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "--max-fps"));
    snprintf(cmd, sizeof cmd, "%s view --hide water", tu_pfsph_bin());
    assert_int_equal(tu_run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "water"));
    snprintf(cmd, sizeof cmd, "%s view %s --frame 99999 --screenshot /tmp/x.png", tu_pfsph_bin(), tu_tmpdir());
    assert_int_equal(tu_run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "scene.json"));
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_input),  cmocka_unit_test(test_live_2d),       cmocka_unit_test(test_replay_2d),
        cmocka_unit_test(test_replay_3d),  cmocka_unit_test(test_replay_meshes), cmocka_unit_test(test_live_surface),
        cmocka_unit_test(test_wall_layer),
    };
    /* Drawing is what this program tests: without a viewer or a display only the bad-input
     * checks can run, and the program reads skipped once they pass. */
    if (!viewer_available()) {
        const struct CMUnitTest bad_input[] = {cmocka_unit_test(test_bad_input)};
        const int rc = tu_run_group(bad_input, NULL, NULL);
        if (rc == 0) print_message("the drawing tests did not run: exit status %d (skipped)\n", TU_SKIPPED);
        return rc ? rc : TU_SKIPPED;
    }
    return tu_run_group(tests, NULL, NULL);
}
