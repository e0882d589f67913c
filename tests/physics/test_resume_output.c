/* Output settings changed between a run and its resume (issue 33, item 2): every key of
 * "output" that RUN/scene.json may change before `pfsph run --resume`. frame_interval is
 * refused (exit status 2, nothing removed): the files on disk are numbered by the old one.
 * The others are taken from the resume on; after each, every frame file's own time is its
 * index times frame_interval / fps, and every .pvd entry gives its file that time. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pfsph/io.h"
#include "testutil.h"

/* about 450 particles at 100 fps; the first run stops at 0.06 s (checkpoint at frame 6) */
static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.12, \"fps\": 100},"
    " \"phases\": [{\"name\": \"water\", \"viscosity\": 2e-4}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}],"
    " \"output\": {%s}}";

#define FPS 100.0

/* A fresh run of SCENE with output keys `before` to 0.06 s, then scene.json's output keys
 * replaced by `after` and a resume to the end; the resume's exit status, its output in out. */
static int run_then_resume(const char *run, const char *before, const char *after, char *out, size_t cap)
{
    char scene[600], text[4096], cmd[2400];
    snprintf(scene, sizeof scene, "%s/resume_output.json", tu_tmpdir());
    snprintf(text, sizeof text, SCENE, before);
    assert_int_equal(tu_write_file(scene, text), 0);
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --force --quiet --end 0.06", tu_pfsph_bin(), scene, run);
    int st = tu_run(cmd, out, cap);
    if (st) fail_msg("first run: exit %d: %s", st, out);
    /* the first run's end is its --end; the resume goes on to the scene's 0.12 s */
    snprintf(scene, sizeof scene, "%s/scene.json", run);
    snprintf(text, sizeof text, SCENE, after);
    assert_int_equal(tu_write_file(scene, text), 0);
    snprintf(cmd, sizeof cmd, "'%s' run --resume '%s' --quiet --end 0.12", tu_pfsph_bin(), run);
    st = tu_run(cmd, out, cap);
    printf("{%s} -> {%s}: exit %d %s", before, after, st, out[0] ? out : "\n");
    return st;
}

/* The time a frame file says it holds (particle sets; liquid outlines have no reader here and
 * are checked through their .pvd entry against the fluid frame of the same index). */
static int file_time(const char *path, double *t)
{
    pfsph_particles ps;
    pfsph_error err;
    int rc = -1;
    if (strstr(path, ".vtp")) rc = pfsph_read_vtp(path, &ps, t, &err);
    else if (strstr(path, ".ply")) rc = pfsph_read_ply(path, &ps, t, &err);
    if (rc == 0) pfsph_particles_free(&ps);
    return rc;
}

/* Every particle frame holds index * fi / FPS; returns how many were checked. */
static int check_frames(const char *run, int fi)
{
    char dir[700], path[1000];
    snprintf(dir, sizeof dir, "%s/frames", run);
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    int n = 0;
    while ((e = readdir(d))) {
        int idx;
        char ext[8];
        if (sscanf(e->d_name, "fluid_%5d.%3s", &idx, ext) != 2) continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        double t;
        if (file_time(path, &t)) fail_msg("%s: unreadable", path);
        if (fabs(t - idx * fi / FPS) > 1e-6) fail_msg("%s holds t = %g, not %g", path, t, idx * fi / FPS);
        n++;
    }
    closedir(d);
    return n;
}

/* Every entry of RUN/<set>.pvd: its timestep is index * fi / FPS (the file name's index); the
 * entries number `want` (-1: any). */
