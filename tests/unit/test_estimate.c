/* The memory estimate of `pfsph check` (issue 15): particle counts in closed form equal the
 * counts of the sampling walk (item 6), a 1e12-particle scene is refused in seconds (item 6),
 * the grid term neither overflows nor passes for a huge domain (item 7), and the estimate
 * covers what a run allocates (item 7: measured against the peak resident size of a run). */
#define _GNU_SOURCE /* wait4 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "pfsph/sim.h"
#include "physics/solver.h"
#include "scene/shapes.h"
#include "testutil.h"

static double urand(unsigned *st)
{
    *st = *st * 1103515245u + 12345u;
    return (double)((*st >> 8) & 0xffffff) / (double)0x1000000;
}

static void base_scene(pfsph_scene *s, int dim)
{
    pfsph_error err = {0};
    const char *j = dim == 2 ? "{\"dimension\":2,\"domain\":{\"min\":[-2,-2],\"max\":[2,2]},"
                               "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[0.1,0.1]}]}"
                             : "{\"dimension\":3,\"domain\":{\"min\":[-2,-2,-2],\"max\":[2,2,2]},"
                               "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[0.1,0.1,0.1]}]}";
    assert_int_equal(pfsph_scene_parse(s, j, "estimate", &err), PFSPH_OK);
}

/* Item 6: the closed-form counts are the walk's, shape by shape. */
static void test_counts_match_walk(void **state)
{
    (void)state;
    static pfsph_scene s;
    unsigned seed = 12345;
    pfsph_particles ps;
    assert_int_equal(pfsph_particles_init(&ps, 1024), PFSPH_OK);
    int cases = 0;
    for (int dim = 2; dim <= 3; dim++) {
        base_scene(&s, dim);
        for (int t = 0; t < 300; t++) {
            pfsph_block b;
            memset(&b, 0, sizeof b);
            b.shape = t % 3 == 0 ? PFSPH_SHAPE_BOX : t % 3 == 1 ? PFSPH_SHAPE_SPHERE : PFSPH_SHAPE_CYLINDER;
            double d = 0.02 + 0.03 * urand(&seed);
            for (int a = 0; a < dim; a++) {
                b.min[a] = -0.5 + urand(&seed);
                b.max[a] = b.min[a] + 0.6 * urand(&seed);
                b.center[a] = -0.5 + urand(&seed);
            }
            /* on-lattice edge cases too: radii and heights of whole spacings */
            b.radius = t % 5 == 0 ? d * (1 + t % 7) : 0.4 * urand(&seed);
            b.height = t % 5 == 1 ? d * (2 + t % 3) : 0.5 * urand(&seed);
            b.axis = t % 3;
            b.jitter = t % 4 == 0 ? 0.1 : 0;
            ps.n = 0;
            long walked = pfsph__sample_block(&s, &b, d, &ps);
            long counted = pfsph__sample_block(&s, &b, d, NULL);
            if (walked != counted)
                fail_msg("dim %d shape %d axis %d d %g r %g h %g: walk %ld, closed form %ld", dim, b.shape, b.axis, d,
                         b.radius, b.height, walked, counted);
            assert_int_equal((long)ps.n, walked);
            cases++;
        }
        for (int t = 0; t < 120; t++) {
            pfsph_solid o;
            memset(&o, 0, sizeof o);
            o.shape = t % 2 ? PFSPH_SHAPE_CONTAINER : PFSPH_SHAPE_BOX;
            o.layers = 1 + t % 3;
            o.open_top = (t / 2) % 2;
            double d = 0.02 + 0.03 * urand(&seed);
            for (int a = 0; a < dim; a++) {
                o.min[a] = -0.5 + urand(&seed);
                o.max[a] = o.min[a] + (t % 7 == 0 ? 0.01 : 0.8 * urand(&seed));
            }
            ps.n = 0;
            long walked = pfsph__sample_solid(&s, &o, d, &ps);
            long counted = pfsph__sample_solid(&s, &o, d, NULL);
            if (walked != counted)
                fail_msg("dim %d solid %d layers %d open %d: walk %ld, closed form %ld", dim, o.shape, o.layers,
                         o.open_top, walked, counted);
            cases++;
        }
    }
    printf("%d shapes: closed-form counts equal the walk's\n", cases);
    pfsph_particles_free(&ps);
}

