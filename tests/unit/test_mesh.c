/* Meshes (mesh.h): the OBJ reader on good, bad and odd inputs, closedness checks, exact mass
 * properties against closed forms, primitives, and the surface sampler's guarantees (largest
 * hole, smallest distance, count, determinism) measured by an independent nearest-point grid. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pfsph/mesh.h"
#include "testutil.h"

#if defined(__has_include)
#if __has_include(<valgrind/valgrind.h>)
#include <valgrind/valgrind.h>
#endif
#endif
#ifndef RUNNING_ON_VALGRIND
#define RUNNING_ON_VALGRIND 0
#endif

static const double PI = 3.14159265358979323846;

/* Under valgrind (about 100 times slower) the largest cases shrink so that CI's memcheck pass
 * stays short: spacings grow by this factor; the checks themselves are the same. */
static double vg_scale(void) { return RUNNING_ON_VALGRIND ? 2.0 : 1.0; }

static void load(pfsph_mesh *m, const char *name, int expect_rc, const char *expect_msg)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/tests/data/meshes/%s", tu_source_dir(), name);
    pfsph_error err = {0};
    int rc = pfsph_mesh_load_obj(m, path, &err);
    if (rc != expect_rc) fail_msg("%s: rc %d, expected %d (%s)", name, rc, expect_rc, err.msg);
    if (expect_msg && !strstr(err.msg, expect_msg)) fail_msg("%s: message '%s' lacks '%s'", name, err.msg, expect_msg);
    if (rc) {
        assert_null(m->v);
        assert_null(m->tri);
        assert_int_equal(m->nverts, 0);
        assert_int_equal(m->ntris, 0);
    }
}

/* parse a NUL-free string; expect rc and (on error) a message fragment */
static int parse_str(pfsph_mesh *m, const char *text, int expect_rc, const char *expect_msg)
{
    pfsph_error err = {0};
    int rc = pfsph_mesh_parse_obj(m, text, strlen(text), "s.obj", &err);
    if (rc != expect_rc) fail_msg("'%s': rc %d, expected %d (%s)", text, rc, expect_rc, err.msg);
    if (expect_msg && !strstr(err.msg, expect_msg))
        fail_msg("'%s': message '%s' lacks '%s'", text, err.msg, expect_msg);
    return rc;
}

static void validate(pfsph_mesh *m, const char *name, int expect_rc, const char *expect_msg)
{
    pfsph_error err = {0};
    int rc = pfsph_mesh_validate_closed(m, name, &err);
    if (rc != expect_rc) fail_msg("%s: validate rc %d, expected %d (%s)", name, rc, expect_rc, err.msg);
    if (expect_msg && !strstr(err.msg, expect_msg)) fail_msg("%s: message '%s' lacks '%s'", name, err.msg, expect_msg);
}

static double volume_of(const pfsph_mesh *m)
{
    double v, c[3], I[9];
    pfsph_mesh_mass_properties(m, &v, c, I);
    return v;
}

/* ---------------------------------------------------------------------------------------- */

static void test_obj_files(void **state)
{
    (void)state;
    struct {
        const char *name;
        size_t nv, nt;
        double vol, vol_tol;
    } good[] = {
        {"cube.obj", 8, 12, 1.0, 1e-14},
        {"lprism.obj", 12, 20, 1.5, 1e-14}, /* CRLF, negatives, no final newline */
        /* a 32 x 16 torus polyhedron: 2 pi^2 R r^2 times the two polygon-area factors */
        {"torus.obj", 512, 1024,
         2 * PI * PI * 1.0 * 0.35 * 0.35 * (sin(2 * PI / 32) / (2 * PI / 32)) * (sin(2 * PI / 16) / (2 * PI / 16)),
         0.01},
        {"icosphere.obj", 42, 80, 4.0 / 3.0 * PI, 0.2},
        {"tetra_inside_out.obj", 4, 4, 1.0 / 6.0, 1e-14},
    };
    for (size_t k = 0; k < sizeof good / sizeof good[0]; k++) {
        pfsph_mesh m;
        load(&m, good[k].name, PFSPH_OK, NULL);
        assert_int_equal(m.nverts, good[k].nv);
        assert_int_equal(m.ntris, good[k].nt);
        validate(&m, good[k].name, PFSPH_OK, NULL);
        double v = volume_of(&m);
        printf("%-22s %5zu vertices %5zu triangles volume %.6f (expected %.6f)\n", good[k].name, m.nverts, m.ntris, v,
               good[k].vol);
        assert_true(fabs(v - good[k].vol) <= good[k].vol_tol * good[k].vol);
        pfsph_mesh_free(&m);
    }
    /* read errors: line numbers and reasons */
    pfsph_mesh m;
    load(&m, "bad_malformed.obj", PFSPH_EINPUT, "bad_malformed.obj:4: expected 3 numbers after 'v'");
    load(&m, "bad_index.obj", PFSPH_EINPUT, "bad_index.obj:11: face index 12 out of range (8 vertices)");
    load(&m, "bad_empty.obj", PFSPH_EINPUT, "no faces");
    load(&m, "bad_nan.obj", PFSPH_EINPUT, "bad_nan.obj:3: vertex coordinate is not finite");
    load(&m, "no_such_file.obj", PFSPH_EINPUT, "no_such_file.obj: cannot open");
    /* validation errors name the triangle or edge (numbered from 1, as in the file) */
    load(&m, "bad_open.obj", PFSPH_OK, NULL);
    validate(&m, "bad_open.obj", PFSPH_EINPUT, "is open (used by triangle");
    pfsph_mesh_free(&m);
    load(&m, "bad_orient.obj", PFSPH_OK, NULL);
    validate(&m, "bad_orient.obj", PFSPH_EINPUT, "inconsistent orientation across edge");
    pfsph_mesh_free(&m);
    load(&m, "bad_degenerate.obj", PFSPH_OK, NULL);
    validate(&m, "bad_degenerate.obj", PFSPH_EINPUT, "triangle 13 (vertices 1 9 2) is degenerate");
    pfsph_mesh_free(&m);
    load(&m, "bad_nonmanifold.obj", PFSPH_OK, NULL);
    validate(&m, "bad_nonmanifold.obj", PFSPH_EINPUT, "edge 1-2 is non-manifold (shared by 4 triangles)");
    pfsph_mesh_free(&m);
    pfsph_mesh_free(&m); /* twice is fine */
}