static void check_pvd(const char *run, const char *set, int fi, int want)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s.pvd", run, set);
    size_t len;
    char *x = (char *)tu_slurp(path, &len);
    int n = 0;
    for (const char *p = strstr(x, "<DataSet "); p; p = strstr(p + 1, "<DataSet ")) {
        double ts;
        int idx;
        const char *f = strstr(p, "file=\"frames/");
        assert_non_null(f);
        assert_int_equal(sscanf(p, "<DataSet timestep=\"%lf\"", &ts), 1);
        assert_int_equal(sscanf(strchr(f + 13, '_') + 1, "%d", &idx), 1);
        if (fabs(ts - idx * fi / FPS) > 1e-9)
            fail_msg("%s: index %d labelled %g, not %g", path, idx, ts, idx * fi / FPS);
        n++;
    }
    free(x);
    if (want >= 0) assert_int_equal(n, want);
}

static void test_frame_interval_refused(void **state)
{
    (void)state;
    char run[600], out[8192], path[700];
    snprintf(run, sizeof run, "%s/fi", tu_tmpdir());
    int st = run_then_resume(run, "\"formats\": [\"vtp\"]", "\"formats\": [\"vtp\"], \"frame_interval\": 2", out,
                             sizeof out);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "$.output.frame_interval"));
    assert_non_null(strstr(out, "run.json"));
    assert_non_null(strstr(out, "--force"));
    /* nothing was swept: frames 0..6 are there, labelled as written */
    snprintf(path, sizeof path, "%s/frames/fluid_00006.vtp", run);
    struct stat sb;
    assert_int_equal(stat(path, &sb), 0);
    assert_int_equal(check_frames(run, 1), 7);
    check_pvd(run, "fluid", 1, 7);
    /* the other way (2 -> 1) too */
    st = run_then_resume(run, "\"formats\": [\"vtp\"], \"frame_interval\": 2", "\"formats\": [\"vtp\"]", out,
                         sizeof out);
    assert_int_equal(st, 2);
    assert_int_equal(check_frames(run, 2), 4);
    /* the same interval resumes */
    st = run_then_resume(run, "\"formats\": [\"vtp\"], \"frame_interval\": 3",
                         "\"formats\": [\"vtp\"], \"frame_interval\": 3", out, sizeof out);
    assert_int_equal(st, 0);
    assert_int_equal(check_frames(run, 3), 5); /* frames 0, 3, .., 12 */
    check_pvd(run, "fluid", 3, 5);
}

static void test_other_keys_allowed(void **state)
{
    (void)state;
    static const char *const cases[][3] = {
        /* before, after, the frame files after the resume (fluid sets, both formats) */
        {"\"formats\": [\"vtp\"]", "\"formats\": [\"vtp\", \"ply\"]", "19"},
        {"\"formats\": [\"vtp\", \"ply\"]", "\"formats\": [\"ply\"]", "20"},
        {"\"formats\": [\"vtp\"]", "\"formats\": [\"vtp\"], \"fields\": [\"id\", \"speed\"]", "13"},
        {"\"formats\": [\"vtp\"]", "\"formats\": [\"vtp\"], \"boundary\": true", "13"},
        {"\"formats\": [\"vtp\"]", "\"formats\": [\"vtp\"], \"checkpoint_interval\": 4", "13"},
        {"\"formats\": [\"vtp\"]", "\"formats\": [\"vtp\"], \"surface\": true", "13"},
        {"\"formats\": [\"vtp\"], \"frame_interval\": 2", "\"formats\": [\"ply\"], \"frame_interval\": 2", "7"},
    };
    char run[600], out[8192];
    snprintf(run, sizeof run, "%s/keys", tu_tmpdir());
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int st = run_then_resume(run, cases[k][0], cases[k][1], out, sizeof out);
        assert_int_equal(st, 0);
        const int fi = strstr(cases[k][1], "\"frame_interval\": 2") ? 2 : 1;
        assert_int_equal(check_frames(run, fi), atoi(cases[k][2]));
        if (strstr(cases[k][1], "vtp")) check_pvd(run, "fluid", fi, -1);
        if (strstr(cases[k][1], "surface")) check_pvd(run, "liquid", fi, 6); /* frames 7..12: after the checkpoint */
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_frame_interval_refused),
                                       cmocka_unit_test(test_other_keys_allowed)};
    return tu_run_group(tests, NULL, NULL);
}
