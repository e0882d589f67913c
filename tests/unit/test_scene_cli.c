/* The pfsph program on bad scenes: `pfsph check` prints "<file>: <JSON path>: <reason>" and exits
 * with status 2; `pfsph run` on a bad scene exits 2 and never creates or touches its output
 * directory. Good scenes pass `pfsph check`. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "testutil.h"

typedef struct cli_case {
    const char *file; /* written into the temporary directory */
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
    {"covered.json", /* issue 11: a later block replaces an earlier one where they overlap */
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0.1,0.1,0.1],\"max\":[0.2,0.2,0.2]},{\"shape\":\"box\",\"min\":[0,0,0],"
     "\"max\":[0.3,0.3,0.3]}]}",
     "$.fluid[0]: every particle of this block lies inside later blocks"},
    {"frames.json", /* issue 15 item 4: end x fps overflowed the frame count */
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"time\":{\"end\":1e6,\"fps\":1e4}}",
     "$.time.end: end 1e+06 s at 10000 fps makes 1e+10 frames, more than the 100000000 one run holds"},
    {"thermo_both.json", /* issue 11: the thermostat takes kT or a reduced temperature */
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"pairwise\":{\"thermostat\":{\"kT\":1e-6,"
     "\"reduced_temperature\":0.01}}}",
     "$.pairwise.thermostat.kT: give kT or reduced_temperature, not both"},
    {"thermo_kind.json",
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"pairwise\":{\"thermostat\":\"hot\"}}",
     "$.pairwise.thermostat: expected true, false or an object"},
    {"thermo_neg.json",
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"pairwise\":{\"thermostat\":{\"kT\":-1}}}",
     "$.pairwise.thermostat.kT: value -1 is out of range"},
    {"lists.json", /* issue 28: DFSPH's neighbour lists are true, false or "auto" */
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"solver\":{\"type\":\"dfsph\",\"neighbour_lists\":\"never\"}}",
     "$.solver.neighbour_lists: expected true, false or \"auto\", got \"never\""},
    {"pieces.json", /* issue 29: the fluid's VTP frames in ParaView pieces, true or false */
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"output\":{\"pieces\":\"yes\"}}",
     "$.output.pieces: expected true or false, got a string"},
    {"pieces_ply.json", /* pieces are VTP files */
     "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"fluid\":[{\"shape\":\"box\","
     "\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],\"output\":{\"pieces\":true,\"formats\":[\"ply\"]}}",
     "$.output.pieces: pieces are VTP files: needs \"vtp\" in $.output.formats"},
};
#define NCASES (sizeof cases / sizeof cases[0])

/* `pfsph check` states the thermostat's temperature and thermal speeds (issue 11): kT = 0.01
 * sigma d^2 with sigma Eq. 13's tension of the coefficients, 0.0728 / f = 0.07786 N/m (f = 0.935,
 * the measured 3D factor at temperature, docs/thermostat.md), = 3.114e-07 J for water of
 * 1000 kg/m^3 at d = 2 cm, thermal speed sqrt(kT / (1000 d^3)) = 0.00624 m/s; switched off it
 * says so. */
