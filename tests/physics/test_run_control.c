/* Stopping and ending a run (issue 33, item 15): Ctrl-C (SIGINT) ends `pfsph run` with exit
 * status 130, a checkpoint of the last finished frame and a message saying how to resume, and the
 * resumed run ends with the frames of an uninterrupted one; an --end between frames is refused;
 * the progress line on a terminal leaves no characters of a longer earlier line behind. */
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "testutil.h"

/* about 450 particles at 100 fps */
static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 2, \"fps\": 100},"
    " \"phases\": [{\"name\": \"water\", \"viscosity\": 2e-4}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}],"
    " \"output\": {\"formats\": [\"vtp\"], \"checkpoint_interval\": 50}}";

static const char *scene_file(void)
{
    static char path[600];
    snprintf(path, sizeof path, "%s/control.json", tu_tmpdir());
    assert_int_equal(tu_write_file(path, SCENE), 0);
    return path;
}

static void test_sigint(void **state)
{
    (void)state;
    const char *scene = scene_file();
    char run[600], ref[600], cmd[4096], out[8192], path[800];
    snprintf(run, sizeof run, "%s/int", tu_tmpdir());
    snprintf(ref, sizeof ref, "%s/ref", tu_tmpdir());
    /* Ctrl-C once stats.csv has the rows of frames 0..7 (no checkpoint yet: every 50 frames);
     * started from here, not from a shell, which would start it with SIGINT ignored */
    snprintf(path, sizeof path, "%s/int.log", tu_tmpdir());
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(fd, 1);
        dup2(fd, 2);
        execl(tu_pfsph_bin(), "pfsph", "run", scene, "-o", run, "--threads", "1", "--quiet", (char *)NULL);
        _exit(127);
    }
    char stats[700];
    snprintf(stats, sizeof stats, "%s/stats.csv", run);
    for (int n = 0; n < 1200; n++) {
        FILE *f = fopen(stats, "r");
        int lines = 0, c;
        while (f && (c = fgetc(f)) != EOF) lines += c == '\n';
        if (f) fclose(f);
        if (lines >= 9) break;
        nanosleep(&(struct timespec){0, 50000000}, NULL);
    }
    kill(pid, SIGINT);
    int wst;
    assert_int_equal(waitpid(pid, &wst, 0), pid);
    size_t len;
    char *log = (char *)tu_slurp(path, &len);
    snprintf(out, sizeof out, "%s", log);
    free(log);
    printf("exit %d: %s", WIFEXITED(wst) ? WEXITSTATUS(wst) : -WTERMSIG(wst), out);
    assert_true(WIFEXITED(wst));
    assert_int_equal(WEXITSTATUS(wst), 130);
    assert_non_null(strstr(out, "interrupted at t = "));
    snprintf(path, sizeof path, "pfsph run --resume %s", run);
    assert_non_null(strstr(out, path));
    /* the checkpoint it names exists */
    const char *k = strstr(out, "checkpoint of frame ");
    assert_non_null(k);
    int frame = atoi(k + 20);
    assert_true(frame >= 7);
    snprintf(path, sizeof path, "%s/checkpoints/ckpt_%05d.bin", run, frame);
    struct stat sb;
    assert_int_equal(stat(path, &sb), 0);
    snprintf(path, sizeof path, "%s/summary.json", run);
    char *sum = (char *)tu_slurp(path, &len);
    assert_non_null(strstr(sum, "\"interrupted\""));
    free(sum);
    /* resumed to 0.3 s: the last frame is the uninterrupted run's */
    snprintf(cmd, sizeof cmd, "'%s' run --resume '%s' --threads 1 --quiet --end 0.3", tu_pfsph_bin(), run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --threads 1 --quiet --end 0.3", tu_pfsph_bin(), scene, ref);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    tu_assert_same_file(run, ref, "frames/fluid_00030.vtp");
    tu_assert_same_file(run, ref, "stats.csv");
}

