/* Rigid bodies in water (2D, WCSPH; Archimedes also with DFSPH): Archimedes' principle for a floating box, a heavy box at
 * rest on the floor, a dense disc that sinks and comes to rest, and momentum exchanged between
 * fluid and body without loss. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/bodies.h"
#include "pfsph/sim.h"
#include "testutil.h"

/* Tank 0.8 x 0.5 m, water 0.25 m deep, d = 1 cm; one body given by `body`. */
static const char *TANK =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, %g],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.85, 0.55]},"
    " \"solver\": {\"type\": \"%s\"}, \"time\": {\"end\": 5, \"fps\": 20},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": %g},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"},"
    "              {\"name\": \"body\", \"kind\": \"solid\", \"rest_density\": 1000}],"
    " \"fluid\": [%s],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.8, 0.5], \"phase\": \"wall\"}],"
    " \"bodies\": [%s]%s}";

static const char *g_solver = "wcsph"; /* of TANK */

static pfsph_sim *make_x(double g, double nu, const char *fluid, const char *body, const char *extra)
{
    static char json[4096];
    snprintf(json, sizeof json, TANK, g, g_solver, nu, fluid, body, extra);
    return tu_sim_from_json(json, "bodies");
}

static pfsph_sim *make(double g, double nu, const char *fluid, const char *body)
{
    return make_x(g, nu, fluid, body, "");
}

static const char *WATER = "{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.8, 0.25], \"phase\": \"water\"}";

/* Archimedes: a box of half the water's density floats with half its height submerged. A
 * 0.2 x 0.06 m box (wide, so upright is its stable attitude: a square of density 0.5 turns
 * onto its corner, which the first runs showed). The water line is the fluid surface 0.15 m
 * or more from the box; the submerged fraction is (water line - bottom) / height. 10% as the
 * issue asks: the surface itself is known to d/2 = 0.5 cm, 8% of the height. */
static void test_archimedes(void **state)
{
    (void)state;
    pfsph_sim *sim = make(-9.81, 1e-3, WATER,
                          "{\"name\": \"raft\", \"shape\": \"box\", \"half_extents\": [0.1, 0.03],"
                          " \"position\": [0.4, 0.27], \"density\": 500, \"phase\": \"body\"}");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    tu_advance(sim, 2.0);
    double frac_sum = 0, tilt_max = 0;
    int samples = 0;
    for (int k = 1; k <= 20; k++) {
        tu_advance(sim, 2.0 + 0.05 * k);
        pfsph_body_state st;
        pfsph_bodies_get_state(pfsph_sim_bodies(sim), 0, &st);
        const pfsph_particles *f = c->fluid;
        double top = -1;
        for (size_t i = 0; i < f->n; i++)
            if (fabs(f->x[i] - st.x[0]) > 0.15 + 0.1 && f->y[i] > top) top = f->y[i];
        double surface = top + 0.5 * c->spacing;
        /* for a small tilt the bottom's centre sits hy cos(angle) below the centre */
        double angle = 2 * asin(fabs(st.q[3]));
        tilt_max = fmax(tilt_max, angle);
        double draft = surface - (st.x[1] - 0.03 * cos(angle));
        frac_sum += draft / 0.06;
        samples++;
    }
    double frac = frac_sum / samples;
    printf("archimedes: submerged fraction %.4f (expected 0.5), largest tilt %.2f deg\n", frac,
           tilt_max * 180 / 3.14159265358979);
    assert_true(fabs(frac - 0.5) < 0.05);
    assert_true(tilt_max < 10 * 3.14159265358979 / 180);
    pfsph_sim_destroy(sim);
}

/* The same with DFSPH: the body feels the density solve's pressure (two-way coupling) */
static void test_archimedes_dfsph(void **state)
{
    g_solver = "dfsph";
    test_archimedes(state);
    g_solver = "wcsph";
}

/* A box twice as dense as water resting on the tank floor under water stays put: it starts
 * on the floor, and its centre moves less than 2 mm (d/5) in 1.5 s. */
