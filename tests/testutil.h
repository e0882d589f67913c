/* Shared helpers for tests: paths, temporary directories, running the pfsph program. */
#ifndef PFSPH_TESTUTIL_H
#define PFSPH_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

/* Skips. A test that cannot run here (no display, no Blender or ParaView, no ffmpeg, a
 * measurement that an instrumented build falsifies) says so with tu_skip, never with cmocka's
 * skip(): cmocka counts a skip as a pass in the exit status, so the program would read
 * "Passed". tu_run_group returns TU_SKIPPED when every test of the group skipped, and CMake sets
 * SKIP_RETURN_CODE to it on every test, so that ctest reports "Not Run (Skipped)"; a group where
 * only some skip passes and lists what it skipped, and why, after cmocka's summary. */
#define TU_SKIPPED 77 /* the exit status of a skipped test program (automake's convention) */
#undef skip
#define skip() tu_skip_needs_a_reason /* use tu_skip(reason) */
/* Skips the calling test (a cmocka test function) and records why; does not return. */
#define tu_skip(reason) tu_skip_(__func__, reason)
void tu_skip_(const char *test, const char *reason);
/* Runs a cmocka group (an array of struct CMUnitTest, as cmocka_run_group_tests does): the
 * number of failed tests, else TU_SKIPPED when all of them skipped, else 0. */
