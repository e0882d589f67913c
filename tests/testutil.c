/* Test helpers (see testutil.h). */
#define _GNU_SOURCE
#include "testutil.h"

#include <math.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "pfsph/sim.h"

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

unsigned char *tu_slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) fprintf(stderr, "cannot open %s\n", path);
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)n + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    b[n] = 0;
    *len = (size_t)n;
    return b;
}

void tu_assert_same_file(const char *dir_a, const char *dir_b, const char *name)
{
    char pa[1200], pb[1200];
    snprintf(pa, sizeof pa, "%s/%s", dir_a, name);
    snprintf(pb, sizeof pb, "%s/%s", dir_b, name);
    size_t la, lb;
    unsigned char *a = tu_slurp(pa, &la), *b = tu_slurp(pb, &lb);
    if (la != lb || memcmp(a, b, la) != 0) fprintf(stderr, "%s and %s differ\n", pa, pb);
    assert_int_equal(la, lb);
    assert_memory_equal(a, b, la);
    free(a);
    free(b);
}

static int uf_find(int *p, int i)
{
    while (p[i] != i) {
        p[i] = p[p[i]];
        i = p[i];
    }
    return i;
}

void tu_bubble_measure(const struct pfsph_ctx *c, int gas, double rho_gas, double R, tu_bubble *b)
{
    const pfsph_particles *f = c->fluid;
    const double h2 = (double)c->h * (double)c->h;
    int *par = malloc(f->n * sizeof *par);
    if (!par) abort();
    double sx = 0, sy = 0;
    int ng = 0;
    b->gas_comp = 0;
    for (size_t i = 0; i < f->n; i++) {
        par[i] = (int)i;
        if (f->phase[i] != gas) continue;
        sx += f->x[i];
        sy += f->y[i];
        ng++;
        double e = (double)f->rho[i] / rho_gas - 1;
        if (e > b->gas_comp) b->gas_comp = e;
    }
    b->cx = ng ? sx / ng : 0;
    b->cy = ng ? sy / ng : 0;
    for (size_t i = 0; i < f->n; i++) {
        if (f->phase[i] != gas) continue;
        for (size_t j = i + 1; j < f->n; j++) {
            if (f->phase[j] != gas) continue;
            double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j];
            if (dx * dx + dy * dy < h2) {
                int a = uf_find(par, (int)i), q = uf_find(par, (int)j);
                if (a != q) par[a] = q;
            }
        }
    }
    b->components = 0;
    b->largest = 0;
    int *size = calloc(f->n ? f->n : 1, sizeof *size);
    if (!size) abort();
    for (size_t i = 0; i < f->n; i++)
        if (f->phase[i] == gas) {
            int r = uf_find(par, (int)i);
            if (++size[r] > b->largest) b->largest = size[r];
        }
    free(size);
    b->rmax = 0;
    b->liquid_in = 0;
    for (size_t i = 0; i < f->n; i++) {
        if (f->phase[i] == gas) {
            double r = hypot((double)f->x[i] - b->cx, (double)f->y[i] - b->cy);
            if (uf_find(par, (int)i) == (int)i) b->components++;
            if (r > b->rmax) b->rmax = r;
            continue;
        }
        /* only liquid near the bubble can be inside it */
        if (hypot((double)f->x[i] - b->cx, (double)f->y[i] - b->cy) > 3 * R) continue;
        int nb = 0, ngas = 0;
        for (size_t j = 0; j < f->n; j++) {
            if (j == i) continue;
            double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j];
            if (dx * dx + dy * dy < h2) {
                nb++;
                ngas += f->phase[j] == gas;
            }
        }
        if (4 * ngas > 3 * nb) b->liquid_in++;
    }
    free(par);
}