static void test_obj_syntax(void **state)
{
    (void)state;
    pfsph_mesh m;
    const char *tet = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
    char buf[4096];

    /* fan triangulation of a pentagon, negative indices */
    parse_str(&m, "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf -5 -4 -3 -2 -1\n", PFSPH_OK, NULL);
    const uint32_t fan[9] = {0, 1, 2, 0, 2, 3, 0, 3, 4};
    assert_int_equal(m.ntris, 3);
    assert_memory_equal(m.tri, fan, sizeof fan);
    pfsph_mesh_free(&m);
    /* lone CR line ends, tabs, a missing final newline, w = 1 and vertex colours */
    parse_str(&m, "v 0 0 0 1\rv\t1 0 0 0.5 0.5 0.5\rv 0 1 0\rf 1 2 3", PFSPH_OK, NULL);
    assert_int_equal(m.nverts, 3);
    assert_true(m.v[3] == 1.0 && m.v[4] == 0.0);
    pfsph_mesh_free(&m);
    /* ignored statements and comments, including ones that look like bad vertices */
    snprintf(buf, sizeof buf, "%s# v 1 2\nvt 1\nvn x y z\nl 1 2\np 1\nusemtl a b c\nf 1 3 2\n", tet);
    parse_str(&m, buf, PFSPH_OK, NULL);
    assert_int_equal(m.ntris, 1);
    pfsph_mesh_free(&m);

    /* errors: each names line and reason, leaves the mesh empty */
    snprintf(buf, sizeof buf, "%sf 1 2 99999999999999999999999999\n", tet);
    parse_str(&m, buf, PFSPH_EINPUT, "s.obj:5: face index 99999999999999999999999999 out of range (4 vertices)");
    assert_null(m.v);
    snprintf(buf, sizeof buf, "%sf 1 2 0\n", tet);
    parse_str(&m, buf, PFSPH_EINPUT, "s.obj:5: face index 0 out of range");
    snprintf(buf, sizeof buf, "%sf -5 1 2\n", tet);
    parse_str(&m, buf, PFSPH_EINPUT, "face index -5 out of range (4 vertices)");
    parse_str(&m, "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", PFSPH_EINPUT,
              "s.obj:1: face index 1 out of range (0 vertices)");
    snprintf(buf, sizeof buf, "%sf 1 2\n", tet);
    parse_str(&m, buf, PFSPH_EINPUT, "s.obj:5: a face needs at least 3 vertices");
    snprintf(buf, sizeof buf, "%sf 1 2/x 3\n", tet);
    parse_str(&m, buf, PFSPH_EINPUT, "bad face vertex '2/x'");
    snprintf(buf, sizeof buf, "%sf 1 2// 3\n", tet);
    parse_str(&m, buf, PFSPH_EINPUT, "bad face vertex '2//'");
    snprintf(buf, sizeof buf, "%sf 1 2 3.0\n", tet);
    parse_str(&m, buf, PFSPH_EINPUT, "bad face vertex '3.0'");
    parse_str(&m, "v 1e400 0 0\n", PFSPH_EINPUT, "s.obj:1: vertex coordinate is not finite");
    parse_str(&m, "v inf 0 0\n", PFSPH_EINPUT, "not finite");
    parse_str(&m, "v 0 0 0 2\n", PFSPH_EINPUT, "weight");
    parse_str(&m, "v 0 0 0 1 1\n", PFSPH_EINPUT, "expected 3 numbers after 'v'");
    parse_str(&m, "v 0 0 0 1 1 1 1 1\n", PFSPH_EINPUT, "expected 3 numbers after 'v'");
    parse_str(&m, "\n\n   v 1 2 three\n", PFSPH_EINPUT, "s.obj:3: bad number 'three' after 'v'");
    parse_str(&m, "v 0x1p3 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3", PFSPH_OK, NULL); /* strtod forms */
    assert_true(m.v[0] == 8.0);
    pfsph_mesh_free(&m);
    parse_str(&m, "", PFSPH_EINPUT, "s.obj:0: no faces");
    parse_str(&m, tet, PFSPH_EINPUT, "s.obj:4: no faces");

    /* NUL bytes: inside a number they are an error, inside a comment they are ignored */
    pfsph_error err;
    static const char nul1[] = "v 0 0 0\nv 1\0 0 0\n";
    assert_int_equal(pfsph_mesh_parse_obj(&m, nul1, sizeof nul1 - 1, "n.obj", &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "n.obj:2: bad number '1?' after 'v'"));
    static const char nul2[] = "# \0\0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\0";
    assert_int_equal(pfsph_mesh_parse_obj(&m, nul2, sizeof nul2 - 1, "n.obj", &err), PFSPH_OK);
    assert_int_equal(m.ntris, 1);
    pfsph_mesh_free(&m);
    assert_int_equal(pfsph_mesh_parse_obj(&m, nul2, sizeof nul2 - 2, "n.obj", &err), PFSPH_OK);
    pfsph_mesh_free(&m);
    static const char nul3[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\0";
    assert_int_equal(pfsph_mesh_parse_obj(&m, nul3, sizeof nul3 - 1, "n.obj", &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "n.obj:4: bad face vertex '3?'"));
    /* len is honoured: the text need not be NUL-terminated */
    assert_int_equal(pfsph_mesh_parse_obj(&m, "v 1 2 3", 5, "n.obj", &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "expected 3 numbers"));

    /* a very long line (2 MB comment), a very long number and a 100000-gon */
    size_t big = 2u << 20;
    char *t = malloc(big + 256);
    assert_non_null(t);
    t[0] = '#';
    memset(t + 1, 'x', big);
    strcpy(t + big, "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_int_equal(pfsph_mesh_parse_obj(&m, t, strlen(t), "big.obj", &err), PFSPH_OK);
    pfsph_mesh_free(&m);
    strcpy(t, "v 1");
    memset(t + 3, '0', 200);
    strcpy(t + 203, " 0 0\n");
    assert_int_equal(pfsph_mesh_parse_obj(&m, t, strlen(t), "big.obj", &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "big.obj:1: bad number '1000"));
    size_t k = (size_t)snprintf(t, big, "%sf", tet);
    for (int i = 0; i < 100000; i++) k += (size_t)snprintf(t + k, big - k, " %d", 1 + i % 4);
    assert_int_equal(pfsph_mesh_parse_obj(&m, t, k, "big.obj", &err), PFSPH_OK);
    assert_int_equal(m.ntris, 99998);
    pfsph_mesh_free(&m);
    free(t);
}

static void test_validate(void **state)
{
    (void)state;
    pfsph_mesh m;
    /* inside-out tetrahedron: accepted and flipped */
    load(&m, "tetra_inside_out.obj", PFSPH_OK, NULL);
    assert_true(volume_of(&m) < 0);
    validate(&m, "t", PFSPH_OK, NULL);
    assert_true(fabs(volume_of(&m) - 1.0 / 6.0) < 1e-15);
    validate(&m, "t", PFSPH_OK, NULL); /* idempotent */
    assert_true(volume_of(&m) > 0);
    pfsph_mesh_free(&m);
    /* two triangles back to back: closed, consistent, but no volume */
    parse_str(&m, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", PFSPH_OK, NULL);
    validate(&m, "flat", PFSPH_EINPUT, "flat: mesh encloses zero volume");
    /* a hand-built mesh with an index out of range */
    m.tri[5] = 7;
    validate(&m, "hand", PFSPH_EINPUT, "hand: triangle 2 uses vertex 8, out of range (3 vertices)");
    pfsph_mesh_free(&m);
    pfsph_mesh empty = {0};
    validate(&empty, "empty", PFSPH_EINPUT, "no triangles");
    /* a thin but valid sliver box is not degenerate; a 1e-13 flat one is */
    double half[3] = {1, 1, 1e-5};
    assert_int_equal(pfsph_mesh_box(&m, half), PFSPH_OK);
    validate(&m, "thin", PFSPH_OK, NULL);
    pfsph_mesh_free(&m);
    half[2] = 1e-14;
    assert_int_equal(pfsph_mesh_box(&m, half), PFSPH_OK);
    validate(&m, "flatbox", PFSPH_EINPUT, "degenerate");
    pfsph_mesh_free(&m);
    /* O(n log n): a fine sphere (about 330000 triangles) validates quickly */
    assert_int_equal(pfsph_mesh_sphere(&m, 1.0, RUNNING_ON_VALGRIND ? 200 : 730), PFSPH_OK);
    clock_t c0 = clock();
    validate(&m, "sphere", PFSPH_OK, NULL);
    printf("validate: %zu triangles in %.3f s\n", m.ntris, (double)(clock() - c0) / CLOCKS_PER_SEC);
    pfsph_mesh_free(&m);
}

/* ---------------------------------------------------------------------------------------- */
/* Mass properties */

static void check_close(const char *what, double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol)) fail_msg("%s: %.15g, expected %.15g (tol %.3g)", what, got, want, tol);
}

static void test_mass_cube_tetra(void **state)
{
    (void)state;
    pfsph_mesh m;
    double v, c[3], I[9];
    load(&m, "cube.obj", PFSPH_OK, NULL);
    pfsph_mesh_mass_properties(&m, &v, c, I);
    check_close("cube V", v, 1.0, 1e-14);
    for (int a = 0; a < 3; a++) check_close("cube com", c[a], 0.5, 1e-14);
    for (int i = 0; i < 9; i++) check_close("cube I", I[i], i % 4 == 0 ? 1.0 / 6.0 : 0.0, 1e-14);
    pfsph_mesh_free(&m);

    /* a general tetrahedron against Tonon (2004): covariance about the origin
     * C = V/20 (sum x_i x_i^T + (sum x_i)(sum x_i)^T), I = tr(C) 1 - C, then shifted to the
     * centroid (parallel axes) */
    const double P[4][3] = {{0.3, -0.2, 1.1}, {2.1, 0.4, 0.9}, {0.7, 1.9, 0.2}, {1.0, 0.8, 2.5}};
    char txt[512];
    snprintf(txt, sizeof txt,
             "v %.17g %.17g %.17g\nv %.17g %.17g %.17g\nv %.17g %.17g %.17g\nv %.17g %.17g %.17g\n"
             "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n",
             P[0][0], P[0][1], P[0][2], P[1][0], P[1][1], P[1][2], P[2][0], P[2][1], P[2][2], P[3][0], P[3][1],
             P[3][2]);
    /* the faces above are in no particular order: validate must reject them (orientation) */
    parse_str(&m, txt, PFSPH_OK, NULL);
    validate(&m, "tet", PFSPH_EINPUT, "inconsistent orientation");
    pfsph_mesh_free(&m);
    /* consistently wound (outwards or inwards: validate settles it) */
    char *f = strstr(txt, "f 1 2 3");
    strcpy(f, "f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n");
    parse_str(&m, txt, PFSPH_OK, NULL);
    validate(&m, "tet", PFSPH_OK, NULL);
    pfsph_mesh_mass_properties(&m, &v, c, I);
    double e1[3], e2[3], e3[3], s[3] = {0, 0, 0}, C[9] = {0};
    for (int a = 0; a < 3; a++) {
        e1[a] = P[1][a] - P[0][a];
        e2[a] = P[2][a] - P[0][a];
        e3[a] = P[3][a] - P[0][a];
        for (int k = 0; k < 4; k++) s[a] += P[k][a];
    }
    double V = fabs(e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) - e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
                    e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) /
        6.0;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double sum = s[a] * s[b];
            for (int k = 0; k < 4; k++) sum += P[k][a] * P[k][b];
            C[3 * a + b] = V / 20.0 * sum - V * (s[a] / 4) * (s[b] / 4); /* about the centroid */
        }
    double tr = C[0] + C[4] + C[8];
    check_close("tet V", v, V, 1e-14 * V);
    for (int a = 0; a < 3; a++) check_close("tet com", c[a], s[a] / 4, 1e-14);
    for (int i = 0; i < 9; i++) check_close("tet I", I[i], (i % 4 == 0 ? tr : 0.0) - C[i], 1e-13 * tr);
    printf("tetrahedron: V %.15g (Tonon %.15g), Ixx %.15g (Tonon %.15g)\n", v, V, I[0], tr - C[0]);
    pfsph_mesh_free(&m);
}

