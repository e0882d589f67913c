/* Liquid surfaces in a run (issue 14): output.surface meshes while running, `pfsph mesh` gives
 * the same bytes afterwards with another thread count, the meshes are closed, the .pvd
 * collections list every frame, frame 0 carries densities, a 2D run gets closed VTP outlines
 * (the same bytes again from `pfsph mesh`), PLY for 2D and bad keys are refused with the JSON path, diffuse frames name their class "type" and carry no density or pressure. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/houdini.h"
#include "pfsph/io.h"
#include "testutil.h"

static const char *SCENE3 =
    "{\"dimension\": 3, \"particle_radius\": 0.01, \"gravity\": [0, -9.81, 0],\n"
    " \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [0.7, 0.6, 0.3]},\n"
    " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"end\": 0.1, \"fps\": 20},\n"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.2, 0.3, 0.2], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.6, 0.5, 0.2], \"open_top\": true,\n"
    "             \"phase\": \"wall\"}],\n"
    " \"output\": {\"formats\": [\"vtp\"], \"surface\": {\"formats\": [\"ply\", \"obj\", \"vtp\"]}}}\n";

static size_t count(const char *hay, const char *needle)
{
    size_t c = 0;
    for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle)) c++;
    return c;
}

static int u64cmp(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : (x > y);
}

/* the binary PLY mesh: every directed edge once, with its reverse: closed and oriented */
static void check_ply_closed(const char *path, size_t *faces)
{
    size_t len;
    unsigned char *b = tu_slurp(path, &len);
    assert_non_null(b);
    size_t nv = 0, nf = 0;
    const char *h = (const char *)b;
    assert_int_equal(sscanf(strstr(h, "element vertex"), "element vertex %zu", &nv), 1);
    assert_int_equal(sscanf(strstr(h, "element face"), "element face %zu", &nf), 1);
    const unsigned char *d = (const unsigned char *)strstr(h, "end_header\n") + 11;
    /* x y z nx ny nz vx vy vz: the liquid's velocity at the vertices since issue 33 */
    assert_non_null(strstr(h, "property float nz\nproperty float vx\nproperty float vy\nproperty float vz\n"));
    assert_int_equal((size_t)(d - b) + nv * 36 + nf * 14, len);
    d += nv * 36;
    uint64_t *e = malloc(3 * nf * sizeof *e);
    for (size_t t = 0; t < nf; t++, d += 14) {
        assert_int_equal(d[0], 3);
        uint32_t v[3];
        memcpy(v, d + 1, 12);
        for (int k = 0; k < 3; k++) {
            assert_true(v[k] < nv);
            e[3 * t + k] = ((uint64_t)v[k] << 32) | v[(k + 1) % 3];
        }
    }
    qsort(e, 3 * nf, sizeof *e, u64cmp);
    for (size_t i = 0; i < 3 * nf; i++) {
        if (i) assert_true(e[i] != e[i - 1]);
        uint64_t r = (e[i] << 32) | (e[i] >> 32);
        assert_non_null(bsearch(&r, e, 3 * nf, sizeof *e, u64cmp));
    }
    free(e);
    free(b);
    *faces = nf;
}

