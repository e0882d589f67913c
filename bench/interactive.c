/* Real-time factor of a scene (simulated seconds per wall second) stepped as the live viewer
 * steps it, frame by frame at 30 frames per second, and which time step limit bound each step
 * (docs/interactive.md). A benchmark, not a test: the figures depend on the machine's load.
 *
 *   interactive SCENE [--end T] [--threads N] [--fps F] [--limits] [--where]
 *
 * Prints the particle counts, steps, steps per frame, mean solver iterations, wall and CPU time,
 * the real-time factor, CPU seconds per simulated second and the load average before and after.
 * --limits also prints, for every limit of the time step, how often it bound and its median.
 * --where prints which particles set the CFL and force limits: after every step, the fastest
 * particle and the one of the largest non-pressure acceleration (gravity, pair forces, viscosity: the
 * force criterion's a_np) (their neighbour counts within h, fluid
 * and wall, against the bulk's median), and the percentiles of a_np. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "bench_util.h"
#include "cli/omp_env.h"
#include "core/nlist.h"
#include "core/stage.h"
#include "physics/solver.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"

/* the limits of timestep.c and the PCISPH / DFSPH dt_limit, as candidates */
enum { L_DTMAX, L_CFL, L_FORCE, L_PCI, L_VISC, L_FRAME, NLIM };
static const char *const lim_name[NLIM] = {"dt_max",
                                           "CFL (cfl d / vmax)",
                                           "force (0.25 or 0.35 sqrt(d / a_np))",
                                           "PCISPH cap (0.2 sqrt(tol d / a_np))",
                                           "viscous (0.125 d^2 / nu_max)",
                                           "frame landing (shorter than all)"};

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, size_t n)
{
    if (!n) return NAN;
    qsort(v, n, sizeof *v, cmp_double);
    return v[n / 2];
}

/* --where: per step, who sets vmax and the pair-force amax (see the file's comment) */
enum { W_AMAX, W_A999, W_A99, W_A90, W_ANB, W_ABNB, W_AV, W_VMAX, W_VNB, W_VBNB, W_VY, W_NB50, NW };
static const char *const w_name[NW] = {"a_np max [m/s^2]",
                                       "a_np 99.9th percentile",
                                       "a_np 99th percentile",
                                       "a_np 90th percentile",
                                       "  its particle: fluid neighbours",
                                       "  its particle: wall neighbours",
                                       "  its particle: speed [m/s]",
                                       "fastest speed [m/s]",
                                       "  its particle: fluid neighbours",
                                       "  its particle: wall neighbours",
                                       "  its particle: height y [m]",
                                       "median fluid neighbours (all)"};

static size_t nl_count(const pfsph_nlist *l, size_t i, size_t n)
{
    return l && l->n == n && l->start ? (size_t)(l->start[i + 1] - l->start[i]) : 0;
}

static void where_sample(const pfsph_step *st, const pfsph_ctx *c, double *row, double *scratch)
{
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    for (int k = 0; k < NW; k++) row[k] = NAN;
    if (!n) return;
    size_t ia = 0, iv = 0;
    double a2m = -1, v2m = -1;
    for (size_t i = 0; i < n; i++) {
        const double ax = c->ax[i], ay = c->ay[i], az = c->az[i];
        const double a2 = ax * ax + ay * ay + az * az;
        const double v2 = f->vx[i] * f->vx[i] + f->vy[i] * f->vy[i] + f->vz[i] * f->vz[i];
        scratch[i] = sqrt(a2);
        if (a2 > a2m) a2m = a2, ia = i;
        if (v2 > v2m) v2m = v2, iv = i;
    }
    row[W_AMAX] = sqrt(a2m);
    row[W_ANB] = (double)nl_count(st->nlist, ia, n);
    row[W_ABNB] = (double)nl_count(st->nlist_b, ia, n);
    row[W_AV] = sqrt(f->vx[ia] * f->vx[ia] + f->vy[ia] * f->vy[ia] + f->vz[ia] * f->vz[ia]);
    row[W_VMAX] = sqrt(v2m);
    row[W_VNB] = (double)nl_count(st->nlist, iv, n);
    row[W_VBNB] = (double)nl_count(st->nlist_b, iv, n);
    row[W_VY] = f->y[iv];
    qsort(scratch, n, sizeof *scratch, cmp_double);
    row[W_A999] = scratch[(size_t)(0.999 * (double)(n - 1))];
    row[W_A99] = scratch[(size_t)(0.99 * (double)(n - 1))];
    row[W_A90] = scratch[(size_t)(0.90 * (double)(n - 1))];
    for (size_t i = 0; i < n; i++) scratch[i] = (double)nl_count(st->nlist, i, n);
    row[W_NB50] = median(scratch, n);
}

