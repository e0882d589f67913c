/* The pfsph program on bad scenes: `pfsph check` prints "<file>: <JSON path>: <reason>" and exits
 * with status 2; `pfsph run` on a bad scene exits 2 and never creates or touches its output
 * directory. Good scenes pass `pfsph check`. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "testutil.h"

typedef struct cli_case {
    const char *file;   /* written into the temporary directory */
    const char *json;
    const char *expect; /* substring of the message after "<path>: " */
} cli_case;

static const cli_case cases[] = {
    {"typo.json",
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"tiem\":{\"end\":1}}",
     "$.tiem: unknown key \"tiem\" (did you mean \"time\"?)"},
    {"syntax.json", "{\"dimension\": 3,\n \"domain\": }", "$: invalid JSON at line 2"},
    {"range.json",
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"time\":{\"end\":-2}}",
     "$.time.end: value -2 is out of range"},
    {"phase.json",
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2],\"phase\":\"oil\"}]}",
     "$.fluid[0].phase: unknown phase \"oil\""},
    {"overlap.json",
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]},{\"shape\":\"box\",\"min\":[0.1,0.1,0.1],"
     "\"max\":[0.3,0.3,0.3]}]}",
     "$.fluid[1]: overlaps $.fluid[0]"},
    {"frames.json", /* issue 15 item 4: end x fps overflowed the frame count */
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"time\":{\"end\":1e6,\"fps\":1e4}}",
     "$.time.end: end 1e+06 s at 10000 fps makes 1e+10 frames, more than the 100000000 one run holds"},
};
#define NCASES (sizeof cases / sizeof cases[0])

static void write_case(const cli_case *c, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", tu_tmpdir(), c->file);
    assert_int_equal(tu_write_file(path, c->json), 0);
}

static void test_check_bad(void **state)
{
    (void)state;
    for (size_t i = 0; i < NCASES; i++) {
        char path[512], cmd[2048], out[4096], want[1024];
        write_case(&cases[i], path, sizeof path);
        snprintf(cmd, sizeof cmd, "'%s' check '%s'", tu_pfsph_bin(), path);
        int st = tu_run(cmd, out, sizeof out);
        if (st != 2) fail_msg("%s: exit status %d, expected 2; output: %s", cases[i].file, st, out);
        snprintf(want, sizeof want, "%s: %s", path, cases[i].expect);
        if (!strstr(out, want)) fail_msg("%s: output lacks \"%s\":\n%s", cases[i].file, want, out);
    }
}

static void test_check_missing_file(void **state)
{
    (void)state;
    char cmd[2048], out[4096], path[512];
    snprintf(path, sizeof path, "%s/does_not_exist.json", tu_tmpdir());
    snprintf(cmd, sizeof cmd, "'%s' check '%s'", tu_pfsph_bin(), path);
    int st = tu_run(cmd, out, sizeof out);
    assert_true(st != 0);
    assert_non_null(strstr(out, path));
}

/* A bad scene must not create the run directory, nor change one that exists. */
static void test_run_bad_writes_nothing(void **state)
{
    (void)state;
    char path[512], dir[600], cmd[2048], out[4096];
    write_case(&cases[0], path, sizeof path);
    snprintf(dir, sizeof dir, "%s/run_new", tu_tmpdir());
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' run '%s' -o '%s' --quiet", tu_tmpdir(),
             tu_pfsph_bin(), path, dir);
    int st = tu_run(cmd, out, sizeof out);
    if (st != 2) fail_msg("exit status %d, expected 2; output: %s", st, out);
    struct stat sb;
    assert_int_not_equal(stat(dir, &sb), 0); /* not created */
    /* also the scene's default output directory ("runs/typo") under the working directory */
    char def[600];
    snprintf(def, sizeof def, "%s/runs", tu_tmpdir());
    assert_int_not_equal(stat(def, &sb), 0);

    /* an existing directory with one file stays exactly as it was */
    snprintf(dir, sizeof dir, "%s/run_old", tu_tmpdir());
    assert_int_equal(mkdir(dir, 0755), 0);
    char marker[700];
    snprintf(marker, sizeof marker, "%s/marker.txt", dir);
    assert_int_equal(tu_write_file(marker, "keep me\n"), 0);
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet", tu_pfsph_bin(), path, dir);
    st = tu_run(cmd, out, sizeof out);
    if (st != 2) fail_msg("exit status %d, expected 2; output: %s", st, out);
    snprintf(cmd, sizeof cmd, "ls -A '%s'", dir);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    assert_string_equal(out, "marker.txt\n");
    snprintf(cmd, sizeof cmd, "cat '%s'", marker);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    assert_string_equal(out, "keep me\n");
}

/* Issue 15 item 4: `--end 1e10` (or inf) overflowed the frame count: the run exited 0 with
 * nothing simulated. Refused with exit 2, before the run directory is created. */
static void test_run_end_overflow(void **state)
{
    (void)state;
    char path[512], dir[600], cmd[2048], out[4096];
    snprintf(path, sizeof path, "%s/small.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, "{\"dimension\":2,\"particle_radius\":0.02,"
                                         "\"domain\":{\"min\":[0,0],\"max\":[1,1]},\"fluid\":[{\"shape\":"
                                         "\"box\",\"min\":[0,0],\"max\":[0.2,0.2]}]}"), 0);
    static const char *const ends[] = {"1e10", "inf", "nan", "1e300", "-1", ""};
    for (size_t i = 0; i < sizeof ends / sizeof ends[0]; i++) {
        snprintf(dir, sizeof dir, "%s/end_run_%zu", tu_tmpdir(), i);
        snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet --end '%s'", tu_pfsph_bin(), path, dir, ends[i]);
        int st = tu_run(cmd, out, sizeof out);
        if (st != 2) fail_msg("--end '%s': exit status %d, expected 2; output: %s", ends[i], st, out);
        if (!strstr(out, "--end")) fail_msg("--end '%s': the message does not name --end: %s", ends[i], out);
        struct stat sb;
        assert_int_not_equal(stat(dir, &sb), 0);
    }
}

/* The shipped example scenes pass `pfsph check`. */
static void test_check_good(void **state)
{
    (void)state;
    static const char *const scenes[] = {"dam_break_2d", "dam_break_3d", "dam_break_cylinder_3d",
                                         "hydrostatic_tank_2d", "hydrostatic_tank_3d"};
    for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
        char cmd[2048], out[8192];
        snprintf(cmd, sizeof cmd, "'%s' check '%s/scenes/%s.json'", tu_pfsph_bin(),
                 tu_source_dir(), scenes[i]);
        int st = tu_run(cmd, out, sizeof out);
        if (st != 0) fail_msg("%s: exit status %d; output: %s", scenes[i], st, out);
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_check_bad),
        cmocka_unit_test(test_check_missing_file),
        cmocka_unit_test(test_run_bad_writes_nothing),
        cmocka_unit_test(test_run_end_overflow),
        cmocka_unit_test(test_check_good),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
