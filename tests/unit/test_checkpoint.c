/* Checkpoints: a round trip restores every bit of the state (and the next step is then the same
 * bit for bit); a flipped byte, a truncated file and a checkpoint of another scene are refused
 * with a message naming the file; only the newest 2 are kept; resume falls back past a corrupt
 * one. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <glob.h>
#include <limits.h>
#include <sys/stat.h>
#include <zlib.h>

#include "pfsph/checkpoint.h"
#include "pfsph/sim.h"
#include "testutil.h"

/* 2D dam break, coarse, with diffuse particles generated early (low thresholds). */
static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, %s],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [1.05, 0.8]},"
    " \"solver\": {\"type\": \"%s\"}, \"time\": {\"end\": 1, \"fps\": 25, \"dt_max\": 0.004},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 5e-4},"
    "              {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.3, 0.5], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [1.0, 0.7], \"open_top\": true,"
    "               \"layers\": 2, \"phase\": \"wall\"}],"
    " \"diffuse\": {\"enabled\": true, \"sampling_rate\": 400, \"phi_v_min\": 0.05, \"phi_v_max\": 1,"
    "               \"phi_e_min\": 0.1, \"phi_e_max\": 2, \"energy_mass\": 1.0,"
    "               \"lifetime_min\": 0.5, \"lifetime_max\": 2}}";

static pfsph_sim *make_sim(const char *gravity, const char *solver)
{
    char json[4096];
    snprintf(json, sizeof json, SCENE, gravity, solver);
    pfsph_sim *sim = tu_sim_from_json(json, "ckpt-scene");
    return sim;
}

static void assert_same_set(const pfsph_particles *a, const pfsph_particles *b)
{
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->next_id, b->next_id);
    for (int k = 0; k < PFSPH_NFIELDS; k++) assert_memory_equal(a->f[k], b->f[k], a->n * sizeof(pfsph_real));
    assert_memory_equal(a->phase, b->phase, a->n);
    assert_memory_equal(a->id, b->id, a->n * sizeof(uint32_t));
}

static void assert_same_sim(const pfsph_sim *a, const pfsph_sim *b)
{
    pfsph_sim_state sa, sb;
    pfsph_sim_get_state(a, &sa);
    pfsph_sim_get_state(b, &sb);
    assert_memory_equal(&sa.time, &sb.time, sizeof(double));
    assert_int_equal(sa.step, sb.step);
    assert_memory_equal(&sa.amax, &sb.amax, sizeof(double));
    assert_memory_equal(&sa.amax_np, &sb.amax_np, sizeof(double));
    assert_int_equal(sa.removed, sb.removed);
    assert_memory_equal(&sa.stats.vmax, &sb.stats.vmax, sizeof(double));
    assert_memory_equal(&sa.stats.dt, &sb.stats.dt, sizeof(double));
    assert_memory_equal(&sa.stats.ekin, &sb.stats.ekin, sizeof(double));
    assert_int_equal(sa.stats.iterations, sb.stats.iterations);
    assert_same_set(pfsph_sim_ctx(a)->fluid, pfsph_sim_ctx(b)->fluid);
    const pfsph_particles *da = pfsph_sim_diffuse(a), *db = pfsph_sim_diffuse(b);
    assert_true((da == NULL) == (db == NULL));
    if (da) assert_same_set(da, db);
    uint64_t ca, ra, cb, rb;
    pfsph_sim_diffuse_totals(a, &ca, &ra);
    pfsph_sim_diffuse_totals(b, &cb, &rb);
    assert_int_equal(ca, cb);
    assert_int_equal(ra, rb);
}

