/* Rigid bodies in contact (3D, ODE): three boxes dropped in a column come to rest stacked on
 * the tank floor, and a mesh body (icosphere OBJ) dropped onto a box rests on it without
 * passing through. A puddle of water in a far corner is the fluid every scene needs. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/bodies.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 3, \"particle_radius\": 0.01, \"gravity\": [0, -9.81, 0],"
    " \"domain\": {\"min\": [-0.05, -0.05, -0.05], \"max\": [0.45, 0.75, 0.45]},"
    " \"solver\": {\"type\": \"wcsph\"},"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"},"
    "              {\"name\": \"wood\", \"kind\": \"solid\", \"rest_density\": 700}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.06, 0.04, 0.06], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.4, 0.7, 0.4], \"phase\": \"wall\"}],"
    " \"bodies\": [%s]}";

static pfsph_sim *make(const char *bodies)
{
    static char json[8192];
    snprintf(json, sizeof json, SCENE, bodies);
    char src[1200];
    snprintf(src, sizeof src, "%s/tests/contacts.json", tu_source_dir()); /* meshes resolve from here */
    return tu_sim_from_json(json, src);
}

/* Boxes 0.1 x 0.05 x 0.1 m released 2 cm apart: resting centres at 0.025, 0.075, 0.125 m above
 * the floor. ODE's contacts may sink by its surface layer (d/20 = 0.5 mm) each: 2 mm allowed. */
static void test_stack(void **st)
{
    (void)st;
    pfsph_sim *sim = make(
        "{\"name\": \"a\", \"shape\": \"box\", \"half_extents\": [0.05, 0.025, 0.05], \"position\": [0.2, 0.1, 0.2]},"
        "{\"name\": \"b\", \"shape\": \"box\", \"half_extents\": [0.05, 0.025, 0.05], \"position\": [0.2, 0.17, 0.2], "
        "\"rotation\": [0, 20, 0]},"
        "{\"name\": \"c\", \"shape\": \"box\", \"half_extents\": [0.05, 0.025, 0.05], \"position\": [0.2, 0.24, 0.2]}");
    tu_advance(sim, 1.2);
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    for (int i = 0; i < 3; i++) {
        pfsph_body_state s;
        pfsph_bodies_get_state(B, i, &s);
        double want = 0.025 + 0.05 * i, speed = sqrt(s.v[0] * s.v[0] + s.v[1] * s.v[1] + s.v[2] * s.v[2]);
        printf("box %d: height %.5f m (resting %.3f), offset %.4f %.4f m, speed %.2g m/s\n", i, s.x[1], want,
               s.x[0] - 0.2, s.x[2] - 0.2, speed);
        assert_true(fabs(s.x[1] - want) < 0.002);
        assert_true(fabs(s.x[0] - 0.2) < 0.02 && fabs(s.x[2] - 0.2) < 0.02);
        assert_true(speed < 0.01);
    }
    pfsph_sim_destroy(sim);
}

/* An icosphere of radius 0.05 m (its faces' inradius is 0.0470 m... the mesh lies inside the
 * unit sphere) dropped onto a static-on-the-floor box: it comes to rest on top, centre above
 * the box top by between the face distance and the radius. */
static void test_mesh_on_box(void **st)
{
    (void)st;
    pfsph_sim *sim =
        make("{\"name\": \"crate\", \"shape\": \"box\", \"half_extents\": [0.08, 0.04, 0.08], \"position\": [0.2, "
             "0.04, 0.2], \"density\": 2000},"
             "{\"name\": \"ball\", \"shape\": \"mesh\", \"file\": \"data/meshes/icosphere.obj\", \"scale\": 0.05,"
             " \"position\": [0.2, 0.25, 0.2], \"density\": 500}");
    tu_advance(sim, 1.2);
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    pfsph_body_state c, b;
    pfsph_bodies_get_state(B, 0, &c);
    pfsph_bodies_get_state(B, 1, &b);
    double speed = sqrt(b.v[0] * b.v[0] + b.v[1] * b.v[1] + b.v[2] * b.v[2]);
    double gap = b.x[1] - (c.x[1] + 0.04);
    printf("mesh ball on crate: centre %.4f m above the crate's top (radius 0.05), speed %.2g m/s, crate at %.4f\n",
           gap, speed, c.x[1]);
    assert_true(gap > 0.040 && gap < 0.0505);
    assert_true(fabs(c.x[1] - 0.04) < 0.002);
    assert_true(speed < 0.05);
    pfsph_sim_destroy(sim);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stack),
        cmocka_unit_test(test_mesh_on_box),
    };
    return tu_run_group(tests, NULL, NULL);
}
