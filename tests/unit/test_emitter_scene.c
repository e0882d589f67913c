/* Emitter scene keys (docs/scene-format.md#emitters): bad values exit with status 2 and a message
 * "<file>: $.emitters[i].<key>: <reason>" from `pfsph check` and `pfsph run`; a good scene's
 * check lists each nozzle (sites, speed, rate) and counts the most fluid it can hold, and the
 * memory estimate grows with it; a scene may start without fluid when an emitter fills it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/checkpoint.h"
#include "pfsph/emitter.h"
#include "pfsph/sim.h"
#include "testutil.h"

#define HEAD2                                                                                         \
    "{\"dimension\": 2, \"particle_radius\": 0.0025, \"domain\": {\"min\": [0, 0], \"max\": [1, 1]}," \
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}], "
#define HEAD3                                                                            \
    "{\"particle_radius\": 0.005, \"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}," \
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}], "

/* a water box and a bubble of air with a soap film: the emitter key "bubble" */
#define HEADB                                                                                            \
    "{\"dimension\": 2, \"particle_radius\": 0.0025, \"domain\": {\"min\": [0, 0], \"max\": [1, 1]},"    \
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"air\", \"kind\": \"gas\"}], \"fluid\": ["         \
    "{\"shape\": \"box\", \"min\": [0, 0], \"max\": [1, 0.1]}, {\"shape\": \"sphere\", \"center\": "     \
    "[0.5, 0.5], \"radius\": 0.1, \"phase\": \"air\", \"bubble\": {\"film\": \"water\", \"thickness\": " \
    "0.001}}], \"emitters\": [{\"center\": [0.5, 0.5], \"width\": 0.02, \"direction\": [0, 1], "         \
    "\"speed\": 0.1, "

typedef struct bad_case {
    const char *json;
    const char *expect; /* after "<path>: " */
} bad_case;