static void roundtrip(const char *solver)
{
    pfsph_error err = {0};
    pfsph_sim *a = make_sim("-9.81", solver);
    assert_int_equal(pfsph_sim_advance(a, 0.2, &err), PFSPH_OK);
    assert_true(pfsph_sim_diffuse(a)->n > 0); /* the diffuse set is exercised */
    void *data;
    size_t len;
    assert_int_equal(pfsph_checkpoint_encode(a, 5, &data, &len, &err), PFSPH_OK);
    pfsph_sim *b = make_sim("-9.81", solver);
    pfsph_checkpoint_info info = {0};
    int rc = pfsph_checkpoint_decode(b, data, len, "mem", &info, &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    assert_int_equal(info.frame, 5);
    assert_int_equal(info.threads, omp_get_max_threads());
    assert_true(info.time == pfsph_sim_time(a));
    assert_int_equal(info.step, pfsph_sim_steps(a));
    assert_same_sim(a, b);
    /* continuing gives the same bits */
    assert_int_equal(pfsph_sim_advance(a, 0.28, &err), PFSPH_OK);
    assert_int_equal(pfsph_sim_advance(b, 0.28, &err), PFSPH_OK);
    assert_same_sim(a, b);
    free(data);
    pfsph_sim_destroy(a);
    pfsph_sim_destroy(b);
}

static void test_roundtrip_pcisph(void **st)
{
    (void)st;
    roundtrip("pcisph");
}

static void test_roundtrip_wcsph(void **st)
{
    (void)st;
    roundtrip("wcsph");
}

/* DFSPH keeps state between steps in particle fields (pressure: warm start; aux: divergence
 * pressure): a resumed run must carry it */
static void test_roundtrip_dfsph(void **st)
{
    (void)st;
    roundtrip("dfsph");
}

/* Load must fail with PFSPH_EINPUT, a message naming the file and containing `what`, and leave
 * the simulation as it was. */
static void expect_reject(const char *path, const char *what)
{
    pfsph_sim *b = make_sim("-9.81", "pcisph");
    pfsph_error err = {0};
    pfsph_checkpoint_info info;
    int rc = pfsph_checkpoint_load(path, b, &info, &err);
    fprintf(stderr, "  rejected as expected: %s\n", err.msg);
    assert_int_equal(rc, PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, what));
    assert_true(pfsph_sim_time(b) == 0.0);
    assert_int_equal(pfsph_sim_steps(b), 0);
    pfsph_sim_destroy(b);
}

static void test_corrupt_and_truncated(void **st)
{
    (void)st;
    pfsph_error err = {0};
    pfsph_sim *a = make_sim("-9.81", "pcisph");
    assert_int_equal(pfsph_sim_advance(a, 0.08, &err), PFSPH_OK);
    char path[512], bad[512];
    snprintf(path, sizeof path, "%s/good.bin", tu_tmpdir());
    size_t bytes = 0;
    assert_int_equal(pfsph_checkpoint_save(path, a, 2, &bytes, &err), PFSPH_OK);
    size_t len;
    unsigned char *b = tu_slurp(path, &len);
    assert_int_equal(len, bytes);
    /* the file is written from the arrays through a staging buffer, the buffer in one piece:
     * the same bytes, and a stash (no fsync) too */
    void *mem;
    size_t mlen;
    assert_int_equal(pfsph_checkpoint_encode(a, 2, &mem, &mlen, &err), PFSPH_OK);
    assert_int_equal(mlen, len);
    assert_memory_equal(mem, b, len);
    free(mem);
    char stash[512];
    snprintf(stash, sizeof stash, "%s/stash.bin", tu_tmpdir());
    assert_int_equal(pfsph_checkpoint_stash(stash, a, 2, &err), PFSPH_OK);
    size_t slen;
    unsigned char *sb = tu_slurp(stash, &slen);
    assert_int_equal(slen, len);
    assert_memory_equal(sb, b, len);
    free(sb);

    /* payload byte flipped (in the middle of the particle arrays) */
    snprintf(bad, sizeof bad, "%s/flipped.bin", tu_tmpdir());
    b[len / 2] ^= 0x10;
    tu_write_bytes(bad, b, len);
    expect_reject(bad, "checksum");
    b[len / 2] ^= 0x10;
    /* header byte flipped (the step count's neighbour: the payload length) */
    snprintf(bad, sizeof bad, "%s/flipped_header.bin", tu_tmpdir());
    b[26] ^= 0x01;
    tu_write_bytes(bad, b, len);
    expect_reject(bad, "checksum");
    b[26] ^= 0x01;
    /* last byte flipped */
    snprintf(bad, sizeof bad, "%s/flipped_last.bin", tu_tmpdir());
    b[len - 1] ^= 0x80;
    tu_write_bytes(bad, b, len);
    expect_reject(bad, "checksum");
    b[len - 1] ^= 0x80;
    /* truncated: by one byte, in the middle, inside the header, empty */
    snprintf(bad, sizeof bad, "%s/truncated.bin", tu_tmpdir());
    const size_t cuts[] = {len - 1, len / 3, 20, 0};
    for (size_t k = 0; k < sizeof cuts / sizeof cuts[0]; k++) {
        tu_write_bytes(bad, b, cuts[k]);
        expect_reject(bad, "truncated");
    }
    /* the intact file still loads */
    pfsph_sim *c = make_sim("-9.81", "pcisph");
    pfsph_checkpoint_info info;
    assert_int_equal(pfsph_checkpoint_load(path, c, &info, &err), PFSPH_OK);
    assert_int_equal(info.frame, 2);
    assert_same_sim(a, c);
    free(b);
    pfsph_sim_destroy(a);
    pfsph_sim_destroy(c);
}

