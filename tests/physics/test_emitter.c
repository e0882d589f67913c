/* Emitters (issue 12 part 3, docs/emitters.md): the mass that enters is rate x time to within
 * 1 % (2D and 3D, a rate given and a speed given, several nozzles, start and stop times); no
 * particle enters closer than 0.8 d to another, also when the jet lands in a pool that rises to
 * the nozzle; a phase with pair forces can be emitted; ids are fresh and unique; 1 and 2
 * threads give the same bits; a run resumed while an emitter is open continues byte for byte. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/emitter.h"
#include "pfsph/run.h"
#include "pfsph/sim.h"
#include "testutil.h"

/* Mass of phase `ph` and whether the ids 0..next_id-1 are each held by at most one particle. */
static double phase_mass(const pfsph_ctx *c, int ph, int *ids_unique)
{
    const pfsph_particles *f = c->fluid;
    double m = 0;
    unsigned char *seen = calloc(f->next_id + 1, 1);
    *ids_unique = 1;
    for (size_t i = 0; i < f->n; i++) {
        if (f->phase[i] == ph) m += (double)c->mass[ph];
        if (f->id[i] >= f->next_id || seen[f->id[i]]++) *ids_unique = 0;
    }
    free(seen);
    return m;
}

/* Free fall, no walls: two nozzles, one with a rate and a start time, one with a speed and a
 * stop time; rates are per metre of depth in 2D. */
static const char *MASS_2D =
    "{\"dimension\": 2, \"particle_radius\": 0.0025, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.5, -4.0], \"max\": [0.5, 0.6]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.6, \"fps\": 25, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-3},"
    "              {\"name\": \"oil\", \"rest_density\": 800, \"viscosity\": 1e-3}],"
    " \"emitters\": ["
    "   {\"phase\": \"water\", \"center\": [-0.2, 0.5], \"width\": 0.08, \"direction\": [0.3, -1],"
    "    \"rate\": 0.1, \"start\": 0.1},"
    "   {\"phase\": \"oil\", \"center\": [0.2, 0.5], \"width\": 0.05, \"direction\": [0, -1],"
    "    \"speed\": 2.0, \"stop\": 0.35}]}";

static void test_mass_2d(void **st)
{
    (void)st;
    pfsph_sim *sim = tu_sim_from_json(MASS_2D, "mass-2d");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_emitters *E = pfsph_sim_emitters(sim);
    pfsph_emitter_info in0, in1;
    pfsph_emitters_info(E, 0, &in0);
    pfsph_emitters_info(E, 1, &in1);
    /* the rate given is the rate used; the speed given gives sites V0 v / d */
    assert_true(fabs(in0.rate - 0.1) < 1e-12);
    assert_true(fabs(in1.rate / ((double)in1.sites * 2.0 * c->spacing) - 1) < 1e-6);
    tu_advance(sim, 0.6);
    int uniq;
    double mw = phase_mass(c, 0, &uniq), mo = phase_mass(c, 1, &uniq);
    double ew = 1000 * 0.1 * (0.6 - 0.1), eo = 800 * in1.rate * 0.35;
    pfsph_emitter_state s0, s1;
    pfsph_emitters_get_state(E, 0, &s0);
    pfsph_emitters_get_state(E, 1, &s1);
    printf("2D: water %.5g kg/m (rate x time %.5g, %+.3f %%), oil %.5g (%.5g, %+.3f %%); sites %zu and %zu; "
           "%zu particles, next id %u, removed %zu, refused %llu + %llu\n",
           mw, ew, 100 * (mw / ew - 1), mo, eo, 100 * (mo / eo - 1), in0.sites, in1.sites, c->fluid->n,
           c->fluid->next_id, pfsph_sim_removed(sim), (unsigned long long)s0.refused, (unsigned long long)s1.refused);
    assert_true(fabs(mw / ew - 1) < 0.01);
    assert_true(fabs(mo / eo - 1) < 0.01);
    assert_true(uniq);
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_int_equal(c->fluid->next_id, c->fluid->n);
    assert_int_equal(s0.emitted + s1.emitted, c->fluid->n);
    pfsph_sim_destroy(sim);
}