static const bad_case cases[] = {
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], \"speed\": 1, "
           "\"sped\": 2}]}",
     "$.emitters[0].sped: unknown key \"sped\""},
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], \"speed\": 1, "
           "\"rate\": 0.1}]}",
     "$.emitters[0].rate: give \"speed\" or \"rate\", not both"},
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1]}]}",
     "$.emitters[0].speed: missing required key \"speed\" (m/s) or \"rate\""},
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], \"speed\": -1}]}",
     "$.emitters[0].speed: value -1 is out of range: must be > 0"},
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], \"speed\": 2000}]}",
     "$.emitters[0].speed: value 2000 is out of range"},
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, 0], \"speed\": 1}]}",
     "$.emitters[0].direction: must not be zero"},
    {HEAD2 "\"emitters\": [{\"center\": [1.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], \"speed\": 1}]}",
     "$.emitters[0].center: the nozzle's centre lies outside the domain"},
    {HEAD2 "\"emitters\": [{\"shape\": \"disc\", \"center\": [0.5, 0.9], \"radius\": 0.1, \"direction\": [0, -1], "
           "\"speed\": 1}]}",
     "$.emitters[0].shape: expected \"segment\" in 2D"},
    {HEAD3 "\"emitters\": [{\"shape\": \"segment\", \"center\": [0.5, 0.9, 0.5], \"width\": 0.1, "
           "\"direction\": [0, -1, 0], \"speed\": 1}]}",
     "$.emitters[0].shape: expected \"disc\" or \"rectangle\" in 3D"},
    {HEAD3 "\"emitters\": [{\"center\": [0.5, 0.9, 0.5], \"width\": 0.1, \"direction\": [0, -1, 0], \"speed\": 1}]}",
     "$.emitters[0].width: not used by a \"disc\" nozzle (it takes \"radius\")"},
    {HEAD3 "\"emitters\": [{\"shape\": \"rectangle\", \"center\": [0.5, 0.9, 0.5], \"size\": [0.1, 0], "
           "\"direction\": [0, -1, 0], \"speed\": 1}]}",
     "$.emitters[0].size: size[1] = 0 must be > 0"},
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], \"speed\": 1, "
           "\"start\": 0.5, \"stop\": 0.2}]}",
     "$.emitters[0].stop: stop 0.2 s must be after start 0.5 s"},
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], \"speed\": 1, "
           "\"start\": -1}]}",
     "$.emitters[0].start: value -1 is out of range"},
    {HEAD2 "\"emitters\": [{\"phase\": \"wall\", \"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], "
           "\"speed\": 1}]}",
     "$.emitters[0].phase: phase \"wall\" is a solid phase"},
    {HEAD2 "\"emitters\": [{\"phase\": \"oil\", \"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1], "
           "\"speed\": 1}]}",
     "$.emitters[0].phase: unknown phase \"oil\""},
    {HEAD2
     "\"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.1, 0.1]}], \"emitters\": {\"center\": [0.5, 0.9]}}",
     "$.emitters: expected an array of emitters"},
    {HEAD2 "\"emitters\": []}", "$.fluid: a scene needs at least one fluid block"},
    /* the lattice: a segment narrower than a spacing between two sites holds none */
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.001, \"direction\": [0, -1], \"speed\": 1}]}",
     "$.emitters[0]: the nozzle holds no lattice site inside the domain"},
    /* a rate that only a jet faster than 1000 m/s delivers */
    {HEAD2 "\"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.01, \"direction\": [0, -1], \"rate\": 100}]}",
     "$.emitters[0].rate: 100 through 2 sites needs an entry speed of 10000 m/s"},
    /* "bubble": the index of a fluid block that is a bubble, blowing that bubble's gas */
    {HEADB "\"bubble\": 1.5}]}", "$.emitters[0].bubble: expected the index of a fluid block"},
    {HEADB "\"bubble\": \"1\"}]}", "$.emitters[0].bubble: expected the index of a fluid block"},
    {HEADB "\"bubble\": 2}]}", "$.emitters[0].bubble: 2 is not a fluid block: $.fluid has 2 (indices 0 .. 1)"},
    {HEADB "\"bubble\": 0}]}", "$.emitters[0].bubble: 0: $.fluid[0] is not a bubble"},
    {HEADB "\"phase\": \"water\", \"bubble\": 1}]}",
     "$.emitters[0].bubble: 1: the emitter's phase \"water\" is not the gas \"air\" of bubble $.fluid[1]"},
};
#define NCASES (sizeof cases / sizeof cases[0])

static void test_bad_keys_exit_2(void **st)
{
    (void)st;
    for (size_t i = 0; i < NCASES; i++) {
        char path[512], cmd[2048], out[4096], want[1024];
        snprintf(path, sizeof path, "%s/bad_%zu.json", tu_tmpdir(), i);
        assert_int_equal(tu_write_file(path, cases[i].json), 0);
        snprintf(want, sizeof want, "%s: %s", path, cases[i].expect);
        snprintf(cmd, sizeof cmd, "'%s' check '%s'", tu_pfsph_bin(), path);
        int rc = tu_run(cmd, out, sizeof out);
        if (rc != 2 || !strstr(out, want))
            fail_msg("case %zu: check exit %d, expected 2 and \"%s\":\n%s", i, rc, want, out);
        snprintf(cmd, sizeof cmd, "cd '%s' && '%s' run '%s' -o '%s/run_%zu' --quiet", tu_tmpdir(), tu_pfsph_bin(), path,
                 tu_tmpdir(), i);
        rc = tu_run(cmd, out, sizeof out);
        if (rc != 2 || !strstr(out, want))
            fail_msg("case %zu: run exit %d, expected 2 and \"%s\":\n%s", i, rc, want, out);
    }
}

/* "bubble": 1 names the bubble of $.fluid[1] (the scene's bubble 0): the emitter takes its gas
 * without "phase", stores k + 1 = 1, and the key enters the checkpoint's scene hash only when set
 * (older emitter scenes keep theirs). */