static void test_other_scene(void **st)
{
    (void)st;
    pfsph_error err = {0};
    pfsph_sim *a = make_sim("-9.81", "pcisph");
    char path[512];
    snprintf(path, sizeof path, "%s/other.bin", tu_tmpdir());
    assert_int_equal(pfsph_checkpoint_save(path, a, 0, NULL, &err), PFSPH_OK);
    const char *variants[][2] = {{"-9.0", "pcisph"}, {"-9.81", "wcsph"}};
    for (int v = 0; v < 2; v++) {
        pfsph_sim *b = make_sim(variants[v][0], variants[v][1]);
        int rc = pfsph_checkpoint_load(path, b, NULL, &err);
        fprintf(stderr, "  rejected as expected: %s\n", err.msg);
        assert_int_equal(rc, PFSPH_EINPUT);
        assert_non_null(strstr(err.msg, path));
        assert_non_null(strstr(err.msg, "another scene"));
        pfsph_sim_destroy(b);
    }
    /* output settings and the end time are not part of the hash */
    static pfsph_scene s1, s2;
    char json[4096];
    snprintf(json, sizeof json, SCENE, "-9.81", "pcisph");
    assert_int_equal(pfsph_scene_parse(&s1, json, "a", &err), PFSPH_OK);
    s2 = s1;
    s2.end_time = 7;
    s2.output.checkpoint_interval = 3;
    s2.threads = 5;
    assert_true(pfsph_scene_hash(&s1) == pfsph_scene_hash(&s2));
    s2.seed = s1.seed + 1;
    assert_true(pfsph_scene_hash(&s1) != pfsph_scene_hash(&s2));
    pfsph_sim_destroy(a);
}