static void test_check_thermostat(void **state)
{
    (void)state;
    const char *fmt = "{\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]},\"particle_radius\":0.01,"
                      "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}],"
                      "\"pairwise\":{%s\"coefficients\":[{\"phases\":[\"water\",\"water\"],\"sigma\":0.0728}]}}";
    char json[1024], path[512], cmd[2048], out[8192];
    snprintf(json, sizeof json, fmt, "");
    snprintf(path, sizeof path, "%s/thermo_on.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, json), 0);
    snprintf(cmd, sizeof cmd, "'%s' check '%s'", tu_pfsph_bin(), path);
    int st = tu_run(cmd, out, sizeof out);
    if (st != 0) fail_msg("exit %d: %s", st, out);
    if (!strstr(out, "thermostat on: kT = 3.114e-07 J = 0.01 sigma d^2") ||
        !strstr(out, "thermal speed sqrt(kT/m) = 0.00624 m/s"))
        fail_msg("check output lacks the thermostat lines:\n%s", out);
    snprintf(json, sizeof json, fmt, "\"thermostat\": false,");
    assert_int_equal(tu_write_file(path, json), 0);
    st = tu_run(cmd, out, sizeof out);
    if (st != 0 || !strstr(out, "thermostat off")) fail_msg("exit %d: %s", st, out);
}

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
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' run '%s' -o '%s' --quiet", tu_tmpdir(), tu_pfsph_bin(), path, dir);
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
    assert_int_equal(tu_write_file(path,
                                   "{\"dimension\":2,\"particle_radius\":0.02,"
                                   "\"domain\":{\"min\":[0,0],\"max\":[1,1]},\"fluid\":[{\"shape\":"
                                   "\"box\",\"min\":[0,0],\"max\":[0.2,0.2]}]}"),
                     0);
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
    static const char *const scenes[] = {"dam_break_2d", "dam_break_3d", "dam_break_cylinder_3d", "hydrostatic_tank_2d",
                                         "hydrostatic_tank_3d"};
    for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
        char cmd[2048], out[8192];
        snprintf(cmd, sizeof cmd, "'%s' check '%s/scenes/%s.json'", tu_pfsph_bin(), tu_source_dir(), scenes[i]);
        int st = tu_run(cmd, out, sizeof out);
        if (st != 0) fail_msg("%s: exit status %d; output: %s", scenes[i], st, out);
    }
}

/* Issue 15 item 12: messages that name the JSON path, the right exit status, escaped bytes,
 * the verdict of `pfsph check` last. */
#define BASE3                                                                                \
    "\"dimension\":3,\"particle_radius\":0.02,\"domain\":{\"min\":[0,0,0],\"max\":[1,1,1]}," \
    "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.2,0.2,0.2]}]"
#define BODY                                                                                             \
    "\"phases\":[{\"name\":\"water\"},{\"name\":\"s\",\"kind\":\"solid\"}],\"bodies\":[{\"name\":\"b\"," \
    "\"shape\":\"box\",\"half_extents\":[0.05,0.05,0.05],\"position\":[0.8,0.8,0.8],\"phase\":\"s\"},"   \
    "{\"name\":\"m\",\"shape\":\"mesh\",\"file\":\"%s\",\"phase\":\"s\",\"position\":[0.5,0.5,0.5]}]"

static void expect(const char *name, const char *json, const char *cmd, int status, const char *want)
{
    char path[600], args[2048], out[8192];
    snprintf(path, sizeof path, "%s/%s", tu_tmpdir(), name);
    assert_int_equal(tu_write_file(path, json), 0);
    snprintf(args, sizeof args, cmd, path);
    int st = tu_pfsph("", out, sizeof out, "%s", args);
    if (st != status) fail_msg("%s: exit status %d, expected %d: %s", name, st, status, out);
    if (!strstr(out, want)) fail_msg("%s: output lacks \"%s\": %s", name, want, out);
    if (status && strstr(out, ": valid ")) fail_msg("%s: \"valid\" printed before the failure: %s", name, out);
}