/* R from an axis and angle (Rodrigues) */
static void rotation(const double axis[3], double ang, double R[9])
{
    double l = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    double x = axis[0] / l, y = axis[1] / l, z = axis[2] / l, c = cos(ang), s = sin(ang), t = 1 - c;
    double r[9] = {t * x * x + c,     t * x * y - s * z, t * x * z + s * y, t * x * y + s * z, t * y * y + c,
                   t * y * z - s * x, t * x * z - s * y, t * y * z + s * x, t * z * z + c};
    memcpy(R, r, sizeof r);
}

static void test_mass_box_transformed(void **state)
{
    (void)state;
    const double h[3] = {0.5, 1.0, 1.5};
    pfsph_mesh m, c2;
    assert_int_equal(pfsph_mesh_box(&m, h), PFSPH_OK);
    assert_int_equal(m.ntris, 12);
    double V0 = 8 * h[0] * h[1] * h[2];
    double I0[3] = {V0 / 3 * (h[1] * h[1] + h[2] * h[2]), V0 / 3 * (h[0] * h[0] + h[2] * h[2]),
                    V0 / 3 * (h[0] * h[0] + h[1] * h[1])};
    double R[9], t[3] = {100.25, -37.5, 12.0}, axis[3] = {1, 2, -0.5};
    rotation(axis, 0.7, R);
    /* scale 2 as well: V * 8, I * 32 */
    assert_int_equal(pfsph_mesh_copy(&c2, &m), PFSPH_OK);
    pfsph_mesh_transform(&c2, 2.0, R, t);
    validate(&c2, "box", PFSPH_OK, NULL);
    double v, c[3], I[9];
    pfsph_mesh_mass_properties(&c2, &v, c, I);
    check_close("box V", v, 8 * V0, 1e-12 * V0);
    for (int a = 0; a < 3; a++) check_close("box com", c[a], t[a], 1e-12);
    double maxerr = 0;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double want = 0; /* 32 R diag(I0) R^T */
            for (int k = 0; k < 3; k++) want += 32 * R[3 * a + k] * I0[k] * R[3 * b + k];
            maxerr = fmax(maxerr, fabs(I[3 * a + b] - want));
            check_close("box I", I[3 * a + b], want, 1e-11 * 32 * I0[0]);
        }
    printf("rotated box at distance 100: V error %.2g, I max error %.2g (of %.3g)\n", v - 8 * V0, maxerr, 32 * I0[2]);
    /* the original is untouched by transforming the copy */
    pfsph_mesh_mass_properties(&m, &v, c, I);
    check_close("orig V", v, V0, 1e-14);
    check_close("orig Ixx", I[0], I0[0], 1e-14);
    /* a mirror (s = -1) keeps the surface facing out */
    pfsph_mesh_transform(&m, -1.0, NULL, NULL);
    check_close("mirrored V", volume_of(&m), V0, 1e-14);
    pfsph_mesh_free(&m);
    pfsph_mesh_free(&c2);
}

