/* Test helpers (see testutil.h). */
#define _GNU_SOURCE
#include "testutil.h"

#include <math.h>
#include <omp.h>
#include <png.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "pfsph/eigen.h"
#include "pfsph/run.h"
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

/* ---- skips (see testutil.h) ---- */

#define TU_MAX_SKIPS 64
static int g_nskip;
static const char *g_skip_test[TU_MAX_SKIPS], *g_skip_why[TU_MAX_SKIPS];

void tu_skip_(const char *test, const char *reason)
{
    print_message("%s: skipped: %s\n", test, reason);
    if (g_nskip < TU_MAX_SKIPS) g_skip_test[g_nskip] = test, g_skip_why[g_nskip] = reason;
    g_nskip++;
    _skip(__FILE__, __LINE__); /* cmocka's skip(): marks the test skipped and jumps out of it */
}

int tu_run_group_(const char *name, const struct CMUnitTest *tests, size_t n, CMFixtureFunction setup,
                  CMFixtureFunction teardown)
{
    g_nskip = 0;
    const int failed = _cmocka_run_group_tests(name, tests, n, setup, teardown);
    if (g_nskip == 0) return failed;
    print_message("%d of %zu tests skipped:\n", g_nskip, n);
    for (int i = 0; i < g_nskip && i < TU_MAX_SKIPS; i++) print_message("  %s: %s\n", g_skip_test[i], g_skip_why[i]);
    if (failed) return failed;
    if ((size_t)g_nskip >= n) {
        print_message("nothing ran: exit status %d (skipped)\n", TU_SKIPPED);
        return TU_SKIPPED;
    }
    return 0;
}

void tu_skip_program(const char *reason)
{
    fflush(stdout);
    fprintf(stderr, "skipped: %s\n", reason);
    exit(TU_SKIPPED);
}

void tu_release_only(void)
{
#ifdef __SANITIZE_ADDRESS__
    tu_skip_program("a validation measurement: too slow under AddressSanitizer, it runs in Release");
#endif
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

void tu_write_bytes(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
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

int tu_pfsph(const char *env, char *out, size_t cap, const char *fmt, ...)
{
    char args[2048], cmd[4096];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(args, sizeof args, fmt, ap);
    va_end(ap);
    snprintf(cmd, sizeof cmd, "%s%s'%s' %s", env, env[0] ? " " : "", tu_pfsph_bin(), args);
    int st = tu_run(cmd, out, cap);
    printf("$ pfsph %s\n-> %d %s", args, st, out);
    return st;
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

tu_img tu_read_png(const char *path)
{
    tu_img m = {0, 0, NULL};
    FILE *f = fopen(path, "rb");
    if (!f) fail_msg("cannot open %s", path);
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png))) fail_msg("libpng failed on %s", path);
    png_init_io(png, f);
    png_read_info(png, info);
    assert_int_equal(png_get_color_type(png, info), PNG_COLOR_TYPE_RGB);
    assert_int_equal(png_get_bit_depth(png, info), 8);
    m.w = (int)png_get_image_width(png, info);
    m.h = (int)png_get_image_height(png, info);
    m.rgb = malloc((size_t)m.w * m.h * 3);
    assert_non_null(m.rgb);
    for (int y = 0; y < m.h; y++) png_read_row(png, m.rgb + (size_t)y * m.w * 3, NULL);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    return m;
}

