/* Test helpers (see testutil.h). */
#define _GNU_SOURCE
#include "testutil.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static const char *g_src = ".";
static const char *g_bin = "pfsph";
static char g_tmp[256];

static void cleanup(void)
{
    if (g_tmp[0]) {
        char cmd[300];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_tmp);
        if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", g_tmp);
    }
}

void tu_init(int argc, char **argv)
{
    const char *e;
    if (argc > 1) g_src = argv[1];
    else if ((e = getenv("PFSPH_SOURCE_DIR"))) g_src = e;
    if (argc > 2) g_bin = argv[2];
    else if ((e = getenv("PFSPH_BIN"))) g_bin = e;
}

const char *tu_source_dir(void) { return g_src; }
const char *tu_pfsph_bin(void) { return g_bin; }

const char *tu_tmpdir(void)
{
    if (!g_tmp[0]) {
        strcpy(g_tmp, "/tmp/pfsph_test_XXXXXX");
        if (!mkdtemp(g_tmp)) return NULL;
        atexit(cleanup);
    }
    return g_tmp;
}

int tu_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    size_t n = strlen(text);
    int ok = fwrite(text, 1, n, f) == n;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

int tu_run(const char *cmd, char *out, size_t cap)
{
    char full[4096];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p) return -1;
    size_t n = 0;
    if (out && cap) {
        n = fread(out, 1, cap - 1, p);
        out[n] = 0;
    }
    char sink[4096];
    while (fread(sink, 1, sizeof sink, p) > 0) {}
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}