/* 3D: a disc (rate) and a rectangle (speed, oblique jet) pouring side by side. */
static const char *MASS_3D =
    "{\"dimension\": 3, \"particle_radius\": 0.005, \"gravity\": [0, -9.81, 0],"
    " \"domain\": {\"min\": [-0.4, -3.0, -0.4], \"max\": [0.8, 0.5, 0.4]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.5, \"fps\": 25, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-3}],"
    " \"emitters\": ["
    "   {\"shape\": \"disc\", \"center\": [-0.15, 0.4, 0], \"radius\": 0.03, \"direction\": [0, -1, 0],"
    "    \"rate\": 0.008},"
    "   {\"shape\": \"rectangle\", \"center\": [0.15, 0.4, 0], \"size\": [0.04, 0.03], \"direction\": [0.2, -1, 0.1],"
    "    \"speed\": 3, \"start\": 0.05}]}";

static void test_mass_3d(void **st)
{
    (void)st;
    pfsph_sim *sim = tu_sim_from_json(MASS_3D, "mass-3d");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_emitters *E = pfsph_sim_emitters(sim);
    pfsph_emitter_info in0, in1;
    pfsph_emitters_info(E, 0, &in0);
    pfsph_emitters_info(E, 1, &in1);
    tu_advance(sim, 0.5);
    pfsph_emitter_state s0, s1;
    pfsph_emitters_get_state(E, 0, &s0);
    pfsph_emitters_get_state(E, 1, &s1);
    double V0 = (double)c->V0;
    double m0 = (double)s0.emitted * V0 * 1000, e0 = 1000 * 0.008 * 0.5;
    double m1 = (double)s1.emitted * V0 * 1000, e1 = 1000 * in1.rate * 0.45;
    int uniq;
    double mall = phase_mass(c, 0, &uniq);
    printf("3D: disc %zu sites, %.5g kg (rate x time %.5g, %+.3f %%); rectangle %zu sites at %.4g m^3/s, %.5g kg "
           "(%.5g, %+.3f %%); %zu particles in all (%.5g kg)\n",
           in0.sites, m0, e0, 100 * (m0 / e0 - 1), in1.sites, in1.rate, m1, e1, 100 * (m1 / e1 - 1), c->fluid->n, mall);
    assert_true(fabs(m0 / e0 - 1) < 0.01);
    assert_true(fabs(m1 / e1 - 1) < 0.01);
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_true(fabs(mall - m0 - m1) < 1e-5 * mall); /* float particle masses */
    assert_true(uniq);
    pfsph_sim_destroy(sim);
}

/* A jet into a small tank that fills up to the nozzle and over it (the pool rises into the
 * inlet): after every step the new particles (ids from the step's first new id on) are at least
 * 0.8 d from every other particle. Pair forces on (surface tension and the thermostat), so a
 * phase with pair forces is emitted; WCSPH. */
static const char *POOL_2D =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.13, 0.3]},"
    " \"solver\": {\"type\": \"wcsph\"}, \"time\": {\"end\": 1, \"fps\": 25, \"dt_max\": 0.001},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 2e-3},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.08, 0.06], \"phase\": \"water\"}],"
    " \"emitters\": [{\"center\": [0.04, 0.11], \"width\": 0.04, \"direction\": [0, -1], \"speed\": 1.0}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.08, 0.2], \"open_top\": true,"
    "              \"layers\": 2, \"phase\": \"wall\"}],"
    " \"pairwise\": {\"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 0.07},"
    "                                   {\"phases\": [\"water\", \"wall\"], \"contact_angle\": 60}]}}";

static void test_entry_spacing(void **st)
{
    (void)st;
    pfsph_sim *sim = tu_sim_from_json(POOL_2D, "pool-2d");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *f = c->fluid;
    const double d = c->spacing;
    double closest = INFINITY;
    size_t entered = 0;
    pfsph_error err = {0};
    while (pfsph_sim_time(sim) < 0.5 - 1e-9) {
        uint32_t first = f->next_id;
        int rc = pfsph_sim_step(sim, 0.5, &err);
        if (rc) fprintf(stderr, "%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        for (size_t i = 0; i < f->n; i++) {
            if (f->id[i] < first) continue;
            entered++;
            for (size_t j = 0; j < f->n; j++) {
                if (j == i) continue;
                double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j];
                closest = fmin(closest, sqrt(dx * dx + dy * dy) / d);
            }
        }
    }
    pfsph_emitter_state es;
    pfsph_emitters_get_state(pfsph_sim_emitters(sim), 0, &es);
    double top = -INFINITY;
    for (size_t i = 0; i < f->n; i++) top = fmax(top, (double)f->y[i]);
    printf("pool: %zu particles entered in %llu steps, closest to another at entry %.4f d; %llu sites refused, %llu "
           "particles pushed by the inlet; %zu fluid particles, the highest at %.3f m (nozzle 0.11 m)\n",
           entered, (unsigned long long)pfsph_sim_steps(sim), closest, (unsigned long long)es.refused,
           (unsigned long long)es.pushed, f->n, top);
    assert_true(entered > 150);
    assert_true(closest >= 0.8);
    /* the pool reached the nozzle: sites were refused, so the spacing check was exercised */
    assert_true(es.refused > 0);
    pfsph_sim_destroy(sim);
}