static void test_end_on_frame(void **state)
{
    (void)state;
    const char *scene = scene_file();
    char cmd[2048], out[4096];
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s/end' --quiet --end 0.155", tu_pfsph_bin(), scene, tu_tmpdir());
    int st = tu_run(cmd, out, sizeof out);
    printf("--end 0.155 at 100 fps: exit %d: %s", st, out);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "not a whole number of frames at 100 fps"));
    assert_non_null(strstr(out, "give 0.15 or 0.16"));
    /* nothing was made */
    char path[700];
    snprintf(path, sizeof path, "%s/end", tu_tmpdir());
    struct stat sb;
    assert_true(stat(path, &sb) != 0);
    /* on a frame it runs, and ends there */
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s/end' --quiet --end 0.03", tu_pfsph_bin(), scene, tu_tmpdir());
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    snprintf(path, sizeof path, "%s/end/frames/fluid_00003.vtp", tu_tmpdir());
    assert_int_equal(stat(path, &sb), 0);
    /* an end beyond $.time.end's range: at fps 1e-300 `--end 2e300` is 2 frames, and ran for
     * ever (found by tools/attack/attack.py, issue 33 repeated); refused at once */
    char tiny[600], text[2048];
    snprintf(tiny, sizeof tiny, "%s/tiny_fps.json", tu_tmpdir());
    snprintf(text, sizeof text, "%s", SCENE);
    char *f = strstr(text, "\"fps\": 100");
    assert_non_null(f);
    memcpy(f, "\"fps\": 1e-300", 14);
    memmove(f + 14, f + 11, strlen(f + 11) + 1);
    assert_int_equal(tu_write_file(tiny, text), 0);
    snprintf(cmd, sizeof cmd, "timeout 60 '%s' run '%s' -o '%s/end2' --quiet --end 2e300", tu_pfsph_bin(), tiny,
             tu_tmpdir());
    st = tu_run(cmd, out, sizeof out);
    printf("--end 2e300 at 1e-300 fps: exit %d: %s", st, out);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "the range of $.time.end"));
}

/* The terminal's view of text with \r, \n and ESC [K (erase to the end of the line): the last
 * line that holds "ETA" into line. */
static void last_progress_line(const char *text, char *line, size_t cap)
{
    char cur[1024] = "";
    size_t col = 0, n = 0;
    line[0] = 0;
    for (const char *c = text; *c; c++) {
        if (*c == '\r') col = 0;
        else if (*c == '\n') {
            if (strstr(cur, "ETA")) snprintf(line, cap, "%s", cur);
            cur[0] = 0, col = n = 0;
        } else if (c[0] == '\033' && c[1] == '[' && c[2] == 'K') {
            cur[col] = 0, n = col;
            c += 2;
        } else if (col < sizeof cur - 1) {
            cur[col++] = *c;
            if (col > n) n = col, cur[n] = 0;
        }
    }
}

static void test_progress_line(void **state)
{
    (void)state;
    char out[65536], cmd[4096], line[1024];
    if (tu_run("script --version", out, sizeof out) != 0) tu_skip("no script(1) to give the run a terminal");
    const char *scene = scene_file();
    snprintf(cmd, sizeof cmd, "script -qfec \"'%s' run '%s' -o '%s/tty' --end 0.2\" /dev/null", tu_pfsph_bin(), scene,
             tu_tmpdir());
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    last_progress_line(out, line, sizeof line);
    printf("last progress line: \"%s\"\n", line);
    const char *eta = strstr(line, "ETA ");
    assert_non_null(eta);
    /* "ETA mm:ss" and nothing after it but blanks */
    for (const char *c = eta + 9; *c; c++)
        if (*c != ' ') fail_msg("leftover characters after \"%.9s\": \"%s\"", eta, eta + 9);
    assert_non_null(strstr(line, "frame 20/20"));
    /* every redraw erases what a longer earlier line left */
    int redraws = 0;
    for (const char *c = strstr(out, "\r["); c; c = strstr(c + 1, "\r[")) {
        const char *e = strpbrk(c + 1, "\r\n");
        const char *k = strstr(c, "\033[K");
        assert_true(k && (!e || k < e));
        redraws++;
    }
    printf("%d redraws, each ending with ESC [K\n", redraws);
    assert_true(redraws > 1);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_sigint), cmocka_unit_test(test_end_on_frame),
                                       cmocka_unit_test(test_progress_line)};
    return tu_run_group(tests, NULL, NULL);
}
