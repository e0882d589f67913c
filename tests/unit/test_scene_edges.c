/* A structure-aware scene fuzzer (issue 33, item 8): every numeric leaf of every example scene in
 * scenes/ replaced, one at a time, by 0, -1, 1e-300, 1e308, a NaN token (not JSON) and a string.
 * Each variant goes through what `pfsph check` does, in process: parse, memory estimate, and for a
 * deterministic sample of the accepted ones within a particle budget the simulation's creation
 * (bodies, emitters, films: no step). A variant must be accepted or refused with PFSPH_EINPUT
 * (exit status 0 or 2) and a message naming a JSON path; a crash or an abort fails the test and
 * names the variant. PFSPH_EDGES_ALL=1 creates every accepted variant's simulation (minutes). */
#include <cjson/cJSON.h>
#include <glob.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "testutil.h"

#define NVALUES 6
static const char *const VALUES[NVALUES] = {"0", "-1", "1e-300", "1e308", "NaN", "\"x\""};

/* the variant under test, for the crash handler */
static char g_current[1024];

static void on_crash(int sig)
{
    static const char head[] = "\ncrash in the variant: ";
    ssize_t w = write(2, head, sizeof head - 1);
    w = write(2, g_current, strlen(g_current));
    w = write(2, "\n", 1);
    (void)w;
    signal(sig, SIG_DFL);
    raise(sig);
}

typedef struct leaf {
    cJSON *node;
    char path[256];
} leaf;

static void collect(cJSON *v, char *path, leaf *out, int *n, int cap)
{
    if (cJSON_IsNumber(v) && *n < cap) {
        out[*n].node = v;
        snprintf(out[*n].path, sizeof out[*n].path, "%s", path);
        (*n)++;
    }
    size_t len = strlen(path);
    int i = 0;
    for (cJSON *c = v->child; c; c = c->next, i++) {
        if (cJSON_IsObject(v)) snprintf(path + len, 256 - len, ".%s", c->string);
        else snprintf(path + len, 256 - len, "[%d]", i);
        collect(c, path, out, n, cap);
        path[len] = 0;
    }
}

typedef struct tally {
    int variants, accepted, refused, estimated, estimate_refused, created, create_refused, skipped_big, bad;
} tally;

static int g_all;

/* The scene with one leaf replaced by VALUES[v] (the leaf is set to a marker number, printed,
 * and the marker replaced in the text); free() it. */
static char *variant(cJSON *root, cJSON *node, int v)
{
    const double keep = node->valuedouble;
    cJSON_SetNumberValue(node, 123456789.25);
    char *out = cJSON_PrintUnformatted(root);
    cJSON_SetNumberValue(node, keep);
    assert_non_null(out);
    char *m = strstr(out, "123456789.25");
    assert_non_null(m);
    size_t pre = (size_t)(m - out), post = strlen(m + 12), vl = strlen(VALUES[v]);
    char *var = malloc(pre + vl + post + 1);
    assert_non_null(var);
    memcpy(var, out, pre);
    memcpy(var + pre, VALUES[v], vl);
    memcpy(var + pre + vl, m + 12, post + 1);
    free(out);
    return var;
}

static void report(int rc, const pfsph_error *err, tally *t)
{
    if (rc != PFSPH_EINPUT || !strstr(err->msg, "$"))
        if (t->bad++ < 20) printf("BAD (rc %d) %s\n    -> %s\n", rc, g_current, err->msg);
}

/* Parsing, for every variant (0.1 ms each): 1 if accepted. */
static int parse_variant(const char *text, const char *source, tally *t)
{
    static pfsph_scene s;
    pfsph_error err = {0};
    t->variants++;
    int rc = pfsph_scene_parse(&s, text, source, &err);
    if (rc == PFSPH_OK) return t->accepted++, 1;
    t->refused++;
    report(rc, &err, t);
    return 0;
}