static void test_run_and_mesh(void **state)
{
    (void)state;
    char out[8192], path[1400], run[1200], scene[1200];
    snprintf(scene, sizeof scene, "%s/s3.json", tu_tmpdir());
    snprintf(run, sizeof run, "%s/run3", tu_tmpdir());
    assert_int_equal(tu_write_file(scene, SCENE3), 0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s' -o '%s' --threads 2 --quiet", scene, run), 0);
    /* the collections list every frame, in order */
    size_t len;
    snprintf(path, sizeof path, "%s/liquid.pvd", run);
    char *pvd = (char *)tu_slurp(path, &len);
    assert_non_null(pvd);
    assert_int_equal(count(pvd, "<DataSet "), 3);
    assert_non_null(strstr(pvd, "timestep=\"0.05\" group=\"\" part=\"0\" file=\"frames/liquid_00001.vtp\""));
    free(pvd);
    snprintf(path, sizeof path, "%s/fluid.pvd", run);
    pvd = (char *)tu_slurp(path, &len);
    assert_int_equal(count(pvd, "<DataSet "), 3);
    free(pvd);
    /* frame 0: densities of the summation, not zeros */
    pfsph_particles ps;
    pfsph_error err;
    snprintf(path, sizeof path, "%s/frames/fluid_00000.vtp", run);
    assert_int_equal(pfsph_read_vtp(path, &ps, NULL, &err), 0);
    double rmax = 0;
    for (size_t i = 0; i < ps.n; i++) rmax = ps.rho[i] > rmax ? ps.rho[i] : rmax;
    assert_true(rmax > 950 && rmax < 1050);
    pfsph_particles_free(&ps);
    size_t faces;
    snprintf(path, sizeof path, "%s/frames/liquid_00002.ply", run);
    check_ply_closed(path, &faces);
    assert_true(faces > 1000);
    /* meshing afterwards, on one thread: the same bytes */
    const char *ext[3] = {"ply", "obj", "vtp"};
    unsigned char *before[3];
    size_t blen[3];
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/frames/liquid_00001.%s", run, ext[k]);
        before[k] = tu_slurp(path, &blen[k]);
        assert_non_null(before[k]);
        remove(path);
    }
    assert_int_equal(tu_pfsph("", out, sizeof out, "mesh '%s' --threads 1 --formats ply,obj,vtp", run), 0);
    assert_non_null(strstr(out, "meshed 3 frames"));
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/frames/liquid_00001.%s", run, ext[k]);
        size_t l;
        unsigned char *after = tu_slurp(path, &l);
        assert_non_null(after);
        assert_int_equal(l, blen[k]);
        assert_memory_equal(after, before[k], l);
        free(after);
        free(before[k]);
    }
    assert_int_equal(tu_pfsph("", out, sizeof out, "mesh '%s' --formats ply,stl", run), 2);
    assert_non_null(strstr(out, "stl"));
    assert_int_equal(tu_pfsph("", out, sizeof out, "mesh '%s/none'", run), 2);
    /* Houdini's classic .geo: every frame, read back equal to the VTP frame (the JSON and
     * binary geometry: test_houdini_export) */
    assert_int_equal(tu_pfsph("", out, sizeof out, "export '%s' --houdini --classic", run), 0);
    assert_non_null(strstr(out, "exported 3 frames"));
    pfsph_particles a, b;
    snprintf(path, sizeof path, "%s/frames/fluid_00002.vtp", run);
    assert_int_equal(pfsph_read_vtp(path, &a, NULL, &err), 0);
    snprintf(path, sizeof path, "%s/frames/fluid_00002.geo", run);
    assert_int_equal(pfsph_read_houdini_geo(path, &b, NULL, &err), 0);
    assert_int_equal(a.n, b.n);
    for (int f = 0; f < PFSPH_F_AUX; f++) assert_memory_equal(a.f[f], b.f[f], a.n * sizeof(pfsph_real));
    assert_memory_equal(a.phase, b.phase, a.n);
    pfsph_particles_free(&a);
    pfsph_particles_free(&b);
}

/* the .geo writer and reader: every attribute exactly, ids and phases; bad files named by line */
static void test_houdini_roundtrip(void **state)
{
    (void)state;
    pfsph_particles ps, back;
    assert_int_equal(pfsph_particles_init(&ps, 8), 0);
    for (int i = 0; i < 5; i++) {
        pfsph_real x[3] = {(pfsph_real)(0.1 * i), (pfsph_real)(-1.0 / 3 * i), (pfsph_real)1e-7},
                   v[3] = {1, -2, (pfsph_real)0.3};
        long k = pfsph_particles_push(&ps, x, v, (uint8_t)(i * 50));
        ps.rho[k] = (pfsph_real)(1000 + i / 7.0);
        ps.p[k] = (pfsph_real)(i * 123.456);
        ps.id[k] = 4000000000u + (uint32_t)i;
    }
    char path[1400];
    pfsph_error err;
    snprintf(path, sizeof path, "%s/p.geo", tu_tmpdir());
    assert_int_equal(pfsph_write_houdini_geo(path, &ps, 0.5, &err), 0);
    assert_int_equal(pfsph_read_houdini_geo(path, &back, NULL, &err), 0);
    assert_int_equal(back.n, 5);
    for (int f = 0; f < PFSPH_F_AUX; f++) assert_memory_equal(ps.f[f], back.f[f], 5 * sizeof(pfsph_real));
    assert_memory_equal(ps.phase, back.phase, 5);
    assert_memory_equal(ps.id, back.id, 5 * sizeof(uint32_t));
    pfsph_particles_free(&back);
    size_t len;
    char *t = (char *)tu_slurp(path, &len);
    assert_non_null(strstr(t, "PGEOMETRY V5\nNPoints 5 NPrims 0\n"));
    assert_non_null(strstr(t, "PointAttrib\nv 3 vector 0 0 0\ndensity 1 float 0\n"));
    char *open = strstr(t, " 1 (");
    assert_non_null(open);
    open[3] = '[';
    assert_int_equal(tu_write_file(path, t), 0);
    assert_int_equal(pfsph_read_houdini_geo(path, &back, NULL, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, ":11: expected '('"));
    free(t);
    pfsph_particles_free(&ps);
}