/* Gas blown into water through a nozzle in the floor of a tank (the way a bubble is blown):
 * the inlet pushes the water in front of the nozzle away, so that the gas (a phase with pair
 * forces) gets in; the run stays stable and the gas stays in the tank. */
static const char *BLOW_2D =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.25, 0.35]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.4, \"fps\": 25, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 0.002},"
    "              {\"name\": \"gas\", \"kind\": \"gas\", \"rest_density\": 100, \"viscosity\": 0.002},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.2, 0.16], \"phase\": \"water\"}],"
    " \"emitters\": [{\"phase\": \"gas\", \"center\": [0.1, 0.0045], \"width\": 0.04, \"direction\": [0, 1],"
    "                 \"speed\": 0.3, \"stop\": 0.2}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.2, 0.3], \"layers\": 3,"
    "              \"open_top\": true, \"phase\": \"wall\"}],"
    " \"pairwise\": {\"k\": 1.7, \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 2},"
    "   {\"phases\": [\"gas\", \"gas\"], \"c\": 20}, {\"phases\": [\"water\", \"wall\"], \"contact_angle\": 90}]}}";

static void test_blow_gas(void **st)
{
    (void)st;
    pfsph_sim *sim = tu_sim_from_json(BLOW_2D, "blow-2d");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    tu_advance(sim, 0.4);
    pfsph_emitter_state es;
    pfsph_emitter_info in;
    pfsph_emitters_get_state(pfsph_sim_emitters(sim), 0, &es);
    pfsph_emitters_info(pfsph_sim_emitters(sim), 0, &in);
    const pfsph_particles *f = c->fluid;
    size_t gas = 0;
    double gy = 0;
    for (size_t i = 0; i < f->n; i++)
        if (f->phase[i] == 1) {
            gas++;
            gy += f->y[i];
        }
    const double owed = in.layer_rate * 0.2 * (double)in.sites;
    printf("blow: %zu sites, %llu gas particles emitted of %.0f owed, %llu refused, %llu pushes by the inlet; "
           "%zu gas in the tank, their mean height %.4f m; %zu removed\n",
           in.sites, (unsigned long long)es.emitted, owed, (unsigned long long)es.refused,
           (unsigned long long)es.pushed, gas, gas ? gy / gas : 0, pfsph_sim_removed(sim));
    assert_int_equal(gas, es.emitted);
    assert_true((double)es.emitted >= 0.75 * owed);
    assert_true(es.pushed > 0);
    assert_int_equal(pfsph_sim_removed(sim), 0);
    pfsph_sim_destroy(sim);
}

static void test_threads_identical(void **st)
{
    (void)st;
    pfsph_sim *a, *b;
    omp_set_num_threads(1);
    a = tu_sim_from_json(POOL_2D, "pool-2d");
    tu_advance(a, 0.2);
    omp_set_num_threads(2);
    b = tu_sim_from_json(POOL_2D, "pool-2d");
    tu_advance(b, 0.2);
    const pfsph_particles *fa = pfsph_sim_ctx(a)->fluid, *fb = pfsph_sim_ctx(b)->fluid;
    printf("threads: %zu particles after %llu steps, 1 and 2 threads compared\n", fa->n,
           (unsigned long long)pfsph_sim_steps(a));
    assert_true(fa->n > pfsph_sim_ctx(a)->fluid->next_id - fa->n); /* particles were emitted */
    assert_int_equal(fa->n, fb->n);
    assert_int_equal(fa->next_id, fb->next_id);
    assert_int_equal(pfsph_sim_steps(a), pfsph_sim_steps(b));
    for (int k = 0; k < PFSPH_NFIELDS; k++) assert_memory_equal(fa->f[k], fb->f[k], fa->n * sizeof(pfsph_real));
    assert_memory_equal(fa->id, fb->id, fa->n * sizeof(uint32_t));
    pfsph_sim_destroy(a);
    pfsph_sim_destroy(b);
}