/* Polyhedral spheres converge to V = 4/3 pi r^3 and I = 8/15 pi r^5 from below at second
 * order: the error shrinks by about 4 each time the segments double. */
static void test_mass_sphere(void **state)
{
    (void)state;
    const double r = 0.8, Va = 4.0 / 3.0 * PI * r * r * r, Ia = 8.0 / 15.0 * PI * pow(r, 5);
    double prev_ev = 0;
    for (int seg = 16; seg <= 128; seg *= 2) {
        pfsph_mesh m;
        assert_int_equal(pfsph_mesh_sphere(&m, r, seg), PFSPH_OK);
        uint32_t *before = malloc(3 * m.ntris * sizeof(uint32_t));
        assert_non_null(before);
        memcpy(before, m.tri, 3 * m.ntris * sizeof(uint32_t));
        validate(&m, "sphere", PFSPH_OK, NULL);
        assert_memory_equal(before, m.tri, 3 * m.ntris * sizeof(uint32_t)); /* already outward */
        free(before);
        double v, c[3], I[9];
        pfsph_mesh_mass_properties(&m, &v, c, I);
        double ev = (Va - v) / Va, eI = 0;
        for (int a = 0; a < 3; a++) eI = fmax(eI, fabs(I[4 * a] - Ia) / Ia);
        /* tolerance: the inscribed polyhedron's deficit is below 2 (2 pi / segments)^2 / 3 */
        double tol = 2.0 / 3.0 * (2 * PI / seg) * (2 * PI / seg);
        printf("sphere segments %3d: %6zu triangles, V rel error %.2e, I rel error %.2e (tol %.2e)\n", seg, m.ntris, ev,
               eI, tol);
        assert_true(ev > 0 && ev < tol);
        assert_true(eI < tol * 5.0 / 3.0); /* I ~ r^5: 5/3 of the volume's relative deficit */
        for (int a = 0; a < 3; a++) check_close("sphere com", c[a], 0, 1e-12);
        for (int i = 0; i < 9; i++)
            if (i % 4) check_close("sphere Ixy", I[i], 0, 1e-3 * Ia * tol);
        if (prev_ev > 0) assert_true(ev < 0.4 * prev_ev); /* second order */
        prev_ev = ev;
        pfsph_mesh_free(&m);
    }
}