/* pixels of the water shading (blue, dark red channel): none in the viridis or grey palettes */
static long water_pixels(const char *path)
{
    tu_img m = tu_read_png(path);
    long n = 0;
    for (size_t k = 0; k < (size_t)m.w * m.h; k++) n += m.rgb[3 * k] < 80 && m.rgb[3 * k + 2] > 150;
    free(m.rgb);
    return n;
}

/* pfsph render draws the liquid meshes as a water surface, and the particles with --particles */
static void test_render_meshes(void **state)
{
    (void)state;
    char out[8192], path[1400], run[1200];
    snprintf(run, sizeof run, "%s/run3", tu_tmpdir());
    snprintf(path, sizeof path, "%s/png/frame_00002.png", run);
    assert_int_equal(tu_pfsph("", out, sizeof out, "render '%s' --size 240x135 --color-by speed", run), 0);
    long mesh = water_pixels(path);
    assert_int_equal(tu_pfsph("", out, sizeof out, "render '%s' --size 240x135 --color-by speed --particles", run), 0);
    long parts = water_pixels(path);
    printf("water-coloured pixels: %ld with meshes, %ld with particles\n", mesh, parts);
    assert_true(mesh > 200);
    assert_int_equal(parts, 0);
}

static const char *SCENE2 =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, -9.81],\n"
    " \"domain\": {\"min\": [-0.1, -0.1], \"max\": [0.7, 0.6]}, \"time\": {\"end\": 0.1, \"fps\": 20},\n"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.2, 0.3], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.5], \"open_top\": true,\n"
    "             \"phase\": \"wall\"}],\n"
    " \"output\": {\"formats\": [\"vtp\"], \"surface\": true}}\n";

/* 2D: output.surface writes the outline as VTP polylines while running (closed: every point
 * starts one line and ends one), `pfsph mesh` gives the same bytes, liquid.pvd lists them, and
 * PLY or OBJ for a 2D run is refused */
static void test_contour_run(void **state)
{
    (void)state;
    char out[8192], path[1400], run[1200], scene[1200];
    snprintf(scene, sizeof scene, "%s/s2run.json", tu_tmpdir());
    snprintf(run, sizeof run, "%s/run2", tu_tmpdir());
    assert_int_equal(tu_write_file(scene, SCENE2), 0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s' -o '%s' --threads 2 --quiet", scene, run), 0);
    size_t len, len2;
    unsigned char *first[3];
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.vtp", run, k);
        first[k] = tu_slurp(path, &len);
        assert_non_null(first[k]);
        const char *t = (const char *)first[k];
        size_t np = 0, nl = 0;
        assert_int_equal(sscanf(strstr(t, "<Piece"), "<Piece NumberOfPoints=\"%zu\" NumberOfLines=\"%zu\"", &np, &nl),
                         2);
        printf("frame %d: %zu points, %zu lines\n", k, np, nl);
        assert_true(np > 50);
        assert_int_equal(np, nl);
        int *seen_from = calloc(np, sizeof *seen_from), *seen_to = calloc(np, sizeof *seen_to);
        const char *c = strstr(t, "Name=\"connectivity\"");
        c = strchr(c, '\n') + 1;
        for (size_t l = 0; l < nl; l++) {
            unsigned a, b;
            int used;
            assert_int_equal(sscanf(c, "%u %u%n", &a, &b, &used), 2);
            c += used;
            assert_true(a < np && b < np && a != b);
            seen_from[a]++;
            seen_to[b]++;
        }
        for (size_t i = 0; i < np; i++) {
            assert_int_equal(seen_from[i], 1);
            assert_int_equal(seen_to[i], 1);
        }
        free(seen_from);
        free(seen_to);
    }
    snprintf(path, sizeof path, "%s/liquid.pvd", run);
    char *pvd = (char *)tu_slurp(path, &len);
    assert_non_null(pvd);
    assert_int_equal(count(pvd, "<DataSet "), 3);
    free(pvd);
    assert_int_equal(tu_pfsph("", out, sizeof out, "mesh '%s' --threads 1", run), 0);
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.vtp", run, k);
        unsigned char *again = tu_slurp(path, &len2);
        assert_non_null(again);
        assert_int_equal(strlen((const char *)first[k]), len2);
        assert_memory_equal(first[k], again, len2);
        free(again);
        free(first[k]);
    }
    assert_int_equal(tu_pfsph("", out, sizeof out, "mesh '%s' --formats ply", run), 2);
    assert_non_null(strstr(out, "VTP"));
    /* a 2D run whose scene has no output.surface: `pfsph mesh` writes the outlines (it refused,
     * the scene's default formats being ply and vtp) */
    char text[2048], *at;
    snprintf(text, sizeof text, "%s", SCENE2);
    const char *cut = ", \"surface\": true";
    at = strstr(text, cut);
    assert_non_null(at);
    memmove(at, at + strlen(cut), strlen(at + strlen(cut)) + 1);
    assert_int_equal(tu_write_file(scene, text), 0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s' -o '%s' --force --quiet --end 0.05", scene, run), 0);
    snprintf(path, sizeof path, "%s/frames/liquid_00001.vtp", run);
    assert_null(fopen(path, "rb"));
    assert_int_equal(tu_pfsph("", out, sizeof out, "mesh '%s'", run), 0);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fclose(f);
}