static double wall(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* `pfsph check` on SCENE text (timeout 60 s); returns the exit status, output in out. */
static int check(const char *name, const char *json, char *out, size_t cap, double *secs)
{
    char path[600], cmd[2048];
    snprintf(path, sizeof path, "%s/%s", tu_tmpdir(), name);
    assert_int_equal(tu_write_file(path, json), 0);
    snprintf(cmd, sizeof cmd, "timeout 60 '%s' check '%s'", tu_pfsph_bin(), path);
    double t0 = wall();
    int st = tu_run(cmd, out, cap);
    if (secs) *secs = wall() - t0;
    printf("%s: exit %d in %.2f s: %s", name, st, wall() - t0, out);
    return st;
}

/* Item 6: 1e12 and 1e9 particles (a 3D box, a 3D sphere) are counted and refused in well under
 * a second each, not after minutes. */
static void test_huge_counts_fast(void **state)
{
    (void)state;
    char out[4096];
    double secs;
    int st = check("e12.json",
                   "{\"dimension\":3,\"particle_radius\":0.0005,\"domain\":{\"min\":[0,0,0],\"max\":[10,10,10]},"
                   "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[10,10,10]}]}",
                   out, sizeof out, &secs);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "1000000000000 fluid"));
    assert_non_null(strstr(out, "enlarge particle_radius"));
    assert_true(secs < 10);
    st = check("e9sphere.json",
               "{\"dimension\":3,\"particle_radius\":0.0005,\"domain\":{\"min\":[0,0,0],\"max\":[1.3,1.3,1.3]},"
               "\"fluid\":[{\"shape\":\"sphere\",\"center\":[0.65,0.65,0.65],\"radius\":0.62}]}",
               out, sizeof out, &secs);
    assert_int_equal(st, 2);
    assert_true(secs < 10);
}

/* Item 7: a tiny radius in a huge domain (the grid term, ~1e22 bytes, overflowed to a small
 * size_t) and a huge radius in a huge domain (a 4.7 GB grid for 25 particles) are refused,
 * and the message blames the domain, not the particle radius (item 12). */
static void test_grid_term(void **state)
{
    (void)state;
    char out[4096];
    int st = check("tiny_r.json",
                   "{\"dimension\":3,\"particle_radius\":0.0001,\"domain\":{\"min\":[0,0,0],"
                   "\"max\":[1e6,1e6,1e6]},\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],"
                   "\"max\":[0.001,0.001,0.001]}]}",
                   out, sizeof out, NULL);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "$.domain"));
    assert_null(strstr(out, "valid 3D scene"));
    st = check("huge_r.json",
               "{\"dimension\":3,\"particle_radius\":2,\"domain\":{\"min\":[0,0,0],"
               "\"max\":[6e3,6e3,6e3]},\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],"
               "\"max\":[20,20,20]}]}",
               out, sizeof out, NULL);
    assert_int_equal(st, 2);
    assert_non_null(strstr(out, "$.domain"));
    assert_non_null(strstr(out, "grid"));
    assert_null(strstr(out, "enlarge particle_radius"));
}

/* Peak resident size [bytes] of `pfsph run SCENE -o DIR --quiet`, one thread. */
static double run_peak(const char *scene, const char *dir)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        setenv("OMP_NUM_THREADS", "1", 1);
        execl(tu_pfsph_bin(), tu_pfsph_bin(), "run", scene, "-o", dir, "--quiet", (char *)NULL);
        _exit(127);
    }
    int st;
    struct rusage ru;
    assert_int_equal(wait4(pid, &st, 0, &ru), pid);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    return (double)ru.ru_maxrss * 1024.0;
}

