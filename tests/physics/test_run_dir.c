/* The run directory (issue 15): two runs into one directory (item 8: the second is refused by
 * the lock, naming the holder), a fresh run into an old one (item 9: refused unless --force,
 * which removes pfsph's files and nothing else; a resume removes temporaries of a killed
 * writer), resume and the end time (item 10: a resume without --end keeps the run's own end;
 * a shorter --end leaves no frame without its stats.csv row; a deleted stats.csv is reported),
 * a crafted checkpoint with frame INT_MAX (item 2: refused, no runaway output). Small 2D
 * scene, one thread. */
#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <time.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "pfsph/run.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.01, \"gravity\": [0, -9.81],\n"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},\n"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.4, \"fps\": 25},\n"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}],\n"
    " \"output\": {\"formats\": [\"vtp\"], \"checkpoint_interval\": 2}}\n";

static char g_scene[600];

static int setup(void **state)
{
    (void)state;
    snprintf(g_scene, sizeof g_scene, "%s/scene.json", tu_tmpdir());
    return tu_write_file(g_scene, SCENE);
}

static int exists(const char *dir, const char *name)
{
    char p[1400];
    struct stat sb;
    snprintf(p, sizeof p, "%s/%s", dir, name);
    return stat(p, &sb) == 0;
}

static void touch(const char *dir, const char *name)
{
    char p[1400];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    assert_int_equal(tu_write_file(p, "x\n"), 0);
}

/* Frame of the last row of RUN/stats.csv, and the row count. */
static int last_row(const char *dir, int *rows)
{
    char p[1400], line[1024];
    snprintf(p, sizeof p, "%s/stats.csv", dir);
    FILE *f = fopen(p, "r");
    assert_non_null(f);
    int last = -1, n = 0;
    while (fgets(line, sizeof line, f))
        if (line[0] >= '0' && line[0] <= '9') last = atoi(line), n++;
    fclose(f);
    if (rows) *rows = n;
    return last;
}

/* Highest NNNNN of frames/fluid_NNNNN.vtp, -1 for none. */
static int last_frame(const char *dir)
{
    char p[1400];
    snprintf(p, sizeof p, "%s/frames", dir);
    DIR *d = opendir(p);
    if (!d) return -1;
    int last = -1;
    struct dirent *e;
    while ((e = readdir(d))) {
        int k;
        char tail[16];
        if (sscanf(e->d_name, "fluid_%d.%15s", &k, tail) == 2 && !strcmp(tail, "vtp") && k > last) last = k;
    }
    closedir(d);
    return last;
}

/* Item 8: a second run (fresh with --force, or a resume) into a directory a run holds. */
static void test_lock(void **state)
{
    (void)state;
    char dir[700], out[8192], cmd[4096], lock[800];
    snprintf(dir, sizeof dir, "%s/locked", tu_tmpdir());
    snprintf(lock, sizeof lock, "%s/.pfsph.lock", dir);
    /* the first run: about 1 s (30 s under the sanitizers) */
    snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=1 '%s' run '%s' -o '%s' --quiet --end 6 > '%s.log' 2>&1 & echo $!",
             tu_pfsph_bin(), g_scene, dir, dir);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    long pid = atol(out);
    assert_true(pid > 0);
    /* wait until it holds the lock and has written scene.json, which a resume reads before it
     * asks for the lock (at most 10 s) */
    int held = 0;
    for (int i = 0; i < 1000 && !held; i++) {
        FILE *f = fopen(lock, "r");
        if (f) {
            held = fgetc(f) != EOF && exists(dir, "scene.json");
            fclose(f);
        }
        if (!held) nanosleep(&(struct timespec){0, 10000000}, NULL);
    }
    char want[64];
    snprintf(want, sizeof want, "(pid %ld,", pid);
    int st =
        tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --force --end 0.08", g_scene, dir);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "in use by another pfsph run"));
    assert_non_null(strstr(out, want));
    st = tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet", dir);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "in use by another pfsph run"));
    snprintf(cmd, sizeof cmd, "while kill -0 %ld 2>/dev/null; do sleep 0.05; done; tail -c 300 '%s.log'", pid, dir);
    tu_run(cmd, out, sizeof out);
    /* the first run was not disturbed: it finished all 150 frames */
    int rows;
    assert_int_equal(last_row(dir, &rows), 150);
    assert_int_equal(rows, 151);
    assert_int_equal(last_frame(dir), 150);
    /* released: the directory can be resumed now (nothing left to do) */
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet", dir), 0);
}

