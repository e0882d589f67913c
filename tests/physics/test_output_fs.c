/* Output on a full and on a read-only file system (tmpfs mounts; skipped where mounting is not
 * permitted): a clear error naming the path and the cause, exit status 1 for the full disk (and
 * every frame that was written before the failure is complete), 2 for the read-only one (the
 * output directory cannot be made: bad input). */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/stat.h>

#include "pfsph/io.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.45]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 0.5, \"fps\": 100},"
    " \"phases\": [{\"name\": \"water\", \"viscosity\": 2e-4}, {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.15, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.4], \"phase\": \"wall\"}],"
    " \"output\": {\"formats\": [\"vtp\", \"ply\"]}}";

static char g_mnt[512];

static int mount_tmpfs(const char *opts)
{
    snprintf(g_mnt, sizeof g_mnt, "%s/mnt", tu_tmpdir());
    mkdir(g_mnt, 0777);
    return mount("tmpfs", g_mnt, "tmpfs", 0, opts);
}

static int teardown(void **state)
{
    (void)state;
    if (g_mnt[0]) umount(g_mnt);
    return 0;
}

static void run_into(const char *run, char *out, size_t cap, int *status)
{
    char scene[600], cmd[2048];
    snprintf(scene, sizeof scene, "%s/fs.json", tu_tmpdir());
    assert_int_equal(tu_write_file(scene, SCENE), 0);
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet", tu_pfsph_bin(), scene, run);
    *status = tu_run(cmd, out, cap);
    printf("exit %d: %s", *status, out);
}

static void test_full_fs(void **state)
{
    (void)state;
    if (mount_tmpfs("size=384k") != 0) tu_skip("cannot mount a tmpfs here (needs root)");
    char run[600], out[4096];
    int st;
    snprintf(run, sizeof run, "%s/run", g_mnt);
    run_into(run, out, sizeof out, &st);
    assert_int_equal(st, 1);
    assert_non_null(strstr(out, "No space left on device"));
    assert_non_null(strstr(out, g_mnt));
    /* every frame on disk reads back whole; no temporary files are left */
    char frames[700];
    snprintf(frames, sizeof frames, "%s/frames", run);
    DIR *d = opendir(frames);
    assert_non_null(d);
    struct dirent *e;
    int complete = 0;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        assert_null(strstr(e->d_name, ".tmp"));
        char p[1024];
        snprintf(p, sizeof p, "%s/%s", frames, e->d_name);
        if (!strstr(e->d_name, ".vtp")) continue;
        pfsph_particles ps;
        pfsph_error err;
        double t;
        int rc = pfsph_read_vtp(p, &ps, &t, &err);
        if (rc) fail_msg("%s", err.msg);
        pfsph_particles_free(&ps);
        complete++;
    }
    closedir(d);
    printf("%d complete vtp frames before the disk filled\n", complete);
    assert_true(complete > 0);
}

/* Issue 33, item 1: a disk with a few free pages, no frames, only stats.csv, the stash of the
 * last good state and summary.json (the stash failed silently and, deleted before the
 * summary, made room for a "finished" with rows missing). For every number of free pages the
 * run either finishes with every row, or exits 1 naming the file, with no "finished". */
static void test_full_stats(void **state)
{
    (void)state;
    if (mount_tmpfs("size=1m") != 0) tu_skip("cannot mount a tmpfs here (needs root)");
    char scene[600], cmd[2400], out[4096], run[600], path[700];
    snprintf(scene, sizeof scene, "%s/stats.json", tu_tmpdir());
    /* 400 fps: 121 rows, three pages of stats.csv */
    char text[2048];
    const char *fps = strstr(SCENE, "\"fps\": 100"), *outk = strstr(SCENE, "\"output\"");
    snprintf(text, sizeof text, "%.*s\"fps\": 400%.*s\"output\": {\"formats\": [], \"checkpoint_interval\": 0}}",
             (int)(fps - SCENE), SCENE, (int)(outk - fps - 10), fps + 10);
    assert_int_equal(tu_write_file(scene, text), 0);
    snprintf(run, sizeof run, "%s/run", g_mnt);
    int failed = 0, finished = 0;
    for (int pages = 2; pages <= 24; pages += pages < 12 ? 1 : 4) {
        snprintf(cmd, sizeof cmd,
                 "rm -rf '%s'/* && avail=$(df -B4096 --output=avail '%s' | tail -1) && "
                 "dd if=/dev/zero of='%s/fill' bs=4096 count=$((avail - %d)) 2>/dev/null; true",
                 g_mnt, g_mnt, g_mnt, pages);
        assert_int_equal(tu_run(cmd, out, sizeof out), 0);
        snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet --end 0.3 2>&1", tu_pfsph_bin(), scene, run);
        int st = tu_run(cmd, out, sizeof out);
        snprintf(path, sizeof path, "%s/stats.csv", run);
        FILE *f = fopen(path, "r");
        int lines = 0, c;
        while (f && (c = fgetc(f)) != EOF) lines += c == '\n';
        if (f) fclose(f);
        snprintf(path, sizeof path, "%s/summary.json", run);
        f = fopen(path, "r");
        char sum[4096] = "";
        if (f) sum[fread(sum, 1, sizeof sum - 1, f)] = 0, fclose(f);
        printf("%2d free pages: exit %d, %d lines in stats.csv, %s", pages, st, lines, out[0] ? out : "\n");
        if (st == 0) {
            finished++;
            assert_int_equal(lines, 1 + 121); /* the header, frames 0..120 */
            assert_non_null(strstr(sum, "\"finished\""));
        } else {
            failed++;
            assert_int_equal(st, 1);
            assert_non_null(strstr(out, "No space left on device"));
            assert_non_null(strstr(out, run));
            assert_null(strstr(sum, "\"finished\""));
        }
    }
    printf("%d runs finished whole, %d failed with the file named\n", finished, failed);
    assert_true(failed > 0);
}

static void test_readonly_fs(void **state)
{
    (void)state;
    if (mount_tmpfs("ro,size=64k") != 0) tu_skip("cannot mount a tmpfs here (needs root)");
    char run[600], out[4096];
    int st;
    snprintf(run, sizeof run, "%s/run", g_mnt);
    run_into(run, out, sizeof out, &st);
    /* an output directory that cannot be made is bad input (issue 15, item 12) */
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "output directory"));
    assert_non_null(strstr(out, "Read-only file system"));
    assert_non_null(strstr(out, run));
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test_teardown(test_full_fs, teardown),
                                       cmocka_unit_test_teardown(test_readonly_fs, teardown),
                                       cmocka_unit_test_teardown(test_full_stats, teardown)};
    return tu_run_group(tests, NULL, NULL);
}