static void test_rest_on_floor(void **state)
{
    (void)state;
    pfsph_sim *sim = make(-9.81, 1e-3, WATER,
                          "{\"name\": \"brick\", \"shape\": \"box\", \"half_extents\": [0.05, 0.025],"
                          " \"position\": [0.4, 0.025], \"density\": 2000, \"phase\": \"body\"}");
    pfsph_body_state s0, st;
    pfsph_bodies_get_state(pfsph_sim_bodies(sim), 0, &s0);
    double drift = 0, vmax = 0;
    for (int k = 1; k <= 30; k++) {
        tu_advance(sim, 0.05 * k);
        pfsph_bodies_get_state(pfsph_sim_bodies(sim), 0, &st);
        double dx = st.x[0] - s0.x[0], dy = st.x[1] - s0.x[1];
        drift = fmax(drift, sqrt(dx * dx + dy * dy));
        vmax = fmax(vmax, sqrt(st.v[0] * st.v[0] + st.v[1] * st.v[1]));
    }
    printf("rest on floor: largest drift %.3g mm, largest speed %.3g mm/s, tilt %.3g deg\n", 1e3 * drift, 1e3 * vmax,
           2 * asin(fabs(st.q[3])) * 180 / 3.14159265358979);
    assert_true(drift < 0.002);
    assert_true(2 * asin(fabs(st.q[3])) < 1 * 3.14159265358979 / 180);
    pfsph_sim_destroy(sim);
}

/* A disc three times as dense as water sinks through 0.2 m of water and comes to rest on the
 * floor: it never rises while sinking by more than d, reaches the floor (centre within d of
 * its radius above the floor face) and ends at rest (speed below 1 cm/s). */
static void test_sinking_disc(void **state)
{
    (void)state;
    pfsph_sim *sim = make(-9.81, 1e-3, WATER,
                          "{\"name\": \"stone\", \"shape\": \"sphere\", \"radius\": 0.03,"
                          " \"position\": [0.4, 0.2], \"density\": 3000, \"phase\": \"body\"}");
    pfsph_body_state st;
    double ymin = 1, vpeak = 0, rise = 0;
    for (int k = 1; k <= 40; k++) {
        tu_advance(sim, 0.05 * k);
        pfsph_bodies_get_state(pfsph_sim_bodies(sim), 0, &st);
        if (st.x[1] < ymin) ymin = st.x[1];
        rise = fmax(rise, st.x[1] - ymin);
        vpeak = fmax(vpeak, -st.v[1]);
    }
    double speed = sqrt(st.v[0] * st.v[0] + st.v[1] * st.v[1]);
    printf("sinking disc: peak sinking speed %.3f m/s, final height %.4f m (radius 0.03), final speed %.3g m/s, "
           "largest rise %.3g mm\n",
           vpeak, st.x[1], speed, 1e3 * rise);
    /* free fall with buoyancy would reach sqrt(2 (2/3) g 0.17) = 1.49 m/s: drag must slow it */
    assert_true(vpeak > 0.1 && vpeak < 1.49);
    assert_true(fabs(st.x[1] - 0.03) < 0.01);
    assert_true(speed < 0.01);
    assert_true(rise < 0.01);
    pfsph_sim_destroy(sim);
}

/* Momentum: no gravity, a free drop of water (no wall within reach during the test) with a
 * disc inside moving at 0.5 m/s, viscosity nu. Fluid plus body momentum stays what the body
 * started with: every pair term (pressure, Morris viscosity, wall friction, thermostat noise,
 * pair forces) is computed with the same bits from both sides, so what is left is the float
 * rounding of each particle's sums and of v += dt a, about 2^-24 of a particle's momentum per
 * step with random sign: over S = 530 steps and N = 656 particles of m = 0.1 kg/m moving at
 * up to 0.5 m/s, sqrt(S N) 2^-24 m v = 1.8e-6 N s, 7e-7 of the initial 2.5 N s. The bound,
 * 1e-5, is 14x that. It fails on a viscosity whose pair terms differ in the two directions:
 * the Morris term with 1 / delta_j (before 2026-12-06) lost 8.0e-4 with the floor viscosity
 * of the pairwise test and 1.05e-3 with water's 1e-3 (docs/viscosity.md, "Momentum"). The body
 * must really give momentum to the fluid (more than 20% of it) for the test to mean anything. */
static void momentum(double nu, const char *extra)
{
    pfsph_sim *sim =
        make_x(0.0, nu, "{\"shape\": \"sphere\", \"center\": [0.4, 0.25], \"radius\": 0.15, \"phase\": \"water\"}",
               "{\"name\": \"puck\", \"shape\": \"sphere\", \"radius\": 0.04, \"position\": [0.4, 0.25],"
               " \"velocity\": [0.5, 0], \"density\": 1000, \"phase\": \"body\"}",
               extra);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const double mb = pfsph_bodies_mass(pfsph_sim_bodies(sim), 0);
    const double P0 = mb * 0.5;
    double worst = 0, pbody = 0;
    for (int k = 1; k <= 8; k++) {
        tu_advance(sim, 0.025 * k);
        pfsph_body_state st;
        pfsph_bodies_get_state(pfsph_sim_bodies(sim), 0, &st);
        double px = mb * st.v[0], py = mb * st.v[1];
        pbody = px;
        const pfsph_particles *f = c->fluid;
        for (size_t i = 0; i < f->n; i++) {
            px += c->mass[f->phase[i]] * (double)f->vx[i];
            py += c->mass[f->phase[i]] * (double)f->vy[i];
        }
        double e = sqrt((px - P0) * (px - P0) + py * py) / P0;
        worst = fmax(worst, e);
    }
    printf("momentum%s (nu %g, Morris %g): %zu fluid particles, %llu steps, body keeps %.1f%% of its momentum, "
           "largest total error %.3g of the initial\n",
           extra[0] ? " with pair forces" : "", nu, (double)c->nu[0], c->fluid->n,
           (unsigned long long)pfsph_sim_steps(sim), 100 * pbody / P0, worst);
    assert_true(pbody / P0 < 0.8);
    assert_true(worst < 1e-5);
    pfsph_sim_destroy(sim);
}