size_t tu_nearest(const pfsph_particles *ps, double x, double y, double z)
{
    size_t best = 0;
    double bd = 1e300;
    for (size_t i = 0; i < ps->n; i++) {
        double dx = ps->x[i] - x, dy = ps->y[i] - y, dz = ps->z[i] - z;
        double r2 = dx * dx + dy * dy + dz * dz;
        if (r2 < bd) {
            bd = r2;
            best = i;
        }
    }
    return best;
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

pfsph_sim *tu_sim_from_json(const char *json, const char *name)
{
    pfsph_scene *s = malloc(sizeof *s);
    assert_non_null(s);
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(s, json, name, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    pfsph_sim *sim = NULL;
    rc = pfsph_sim_create(&sim, s, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    free(s); /* the simulation keeps its own copy */
    return sim;
}

void tu_pfsph_run(const pfsph_scene *s, const char *dir, double end, int resume)
{
    pfsph_run_opts o = {.out_dir = dir, .end_time = end, .resume = resume};
    pfsph_error err = {0};
    int rc = pfsph_run(s, &o, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
}

void tu_advance(pfsph_sim *sim, double t)
{
    pfsph_error err = {0};
    int rc = pfsph_sim_advance(sim, t, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
}

/* ---- shape of a free drop (the shape tests of docs/thermostat.md) ---- */

tu_shape tu_shape_measure(const pfsph_ctx *c)
{
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    double m[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) m[0] += f->x[i], m[1] += f->y[i], m[2] += f->z[i];
    for (int a = 0; a < 3; a++) m[a] /= (double)n;
    double C[3][3] = {{0}};
    for (size_t i = 0; i < n; i++) {
        const double q[3] = {f->x[i] - m[0], f->y[i] - m[1], f->z[i] - m[2]};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) C[a][b] += q[a] * q[b];
    }
    tu_shape s;
    if (c->dim == 2) {
        const double C2[2][2] = {{C[0][0], C[0][1]}, {C[0][1], C[1][1]}};
        double w[2], v[2][2];
        pfsph_eigen_sym2(C2, w, v);
        s.ratio = fmin(w[0], w[1]) / fmax(w[0], w[1]);
    } else {
        double w[3], v[3][3];
        pfsph_eigen_sym3(C, w, v);
        s.ratio = fmin(w[0], fmin(w[1], w[2])) / fmax(w[0], fmax(w[1], w[2]));
    }
    const double d = c->spacing, h2 = 4 * d * d, c2 = 0.25 * d * d;
    size_t nh = 0, nc = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            double dx = f->x[i] - f->x[j], dy = f->y[i] - f->y[j], dz = f->z[i] - f->z[j];
            double q = dx * dx + dy * dy + dz * dz;
            nh += q < h2;
            nc += q < c2;
        }
    s.close = nh ? (double)nc / (double)nh : 0;
    return s;
}

tu_relax tu_shape_relax(int dim, int nl, int ns, int seed, double t_end, double t_win, double dt_s)
{
    char json[2048];
    const double d = 0.01, a = 0.5 * nl * d, b = 0.5 * ns * d;
    if (dim == 2)
        snprintf(json, sizeof json,
                 "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
                 " \"domain\": {\"min\": [-1, -1], \"max\": [1, 1]},"
                 " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.003}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [%g, %g], \"max\": [%g, %g]}],"
                 " \"pairwise\": {\"thermostat\": {\"reduced_temperature\": 0.01}, \"k\": 1.7,"
                 " \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 4}]}}",
                 seed, -a, -b, a, b);
    else
        snprintf(json, sizeof json,
                 "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": 0.005, \"gravity\": [0, 0, 0],"
                 " \"domain\": {\"min\": [-0.5, -0.5, -0.5], \"max\": [0.5, 0.5, 0.5]},"
                 " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.003}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}],"
                 " \"pairwise\": {\"thermostat\": {\"reduced_temperature\": 0.01}, \"k\": 1.3867,"
                 " \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 4}]}}",
                 seed, -a, -b, -b, a, b, b);
    pfsph_sim *sim = tu_sim_from_json(json, "block.json");
    pfsph_error err = {0};
    int rc;
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    tu_shape st = tu_shape_measure(c);
    assert_true(st.ratio < 0.3); /* 2:1 block: 0.25 */
    tu_relax r = {0, 0, 0};
    int navg = 0;
    const int ns_tot = (int)lround(t_end / dt_s);
    const double c0 = ((double)clock() / CLOCKS_PER_SEC);
    for (int i = 1; i <= ns_tot; i++) {
        rc = pfsph_sim_advance(sim, dt_s * i, &err);
        if (rc) print_message("%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        st = tu_shape_measure(c);
        if (dt_s * i > t_end - t_win + 1e-9) {
            r.ratio += st.ratio;
            r.close += st.close;
            navg++;
        }
        if (i % (int)lround(0.5 / dt_s) == 0)
            print_message("  seed %d t = %.2f s: moment ratio %.4f, %.4f %% of pairs closer than d/2\n", seed,
                          pfsph_sim_time(sim), st.ratio, 100 * st.close);
    }
    r.cpu = ((double)clock() / CLOCKS_PER_SEC) - c0;
    r.ratio /= navg;
    r.close /= navg;
    assert_int_equal(pfsph_sim_removed(sim), 0);
    pfsph_sim_destroy(sim);
    return r;
}

/* ---- small numerics shared by the measurement tests ---- */

double tu_shape_relax_seeds(int dim, int nl, int ns, double t_end, double t_win, double dt_s, const char *window)
{
    double mean = 0;
    for (int seed = 1; seed <= 3; seed++) {
        tu_relax r = tu_shape_relax(dim, nl, ns, seed, t_end, t_win, dt_s);
        print_message("seed %d: over %.2f - %.2f s (%s) moment ratio %.4f, %.4f %% of "
                      "pairs closer than d/2; %.1f s CPU\n",
                      seed, t_end - t_win, t_end, window, r.ratio, 100 * r.close, r.cpu);
        assert_true(r.ratio >= 0.95);
        assert_true(r.close <= 0.001);
        mean += r.ratio / 3;
    }
    return mean;
}

tu_line tu_line_fit(int n, const double *x, const double *y)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    for (int i = 0; i < n; i++) sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i], syy += y[i] * y[i];
    tu_line l;
    const double det = n * sxx - sx * sx;
    l.slope = (n * sxy - sx * sy) / det, l.icpt = (sy - l.slope * sx) / n;
    const double cov = sxy / n - sx * sy / (n * n), vx = sxx / n - sx * sx / (n * n), vy = syy / n - sy * sy / (n * n);
    l.r2 = vy > 0 ? cov * cov / (vx * vy) : 0;
    return l;
}

void tu_block_mean(const double *s, size_t m, int nb, double *mean, double *se, double *bm)
{
    double b_[64];
    if (nb < 2 || nb > 64 || m < (size_t)nb) { /* no assertion: called from parallel jobs */
        *mean = *se = NAN;
        return;
    }
    const size_t bl = m / (size_t)nb;
    double mu = 0, v = 0;
    for (int b = 0; b < nb; b++) {
        b_[b] = 0;
        for (size_t i = (size_t)b * bl; i < (size_t)(b + 1) * bl; i++) b_[b] += s[i];
        b_[b] /= (double)bl;
        mu += b_[b] / nb;
    }
    for (int b = 0; b < nb; b++) v += (b_[b] - mu) * (b_[b] - mu);
    *mean = mu;
    *se = sqrt(v / (nb - 1) / nb);
    if (bm) memcpy(bm, b_, (size_t)nb * sizeof *bm);
}

const char *tu_env(const char *env, const char *def)
{
    const char *e = getenv(env);
    return e ? e : def;
}

double tu_env_num(const char *env, double def)
{
    const char *e = getenv(env);
    return e ? atof(e) : def;
}

int tu_env_list(const char *env, double *v, int max, int n_default)
{
    const char *e = getenv(env);
    if (!e) return n_default;
    int n = 0;
    for (char *p = (char *)e; *p && n < max;) {
        char *end;
        v[n] = strtod(p, &end);
        if (end == p) break;
        n++, p = end;
        if (*p == ',') p++;
    }
    return n;
}

void tu_parallel_largest_first(int n, const double *size, void (*fn)(void *arg, int i), void *arg)
{
    int order[64];
    assert_true(n >= 0 && n <= 64);
    for (int i = 0; i < n; i++) order[i] = i;
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && size[order[j]] > size[order[j - 1]]; j--) {
            const int t = order[j];
            order[j] = order[j - 1], order[j - 1] = t;
        }
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1); /* inside each call (nested regions are inactive anyway) */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int q = 0; q < n; q++) fn(arg, order[q]);
    omp_set_num_threads(threads);
}