#define tu_run_group(tests, setup, teardown) \
    tu_run_group_(#tests, tests, sizeof(tests) / sizeof((tests)[0]), setup, teardown)
int tu_run_group_(const char *name, const struct CMUnitTest *tests, size_t n, CMFixtureFunction setup,
                  CMFixtureFunction teardown);
/* The whole program cannot run here: prints why and exits with TU_SKIPPED (from main, or from
 * the one test of a one-test group). */
_Noreturn void tu_skip_program(const char *reason);
/* A validation test (a measurement over seconds of simulated time, run in Release: CI's last
 * step) calls this first: under AddressSanitizer (the asan preset, 4-10x slower) it skips the
 * program, since a run short enough would measure nothing; elsewhere it returns. */
void tu_release_only(void);

/* Source directory (argv[1] / PFSPH_SOURCE_DIR) and pfsph program (argv[2] / PFSPH_BIN). */
void tu_init(int argc, char **argv);
const char *tu_source_dir(void);
const char *tu_pfsph_bin(void);
/* A fresh empty directory under /tmp, removed by tu_cleanup (registered with atexit). */
const char *tu_tmpdir(void);
/* Write text to a file; returns 0 on success. */
int tu_write_file(const char *path, const char *text);
/* Write len bytes to a file; fails the test if it cannot. */
void tu_write_bytes(const char *path, const void *data, size_t len);
/* Run a shell command, capturing stdout+stderr into out (truncated to cap). Returns the exit
 * status (or -1). */
int tu_run(const char *cmd, char *out, size_t cap);
/* The pfsph program with the printf-style arguments fmt, after the environment assignments env
 * ("" for none; "OMP_NUM_THREADS=1"); prints the command line, status and output. Returns the
 * exit status, the output (stdout+stderr) in out[cap]. */
int tu_pfsph(const char *env, char *out, size_t cap, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* A whole file, NUL-terminated (len excludes the NUL); fails the test if it cannot be read.
 * Free with free(). */
unsigned char *tu_slurp(const char *path, size_t *len);
/* dir_a/name and dir_b/name have the same bytes (fails the test otherwise, naming both). */
void tu_assert_same_file(const char *dir_a, const char *dir_b, const char *name);

/* Least-squares line y = icpt + slope x through n points, and its coefficient of determination
 * r2 (0 when y does not vary). */
typedef struct tu_line {
    double slope, icpt, r2;
} tu_line;
tu_line tu_line_fit(int n, const double *x, const double *y);
/* The mean of m samples and its standard error from nb consecutive block means (the samples of
 * a time series are correlated; blocks longer than the correlation time are not): needs
 * m >= nb, 2 <= nb <= 64 (else NaN); bm, if not NULL, receives the nb block means. Safe in
 * parallel jobs (no assertion). */
void tu_block_mean(const double *s, size_t m, int nb, double *mean, double *se, double *bm);
/* A study knob: the environment variable env, or def when it is not set; as a number. */
const char *tu_env(const char *env, const char *def);
double tu_env_num(const char *env, double def);
/* Up to max comma-separated numbers from the environment variable env into v (a study knob);
 * returns how many, or n_default with v untouched when env is not set. */
int tu_env_list(const char *env, double *v, int max, int n_default);
/* Calls fn(arg, i) for every i in [0, n), in parallel on omp_get_max_threads() threads, the
 * largest size[i] first (so the longest job starts at once), each call with OpenMP's thread
 * count set to 1: for independent simulations too small to gain from threads, whose bits
 * then do not depend on the order. fn must not use cmocka's assertions (they jump). */
void tu_parallel_largest_first(int n, const double *size, void (*fn)(void *arg, int i), void *arg);

/* An 8-bit RGB PNG, rows top to bottom (fails the test if the file is anything else); free rgb
 * with free(). */
typedef struct tu_img {
    int w, h;
    unsigned char *rgb;
} tu_img;
tu_img tu_read_png(const char *path);

/* Index of the particle of ps nearest to (x, y, z). */
struct pfsph_particles;
size_t tu_nearest(const struct pfsph_particles *ps, double x, double y, double z);

/* A gas bubble in a liquid (test_pf_rising_bubble, test_pf_density_ratio), measured over the
 * fluid particles of ctx: particles of phase `gas` are the bubble, R is its equivalent radius. */
struct pfsph_ctx;
typedef struct tu_bubble {
    double cx, cy;   /* gas centroid */
    int components;  /* connected components of gas particles, links shorter than h */
    int largest;     /* gas particles in the largest component */
    double rmax;     /* farthest gas particle from the centroid */
    int liquid_in;   /* other particles within 3 R with more than 3/4 of their neighbours gas */
    double gas_comp; /* largest gas compression rho / rho_gas - 1 */
} tu_bubble;
void tu_bubble_measure(const struct pfsph_ctx *c, int gas, double rho_gas, double R, tu_bubble *b);

/* A simulation of a scene given as JSON text (name: for messages); fails the test, printing the
 * message, when the scene does not parse or the simulation cannot start. */
struct pfsph_sim;
struct pfsph_sim *tu_sim_from_json(const char *json, const char *name);
/* pfsph_run of scene s into dir to time end (a resume when resume is set); fails the test,
 * printing the message, on an error. */
struct pfsph_scene;
void tu_pfsph_run(const struct pfsph_scene *s, const char *dir, double end, int resume);
/* pfsph_sim_advance to time t; fails the test, printing the message, on an error. */
void tu_advance(struct pfsph_sim *sim, double t);

/* Shape of a free drop (docs/thermostat.md, "The shape tests"): ratio is the smallest / largest
 * principal second moment about the centroid, close the fraction of kernel-neighbour pairs
 * (r < 2 d) closer than d/2. */
typedef struct tu_shape {
    double ratio, close;
} tu_shape;
tu_shape tu_shape_measure(const struct pfsph_ctx *c);
/* A lattice block of nl x ns (x ns) particles of pair-force liquid (d = 1 cm, sigma 4 N/m, nu
 * 3e-3, theta 0.01, k 1.7 in 2D and Eq. 5's 1.3867 in 3D, DFSPH, no gravity) runs to t_end,
 * sampled every dt_s (the sample times are part of the scene: the step is an equal division of
 * the interval to the next one); ratio and close are averaged over the samples after
 * t_end - t_win, cpu is the run's CPU seconds. */
typedef struct tu_relax {
    double ratio, close, cpu;
} tu_relax;
tu_relax tu_shape_relax(int dim, int nl, int ns, int seed, double t_end, double t_win, double dt_s);
/* tu_shape_relax for seeds 1, 2 and 3, each of which must end with a moment ratio >= 0.95 and
 * at most 0.1 % of close pairs (`window` names the averaging window in the report); returns the
 * mean ratio of the three. */
double tu_shape_relax_seeds(int dim, int nl, int ns, double t_end, double t_win, double dt_s, const char *window);

#endif
