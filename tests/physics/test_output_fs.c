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
                                       cmocka_unit_test_teardown(test_readonly_fs, teardown)};
    return tu_run_group(tests, NULL, NULL);
}