static void test_messages(void **state)
{
    (void)state;
    char json[4096], out[8192], args[2048];
    snprintf(json, sizeof json, "{" BASE3 "," BODY "}", "no_such_mesh.obj");
    expect("mesh_missing.json", json, "check '%s'", 2, "$.bodies[1].file (body \"m\"): ");
    expect("mesh_missing2.json", json, "check '%s'", 2, "no_such_mesh.obj: cannot open: No such file");
    snprintf(json, sizeof json, "{" BASE3 "," BODY "}", tu_tmpdir());
    expect("mesh_dir.json", json, "check '%s'", 2, "is a directory, not an OBJ file");
    /* a directory as the scene */
    assert_int_equal(tu_pfsph("", out, sizeof out, "check '%s'", tu_tmpdir()), 2);
    assert_non_null(strstr(out, "is a directory, not a scene file"));
    /* nested past cJSON's limit */
    static char deep[3000];
    memset(deep, '[', 2000);
    deep[2000] = 0;
    expect("deep.json", deep, "check '%s'", 2, "$: JSON nested too deep: more than 1000");
    /* bytes that would drive the terminal come back escaped */
    expect("bytes.json", "{\"\x1b[31mred\xff\xfe\": 1}", "check '%s'", 2, "\\x1b[31mred\\xff\\xfe");
    tu_pfsph("", out, sizeof out, "check '%s/bytes.json'", tu_tmpdir());
    for (const char *c = out; *c; c++)
        if ((unsigned char)*c == 0x1b || (unsigned char)*c >= 0x80)
            fail_msg("raw byte 0x%02x in: %s", (unsigned char)*c, out);
    expect("garbage.json", "\x01\x02\x9b\x1b]0;title\x07", "check '%s'", 2, "near \"\\x9b\\x1b]0;title\\x07\"");
    /* an output directory that is a file: bad input, exit 2, the JSON path named */
    char file[700];
    snprintf(file, sizeof file, "%s/a_file", tu_tmpdir());
    assert_int_equal(tu_write_file(file, "x"), 0);
    snprintf(json, sizeof json, "{" BASE3 ",\"output\":{\"directory\":\"%s/sub\"}}", file);
    expect("out_file.json", json, "run '%s' --quiet", 2, "$.output.directory");
    snprintf(json, sizeof json, "{" BASE3 "}");
    snprintf(args, sizeof args, "%s/plain.json", tu_tmpdir());
    assert_int_equal(tu_write_file(args, json), 0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s/plain.json' -o '%s' --quiet", tu_tmpdir(), file), 2);
    assert_non_null(strstr(out, "output directory"));
    assert_non_null(strstr(out, "exists and is not a directory"));
    /* the verdict last */
    assert_int_equal(tu_pfsph("", out, sizeof out, "check '%s/scenes/dam_break_2d.json'", tu_source_dir()), 0);
    size_t n = strlen(out);
    while (n && out[n - 1] == '\n') out[--n] = 0;
    const char *last = strrchr(out, '\n');
    last = last ? last + 1 : out;
    assert_non_null(strstr(last, ": valid 2D scene"));
}

/* Issue 15 item 12: "output": {"boundary": false} writes no boundary frame. */
/* Issue 33, item 4: every file is read through the library's capped readers. `pfsph check
 * /dev/zero` grew to 1 GB in 10 s, a 30 MB scene took 12 s and 816 MB: now 16 MiB at most
 * (refused, exit status 2, at once); a frame larger than 8 GiB (a sparse file here) is refused
 * by render before anything is allocated. The commands run under a 1 GB address-space limit
 * (not in sanitizer builds, whose shadow memory needs more) and a 60 s timeout. */
static void test_read_caps(void **state)
{
    (void)state;
#ifdef PFSPH_SANITIZED
    const char *limit = "";
#else
    const char *limit = "ulimit -v 1000000; ";
#endif
    char cmd[4096], out[8192], path[600], run[600];
    snprintf(cmd, sizeof cmd, "%stimeout 60 '%s' check /dev/zero", limit, tu_pfsph_bin());
    int st = tu_run(cmd, out, sizeof out);
    printf("check /dev/zero: exit %d: %s", st, out);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "/dev/zero: $: file is larger than 16 MiB"));
    snprintf(cmd, sizeof cmd, "%stimeout 60 '%s' run /dev/zero -o '%s/zero_run'", limit, tu_pfsph_bin(), tu_tmpdir());
    st = tu_run(cmd, out, sizeof out);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "larger than 16 MiB"));
    /* a 17 MiB scene of blanks around {} */
    snprintf(path, sizeof path, "%s/huge.json", tu_tmpdir());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputc('{', f);
    for (int k = 0; k < 17 * 1024; k++) fprintf(f, "%1023s\n", "");
    fputc('}', f);
    assert_int_equal(fclose(f), 0);
    snprintf(cmd, sizeof cmd, "%stimeout 60 '%s' check '%s'", limit, tu_pfsph_bin(), path);
    st = tu_run(cmd, out, sizeof out);
    printf("check huge.json: exit %d: %s", st, out);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "huge.json: $: file is larger than 16 MiB"));
    /* a frame of 9 GiB (sparse: no space taken) */
    snprintf(run, sizeof run, "%s/bigframe", tu_tmpdir());
    snprintf(cmd, sizeof cmd,
             "mkdir -p '%s/frames' && printf '{\"dimension\":2,\"domain\":{\"min\":[0,0],\"max\":[1,1]},"
             "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[0.2,0.2]}]}' > '%s/scene.json' && "
             "truncate -s 9G '%s/frames/fluid_00000.vtp'",
             run, run, run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd, "%stimeout 60 '%s' render '%s'", limit, tu_pfsph_bin(), run);
    st = tu_run(cmd, out, sizeof out);
    printf("render of a 9 GiB frame: exit %d: %s", st, out);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "fluid_00000.vtp: 9 GiB, larger than the 8 GiB"));
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", run);
    tu_run(cmd, out, sizeof out);
}