/* The rest of `pfsph check` and the simulation's creation, for a sample of the accepted
 * variants (up to 0.5 s each): the memory estimate (it builds bodies), then, within a particle
 * budget, pfsph_sim_create. */
static void build_variant(const char *text, const char *source, tally *t)
{
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, text, source, &err), PFSPH_OK);
    t->estimated++;
    size_t nf = 0, nb = 0, bytes = 0;
    int rc = pfsph_scene_estimate(&s, &nf, &nb, &bytes, &err);
    if (rc != PFSPH_OK) {
        t->estimate_refused++;
        report(rc, &err, t);
        return;
    }
    /* `pfsph check` refuses beyond 80% of the memory; here a budget keeps it quick */
    if (nf + nb > 15000 || bytes > ((size_t)64 << 20)) {
        t->skipped_big++;
        return;
    }
    pfsph_sim *sim = NULL;
    rc = pfsph_sim_create(&sim, &s, &err);
    pfsph_sim_destroy(sim);
    if (rc == PFSPH_OK) {
        t->created++;
        return;
    }
    t->create_refused++;
    report(rc, &err, t);
}

/* accepted variants built per scene (spread evenly over its leaves), unless PFSPH_EDGES_ALL */
#define BUILDS_PER_SCENE 3

static void test_edges(void **state)
{
    (void)state;
    g_all = getenv("PFSPH_EDGES_ALL") ? atoi(getenv("PFSPH_EDGES_ALL")) : 0;
    signal(SIGSEGV, on_crash);
    signal(SIGABRT, on_crash);
    signal(SIGFPE, on_crash);
    signal(SIGBUS, on_crash);
    char pattern[1100];
    snprintf(pattern, sizeof pattern, "%s/scenes/*.json", tu_source_dir());
    glob_t g;
    assert_int_equal(glob(pattern, 0, NULL, &g), 0);
    tally t = {0};
    int leaves = 0;
    for (size_t f = 0; f < g.gl_pathc; f++) {
        size_t len;
        char *text = (char *)tu_slurp(g.gl_pathv[f], &len);
        cJSON *root = cJSON_Parse(text);
        free(text);
        assert_non_null(root);
        static leaf L[4096];
        char path[256] = "$";
        int n = 0;
        collect(root, path, L, &n, 4096);
        leaves += n;
        static int acc[4096 * NVALUES];
        int nacc = 0;
        for (int i = 0; i < n; i++)
            for (int v = 0; v < NVALUES; v++) {
                char *var = variant(root, L[i].node, v);
                snprintf(g_current, sizeof g_current, "%s %s = %s", g.gl_pathv[f], L[i].path, VALUES[v]);
                if (parse_variant(var, g.gl_pathv[f], &t)) acc[nacc++] = i * NVALUES + v;
                free(var);
            }
        const int nb = g_all ? nacc : nacc < BUILDS_PER_SCENE ? nacc : BUILDS_PER_SCENE;
        for (int k = 0; k < nb; k++) {
            const int a = acc[g_all ? k : (int)((long)k * nacc / nb)], i = a / NVALUES, v = a % NVALUES;
            char *var = variant(root, L[i].node, v);
            snprintf(g_current, sizeof g_current, "%s %s = %s", g.gl_pathv[f], L[i].path, VALUES[v]);
            build_variant(var, g.gl_pathv[f], &t);
            free(var);
        }
        cJSON_Delete(root);
    }
    globfree(&g);
    printf("%zu scenes, %d numeric leaves, %d variants: %d refused by the parser, %d accepted; of these %d "
           "estimated (%d refused), %d too large to build here, %d simulations built, %d refused when built; %d "
           "without PFSPH_EINPUT (exit status 2) and a JSON path\n",
           g.gl_pathc, leaves, t.variants, t.refused, t.accepted, t.estimated, t.estimate_refused, t.skipped_big,
           t.created, t.create_refused, t.bad);
    assert_true(leaves > 1000);
    assert_int_equal(t.bad, 0);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_edges)};
    return tu_run_group(tests, NULL, NULL);
}