/* Water's viscosity, 1e-3 m^2/s: the Morris term between fluid particles of different number
 * densities (the drop's surface, the layer by the disc) must conserve momentum too. */
static void test_momentum(void **state)
{
    (void)state;
    momentum(1e-3, "");
}

/* The same with the pairwise model's cohesion and adhesion to the body (filter off: Eq. 12's
 * T_i is applied per particle and is not momentum-conserving, docs/pairwise.md): the body
 * receives the reaction of the pair forces too. The viscosity is set to 0 and the default 2D
 * correction applies its floor, 0.05 sqrt(sigma d / rho), with the thermostat's noise: friction
 * and noise between fluid particles and with the disc's particles. */
static void test_momentum_pairwise(void **state)
{
    (void)state;
    momentum(0.0,
             ", \"pairwise\": {\"filter\": false, \"coefficients\": ["
             "{\"phases\": [\"water\", \"water\"], \"sigma\": 0.5},"
             "{\"phases\": [\"water\", \"body\"], \"contact_angle\": 45}]}");
}

/* Regression (review of the bodies code): a body that leaves the domain (here pushed out by
 * its own velocity, no gravity, water adhering to it) loses its particles; it must then feel
 * no fluid force at all, not the last one its particles had (it used to keep braking at a
 * constant -0.0626 N on water it no longer touched). */
static void test_left_domain_feels_nothing(void **state)
{
    (void)state;
    static const char *json =
        "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, 0],"
        " \"domain\": {\"min\": [0, 0], \"max\": [1.0, 1.0]},"
        " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.7, \"fps\": 25, \"dt_max\": 0.004},"
        " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 0},"
        "              {\"name\": \"body\", \"kind\": \"solid\", \"rest_density\": 1000}],"
        " \"bodies\": [{\"name\": \"crate\", \"shape\": \"box\", \"half_extents\": [0.05, 0.05],"
        "              \"position\": [0.85, 0.45], \"velocity\": [0.6, 0], \"phase\": \"body\"}],"
        " \"fluid\": [{\"shape\": \"box\", \"min\": [0.5, 0.3], \"max\": [0.95, 0.6], \"phase\": \"water\"}],"
        " \"pairwise\": {\"filter\": false, \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 0.5},"
        "              {\"phases\": [\"water\", \"body\"], \"contact_angle\": 45}]}}";
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, json, "left", &err), PFSPH_OK);
    pfsph_sim *sim = NULL;
    assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
    /* wholly outside from about 0.58 s (0.52 s before issue 11 put the water block, 0.45 m
     * wide, on the scene lattice: its sites moved by a quarter spacing, and the water that
     * adheres to the body slows it a little more) */
    tu_advance(sim, 0.6);
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    pfsph_body_state a, b;
    double F[3], T[3];
    pfsph_bodies_get_state(B, 0, &a);
    tu_advance(sim, 0.68);
    pfsph_bodies_get_state(B, 0, &b);
    pfsph_bodies_last_force(B, 0, F, T);
    printf("left the domain: x %.4f -> %.4f m, vx %.9f -> %.9f m/s, force %g %g N\n", a.x[0], b.x[0], a.v[0], b.v[0],
           F[0], F[1]);
    assert_true(a.x[0] - 0.05 > 1.0 + 0.02); /* wholly outside, beyond the grid's margin */
    assert_true(F[0] == 0 && F[1] == 0 && T[2] == 0);
    assert_true(b.v[0] == a.v[0]);
    pfsph_sim_destroy(sim);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_momentum),
        cmocka_unit_test(test_momentum_pairwise),
        cmocka_unit_test(test_archimedes),
        cmocka_unit_test(test_archimedes_dfsph),
        cmocka_unit_test(test_rest_on_floor),
        cmocka_unit_test(test_sinking_disc),
        cmocka_unit_test(test_left_domain_feels_nothing),
    };
    return tu_run_group(tests, NULL, NULL);
}
