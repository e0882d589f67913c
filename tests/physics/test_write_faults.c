/* Every output of a run on a full disk, one at a time (issue 33, items 1 and 5): the test hook
 * PFSPH_FAULT_WRITE makes the writes to one file fail with ENOSPC from the N-th on. Each run
 * must exit with status 1, name the file and the cause, never print "done" nor leave
 * summary.json saying "finished", and summary.json's last checkpoint must be one on disk. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "testutil.h"

/* about 450 particles, 10 frames of 0.01 s: a fraction of a second a run */
static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.1, \"fps\": 100},"
    " \"phases\": [{\"name\": \"water\", \"viscosity\": 2e-4}, {\"name\": \"wall\", \"kind\": \"solid\"},"
    "              {\"name\": \"wood\", \"kind\": \"solid\", \"rest_density\": 600}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}],"
    " %s"
    " \"output\": {\"formats\": [\"vtp\", \"ply\"], \"checkpoint_interval\": 2%s}}";

#define BODY                                                                                              \
    "\"bodies\": [{\"name\": \"log\", \"shape\": \"box\", \"half_extents\": [0.03, 0.02], \"position\": " \
    "[0.4, 0.1], \"phase\": \"wood\"}],"

typedef struct fault_case {
    const char *fault;  /* PFSPH_FAULT_WRITE */
    const char *named;  /* what the message names */
    const char *bodies; /* "" or BODY */
    const char *output; /* more output keys */
    int render;         /* --render */
} fault_case;

/* Runs the scene with the fault; returns the exit status, the output in out. */
static int run_fault(const fault_case *fc, const char *run, char *out, size_t cap)
{
    char scene[600], text[4096], cmd[2400];
    snprintf(scene, sizeof scene, "%s/faults.json", tu_tmpdir());
    snprintf(text, sizeof text, SCENE, fc->bodies, fc->output);
    assert_int_equal(tu_write_file(scene, text), 0);
    snprintf(cmd, sizeof cmd, "PFSPH_FAULT_WRITE='%s' '%s' run '%s' -o '%s' --force%s", fc->fault, tu_pfsph_bin(),
             scene, run, fc->render ? " --render" : "");
    int st = tu_run(cmd, out, cap);
    const char *tail = strlen(out) > 600 ? out + strlen(out) - 600 : out;
    printf("%s: exit %d: ...%s", fc->fault, st, tail);
    return st;
}

static void check_summary(const char *run, int finished_ok)
{
    char path[700];
    snprintf(path, sizeof path, "%s/summary.json", run);
    struct stat sb;
    if (stat(path, &sb) != 0) return; /* lost too: the error said so */
    size_t len;
    char *j = (char *)tu_slurp(path, &len);
    if (!finished_ok) assert_null(strstr(j, "\"finished\""));
    /* the last checkpoint it names is on disk (item 5) */
    const char *ck = strstr(j, "\"last_checkpoint\"");
    if (ck) {
        const char *fr = strstr(ck, "\"frame\":");
        assert_non_null(fr);
        int frame = atoi(fr + 8);
        snprintf(path, sizeof path, "%s/checkpoints/ckpt_%05d.bin", run, frame);
        if (stat(path, &sb) != 0) fail_msg("summary.json names checkpoint frame %d, but %s is missing", frame, path);
    }
    free(j);
}

static void test_each_output(void **state)
{
    (void)state;
    static const fault_case cases[] = {
        {"stats.csv:1", "stats.csv", "", "", 0},
        {"stats.csv:6", "stats.csv", "", "", 0},
        {"bodies.csv:4", "bodies.csv", BODY, "", 0},
        {".last_good.bin:1", ".last_good.bin", "", "", 0},
        {".last_good.bin:5", ".last_good.bin", "", "", 0},
        {"summary.json", "summary.json", "", "", 0},
        {"ckpt_00006", "ckpt_00006.bin", "", "", 0},
        {"fluid_00003.vtp", "fluid_00003.vtp", "", "", 0},
        {"fluid_00004.ply", "fluid_00004.ply", "", "", 0},
        {"boundary_00000", "boundary_00000", "", ", \"boundary\": true", 0},
        {"surfaces_00002", "surfaces_00002", BODY, "", 0},
        {"liquid_00002", "liquid_00002", "", ", \"surface\": true", 0},
        {"fluid.pvd", "fluid.pvd", "", "", 0},
        {"run.json", "run.json", "", "", 0},
        {"frame_00003.png", "frame_00003.png", "", "", 1},
    };
    const int n = (int)(sizeof cases / sizeof cases[0]);
    char run[600], out[16384];
    snprintf(run, sizeof run, "%s/run", tu_tmpdir());
    for (int k = 0; k < n; k++) {
        int st = run_fault(&cases[k], run, out, sizeof out);
        if (st != 1) fail_msg("%s: exit status %d, not 1", cases[k].fault, st);
        assert_non_null(strstr(out, cases[k].named));
        assert_non_null(strstr(out, "No space left on device"));
        assert_non_null(strstr(out, run));
        assert_null(strstr(out, "done:"));
        check_summary(run, cases[k].render); /* a render after the run: the run did finish */
    }
    printf("%d outputs, each lost on its own: exit 1, named\n", n);
}

/* A checkpoint that fails is not reported as the last one: ckpt 4 is written, 6 fails. */
static void test_last_checkpoint(void **state)
{
    (void)state;
    fault_case fc = {"ckpt_00006", "ckpt_00006.bin", "", "", 0};
    char run[600], out[16384], path[700];
    snprintf(run, sizeof run, "%s/ck", tu_tmpdir());
    assert_int_equal(run_fault(&fc, run, out, sizeof out), 1);
    snprintf(path, sizeof path, "%s/summary.json", run);
    size_t len;
    char *j = (char *)tu_slurp(path, &len);
    assert_non_null(strstr(j, "\"failed\""));
    const char *ck = strstr(j, "\"last_checkpoint\"");
    assert_non_null(ck);
    assert_non_null(strstr(ck, "\"frame\":\t4"));
    free(j);
    check_summary(run, 0);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_each_output), cmocka_unit_test(test_last_checkpoint)};
    return tu_run_group(tests, NULL, NULL);
}