static void test_bubble_key(void **st)
{
    (void)st;
    static pfsph_scene s;
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(&s, HEADB "\"bubble\": 1}]}", "blow", &err);
    if (rc) fail_msg("%s", err.msg);
    assert_int_equal(s.emitters[0].phase, pfsph_scene_phase_index(&s, "air"));
    assert_int_equal(s.emitters[0].bubble, 1);
    const uint64_t h1 = pfsph_scene_hash(&s);
    s.emitters[0].bubble = 0;
    assert_true(pfsph_scene_hash(&s) != h1);
    assert_int_equal(pfsph_scene_parse(&s, HEADB "\"phase\": \"air\"}]}", "plain", &err), PFSPH_OK);
    assert_int_equal(s.emitters[0].bubble, 0);
}

/* A good scene: 20 sites (width 0.1 m at d = 5 mm), 1 m/s -> 200 layers/s, 0.1 m^2/s; open from
 * 0.2 to 0.7 s of a 1 s scene: at most (floor(200 x 0.5) + 1) x 20 = 2,020 particles. */
static void test_check_counts(void **st)
{
    (void)st;
    const char *json =
        HEAD2 "\"gravity\": [0, 0], \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.1, 0.1]}],"
              " \"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1, \"direction\": [0, -1],"
              " \"speed\": 1, \"start\": 0.2, \"stop\": 0.7}]}";
    char path[512], cmd[2048], out[8192];
    snprintf(path, sizeof path, "%s/good.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, json), 0);
    snprintf(cmd, sizeof cmd, "'%s' check '%s'", tu_pfsph_bin(), path);
    int rc = tu_run(cmd, out, sizeof out);
    printf("%s", out);
    if (rc) fail_msg("exit %d: %s", rc, out);
    assert_non_null(strstr(out, "particles: 400 fluid at the start, up to 2420 with the emitters' by t = 1 s"));
    assert_non_null(strstr(out,
                           "[0] segment of 20 sites, phase \"water\", 1 m/s, 0.1 m^2/s (100 kg/s per metre, "
                           "200 layers/s), from 0.2 s to 0.7 s"));
    assert_non_null(strstr(out, "1 emitter"));

    /* the estimate counts the most fluid: a nozzle open longer needs more memory */
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, json, "good", &err), PFSPH_OK);
    size_t nf, nb, b1, b2, ne;
    assert_int_equal(pfsph_scene_estimate(&s, &nf, &nb, &b1, &err), PFSPH_OK);
    assert_int_equal(pfsph_scene_emitted_max(&s, s.end_time, &ne, &err), PFSPH_OK);
    assert_int_equal(nf, 400);
    assert_int_equal(ne, 2020);
    s.emitters[0].stop = INFINITY;
    assert_int_equal(pfsph_scene_estimate(&s, &nf, &nb, &b2, &err), PFSPH_OK);
    assert_int_equal(pfsph_scene_emitted_max(&s, s.end_time, &ne, &err), PFSPH_OK);
    assert_int_equal(ne, 3220); /* (160 + 1) x 20 */
    printf("estimate: %zu bytes for 2,420 fluid particles at most, %zu for 3,620\n", b1, b2);
    assert_true(b2 > b1);
    assert_true((double)(b2 - b1) / 1200 > 100); /* per particle: the set, scratch, sort, states */

    /* the simulation reserves the most up front: emitting never grows the arrays */
    pfsph_sim *sim = NULL;
    s.end_time = 0.3;
    assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    size_t cap = f->cap;
    assert_true(cap >= 400 + 420);
    assert_int_equal(pfsph_sim_advance(sim, 0.3, &err), PFSPH_OK);
    printf("reserved %zu, %zu particles at 0.3 s, capacity %zu\n", cap, f->n, f->cap);
    assert_int_equal(f->n, 400 + 400); /* 20 layers of 20 in 0.1 s */
    assert_int_equal(f->cap, cap);
    /* past the scene's end (a longer --end): the arrays grow */
    assert_int_equal(pfsph_sim_advance(sim, 0.5, &err), PFSPH_OK);
    printf("%zu particles at 0.5 s, capacity %zu\n", f->n, f->cap);
    assert_int_equal(f->n, 400 + 1200);
    assert_true(f->cap >= f->n);
    pfsph_sim_destroy(sim);
}

