/* The stage interface (src/core/stage.h): the schedule a scene gets, a stage inserted from
 * outside (as a halo exchange would be) runs at its place every step without editing the loop,
 * bad insertions are refused, and the explicit hand-over of the pair accelerations survives a
 * stage that touches the pressure accelerations in between (the schedule then gives the pair
 * accelerations their own arrays: the same bits as without it). */
#include <stdio.h>
#include <string.h>

#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const char *PAIR_SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.0025, \"domain\": {\"min\": [-0.1, -0.1], \"max\": [0.2, 0.2]},"
    " \"gravity\": [0, 0], \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.01},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-3}],"
    " \"pairwise\": {\"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 4}]},"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.1, 0.05], \"phase\": \"water\"}]}";

typedef struct probe {
    int calls;
    uint64_t last_step;
    int saw_dt; /* the step's dt was set when it ran (it runs after the timestep stage) */
} probe;

static int probe_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    probe *p = state;
    p->calls++;
    p->last_step = st->step;
    p->saw_dt = st->ctx->dt > 0 && st->ctx->step == st->step;
    return PFSPH_OK;
}

static const pfsph_stage_ops probe_stage = {
    .name = "probe", .slot = PFSPH_STAGE_OUTPUT, .reads = PFSPH_D_DT, .run = probe_run};
/* writes the pressure accelerations (zeros: the solve overwrites them anyway) and says so:
 * between the pair walk and the pairwise stage that forbids keeping the pair accelerations in
 * ap's arrays; were they kept there, this stage would erase them and the runs would differ */
static int ap_clear_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    for (size_t i = 0; i < st->ctx->fluid->n; i++) st->ap[0][i] = st->ap[1][i] = st->ap[2][i] = 0;
    return probe_run(state, st, bad, err);
}
static const pfsph_stage_ops ap_reader = {
    .name = "ap_reader", .slot = PFSPH_STAGE_OUTPUT, .writes = PFSPH_D_AP, .run = ap_clear_run};

static pfsph_sim *make(pfsph_scene *s)
{
    pfsph_error err = {0};
    if (pfsph_scene_parse(s, PAIR_SCENE, "stages", &err)) fail_msg("%s", err.msg);
    pfsph_sim *sim = NULL;
    if (pfsph_sim_create(&sim, s, &err)) fail_msg("%s", err.msg);
    return sim;
}

/* "output": {"surface_layer": false} drops the output stage that peels the surface (20 min at
 * frame 0 of the 1.9e8-particle table-1 scene) and its buffer; on by default, with an outer layer
 * present and the interior unmarked. */
static void surface_layer_output_is_optional(void **state)
{
    (void)state;
    for (int on = 0; on < 2; on++) {
        char json[2048];
        snprintf(json, sizeof json, "%.*s, \"output\": {\"surface_layer\": %s}}", (int)strlen(PAIR_SCENE) - 1,
                 PAIR_SCENE, on ? "true" : "false");
        pfsph_sim *sim = tu_sim_from_json(json, "surface_layer");
        pfsph_error err = {0};
        if (pfsph_sim_output(sim, &err)) fail_msg("%s", err.msg);
        const uint8_t *layer = pfsph_sim_output_surface_layer(sim);
        if (!on) {
            assert_null(layer);
        } else {
            assert_non_null(layer);
            size_t outer = 0, inner = 0;
            const size_t n = pfsph_sim_ctx(sim)->fluid->n;
            for (size_t i = 0; i < n; i++) {
                outer += layer[i] == 1;
                inner += layer[i] == 0;
            }
            assert_true(outer > 0 && inner > 0);
        }
        pfsph_sim_destroy(sim);
    }
}

typedef struct notes {
    int n;
    double total;
    char first[256];
} notes;

static void note(const char *done, double wall_s, double cpu_s, void *user)
{
    notes *k = user;
    if (!k->n) snprintf(k->first, sizeof k->first, "%s", done);
    k->n++;
    assert_true(wall_s >= 0 && cpu_s >= 0);
    k->total += wall_s;
}

/* pfsph_sim_create_ex tells its caller each phase of the set-up (the program prints the slow
 * ones: minutes at 1.9e8 particles): the sampling first, with the particle counts. */