static void test_scene_key(void **st)
{
    (void)st;
    static pfsph_scene s;
    pfsph_error err = {0};
    char base[4096], json[4200];
    snprintf(base, sizeof base, SCENE, "-9.81", "pcisph");
    base[strlen(base) - 1] = 0; /* drop the closing brace */
    snprintf(json, sizeof json, "%s}", base);
    int rc = pfsph_scene_parse(&s, json, "k", &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    assert_int_equal(s.output.checkpoint_interval, 10);
    snprintf(json, sizeof json, "%s, \"output\": {\"checkpoint_interval\": 0}}", base);
    assert_int_equal(pfsph_scene_parse(&s, json, "k", &err), PFSPH_OK);
    assert_int_equal(s.output.checkpoint_interval, 0);
    snprintf(json, sizeof json, "%s, \"output\": {\"checkpoint_interval\": -1}}", base);
    assert_int_equal(pfsph_scene_parse(&s, json, "k", &err), PFSPH_EINPUT);
    fprintf(stderr, "  rejected as expected: %s\n", err.msg);
    assert_non_null(strstr(err.msg, "$.output.checkpoint_interval"));
}

static int nwarn;
static char lastwarn[1200];
static void on_warn(const char *msg, void *user)
{
    (void)user;
    nwarn++;
    snprintf(lastwarn, sizeof lastwarn, "%s", msg);
    fprintf(stderr, "  warning: %s\n", msg);
}

static void test_keep_and_fallback(void **st)
{
    (void)st;
    pfsph_error err = {0};
    const char *run = tu_tmpdir();
    pfsph_sim *a = make_sim("-9.81", "pcisph");
    pfsph_sim *ref = make_sim("-9.81", "pcisph");
    for (int fr = 1; fr <= 3; fr++) {
        assert_int_equal(pfsph_sim_advance(a, fr * 0.04, &err), PFSPH_OK);
        assert_int_equal(pfsph_checkpoint_write_run(run, a, fr, PFSPH_CHECKPOINT_KEEP, NULL, &err), PFSPH_OK);
        if (fr <= 2) assert_int_equal(pfsph_sim_advance(ref, fr * 0.04, &err), PFSPH_OK);
    }
    char p1[1100], p2[1100], p3[1100];
    struct stat sb;
    pfsph_checkpoint_path(p1, sizeof p1, run, 1);
    pfsph_checkpoint_path(p2, sizeof p2, run, 2);
    pfsph_checkpoint_path(p3, sizeof p3, run, 3);
    assert_int_not_equal(stat(p1, &sb), 0); /* pruned */
    assert_int_equal(stat(p2, &sb), 0);
    assert_int_equal(stat(p3, &sb), 0);

    /* newest intact: used, no warning */
    pfsph_sim *b = make_sim("-9.81", "pcisph");
    pfsph_checkpoint_info info;
    nwarn = 0;
    assert_int_equal(pfsph_checkpoint_resume(run, b, &info, on_warn, NULL, &err), PFSPH_OK);
    assert_int_equal(info.frame, 3);
    assert_int_equal(nwarn, 0);
    assert_same_sim(a, b);
    pfsph_sim_destroy(b);

    /* newest truncated: reported, the previous one used */
    size_t len;
    unsigned char *buf = tu_slurp(p3, &len);
    tu_write_bytes(p3, buf, len - 7);
    free(buf);
    b = make_sim("-9.81", "pcisph");
    nwarn = 0;
    assert_int_equal(pfsph_checkpoint_resume(run, b, &info, on_warn, NULL, &err), PFSPH_OK);
    assert_int_equal(info.frame, 2);
    assert_int_equal(nwarn, 1);
    assert_non_null(strstr(lastwarn, p3));
    assert_same_sim(ref, b);
    pfsph_sim_destroy(b);

    /* both bad: an error naming the folder */
    buf = tu_slurp(p2, &len);
    buf[len / 2] ^= 1;
    tu_write_bytes(p2, buf, len);
    free(buf);
    b = make_sim("-9.81", "pcisph");
    nwarn = 0;
    assert_int_equal(pfsph_checkpoint_resume(run, b, &info, on_warn, NULL, &err), PFSPH_EINPUT);
    assert_int_equal(nwarn, 2);
    assert_non_null(strstr(err.msg, "checkpoints"));
    pfsph_sim_destroy(b);
    pfsph_sim_destroy(a);
    pfsph_sim_destroy(ref);
}

/* ---- crafted checkpoints: valid CRCs over bad contents (issue 15, items 1 and 2) ---- */

enum { OFF_FRAME = 40, OFF_TIME = 56, OFF_NST = 140 };

static uint32_t get_u32(const unsigned char *b) { return b[0] | b[1] << 8 | b[2] << 16 | (uint32_t)b[3] << 24; }
static void put_u32(unsigned char *b, uint32_t v)
{
    for (int k = 0; k < 4; k++) b[k] = (unsigned char)(v >> 8 * k);
}

/* Recompute the payload and header CRC32s after an edit. */
static void reseal(unsigned char *b, size_t len)
{
    put_u32(b + 32, (uint32_t)crc32(crc32(0L, Z_NULL, 0), b + 40, (uInt)(len - 40)));
    put_u32(b + 36, (uint32_t)crc32(crc32(0L, Z_NULL, 0), b, 36));
}

/* Offset of the fluid set's next_id (after u64 n). */
static size_t off_fluid_next_id(const unsigned char *b) { return OFF_NST + 4 + 8 * (size_t)get_u32(b + OFF_NST) + 8; }

static unsigned char *good_checkpoint(int frame, size_t *len)
{
    pfsph_error err = {0};
    pfsph_sim *a = make_sim("-9.81", "pcisph");
    assert_int_equal(pfsph_sim_advance(a, frame / 25.0, &err), PFSPH_OK);
    void *data;
    assert_int_equal(pfsph_checkpoint_encode(a, frame, &data, len, &err), PFSPH_OK);
    pfsph_sim_destroy(a);
    return data;
}

/* Decoding must refuse with PFSPH_EINPUT and a message containing `what`, sim untouched. */
static void expect_reject_mem(const unsigned char *b, size_t len, const char *what)
{
    pfsph_sim *s = make_sim("-9.81", "pcisph");
    pfsph_error err = {0};
    int rc = pfsph_checkpoint_decode(s, b, len, "crafted", NULL, &err);
    fprintf(stderr, "  rejected as expected: %s\n", err.msg);
    assert_int_equal(rc, PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "crafted"));
    assert_non_null(strstr(err.msg, what));
    assert_true(pfsph_sim_time(s) == 0.0);
    pfsph_sim_destroy(s);
}