/* Resume while the nozzle pours: frames 0..5 with a checkpoint at 5, resumed to 10, against
 * 0..10 in one go. Two emitters, one of them opening after the checkpoint; diffuse material on
 * (its stage sees the fluid grow). */
static const char *RESUME_2D =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.35, 0.4]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.4, \"fps\": 25, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-3},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"emitters\": [{\"center\": [0.1, 0.3], \"width\": 0.04, \"direction\": [0.2, -1], \"rate\": 0.03},"
    "                {\"center\": [0.22, 0.3], \"width\": 0.03, \"direction\": [0, -1], \"speed\": 0.7,"
    "                 \"start\": 0.27, \"stop\": 0.35}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.3, 0.2], \"open_top\": true,"
    "              \"layers\": 2, \"phase\": \"wall\"}],"
    " \"diffuse\": {\"enabled\": true, \"sampling_rate\": 400, \"phi_v_min\": 0.05, \"phi_v_max\": 1,"
    "               \"phi_e_min\": 0.1, \"phi_e_max\": 2, \"energy_mass\": 1.0,"
    "               \"lifetime_min\": 0.5, \"lifetime_max\": 2},"
    " \"output\": {\"formats\": [\"vtp\"], \"fields\": [\"id\", \"speed\"], \"checkpoint_interval\": 5}}";

static void test_resume(void **st)
{
    (void)st;
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, RESUME_2D, "resume-2d", &err), PFSPH_OK);
    char full[1024], part[1024];
    snprintf(full, sizeof full, "%s/full", tu_tmpdir());
    snprintf(part, sizeof part, "%s/part", tu_tmpdir());
    tu_pfsph_run(&s, full, -1, false);
    tu_pfsph_run(&s, part, 0.2, false);
    tu_pfsph_run(&s, part, 0.4, true);
    tu_assert_same_file(full, part, "frames/fluid_00006.vtp");
    tu_assert_same_file(full, part, "frames/fluid_00008.vtp");
    tu_assert_same_file(full, part, "frames/fluid_00010.vtp");
    tu_assert_same_file(full, part, "frames/diffuse_00010.vtp");
    tu_assert_same_file(full, part, "stats.csv");
    /* the fluid grew across the resume (stats.csv's n_fluid at frames 5 and 10) */
    char p[1100];
    snprintf(p, sizeof p, "%s/stats.csv", full);
    size_t len;
    char *csv = (char *)tu_slurp(p, &len);
    long n5 = -1, n10 = -1, dif10 = -1;
    for (char *line = strtok(csv, "\n"); line; line = strtok(NULL, "\n")) {
        int fr;
        double t, dt;
        unsigned long long steps;
        long nf;
        if (sscanf(line, "%d,%lf,%lf,%llu,%ld", &fr, &t, &dt, &steps, &nf) == 5) {
            if (fr == 5) n5 = nf;
            if (fr == 10) {
                n10 = nf;
                long a, b, c3;
                const char *q = line;
                for (int k = 0; k < 11 && q; k++) q = strchr(q, ',') ? strchr(q, ',') + 1 : NULL;
                if (q && sscanf(q, "%ld,%ld,%ld", &a, &b, &c3) == 3) dif10 = a + b + c3;
            }
        }
    }
    free(csv);
    printf("resume: fluid %ld at the checkpoint (frame 5), %ld at frame 10, %ld diffuse particles; frames 6, 8, 10 "
           "(fluid and diffuse) and stats.csv identical\n",
           n5, n10, dif10);
    assert_true(n5 > 0 && n10 > n5);
    assert_true(dif10 > 0);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mass_2d),  cmocka_unit_test(test_mass_3d),           cmocka_unit_test(test_entry_spacing),
        cmocka_unit_test(test_blow_gas), cmocka_unit_test(test_threads_identical), cmocka_unit_test(test_resume),
    };
    return tu_run_group(tests, NULL, NULL);
}
