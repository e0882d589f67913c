/* The static solids as meshes (issue 33 item 10): every shape closed and facing out, the volume
 * it should have, a container's inner faces on min..max and its walls as thick as its particle
 * layers, a plane's slab clipped to the domain; RUN/solids.ply and .obj as the run writes them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/solid_mesh.h"
#include "testutil.h"

#define PI 3.14159265358979323846

static const char *SCENE =
    "{\"dimension\": 3, \"particle_radius\": 0.01, \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [1.1, 0.9, "
    "0.6]},\n"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}, {\"name\": \"rock\", \"kind\": "
    "\"solid\"}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.2, 0.2, 0.2], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [1, 0.8, 0.5], \"open_top\": true, "
    "\"layers\": 2, \"phase\": \"wall\"},\n"
    "  {\"shape\": \"box\", \"min\": [0.5, 0, 0.1], \"max\": [0.6, 0.3, 0.2], \"phase\": \"rock\"},\n"
    "  {\"shape\": \"sphere\", \"center\": [0.3, 0.2, 0.25], \"radius\": 0.1, \"phase\": \"rock\"},\n"
    "  {\"shape\": \"cylinder\", \"center\": [0.8, 0.2, 0.25], \"radius\": 0.05, \"height\": 0.4, \"axis\": \"y\", "
    "\"phase\": \"rock\"},\n"
    "  {\"shape\": \"plane\", \"point\": [0, 0.5, 0], \"normal\": [0, 1, 0.2], \"phase\": \"wall\"}]}\n";

static void check(const pfsph_scene *s, int k, double want_volume, double tol)
{
    pfsph_mesh m;
    pfsph_error err = {0};
    assert_int_equal(pfsph_solid_mesh(s, &s->solids[k], &m), 0);
    double vol = 0;
    pfsph_mesh_mass_properties(&m, &vol, NULL, NULL);
    int closed = pfsph_mesh_validate_closed(&m, "solid", &err);
    double vol2 = 0;
    pfsph_mesh_mass_properties(&m, &vol2, NULL, NULL);
    printf("solid %d: %zu vertices, %zu triangles, volume %.6g m^3 (want %.6g)%s%s\n", k, m.nverts, m.ntris, vol,
           want_volume, closed ? ": " : "", closed ? err.msg : "");
    assert_int_equal(closed, 0);
    assert_true(vol2 == vol); /* already facing out: validation flipped nothing */
    assert_true(fabs(vol - want_volume) <= tol * want_volume);
    pfsph_mesh_free(&m);
}

static void test_shapes(void **state)
{
    (void)state;
    pfsph_scene *s = malloc(sizeof *s);
    pfsph_error err = {0};
    int prc = pfsph_scene_parse(s, SCENE, "solids", &err);
    if (prc) printf("%s\n", err.msg);
    assert_int_equal(prc, 0);
    /* container: 2 layers of 0.02 m outside 1 x 0.8 x 0.5, open top */
    double T = 0.04, outer = (1 + 2 * T) * (0.8 + T) * (0.5 + 2 * T), inner = 1 * 0.8 * 0.5;
    /* the container's wall slabs touch, so its volume counts each once: the shell */
    check(s, 0, outer - inner, 1e-9);
    check(s, 1, 0.1 * 0.3 * 0.1, 1e-9);
    check(s, 2, 4.0 / 3 * PI * 0.001, 0.01);
    check(s, 3, PI * 0.05 * 0.05 * 0.4, 0.01);
    /* the plane: a slab of its layers (2 by default, 0.04 m) behind it, inside the domain grown as much */
    const double TP = s->solids[4].layers * 0.02;
    pfsph_mesh m;
    assert_int_equal(pfsph_solid_mesh(s, &s->solids[4], &m), 0);
    assert_int_equal(pfsph_mesh_validate_closed(&m, "plane", &err), 0);
    double lo[3], hi[3];
    assert_int_equal(pfsph_mesh_bounds(&m, lo, hi), 0);
    printf("plane slab: %zu vertices, bounds %g %g %g .. %g %g %g\n", m.nverts, lo[0], lo[1], lo[2], hi[0], hi[1],
           hi[2]);
    for (int a = 0; a < 3; a++) {
        assert_true(lo[a] >= s->domain_min[a] - TP - 1e-9);
        assert_true(hi[a] <= s->domain_max[a] + TP + 1e-9);
    }
    assert_true(fabs(lo[0] - (s->domain_min[0] - TP)) < 1e-9 && fabs(hi[0] - (s->domain_max[0] + TP)) < 1e-9);
    double n[3] = {0, 1 / sqrt(1.04), 0.2 / sqrt(1.04)};
    for (size_t i = 0; i < m.nverts; i++) { /* every vertex on the plane or 0.02 behind it */
        double dist = (m.v[3 * i + 1] - 0.5) * n[1] + m.v[3 * i + 2] * n[2];
        assert_true(fabs(dist) < 1e-9 || fabs(dist + TP) < 1e-9);
    }
    pfsph_mesh_free(&m);
    /* a 2D scene has no solid meshes */
    s->dim = 2;
    assert_int_equal(pfsph_solid_mesh(s, &s->solids[1], &m), PFSPH_EINPUT);
    s->dim = 3;
    /* the run directory's files */
    int count = -1;
    assert_int_equal(pfsph_write_solids(s, tu_tmpdir(), &count, &err), 0);
    assert_int_equal(count, 5);
    char path[1200];
    snprintf(path, sizeof path, "%s/solids.ply", tu_tmpdir());
    size_t len;
    unsigned char *ply = tu_slurp(path, &len);
    assert_non_null(ply);
    assert_non_null(strstr((char *)ply, "comment solid 0 container wall\n"));
    assert_non_null(strstr((char *)ply, "comment solid 3 cylinder rock\n"));
    assert_non_null(strstr((char *)ply, "property uchar solid\nproperty uchar phase\nend_header\n"));
    free(ply);
    snprintf(path, sizeof path, "%s/solids.obj", tu_tmpdir());
    unsigned char *obj = tu_slurp(path, &len);
    assert_non_null(obj);
    assert_non_null(strstr((char *)obj, "\no solid_2_rock\n"));
    free(obj);
    free(s);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shapes),
    };
    return tu_run_group(tests, NULL, NULL);
}