/* Item 1: an id >= next_id used to crash (the message read the freed id array). */
static void test_crafted_ids(void **st)
{
    (void)st;
    size_t len;
    unsigned char *b = good_checkpoint(2, &len);
    const size_t o = off_fluid_next_id(b);
    const uint32_t next = get_u32(b + o);
    put_u32(b + o, 0);
    reseal(b, len);
    expect_reject_mem(b, len, "particle id 0 not below next id 0");
    /* ids all below a larger next id, but the scene never made that many */
    put_u32(b + o, next + 1000);
    reseal(b, len);
    expect_reject_mem(b, len, "fluid next id");
    put_u32(b + o, next);
    reseal(b, len);
    pfsph_sim *s = make_sim("-9.81", "pcisph");
    pfsph_error err = {0};
    assert_int_equal(pfsph_checkpoint_decode(s, b, len, "crafted", NULL, &err), PFSPH_OK);
    pfsph_sim_destroy(s);
    free(b);
}

/* Item 2: frame INT_MAX made the run loop's frame0 + 1 overflow and write frames until the
 * disk filled. The frame is bounded, the time must be that frame's, a file's name must match
 * the frame it holds, and the clock's rates must be finite. */
static void test_crafted_clock(void **st)
{
    (void)st;
    size_t len;
    unsigned char *b = good_checkpoint(2, &len);
    put_u32(b + OFF_FRAME, INT_MAX);
    reseal(b, len);
    expect_reject_mem(b, len, "frame 2147483647 is outside");
    put_u32(b + OFF_FRAME, (uint32_t)-5);
    reseal(b, len);
    expect_reject_mem(b, len, "frame -5 is outside");
    put_u32(b + OFF_FRAME, 3); /* the time is frame 2's */
    reseal(b, len);
    expect_reject_mem(b, len, "is not the time of frame 3");
    put_u32(b + OFF_FRAME, 2);
    double t;
    memcpy(&t, b + OFF_TIME + 8 * 2, 8); /* amax */
    double inf = INFINITY;
    memcpy(b + OFF_TIME + 8 * 2, &inf, 8);
    reseal(b, len);
    expect_reject_mem(b, len, "amax is inf");
    memcpy(b + OFF_TIME + 8 * 2, &t, 8);
    reseal(b, len);
    /* a file named for frame 7 that holds frame 2 */
    char path[600];
    snprintf(path, sizeof path, "%s/ckpt_00007.bin", tu_tmpdir());
    tu_write_bytes(path, b, len);
    expect_reject(path, "its name says 7");
    snprintf(path, sizeof path, "%s/ckpt_00002.bin", tu_tmpdir());
    tu_write_bytes(path, b, len);
    pfsph_sim *s = make_sim("-9.81", "pcisph");
    pfsph_error err = {0};
    assert_int_equal(pfsph_checkpoint_load(path, s, NULL, &err), PFSPH_OK);
    pfsph_sim_destroy(s);
    free(b);
}

