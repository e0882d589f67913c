/* Interrupt and resume (issue 6): a 2D dam break with diffuse particles run to frame 10 in one
 * go, and run to frame 5 then resumed to frame 10, give the same frame files byte for byte
 * (fluid and diffuse, a middle frame and the last) and the same stats.csv; with the newest
 * checkpoint corrupted, `pfsph run --resume` says so, falls back to the previous one and still
 * matches. A floating box (a rigid body, issue 5) rides the wave: its particles, surfaces and
 * bodies.csv must match too. Same thread count throughout (this process's). Two bubbles in air
 * (docs/film.md) resumed mid-collision: the film fractions and bubble ids come back from the
 * checkpoint, frames (with their film and surface_layer fields) the same bytes. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/run.h"
#include "testutil.h"

/* 25 fps: frame 10 at t = 0.4 s. Low diffuse thresholds so spray/foam/bubbles exist early. */
static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, -9.81],\n"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [1.05, 0.8]},\n"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.4, \"fps\": 25, \"dt_max\": 0.004},\n"
    " \"seed\": 7,\n"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 5e-4},\n"
    "              {\"name\": \"wall\", \"kind\": \"solid\"},\n"
    "              {\"name\": \"wood\", \"kind\": \"solid\", \"rest_density\": 500}],\n"
    " \"bodies\": [{\"name\": \"crate\", \"shape\": \"box\", \"half_extents\": [0.06, 0.04],\n"
    "              \"position\": [0.6, 0.05], \"rotation\": 10, \"phase\": \"wood\"}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.3, 0.5], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [1.0, 0.7], \"open_top\": true,\n"
    "               \"layers\": 2, \"phase\": \"wall\"}],\n"
    " \"diffuse\": {\"enabled\": true, \"sampling_rate\": 400, \"phi_v_min\": 0.05, \"phi_v_max\": 1,\n"
    "               \"phi_e_min\": 0.1, \"phi_e_max\": 2, \"energy_mass\": 1.0,\n"
    "               \"lifetime_min\": 0.5, \"lifetime_max\": 2},\n"
    " \"output\": {\"formats\": [\"vtp\"], \"fields\": [\"id\", \"speed\"], \"checkpoint_interval\": %d}}\n";