/* A cylinder mesh is a regular n-gon prism: its volume and inertia have exact closed forms
 * (polygon area n/2 R^2 sin(2 pi/n), polar moment A R^2 (1 + 2 cos^2(pi/n)) / 6), and both
 * converge to the round cylinder's. */
static void test_mass_cylinder(void **state)
{
    (void)state;
    const double R = 0.3, H = 1.7;
    for (int axis = 0; axis < 3; axis++)
        for (int n = 8; n <= 64; n *= 8) {
            pfsph_mesh m;
            assert_int_equal(pfsph_mesh_cylinder(&m, R, H, axis, n), PFSPH_OK);
            validate(&m, "cyl", PFSPH_OK, NULL);
            double v, c[3], I[9];
            pfsph_mesh_mass_properties(&m, &v, c, I);
            double A = 0.5 * n * R * R * sin(2 * PI / n), V = A * H;
            double J = A * R * R * (1 + 2 * pow(cos(PI / n), 2)) / 6.0;
            double Iax = H * J, Itr = H * J / 2 + V * H * H / 12;
            check_close("prism V", v, V, 1e-13);
            for (int a = 0; a < 3; a++) {
                check_close("prism com", c[a], 0, 1e-13);
                check_close("prism I", I[4 * a], a == axis ? Iax : Itr, 1e-13);
                for (int b = 0; b < 3; b++)
                    if (a != b) check_close("prism Ixy", I[3 * a + b], 0, 1e-13);
            }
            /* against the round cylinder: relative error within (2 pi / n)^2 / 6 for the volume
             * (polygon area deficit) and twice that for the moments */
            double Vc = PI * R * R * H, Iaxc = Vc * R * R / 2, Itrc = Vc * (3 * R * R + H * H) / 12;
            double tol = pow(2 * PI / n, 2) / 6;
            double ev = fabs(v - Vc) / Vc, ea = fabs(I[4 * axis] - Iaxc) / Iaxc,
                   et = fabs(I[4 * ((axis + 1) % 3)] - Itrc) / Itrc;
            if (axis == 0)
                printf("cylinder n=%2d: rel errors vs round: V %.2e, I_axis %.2e, I_trans %.2e "
                       "(tol %.2e)\n",
                       n, ev, ea, et, tol);
            assert_true(ev < tol && ea < 2 * tol && et < 2 * tol);
            pfsph_mesh_free(&m);
        }
    /* bad arguments */
    pfsph_mesh m;
    double bad[3] = {1, -1, 1};
    assert_int_equal(pfsph_mesh_cylinder(&m, R, H, 3, 16), PFSPH_EINPUT);
    assert_int_equal(pfsph_mesh_cylinder(&m, -R, H, 0, 16), PFSPH_EINPUT);
    assert_int_equal(pfsph_mesh_cylinder(&m, R, H, 0, 2), PFSPH_EINPUT);
    assert_int_equal(pfsph_mesh_sphere(&m, NAN, 16), PFSPH_EINPUT);
    assert_int_equal(pfsph_mesh_box(&m, bad), PFSPH_EINPUT);
    assert_null(m.v);
    pfsph_mesh_free(&m);
}