/* Item 9: a fresh run into an old run directory. */
static void test_fresh_into_old(void **state)
{
    (void)state;
    char dir[700], out[8192];
    snprintf(dir, sizeof dir, "%s/old", tu_tmpdir());
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --end 0.2", g_scene, dir),
                     0);
    assert_int_equal(last_frame(dir), 5);
    /* what a kill leaves, and a file of the user's */
    touch(dir, "frames/fluid_00009.vtp.tmp.12345");
    touch(dir, "summary.json.tmp.77");
    touch(dir, "notes.txt");
    /* refused, nothing changed */
    assert_int_equal(
        tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --end 0.08", g_scene, dir), 2);
    assert_non_null(strstr(out, "not empty"));
    assert_non_null(strstr(out, "--force"));
    assert_int_equal(last_frame(dir), 5);
    assert_true(exists(dir, "frames/fluid_00009.vtp.tmp.12345"));
    /* --force: pfsph's files go, the user's stay; the new run alone is on disk */
    assert_int_equal(
        tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --end 0.08 --force", g_scene, dir), 0);
    assert_int_equal(last_frame(dir), 2);
    int rows;
    assert_int_equal(last_row(dir, &rows), 2);
    assert_int_equal(rows, 3);
    assert_false(exists(dir, "frames/fluid_00003.vtp"));
    assert_false(exists(dir, "frames/fluid_00009.vtp.tmp.12345"));
    assert_false(exists(dir, "summary.json.tmp.77"));
    assert_false(exists(dir, "checkpoints/ckpt_00004.bin"));
    assert_true(exists(dir, "checkpoints/ckpt_00002.bin"));
    assert_true(exists(dir, "notes.txt"));
    /* a resume removes temporaries of a killed writer */
    touch(dir, "frames/fluid_00001.vtp.tmp.999");
    touch(dir, "checkpoints/ckpt_00004.bin.tmp.999");
    touch(dir, "stats.csv.tmp.999");
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet --end 0.16", dir), 0);
    assert_false(exists(dir, "frames/fluid_00001.vtp.tmp.999"));
    assert_false(exists(dir, "checkpoints/ckpt_00004.bin.tmp.999"));
    assert_false(exists(dir, "stats.csv.tmp.999"));
    assert_int_equal(last_frame(dir), 4);
    /* an empty existing directory is fine without --force */
    snprintf(dir, sizeof dir, "%s/empty", tu_tmpdir());
    assert_int_equal(mkdir(dir, 0755), 0);
    assert_int_equal(
        tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --end 0.04", g_scene, dir), 0);
}

/* Item 10: resume and the end time. */
static void test_resume_end(void **state)
{
    (void)state;
    char dir[700], out[8192], p[1400];
    int rows;
    snprintf(dir, sizeof dir, "%s/ends", tu_tmpdir());
    /* given --end 0.2 (frame 5; checkpoints at 4 and 5, the last frame); the scene's end is 0.4 */
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --end 0.2", g_scene, dir),
                     0);
    /* a resume without --end runs to the run's own end, not the scene's */
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet", dir), 0);
    assert_int_equal(last_row(dir, &rows), 5);
    assert_int_equal(rows, 6);
    assert_int_equal(last_frame(dir), 5);
    /* extend to 0.32 (frame 8; checkpoints 6 and 8), then lose checkpoint 8, as if killed
     * just before it: a resume to a shorter end (0.28, frame 7) starts at 6 and must not
     * leave frame 8 without its row (and checkpoints frame 7, its last) */
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet --end 0.32", dir), 0);
    assert_int_equal(last_frame(dir), 8);
    snprintf(p, sizeof p, "%s/checkpoints/ckpt_00008.bin", dir);
    assert_int_equal(unlink(p), 0);
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet --end 0.28", dir), 0);
    assert_int_equal(last_row(dir, &rows), 7);
    assert_int_equal(rows, 8);
    assert_int_equal(last_frame(dir), 7);
    /* and that shorter end is now the run's own */
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet", dir), 0);
    assert_int_equal(last_row(dir, &rows), 7);
    /* an end before the newest checkpoint: refused, nothing changed */
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet --end 0.08", dir), 2);
    assert_non_null(strstr(out, "before the newest checkpoint"));
    assert_int_equal(last_frame(dir), 7);
    assert_int_equal(last_row(dir, &rows), 7);
    /* a deleted stats.csv is reported */
    snprintf(p, sizeof p, "%s/stats.csv", dir);
    assert_int_equal(unlink(p), 0);
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet --end 0.32", dir), 0);
    assert_non_null(strstr(out, "warning"));
    assert_non_null(strstr(out, "stats.csv: the rows of frames 0..7 are missing"));
}

/* Item 2 through the program: a checkpoint with valid CRCs and frame INT_MAX. */
static void put_u32(unsigned char *b, uint32_t v)
{
    for (int k = 0; k < 4; k++) b[k] = (unsigned char)(v >> 8 * k);
}

static void test_frame_int_max(void **state)
{
    (void)state;
    char dir[700], out[8192], p[1400];
    snprintf(dir, sizeof dir, "%s/intmax", tu_tmpdir());
    assert_int_equal(
        tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --end 0.16", g_scene, dir), 0);
    for (int k = 2; k <= 4; k += 2) {
        snprintf(p, sizeof p, "%s/checkpoints/ckpt_%05d.bin", dir, k);
        FILE *f = fopen(p, "r+b");
        assert_non_null(f);
        fseek(f, 0, SEEK_END);
        long len = ftell(f);
        unsigned char *b = malloc((size_t)len);
        fseek(f, 0, SEEK_SET);
        assert_int_equal(fread(b, 1, (size_t)len, f), (size_t)len);
        put_u32(b + 40, INT_MAX);
        put_u32(b + 32, (uint32_t)crc32(crc32(0L, Z_NULL, 0), b + 40, (uInt)(len - 40)));
        put_u32(b + 36, (uint32_t)crc32(crc32(0L, Z_NULL, 0), b, 36));
        fseek(f, 0, SEEK_SET);
        assert_int_equal(fwrite(b, 1, (size_t)len, f), (size_t)len);
        fclose(f);
        free(b);
    }
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet --end 0.4", dir), 2);
    assert_non_null(strstr(out, "frame 2147483647 is outside"));
    assert_non_null(strstr(out, "no valid checkpoint"));
    assert_int_equal(last_frame(dir), 4);
}

/* Item 11: a checkpoint is written at the last frame too (docs/checkpoints.md), so a later
 * --end extends the run from there. */
static void test_checkpoint_at_last_frame(void **state)
{
    (void)state;
    char dir[700], out[8192];
    snprintf(dir, sizeof dir, "%s/lastckpt", tu_tmpdir());
    /* checkpoint_interval 2, end at frame 3 */
    assert_int_equal(
        tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run '%s' -o '%s' --quiet --end 0.12", g_scene, dir), 0);
    assert_true(exists(dir, "checkpoints/ckpt_00002.bin"));
    assert_true(exists(dir, "checkpoints/ckpt_00003.bin"));
    /* the stash of the last good frame (kept on disk for a blow-up) goes when the run ends well */
    assert_false(exists(dir, ".last_good.bin"));
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "run --resume '%s' --quiet --end 0.16", dir), 0);
    assert_false(exists(dir, ".last_good.bin"));
    char p[1400], sum[4096];
    snprintf(p, sizeof p, "%s/summary.json", dir);
    FILE *f = fopen(p, "r");
    assert_non_null(f);
    size_t n = fread(sum, 1, sizeof sum - 1, f);
    sum[n] = 0;
    fclose(f);
    assert_non_null(strstr(sum, "\"resumed_from_frame\":\t3"));
}

/* Item 14: progress by steps, at most 4 times a second, from the start of the run (not only
 * once a frame is done); `pfsph render` without a terminal writes no \r-joined line. */
typedef struct prog_log {
    int partial, frames, first_partial_before_step;
    double last_wall, min_gap;
} prog_log;

static void on_progress(const pfsph_progress *p, void *user)
{
    prog_log *l = user;
    if (p->partial) {
        if (l->partial == 0 && p->steps == 0) l->first_partial_before_step = 1;
        if (l->partial > 0 && p->wall_s - l->last_wall < l->min_gap) l->min_gap = p->wall_s - l->last_wall;
        l->last_wall = p->wall_s;
        l->partial++;
    } else l->frames++;
}

static void test_progress(void **state)
{
    (void)state;
    static pfsph_scene s;
    pfsph_error err = {0};
    /* one frame of 1.5 s: about 2,700 steps, a second or two */
    char json[4096];
    snprintf(json, sizeof json, "%s", SCENE);
    char *fps = strstr(json, "\"fps\": 25");
    assert_non_null(fps);
    memcpy(fps, "\"fps\": 1 ", 9);
    char *end = strstr(json, "\"end\": 0.4");
    memcpy(end, "\"end\": 1.5", 10);
    int rc = pfsph_scene_parse(&s, json, "progress", &err);
    if (rc) fail_msg("%s", err.msg);
    char dir[700];
    snprintf(dir, sizeof dir, "%s/progress", tu_tmpdir());
    prog_log l = {0, 0, 0, 0, 1e9};
    pfsph_run_opts o = {.out_dir = dir, .end_time = -1, .scene_text = json, .progress = on_progress, .user = &l};
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    rc = pfsph_run(&s, &o, &err);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (rc) fail_msg("%s", err.msg);
    double wall = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    printf("%d updates within the frame (smallest gap %.3f s) in %.2f s, %d frame updates\n", l.partial, l.min_gap,
           wall, l.frames);
    assert_int_equal(l.frames, 1);
    assert_true(l.first_partial_before_step);
    /* One at the start, then one per 0.25 s of stepping: the count follows the run's own wall
     * time (a fast, idle machine runs this frame in under 0.75 s), less one for the time spent
     * before the first step and after the last. */
    int expect = 1 + (int)floor(wall / 0.25) - 2;
    assert_true(l.partial >= (expect > 1 ? expect : 1));
    assert_true(l.partial <= 1 + (int)ceil(wall / 0.25));
    assert_true(l.min_gap >= 0.24);
    /* render without a terminal: one summary line, no carriage returns */
    char out[8192];
    assert_int_equal(tu_pfsph("OMP_NUM_THREADS=1", out, sizeof out, "render '%s' --size 64x48", dir), 0);
    assert_null(strchr(out, '\r'));
    assert_null(strchr(strchr(out, '\n') + 1, '\n'));
    assert_non_null(strstr(out, "rendered 2 frames"));
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lock),
        cmocka_unit_test(test_fresh_into_old),
        cmocka_unit_test(test_resume_end),
        cmocka_unit_test(test_frame_int_max),
        cmocka_unit_test(test_checkpoint_at_last_frame),
        cmocka_unit_test(test_progress),
    };
    return tu_run_group(tests, setup, NULL);
}