static void parse(pfsph_scene *s, int ckpt_interval)
{
    char json[4096];
    snprintf(json, sizeof json, SCENE, ckpt_interval);
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(s, json, "resume-scene", &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
}

static void compare_runs(const char *a, const char *b)
{
    tu_assert_same_file(a, b, "frames/fluid_00010.vtp");
    tu_assert_same_file(a, b, "frames/fluid_00007.vtp");
    tu_assert_same_file(a, b, "frames/diffuse_00010.vtp");
    tu_assert_same_file(a, b, "frames/diffuse_00007.vtp");
    tu_assert_same_file(a, b, "stats.csv");
    tu_assert_same_file(a, b, "frames/bodies_00010.vtp");
    tu_assert_same_file(a, b, "frames/surfaces_00010.vtp");
    tu_assert_same_file(a, b, "bodies.csv");
}

static char full_dir[1024];

static void test_resume_library(void **st)
{
    (void)st;
    static pfsph_scene s;
    parse(&s, 5);
    snprintf(full_dir, sizeof full_dir, "%s/full", tu_tmpdir());
    tu_pfsph_run(&s, full_dir, -1, false);
    char part[1024];
    snprintf(part, sizeof part, "%s/part", tu_tmpdir());
    tu_pfsph_run(&s, part, 0.2, false); /* frames 0..5, checkpoint at 5 */
    tu_pfsph_run(&s, part, 0.4, true);  /* 6..10 (without an end time it would keep its own, 0.2) */
    compare_runs(full_dir, part);
    /* the diffuse set is not empty at frame 10 (so its restore was exercised) */
    size_t len;
    char p[1100];
    snprintf(p, sizeof p, "%s/frames/diffuse_00010.vtp", part);
    unsigned char *b = tu_slurp(p, &len);
    assert_null(strstr((char *)b, "NumberOfPoints=\"0\""));
    free(b);
}

/* Two 2D soap bubbles (80 particles each) driven together; frames 7 and 10 and stats.csv. */
static void test_resume_film(void **st)
{
    (void)st;
    static pfsph_scene s;
    const char *json =
        "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
        " \"domain\": {\"min\": [-0.2, -0.2], \"max\": [0.2, 0.2]}, \"time\": {\"end\": 0.4, \"fps\": 25, \"dt_max\": "
        "0.002},"
        " \"phases\": [{\"name\": \"soap\", \"kind\": \"fluid\", \"viscosity\": 0.005},"
        " {\"name\": \"air\", \"kind\": \"gas\", \"rest_density\": 1000, \"viscosity\": 0.005}],"
        " \"fluid\": [{\"shape\": \"sphere\", \"center\": [-0.055, 0], \"radius\": 0.05, \"phase\": \"air\","
        " \"velocity\": [0.2, 0], \"bubble\": {\"film\": \"soap\", \"thickness\": 0.004}},"
        " {\"shape\": \"sphere\", \"center\": [0.055, 0.01], \"radius\": 0.05, \"phase\": \"air\","
        " \"velocity\": [-0.2, 0], \"bubble\": {\"film\": \"soap\", \"liquid_volume\": 0.0001}}],"
        " \"pairwise\": {\"k\": 1.633, \"coefficients\": [{\"phases\": [\"soap\", \"soap\"], \"sigma\": 4},"
        " {\"phases\": [\"air\", \"air\"], \"sigma\": 2}, {\"phases\": [\"soap\", \"air\"], \"sigma\": 0}]},"
        " \"output\": {\"formats\": [\"vtp\"], \"fields\": [\"id\"], \"checkpoint_interval\": 5}}";
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(&s, json, "film-resume", &err);
    if (rc) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    char a[1024], b[1024];
    snprintf(a, sizeof a, "%s/film_full", tu_tmpdir());
    snprintf(b, sizeof b, "%s/film_part", tu_tmpdir());
    tu_pfsph_run(&s, a, -1, false);
    tu_pfsph_run(&s, b, 0.2, false);
    tu_pfsph_run(&s, b, 0.4, true);
    tu_assert_same_file(a, b, "frames/fluid_00007.vtp");
    tu_assert_same_file(a, b, "frames/fluid_00010.vtp");
    tu_assert_same_file(a, b, "stats.csv");
    size_t len;
    char p[1100];
    snprintf(p, sizeof p, "%s/frames/fluid_00010.vtp", b);
    unsigned char *buf = tu_slurp(p, &len);
    assert_non_null(strstr((char *)buf, "Name=\"film\""));
    assert_non_null(strstr((char *)buf, "Name=\"surface_layer\""));
    free(buf);
}

/* Through the program: a corrupt newest checkpoint is reported and the previous one used. */
static void test_resume_fallback_cli(void **st)
{
    (void)st;
    if (!full_dir[0]) tu_skip("the full run it resumes from failed (an earlier test)");
    char dir[1024], scene[1100], cmd[4096], out[8192];
    snprintf(dir, sizeof dir, "%s/cli", tu_tmpdir());
    snprintf(scene, sizeof scene, "%s/scene2.json", tu_tmpdir());
    char json[4096];
    snprintf(json, sizeof json, SCENE, 2);
    assert_int_equal(tu_write_file(scene, json), 0);
    /* frames 0..6, checkpoints at 4 and 6 (2 is pruned) */
    snprintf(cmd, sizeof cmd, "%s run %s -o %s --end 0.24 --quiet --threads %d", tu_pfsph_bin(), scene, dir,
             omp_get_max_threads());
    int rc = tu_run(cmd, out, sizeof out);
    if (rc) fprintf(stderr, "%s\n", out);
    assert_int_equal(rc, 0);
    char ck[1200];
    snprintf(ck, sizeof ck, "%s/checkpoints/ckpt_00002.bin", dir);
    FILE *f = fopen(ck, "rb");
    assert_null(f);
    snprintf(ck, sizeof ck, "%s/checkpoints/ckpt_00006.bin", dir);
    size_t len;
    unsigned char *b = tu_slurp(ck, &len);
    b[len / 2] ^= 0x04;
    f = fopen(ck, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, len, f), len);
    fclose(f);
    free(b);
    snprintf(cmd, sizeof cmd, "%s run --resume %s --quiet --end 0.4 --threads %d", tu_pfsph_bin(), dir,
             omp_get_max_threads());
    rc = tu_run(cmd, out, sizeof out);
    fprintf(stderr, "%s", out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, "ckpt_00006.bin"));
    assert_non_null(strstr(out, "checksum"));
    compare_runs(full_dir, dir);
    /* resumed from frame 4: summary says so */
    char sum[1200];
    snprintf(sum, sizeof sum, "%s/summary.json", dir);
    b = tu_slurp(sum, &len);
    assert_non_null(strstr((char *)b, "\"resumed_from_frame\":\t4"));
    free(b);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_resume_library),
        cmocka_unit_test(test_resume_fallback_cli),
        cmocka_unit_test(test_resume_film),
    };
    return tu_run_group(tests, NULL, NULL);
}