static void setup_reports_its_phases(void **state)
{
    (void)state;
    pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, PAIR_SCENE, "<notes>", &err), PFSPH_OK);
    notes k = {0};
    pfsph_sim *sim = NULL;
    if (pfsph_sim_create_ex(&sim, &s, note, &k, &err)) fail_msg("%s", err.msg);
    assert_int_equal(k.n, 3);
    char want[64];
    snprintf(want, sizeof want, "sampled %zu fluid and 0 boundary particles", pfsph_sim_ctx(sim)->fluid->n);
    assert_string_equal(k.first, want);
    pfsph_sim_destroy(sim);
}

static int index_of(const pfsph_sim *sim, const char *name)
{
    for (int i = 0; i < pfsph_sim_stage_count(sim); i++)
        if (!strcmp(pfsph_sim_stage_name(sim, i), name)) return i;
    return -1;
}

static void inserted_stage_runs_in_place(void **state)
{
    (void)state;
    static pfsph_scene s;
    pfsph_sim *sim = make(&s);
    /* pair forces under PCISPH: the density is summed in the pair walk */
    assert_true(index_of(sim, "density") >= 0 && index_of(sim, "pairwise") > index_of(sim, "density"));
    int n0 = pfsph_sim_stage_count(sim);
    probe p = {0};
    pfsph_error err = {0};
    /* refused: an unknown anchor */
    assert_int_equal(pfsph_sim_insert_stage(sim, "nosuch", 0, &probe_stage, &p, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "nosuch"));
    assert_int_equal(pfsph_sim_insert_stage(sim, "timestep", 1, &probe_stage, &p, &err), PFSPH_OK);
    assert_int_equal(pfsph_sim_stage_count(sim), n0 + 1);
    assert_int_equal(index_of(sim, "probe"), index_of(sim, "timestep") + 1);
    /* refused: a name in use, a stage without run */
    assert_int_equal(pfsph_sim_insert_stage(sim, "grid", 0, &probe_stage, &p, &err), PFSPH_EINPUT);
    pfsph_stage_ops norun = {.name = "norun"};
    assert_int_equal(pfsph_sim_insert_stage(sim, "grid", 0, &norun, NULL, &err), PFSPH_EINPUT);
    assert_int_equal(pfsph_sim_stage_count(sim), n0 + 1);
    for (int k = 0; k < 5; k++) assert_int_equal(pfsph_sim_step(sim, 1.0, &err), PFSPH_OK);
    assert_int_equal(p.calls, 5);
    assert_int_equal((int)p.last_step, 4);
    assert_true(p.saw_dt);
    pfsph_sim_destroy(sim);
}

static void hand_over_survives_an_ap_reader(void **state)
{
    (void)state;
    static pfsph_scene s;
    pfsph_sim *a = make(&s), *b = make(&s);
    probe p = {0};
    pfsph_error err = {0};
    assert_int_equal(pfsph_sim_insert_stage(b, "forces", 1, &ap_reader, &p, &err), PFSPH_OK);
    assert_true(index_of(b, "ap_reader") > index_of(b, "density") &&
                index_of(b, "ap_reader") < index_of(b, "pairwise"));
    for (int k = 0; k < 10; k++) {
        assert_int_equal(pfsph_sim_step(a, 1.0, &err), PFSPH_OK);
        assert_int_equal(pfsph_sim_step(b, 1.0, &err), PFSPH_OK);
    }
    assert_int_equal(p.calls, 10);
    const pfsph_particles *fa = pfsph_sim_ctx(a)->fluid, *fb = pfsph_sim_ctx(b)->fluid;
    assert_int_equal(fa->n, fb->n);
    assert_true(fa->n > 100);
    /* the same bits: the pair accelerations reached the pairwise stage intact */
    assert_memory_equal(fa->x, fb->x, fa->n * sizeof(pfsph_real));
    assert_memory_equal(fa->vy, fb->vy, fa->n * sizeof(pfsph_real));
    pfsph_sim_destroy(a);
    pfsph_sim_destroy(b);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(inserted_stage_runs_in_place), cmocka_unit_test(hand_over_survives_an_ap_reader),
        cmocka_unit_test(surface_layer_output_is_optional), cmocka_unit_test(setup_reports_its_phases)};
    return tu_run_group(tests, NULL, NULL);
}