/* A checkpoint's emitter state is checked against the nozzle: layers owed in [0, 1), emitted +
 * refused a whole number of layers, no more layers than the time allows; and a checkpoint with
 * emitters restores into a fresh simulation to the same state (encode, decode, encode again). */
static void test_state_checks(void **st)
{
    (void)st;
    const char *json = HEAD2 "\"gravity\": [0, 0], \"emitters\": [{\"center\": [0.5, 0.9], \"width\": 0.1,"
                             " \"direction\": [0, -1], \"speed\": 1}], \"time\": {\"end\": 0.2}}";
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, json, "state", &err), PFSPH_OK);
    pfsph_sim *sim = NULL;
    assert_int_equal(pfsph_sim_create(&sim, &s, &err), PFSPH_OK);
    const pfsph_emitters *E = pfsph_sim_emitters(sim);
    /* 20 sites, 200 layers/s: by 0.1 s at most 21 layers */
    const pfsph_emitter_state good = {0.25, 400, 20, 0}, owed = {1.0, 400, 0, 0}, partial = {0.5, 399, 0, 0},
                              many = {0.5, 22 * 20, 0, 0};
    assert_int_equal(pfsph_emitters_check_state(E, 0, &good, 0.1, &err), PFSPH_OK);
    assert_int_equal(pfsph_emitters_check_state(E, 0, &owed, 0.1, &err), PFSPH_EINPUT);
    assert_int_equal(pfsph_emitters_check_state(E, 0, &partial, 0.1, &err), PFSPH_EINPUT);
    assert_int_equal(pfsph_emitters_check_state(E, 0, &many, 0.1, &err), PFSPH_EINPUT);
    printf("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "is not one this nozzle of 20 sites reaches by t = 0.1 s"));
    assert_int_equal(pfsph_sim_restore_emitters(sim, 2, &good, 0.1, &err), PFSPH_EINPUT);

    assert_int_equal(pfsph_sim_advance(sim, 0.08, &err), PFSPH_OK);
    void *a = NULL, *b = NULL;
    size_t la, lb;
    assert_int_equal(pfsph_checkpoint_encode(sim, 2, &a, &la, &err), PFSPH_OK);
    pfsph_sim *sim2 = NULL;
    assert_int_equal(pfsph_sim_create(&sim2, &s, &err), PFSPH_OK);
    int rc = pfsph_checkpoint_decode(sim2, a, la, "mem", NULL, &err);
    if (rc) fail_msg("%s", err.msg);
    pfsph_emitter_state s1, s2;
    pfsph_emitters_get_state(pfsph_sim_emitters(sim), 0, &s1);
    pfsph_emitters_get_state(pfsph_sim_emitters(sim2), 0, &s2);
    assert_memory_equal(&s1, &s2, sizeof s1);
    assert_true((s1.emitted == 15 * 20 || s1.emitted == 16 * 20) && s1.debt >= 0 && s1.debt < 1);
    assert_int_equal(pfsph_checkpoint_encode(sim2, 2, &b, &lb, &err), PFSPH_OK);
    assert_int_equal(la, lb);
    /* the stored stage seconds differ; all after them (the fluid set, the diffuse flag, the body
     * count, the emitters) does not */
    const size_t tail =
        8 + 4 + pfsph_sim_ctx(sim)->fluid->n * (PFSPH_NFIELDS * sizeof(pfsph_real) + 5) + 1 + 4 + 4 + 32;
    assert_memory_equal((char *)a + la - tail, (char *)b + lb - tail, tail);
    free(a);
    free(b);
    pfsph_sim_destroy(sim);
    pfsph_sim_destroy(sim2);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_keys_exit_2),
        cmocka_unit_test(test_check_counts),
        cmocka_unit_test(test_bubble_key),
        cmocka_unit_test(test_state_checks),
    };
    return tu_run_group(tests, NULL, NULL);
}