static void test_no_boundary(void **state)
{
    (void)state;
    char path[600], out[8192], dir[700], b[800];
    struct stat sb;
    const char *json = "{\"dimension\":2,\"particle_radius\":0.02,\"domain\":{\"min\":[-0.1,-0.1],\"max\":[1,1]},"
                       "\"time\":{\"end\":0.04},\"phases\":[{\"name\":\"w\"},{\"name\":\"wall\",\"kind\":\"solid\"}],"
                       "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[0.2,0.2]}],"
                       "\"solids\":[{\"shape\":\"container\",\"min\":[0,0],\"max\":[0.8,0.8],\"phase\":\"wall\"}],"
                       "\"output\":{\"formats\":[\"vtp\"],\"boundary\":%s}}";
    for (int on = 0; on < 2; on++) {
        char text[2048];
        snprintf(text, sizeof text, json, on ? "true" : "false");
        snprintf(path, sizeof path, "%s/boundary_%d.json", tu_tmpdir(), on);
        assert_int_equal(tu_write_file(path, text), 0);
        snprintf(dir, sizeof dir, "%s/boundary_run_%d", tu_tmpdir(), on);
        assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s' -o '%s' --quiet", path, dir), 0);
        snprintf(b, sizeof b, "%s/frames/boundary_00000.vtp", dir);
        assert_int_equal(stat(b, &sb) == 0, on);
        snprintf(b, sizeof b, "%s/frames/fluid_00001.vtp", dir);
        assert_int_equal(stat(b, &sb), 0);
    }
}

/* Issue 11: "output": {"boundary": false} with a rigid body as well. The static walls'
 * frame is not written (nor on a resume); the body's own frames (its particles and its
 * surface, which move) are, every frame, as docs/scene-format.md says. */