static void test_copy_free(void **state)
{
    (void)state;
    pfsph_mesh z = {0}, a, b;
    pfsph_mesh_free(&z);
    pfsph_mesh_free(&z);
    pfsph_mesh_free(NULL);
    assert_int_equal(pfsph_mesh_sphere(&a, 1.0, 20), PFSPH_OK);
    assert_int_equal(pfsph_mesh_copy(&b, &a), PFSPH_OK);
    assert_int_equal(a.nverts, b.nverts);
    assert_int_equal(a.ntris, b.ntris);
    assert_true(a.v != b.v && a.tri != b.tri);
    assert_memory_equal(a.v, b.v, 3 * a.nverts * sizeof(double));
    assert_memory_equal(a.tri, b.tri, 3 * a.ntris * sizeof(uint32_t));
    pfsph_mesh_free(&a);
    assert_null(a.v);
    assert_null(a.tri);
    pfsph_mesh_free(&a);
    validate(&b, "copy", PFSPH_OK, NULL); /* still valid after the source is gone */
    double v;
    pfsph_mesh_mass_properties(&b, &v, NULL, NULL); /* any output may be NULL */
    assert_true(v > 4.0 && v < 4.0 / 3.0 * PI);
    pfsph_mesh_free(&b);
    /* copying an empty mesh gives an empty mesh, not an allocation failure */
    assert_int_equal(pfsph_mesh_copy(&b, &z), PFSPH_OK);
    assert_int_equal(b.nverts, 0);
    assert_int_equal(b.ntris, 0);
    pfsph_mesh_mass_properties(&b, &v, NULL, NULL);
    assert_true(v == 0);
    pfsph_mesh_free(&b);
}

/* ---------------------------------------------------------------------------------------- */
/* Sampling, measured with a uniform grid of cell = spacing (any pair or gap that matters is
 * within the 27 neighbouring cells). */

typedef struct {
    double lo[3], cell;
    int nc[3];
    size_t *start, *idx;
    const double *p;
} tgrid;

static int tcell(const tgrid *g, const double *p, int a)
{
    int c = (int)floor((p[a] - g->lo[a]) / g->cell);
    return c < 0 ? 0 : c >= g->nc[a] ? g->nc[a] - 1 : c;
}

static void tgrid_build(tgrid *g, const double *p, size_t n, double cell)
{
    double hi[3];
    for (int a = 0; a < 3; a++) {
        g->lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            g->lo[a] = fmin(g->lo[a], p[3 * i + a]);
            hi[a] = fmax(hi[a], p[3 * i + a]);
        }
    g->cell = cell;
    g->p = p;
    size_t total = 1;
    for (int a = 0; a < 3; a++) {
        g->lo[a] -= cell;
        g->nc[a] = (int)((hi[a] - g->lo[a]) / cell) + 2;
        total *= (size_t)g->nc[a];
    }
    g->start = calloc(total + 1, sizeof(size_t));
    g->idx = malloc(n * sizeof(size_t));
    assert_non_null(g->start);
    assert_non_null(g->idx);
    size_t *cid = malloc(n * sizeof(size_t));
    assert_non_null(cid);
    for (size_t i = 0; i < n; i++) {
        const double *q = p + 3 * i;
        cid[i] = ((size_t)tcell(g, q, 2) * (size_t)g->nc[1] + (size_t)tcell(g, q, 1)) * (size_t)g->nc[0] +
            (size_t)tcell(g, q, 0);
        g->start[cid[i] + 1]++;
    }
    for (size_t c = 0; c < total; c++) g->start[c + 1] += g->start[c];
    size_t *fill = calloc(total, sizeof(size_t));
    assert_non_null(fill);
    for (size_t i = 0; i < n; i++) g->idx[g->start[cid[i]] + fill[cid[i]]++] = i;
    free(fill);
    free(cid);
}