/* Issue 28: the estimate follows the neighbour-list choice. A 3D DFSPH (IISPH) scene with lists
 * counts about 537 B per fluid particle more than with grid walks (src/sim_estimate.c), and
 * DFSPH's scratch of 15 values per particle with lists, none of its own without (walk_nscratch:
 * its one array in the stages' shared one); "auto"
 * takes lists for a small scene, and grid walks where the lists' 32-bit offsets would overflow
 * (2.2e8 particles, whatever the machine's memory); WCSPH builds none whatever the key says. */
static double lists_estimate(const char *solver, const char *lists, double side, size_t *nf, int *built)
{
    char json[1024], key[64] = "";
    if (lists) snprintf(key, sizeof key, ",\"neighbour_lists\":%s", lists);
    snprintf(json, sizeof json,
             "{\"dimension\":3,\"particle_radius\":0.005,\"domain\":{\"min\":[-0.1,-0.1,-0.1],"
             "\"max\":[%g,%g,%g]},\"solver\":{\"type\":\"%s\"%s},"
             "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0,0],\"max\":[%g,%g,%g]}]}",
             side + 0.1, side + 0.1, side + 0.1, solver, key, side, side, side);
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, json, "lists", &err), PFSPH_OK);
    size_t bytes = 0;
    assert_int_equal(pfsph_scene_estimate(&s, nf, NULL, &bytes, &err), PFSPH_OK);
    *built = pfsph__sim_lists(&s, (double)*nf);
    return (double)bytes;
}

static void test_lists_follow_mode(void **state)
{
    (void)state;
    static const char *const solvers[] = {"dfsph", "iisph"};
    size_t nf;
    int on_built, off_built, auto_built;
    for (int k = 0; k < 2; k++) {
        const double on = lists_estimate(solvers[k], "true", 0.2, &nf, &on_built),
                     off = lists_estimate(solvers[k], "false", 0.2, &nf, &off_built);
        const pfsph_solver_ops *ops = pfsph_solver_find(solvers[k]);
        const int walk = ops->walk_nscratch ? (ops->walk_nscratch > 1 ? ops->walk_nscratch - 1 : 0)
                                            : ops->nscratch + 3 * ops->nscratch4;
        const double layout = 1.05 * (double)(ops->nscratch + 3 * ops->nscratch4 - walk) * sizeof(pfsph_real);
        const double per = (on - off) / (double)nf - layout;
        printf("%s: %zu fluid particles, %.0f B each with lists, %.0f without: the lists %.0f B, the scratch %.0f B\n",
               solvers[k], nf, on / (double)nf, off / (double)nf, per, layout);
        assert_true(on_built && !off_built);
        assert_true(per > 1.05 * 530 && per < 1.05 * 545);
        assert_true(lists_estimate(solvers[k], NULL, 0.2, &nf, &auto_built) == on && auto_built);
    }
    /* 6 m at d = 1 cm: 2.2e8 particles, 1.2e10 list entries */
    const double big_off = lists_estimate("dfsph", "false", 6.0, &nf, &off_built);
    assert_true(nf > 200000000);
    assert_true(lists_estimate("dfsph", NULL, 6.0, &nf, &auto_built) == big_off && !auto_built);
    assert_true(lists_estimate("dfsph", "true", 6.0, &nf, &on_built) > big_off && on_built);
    assert_true(lists_estimate("wcsph", "true", 0.2, &nf, &on_built) ==
                lists_estimate("wcsph", "false", 0.2, &nf, &off_built));
    assert_true(!on_built && !off_built);
}

/* Item 7: the estimate is not below what a run holds at its peak (resident size of a run of
 * a 2D scene of 160,000 particles, less that of the same program on 16 particles), nor far
 * above it. 160,000 rather than 40,000: the small run's size varies by about 0.2 MiB, which at
 * 40,000 particles was 2 % of the measurement, as much as the estimate's margin (ratios
 * 1.01-1.03 over three runs). Under the sanitizers the run's own size means nothing: only the
 * estimate's. */