/* A checkpoint of an older format version is refused as such, not as another scene's. */
static void test_older_version(void **st)
{
    (void)st;
    size_t len;
    unsigned char *b = good_checkpoint(2, &len);
    put_u32(b + 8, PFSPH_CHECKPOINT_VERSION - 1);
    reseal(b, len);
    expect_reject_mem(b, len, "written by an older pfsph");
    put_u32(b + 8, PFSPH_CHECKPOINT_VERSION + 1);
    reseal(b, len);
    expect_reject_mem(b, len, "written by a newer pfsph");
    free(b);
}

/* The scene hash (src/scene/scene_hash.c): every shipped scene hashes the same as parsed and as
 * its simulation holds it (pair coefficients resolved, film volumes filled in), and no two
 * alike; colours and the run's own settings do not count, the scene's values do. */
static void test_hash_of_scenes(void **st)
{
    (void)st;
    char pattern[1024];
    snprintf(pattern, sizeof pattern, "%s/scenes/*.json", tu_source_dir());
    glob_t g;
    assert_int_equal(glob(pattern, 0, NULL, &g), 0);
    assert_true(g.gl_pathc >= 5);
    uint64_t *h = calloc(g.gl_pathc, sizeof *h);
    assert_non_null(h);
    static pfsph_scene s, t;
    for (size_t i = 0; i < g.gl_pathc; i++) {
        pfsph_error err = {0};
        if (pfsph_scene_load(&s, g.gl_pathv[i], &err)) fail_msg("%s", err.msg);
        h[i] = pfsph_scene_hash(&s);
        for (size_t j = 0; j < i; j++)
            if (h[j] == h[i]) fail_msg("%s and %s hash alike", g.gl_pathv[j], g.gl_pathv[i]);
        t = s;
        t.phases[0].color[0] += 0.5f;
        t.phases[0].color_set = !t.phases[0].color_set;
        t.end_time += 1;
        t.threads += 3;
        t.output.frame_interval += 1;
        t.camera.fov_deg += 1;
        snprintf(t.source, sizeof t.source, "elsewhere.json");
        assert_true(pfsph_scene_hash(&t) == h[i]);
        t = s;
        t.blocks[0].jitter += 0.1; /* a block in use counts, one beyond nblocks not */
        assert_true((pfsph_scene_hash(&t) != h[i]) == (s.nblocks > 0));
        t = s;
        t.pairwise.shift.D += 1e-3;
        assert_true(pfsph_scene_hash(&t) != h[i]);
        /* the simulation's copy: not for a scene of the full-size kind (Table 1 of the diffuse
         * paper needs 18 GiB) */
        size_t bytes = 0;
        if (pfsph_scene_estimate(&s, NULL, NULL, &bytes, &err)) fail_msg("%s", err.msg);
        if (bytes > ((size_t)512 << 20)) {
            print_message("%s: %zu MiB, not built\n", g.gl_pathv[i], bytes >> 20);
            continue;
        }
        pfsph_sim *sim = NULL;
        if (pfsph_sim_create(&sim, &s, &err)) fail_msg("%s", err.msg);
        if (pfsph_scene_hash(pfsph_sim_scene(sim)) != h[i])
            fail_msg("%s: the simulation's scene hashes otherwise", g.gl_pathv[i]);
        pfsph_sim_destroy(sim);
    }
    free(h);
    globfree(&g);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roundtrip_pcisph), cmocka_unit_test(test_roundtrip_wcsph),
        cmocka_unit_test(test_roundtrip_dfsph),  cmocka_unit_test(test_corrupt_and_truncated),
        cmocka_unit_test(test_other_scene),      cmocka_unit_test(test_keep_and_fallback),
        cmocka_unit_test(test_scene_key),        cmocka_unit_test(test_crafted_ids),
        cmocka_unit_test(test_crafted_clock),    cmocka_unit_test(test_older_version),
        cmocka_unit_test(test_hash_of_scenes),
    };
    return tu_run_group(tests, NULL, NULL);
}