/* distance from q to the nearest point (skipping index `self`), capped at the cell size */
static double tgrid_nearest(const tgrid *g, const double *q, size_t self)
{
    double best = g->cell * g->cell;
    int c[3] = {tcell(g, q, 0), tcell(g, q, 1), tcell(g, q, 2)};
    for (int z = c[2] - 1; z <= c[2] + 1; z++)
        for (int y = c[1] - 1; y <= c[1] + 1; y++)
            for (int x = c[0] - 1; x <= c[0] + 1; x++) {
                if (x < 0 || y < 0 || z < 0 || x >= g->nc[0] || y >= g->nc[1] || z >= g->nc[2]) continue;
                size_t cc = ((size_t)z * (size_t)g->nc[1] + (size_t)y) * (size_t)g->nc[0] + (size_t)x;
                for (size_t k = g->start[cc]; k < g->start[cc + 1]; k++) {
                    size_t j = g->idx[k];
                    if (j == self) continue;
                    const double *o = g->p + 3 * j;
                    double d2 =
                        (o[0] - q[0]) * (o[0] - q[0]) + (o[1] - q[1]) * (o[1] - q[1]) + (o[2] - q[2]) * (o[2] - q[2]);
                    if (d2 < best) best = d2;
                }
            }
    return sqrt(best);
}

static uint64_t lcg;
static double uni(void)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg >> 11) * (1.0 / 9007199254740992.0);
}