static void test_no_boundary_bodies(void **state)
{
    (void)state;
    char path[600], out[8192], dir[700], b[800];
    struct stat sb;
    const char *json = "{\"dimension\":2,\"particle_radius\":0.02,\"domain\":{\"min\":[-0.1,-0.1],\"max\":[1,1]},"
                       "\"time\":{\"end\":0.08},\"phases\":[{\"name\":\"w\"},{\"name\":\"wall\",\"kind\":\"solid\"}],"
                       "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[0.2,0.2]}],"
                       "\"solids\":[{\"shape\":\"container\",\"min\":[0,0],\"max\":[0.8,0.8],\"phase\":\"wall\"}],"
                       "\"bodies\":[{\"name\":\"crate\",\"shape\":\"box\",\"half_extents\":[0.05,0.05],"
                       "\"position\":[0.5,0.3],\"phase\":\"wall\"}],"
                       "\"output\":{\"formats\":[\"vtp\",\"ply\"],\"boundary\":%s,\"checkpoint_interval\":1}}";
    for (int on = 0; on < 2; on++) {
        char text[2048];
        snprintf(text, sizeof text, json, on ? "true" : "false");
        snprintf(path, sizeof path, "%s/boundary_bodies_%d.json", tu_tmpdir(), on);
        assert_int_equal(tu_write_file(path, text), 0);
        snprintf(dir, sizeof dir, "%s/boundary_bodies_run_%d", tu_tmpdir(), on);
        assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s' -o '%s' --quiet", path, dir), 0);
        assert_int_equal(tu_pfsph("", out, sizeof out, "run --resume '%s' --end 0.16 --quiet", dir), 0);
        for (int f = 0; f <= 4; f++)
            for (int ply = 0; ply < 2; ply++) {
                const char *ext = ply ? "ply" : "vtp";
                snprintf(b, sizeof b, "%s/frames/boundary_%05d.%s", dir, f, ext);
                assert_int_equal(stat(b, &sb) == 0, on && f == 0);
                snprintf(b, sizeof b, "%s/frames/bodies_%05d.%s", dir, f, ext);
                assert_int_equal(stat(b, &sb), 0);
                snprintf(b, sizeof b, "%s/frames/surfaces_%05d.%s", dir, f, ext);
                assert_int_equal(stat(b, &sb), 0);
            }
    }
}

/* Issue 15 item 13: every subcommand explains itself; --threads 0 is the default. */
static void test_help(void **state)
{
    (void)state;
    static const struct {
        const char *args;
        const char *want[10];
    } cases[] = {
        {"--help", {"run ", "check ", "render ", "help ", "--version", "Exit status", NULL}},
        {"help", {"run ", "check ", "render ", NULL}},
        {"run --help",
         {"usage: pfsph run", "-o, --output DIR", "--force ", "--resume RUN_DIR ", "--threads N ", "0 = the default",
          "--end T ", "--render ", "--quiet ", NULL}},
        {"run -h", {"usage: pfsph run", NULL}},
        {"help run", {"usage: pfsph run", NULL}},
        {"check --help", {"usage: pfsph check", "verdict", NULL}},
        {"render --help", {"usage: pfsph render", "--video ", "--color-by FIELD ", "--size WxH ", NULL}},
        {"help render", {"usage: pfsph render", NULL}},
    };
    char out[8192];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int st = tu_pfsph("", out, sizeof out, "%s", cases[i].args);
        if (st != 0) fail_msg("pfsph %s: exit status %d", cases[i].args, st);
        for (int k = 0; cases[i].want[k]; k++)
            if (!strstr(out, cases[i].want[k])) fail_msg("pfsph %s: lacks \"%s\"", cases[i].args, cases[i].want[k]);
    }
    assert_int_equal(tu_pfsph("", out, sizeof out, "%s", "help nosuch"), 2);
    char path[600];
    snprintf(path, sizeof path, "%s/threads0.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path,
                                   "{\"dimension\":2,\"particle_radius\":0.02,\"time\":{\"end\":0.04},"
                                   "\"domain\":{\"min\":[0,0],\"max\":[1,1]},\"fluid\":[{\"shape\":"
                                   "\"box\",\"min\":[0,0],\"max\":[0.2,0.2]}]}"),
                     0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s' -o '%s/threads0' --quiet --threads 0", path, tu_tmpdir()),
                     0);
    assert_int_equal(tu_pfsph("", out, sizeof out, "run '%s' -o '%s/threads0' --quiet --threads -1", path, tu_tmpdir()),
                     2);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_check_bad),          cmocka_unit_test(test_check_thermostat),
        cmocka_unit_test(test_check_missing_file), cmocka_unit_test(test_run_bad_writes_nothing),
        cmocka_unit_test(test_run_end_overflow),   cmocka_unit_test(test_messages),
        cmocka_unit_test(test_read_caps),          cmocka_unit_test(test_no_boundary),
        cmocka_unit_test(test_no_boundary_bodies), cmocka_unit_test(test_help),
        cmocka_unit_test(test_check_good),
    };
    return tu_run_group(tests, NULL, NULL);
}