static void peak_vs_estimate(const char *solver, const char *tag)
{
    static const char *const fmt =
        "{\"dimension\":2,\"particle_radius\":%s,\"gravity\":[0,-9.81],"
        "\"domain\":{\"min\":[-0.05,-0.05],\"max\":[1.05,1.05]},\"time\":{\"end\":0.01,\"fps\":100},"
        "\"phases\":[{\"name\":\"water\"},{\"name\":\"wall\",\"kind\":\"solid\"}],"
        "\"fluid\":[{\"shape\":\"box\",\"min\":[0,0],\"max\":[%s,%s]}],"
        "\"solids\":[{\"shape\":\"container\",\"min\":[0,0],\"max\":[1,1],\"phase\":\"wall\"}],"
        "\"output\":{\"formats\":[\"vtp\"],\"checkpoint_interval\":1}%s}";
    char json[2048], path[600], dir[600];
    snprintf(json, sizeof json, fmt, "0.00125", "1", "1", solver);
    snprintf(path, sizeof path, "%s/peak%s.json", tu_tmpdir(), tag);
    assert_int_equal(tu_write_file(path, json), 0);
    static pfsph_scene s;
    pfsph_error err = {0};
    assert_int_equal(pfsph_scene_parse(&s, json, "peak", &err), PFSPH_OK);
    size_t nf, nb, bytes;
    assert_int_equal(pfsph_scene_estimate(&s, &nf, &nb, &bytes, &err), PFSPH_OK);
    printf("%s: estimate %.1f MiB (%.0f B per fluid particle) for %zu fluid + %zu boundary\n", tag, bytes / 1048576.0,
           (double)bytes / nf, nf, nb);
#if defined(__SANITIZE_ADDRESS__) || defined(PFSPH_SANITIZED)
    /* clang's UBSan run measured 239 B per particle against 238 estimated */
    tu_skip("an instrumented build's memory is not the program's");
#endif
    /* a forked child starts with this process's size, which under valgrind is tens of MiB */
    struct rusage self;
    assert_int_equal(getrusage(RUSAGE_SELF, &self), 0);
    if (self.ru_maxrss > 32 * 1024) {
        printf("this process holds %ld KiB (valgrind?): no measurement\n", self.ru_maxrss);
        tu_skip("a forked child would start with this process's size (valgrind?)");
    }
    snprintf(dir, sizeof dir, "%s/peak%s_run", tu_tmpdir(), tag);
    double peak = run_peak(path, dir);
    char small[600];
    snprintf(json, sizeof json, fmt, "0.00125", "0.005", "0.005", solver);
    snprintf(small, sizeof small, "%s/base%s.json", tu_tmpdir(), tag);
    assert_int_equal(tu_write_file(small, json), 0);
    snprintf(dir, sizeof dir, "%s/base%s_run", tu_tmpdir(), tag);
    double base = run_peak(small, dir);
    double used = peak - base;
    printf("run peak RSS %.1f MiB, the program alone %.1f MiB: %.0f B per fluid particle; estimate / measured %.2f\n",
           peak / 1048576.0, base / 1048576.0, used / nf, (double)bytes / used);
    assert_true((double)bytes >= used);
    assert_true((double)bytes <= 2.0 * used);
}

static void test_estimate_vs_run(void **state)
{
    (void)state;
    peak_vs_estimate("", "pcisph");
}

/* Issue 28: DFSPH with grid walks instead of neighbour lists, as a large scene runs it */
static void test_estimate_vs_run_dfsph_grid(void **state)
{
    (void)state;
    peak_vs_estimate(",\"solver\":{\"type\":\"dfsph\",\"neighbour_lists\":false}", "dfsph_grid");
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_counts_match_walk), cmocka_unit_test(test_huge_counts_fast),
        cmocka_unit_test(test_grid_term),         cmocka_unit_test(test_lists_follow_mode),
        cmocka_unit_test(test_estimate_vs_run),   cmocka_unit_test(test_estimate_vs_run_dfsph_grid),
    };
    return tu_run_group(tests, NULL, NULL);
}