static double tri_area(const pfsph_mesh *m, size_t t)
{
    const double *a = m->v + 3 * m->tri[3 * t], *b = m->v + 3 * m->tri[3 * t + 1], *c = m->v + 3 * m->tri[3 * t + 2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x = u[1] * w[2] - u[2] * w[1], y = u[2] * w[0] - u[0] * w[2], z = u[0] * w[1] - u[1] * w[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

typedef struct {
    double max_gap, min_dist, ratio;
    size_t n;
} sample_stats;

/* Sample, then measure: largest distance from a surface point to the nearest sample (random
 * points by area, plus every triangle's corners, edge midpoints and centroid), smallest
 * distance between two samples, count against a hexagonal packing A / (s^2 sqrt(3)/2). */
static sample_stats check_sampling(const pfsph_mesh *m, double s, const char *name, int check_count)
{
    double *p = NULL;
    size_t n = 0;
    pfsph_error err;
    clock_t c0 = clock();
    int rc = pfsph_mesh_sample_surface(m, s, &p, &n, &err);
    double secs = (double)(clock() - c0) / CLOCKS_PER_SEC;
    if (rc) fail_msg("%s: %s", name, err.msg);
    /* deterministic: a second call gives the same bytes */
    double *p2 = NULL;
    size_t n2 = 0;
    assert_int_equal(pfsph_mesh_sample_surface(m, s, &p2, &n2, &err), PFSPH_OK);
    assert_int_equal(n, n2);
    assert_memory_equal(p, p2, 3 * n * sizeof(double));
    free(p2);

    tgrid g;
    tgrid_build(&g, p, n, s);
    sample_stats st = {0, INFINITY, 0, n};
    for (size_t i = 0; i < n; i++) st.min_dist = fmin(st.min_dist, tgrid_nearest(&g, p + 3 * i, i));
    double area = 0, *cum = malloc(m->ntris * sizeof(double));
    assert_non_null(cum);
    for (size_t t = 0; t < m->ntris; t++) cum[t] = area += tri_area(m, t);
    lcg = 12345;
    const int nrand = 30000;
    for (int k = 0; k < nrand + (int)m->ntris * 7; k++) {
        size_t t;
        double b1, b2;
        if (k < nrand) { /* uniform by area */
            double x = uni() * area;
            size_t lo = 0, hi = m->ntris - 1;
            while (lo < hi) {
                size_t mid = (lo + hi) / 2;
                if (cum[mid] < x) lo = mid + 1;
                else hi = mid;
            }
            t = lo;
            b1 = uni();
            b2 = uni();
            if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
        } else { /* corners, edge midpoints, centroid of every triangle */
            static const double bb[7][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}, {1.0 / 3, 1.0 / 3}};
            t = (size_t)(k - nrand) / 7;
            b1 = bb[(k - nrand) % 7][0];
            b2 = bb[(k - nrand) % 7][1];
        }
        const double *A = m->v + 3 * m->tri[3 * t], *B = m->v + 3 * m->tri[3 * t + 1],
                     *C = m->v + 3 * m->tri[3 * t + 2];
        double q[3];
        for (int a = 0; a < 3; a++) q[a] = A[a] + b1 * (B[a] - A[a]) + b2 * (C[a] - A[a]);
        st.max_gap = fmax(st.max_gap, tgrid_nearest(&g, q, SIZE_MAX));
    }
    st.ratio = (double)n / (area / (s * s * sqrt(3.0) / 2));
    printf("%-12s s=%.3g: %6zu samples (%.2f x hex count A/(s^2 sqrt3/2) = %.0f), max gap %.3f s, "
           "min distance %.3f s, %.3f s\n",
           name, s, n, st.ratio, area / (s * s * sqrt(3.0) / 2), st.max_gap / s, st.min_dist / s, secs);
    if (!(st.max_gap <= 0.75 * s)) fail_msg("%s: hole of %.3f s", name, st.max_gap / s);
    if (!(st.min_dist >= 0.5 * s)) fail_msg("%s: samples %.3f s apart", name, st.min_dist / s);
    if (check_count && !(st.ratio > 0.7 && st.ratio < 1.3))
        fail_msg("%s: %zu samples, %.2f x the hexagonal count", name, n, st.ratio);
    free(cum);
    free(g.start);
    free(g.idx);
    free(p);
    return st;
}

static void test_sample_files(void **state)
{
    (void)state;
    struct {
        const char *name;
        double s;
        int count;
    } cases[] = {
        {"cube.obj", 0.05, 1},   {"cube.obj", 0.3, 0},   {"icosphere.obj", 0.05, 1}, {"icosphere.obj", 0.4, 0},
        {"lprism.obj", 0.04, 1}, {"lprism.obj", 0.2, 0}, {"torus.obj", 0.04, 1},     {"torus.obj", 0.15, 0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        pfsph_mesh m;
        load(&m, cases[k].name, PFSPH_OK, NULL);
        validate(&m, cases[k].name, PFSPH_OK, NULL);
        /* the coarse cases (count not checked) keep their spacing */
        check_sampling(&m, cases[k].s * (cases[k].count ? vg_scale() : 1.0), cases[k].name, cases[k].count);
        pfsph_mesh_free(&m);
    }
}

static void test_sample_primitives(void **state)
{
    (void)state;
    pfsph_mesh m;
    /* a fine sphere (triangles smaller than the spacing) and a coarse one (larger) */
    assert_int_equal(pfsph_mesh_sphere(&m, 1.0, 128), PFSPH_OK);
    check_sampling(&m, 0.06 * vg_scale(), "sphere128", 1);
    pfsph_mesh_free(&m);
    assert_int_equal(pfsph_mesh_sphere(&m, 1.0, 12), PFSPH_OK);
    check_sampling(&m, 0.06 * vg_scale(), "sphere12", 1);
    pfsph_mesh_free(&m);
    /* a tall cylinder: long sliver side triangles, fan caps */
    assert_int_equal(pfsph_mesh_cylinder(&m, 0.3, 2.0, 1, 24), PFSPH_OK);
    check_sampling(&m, 0.04 * vg_scale(), "cylinder", 1);
    pfsph_mesh_free(&m);
    /* the points of the unit cube lie on its faces */
    double h[3] = {0.5, 0.5, 0.5}, *p, t[3] = {0.5, 0.5, 0.5};
    size_t n;
    pfsph_error err;
    assert_int_equal(pfsph_mesh_box(&m, h), PFSPH_OK);
    pfsph_mesh_transform(&m, 1.0, NULL, t);
    assert_int_equal(pfsph_mesh_sample_surface(&m, 0.1, &p, &n, &err), PFSPH_OK);
    for (size_t i = 0; i < n; i++) {
        int on_face = 0;
        for (int a = 0; a < 3; a++) {
            assert_true(p[3 * i + a] >= 0 && p[3 * i + a] <= 1);
            on_face |= p[3 * i + a] == 0 || fabs(p[3 * i + a] - 1) < 1e-12;
        }
        assert_true(on_face);
    }
    free(p);
    /* bad spacings */
    const double bad[] = {0, -1, NAN, INFINITY, 1e-9};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        p = (double *)&err;
        n = 7;
        assert_int_equal(pfsph_mesh_sample_surface(&m, bad[k], &p, &n, &err), PFSPH_EINPUT);
        assert_null(p);
        assert_int_equal(n, 0);
        assert_true(strstr(err.msg, "spacing") != NULL);
    }
    pfsph_mesh_free(&m);
}

/* About 100000 samples on a sphere in a few seconds (timing printed, not asserted: sanitizer
 * and valgrind builds are many times slower; under valgrind 10000). */
static void test_sample_large(void **state)
{
    (void)state;
    pfsph_mesh m;
    const double want = RUNNING_ON_VALGRIND ? 1e4 : 1e5;
    assert_int_equal(pfsph_mesh_sphere(&m, 1.0, RUNNING_ON_VALGRIND ? 96 : 256), PFSPH_OK);
    double s = sqrt(4 * PI / (want * sqrt(3.0) / 2)), *p;
    size_t n;
    pfsph_error err;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(pfsph_mesh_sample_surface(&m, s, &p, &n, &err), PFSPH_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("sphere %zu triangles, spacing %.4f: %zu samples in %.2f s\n", m.ntris, s, n,
           (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    assert_true((double)n > 0.7 * want && (double)n < 1.3 * want);
    free(p);
    pfsph_mesh_free(&m);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj_files),
        cmocka_unit_test(test_obj_syntax),
        cmocka_unit_test(test_validate),
        cmocka_unit_test(test_mass_cube_tetra),
        cmocka_unit_test(test_mass_box_transformed),
        cmocka_unit_test(test_mass_sphere),
        cmocka_unit_test(test_mass_cylinder),
        cmocka_unit_test(test_copy_free),
        cmocka_unit_test(test_sample_files),
        cmocka_unit_test(test_sample_primitives),
        cmocka_unit_test(test_sample_large),
    };
    return tu_run_group(tests, NULL, NULL);
}