int main(int argc, char **argv)
{
    pfsph_omp_wait_default(argv);
    const char *path = NULL;
    double end = 0, fps = 30;
    int threads = 2, limits = 0, where = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--end") && v) end = atof(argv[++i]);
        else if (!strcmp(a, "--threads") && v) threads = atoi(argv[++i]);
        else if (!strcmp(a, "--fps") && v) fps = atof(argv[++i]);
        else if (!strcmp(a, "--limits")) limits = 1;
        else if (!strcmp(a, "--where")) where = 1;
        else if (a[0] != '-' && !path) path = a;
        else {
            fprintf(stderr, "usage: interactive SCENE [--end T] [--threads N] [--fps F] [--limits] [--where]\n");
            return 2;
        }
    }
    if (!path) {
        fprintf(stderr, "usage: interactive SCENE [--end T] [--threads N] [--fps F] [--limits] [--where]\n");
        return 2;
    }
    omp_set_num_threads(threads);
    static pfsph_scene s;
    pfsph_error err = {0};
    if (pfsph_scene_load(&s, path, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    if (!(end > 0)) end = s.end_time;
    pfsph_sim *sim = NULL;
    if (pfsph_sim_create(&sim, &s, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    pfsph_step *st = pfsph_sim_step_state(sim);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const double d = c->spacing, tol = pfsph_scene_solver_setting(&s, "tolerance");
    const int pci = !strcmp(pfsph_scene_solver_name(&s), "pcisph");
    size_t cap = 1024, n = 0;
    double *cand[NLIM];
    for (int l = 0; l < NLIM; l++) cand[l] = malloc(cap * sizeof(double));
    long bound[NLIM] = {0};
    double iters = 0;
    size_t wn = 0, wcap = 1024, scap = 0;
    double *wrow = where ? malloc(wcap * NW * sizeof(double)) : NULL, *wscr = NULL;
    const double load0 = bench_load_average(), w0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
    const int frames = (int)lround(end * fps);
    int rc = 0;
    for (int fr = 1; fr <= frames && !rc; fr++) {
        const double t = fr / fps;
        while (pfsph_sim_time(sim) < t) {
            double v[NLIM];
            if (limits) {
                const double vmax = st->stats.vmax, anp = st->amax_np;
                v[L_DTMAX] = st->dt_max;
                v[L_CFL] = vmax > 0 ? s.cfl * d / vmax : INFINITY;
                v[L_FORCE] = pci && c->interactive ? pfsph__dt_force_interactive(d, anp) : pfsph__dt_force(d, anp);
                v[L_PCI] = pci && !c->interactive && anp > 0 ? 0.2 * sqrt(tol * d / anp) : INFINITY;
                v[L_VISC] = st->nu_max > 0 ? 0.125 * d * d / st->nu_max : INFINITY;
            }
            if ((rc = pfsph_sim_step(sim, t, &err)) != PFSPH_OK) break;
            iters += pfsph_sim_stats(sim)->iterations;
            if (where) {
                if (c->fluid->n > scap) wscr = realloc(wscr, (scap = 2 * c->fluid->n + 1) * sizeof(double));
                if (wn == wcap) wrow = realloc(wrow, (wcap *= 2) * NW * sizeof(double));
                where_sample(st, c, wrow + NW * wn, wscr);
                if (!isnan(wrow[NW * wn])) wn++;
            }
            if (!limits) continue;
            const double dt = pfsph_sim_stats(sim)->dt;
            /* the limit is the smallest candidate; the landing on the frame in equal steps
             * shortens it by less than half, a last step shorter than that is the frame's */
            int b = L_FRAME;
            double lo = INFINITY;
            for (int l = 0; l < L_FRAME; l++) lo = fmin(lo, v[l]);
            if (dt > 0.5 * lo)
                for (int l = L_FRAME - 1; l >= 0; l--)
                    if (v[l] == lo) b = l;
            bound[b]++;
            v[L_FRAME] = dt;
            if (n == cap) {
                cap *= 2;
                for (int l = 0; l < NLIM; l++) cand[l] = realloc(cand[l], cap * sizeof(double));
            }
            for (int l = 0; l < NLIM; l++) cand[l][n] = v[l];
            n++;
        }
    }
    const double wall = bench_wall_seconds() - w0, cpu = bench_cpu_seconds() - c0, load1 = bench_load_average();
    const double sim_t = pfsph_sim_time(sim);
    const unsigned long long steps = (unsigned long long)pfsph_sim_steps(sim);
    size_t nb = 0;
    if (c->boundary) nb = c->boundary->n;
    printf("scene %s: %zu fluid, %zu boundary particles, %d threads\n", path, c->fluid->n, nb, threads);
    if (rc) printf("STOPPED at t = %.4f s: %s\n", sim_t, err.msg);
    printf("simulated %.3f s in %llu steps (%.2f per 1/%g s frame), mean dt %.3g s, mean iterations %.2f\n", sim_t,
           steps, steps / (sim_t * fps), fps, steps ? sim_t / (double)steps : 0, steps ? iters / (double)steps : 0);
    printf("wall %.2f s, cpu %.2f s, load average %.2f -> %.2f\n", wall, cpu, load0, load1);
    printf("real-time factor %.4f (simulated s per wall s), cpu s per simulated s %.2f, steps/wall s %.1f\n",
           sim_t / wall, cpu / sim_t, (double)steps / wall);
    if (limits && n) {
        printf("limit                                   binds   median [s]\n");
        for (int l = 0; l < NLIM; l++)
            printf("%-38s %6.1f%%   %.3g\n", lim_name[l], 100.0 * (double)bound[l] / (double)n, median(cand[l], n));
    }
    if (where && wn) {
        /* per quantity, the median and the 90th percentile over the steps */
        printf("over %zu steps                         median      90%%\n", wn);
        double *col = malloc(wn * sizeof(double));
        for (int k = 0; k < NW; k++) {
            for (size_t j = 0; j < wn; j++) col[j] = wrow[NW * j + k];
            qsort(col, wn, sizeof *col, cmp_double);
            printf("%-38s %8.3g %8.3g\n", w_name[k], col[wn / 2], col[(size_t)(0.9 * (double)(wn - 1))]);
        }
        free(col);
    }
    free(wrow);
    free(wscr);
    for (int l = 0; l < NLIM; l++) free(cand[l]);
    pfsph_sim_destroy(sim);
    return rc ? 3 : 0;
}