static void test_refusals(void **state)
{
    (void)state;
    char out[8192], path[1400];
    /* PLY for a 2D scene's outline, a bad format: exit 2 with the JSON path */
    snprintf(path, sizeof path, "%s/s2.json", tu_tmpdir());
    assert_int_equal(
        tu_write_file(path,
                      "{\"dimension\": 2, \"particle_radius\": 0.01, \"domain\": {\"min\": [0, 0], \"max\": [1, 1]},\n"
                      " \"phases\": [{\"name\": \"water\"}], \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], "
                      "\"max\": [0.1, 0.1]}],\n"
                      " \"output\": {\"surface\": {\"formats\": [\"ply\"]}}}\n"),
        0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "check '%s'", path), 2);
    assert_non_null(strstr(out, "$.output.surface.formats"));
    assert_non_null(strstr(out, "VTP"));
    snprintf(path, sizeof path, "%s/s3bad.json", tu_tmpdir());
    char text[2048];
    snprintf(text, sizeof text, "%s", SCENE3);
    char *f = strstr(text, "\"obj\"");
    memcpy(f, "\"stl\"", 5);
    assert_int_equal(tu_write_file(path, text), 0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "check '%s'", path), 2);
    assert_non_null(strstr(out, "$.output.surface.formats[1]"));
}

/* diffuse frames: "type" instead of "phase", no density or pressure; read back into phase */
static void test_diffuse_type(void **state)
{
    (void)state;
    pfsph_particles ps, back;
    assert_int_equal(pfsph_particles_init(&ps, 4), 0);
    for (int i = 0; i < 3; i++) {
        pfsph_real x[3] = {(pfsph_real)i, 0, 0};
        assert_true(pfsph_particles_push(&ps, x, NULL, (uint8_t)i) >= 0);
    }
    pfsph_io_opts o = {.dim = 3, .aux_name = "lifetime", .diffuse = true};
    pfsph_error err;
    char path[1400];
    for (int fmt = 0; fmt < 2; fmt++) {
        snprintf(path, sizeof path, "%s/d.%s", tu_tmpdir(), fmt ? "ply" : "vtp");
        assert_int_equal((fmt ? pfsph_write_ply : pfsph_write_vtp)(path, &ps, &o, &err), 0);
        size_t len;
        char *t = (char *)tu_slurp(path, &len);
        assert_non_null(strstr(t, fmt ? "uchar type" : "Name=\"type\""));
        assert_null(strstr(t, "density"));
        assert_null(strstr(t, "pressure"));
        assert_null(strstr(t, "phase"));
        free(t);
        assert_int_equal((fmt ? pfsph_read_ply : pfsph_read_vtp)(path, &back, NULL, &err), 0);
        assert_int_equal(back.n, 3);
        for (int i = 0; i < 3; i++) assert_int_equal(back.phase[i], i);
        pfsph_particles_free(&back);
    }
    pfsph_particles_free(&ps);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_and_mesh), cmocka_unit_test(test_render_meshes),
        cmocka_unit_test(test_contour_run),  cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_diffuse_type), cmocka_unit_test(test_houdini_roundtrip),
    };
    return tu_run_group(tests, NULL, NULL);
}
