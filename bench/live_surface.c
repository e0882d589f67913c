/* Cost of the live viewer's liquid surface (src/view/vsurf.c, docs/viewer.md): a scene is
 * simulated to a time, then its fluid is reconstructed with pfsph_surface_reconstruct on one
 * thread (as the viewer's surface thread does) at the marching cells the viewer chooses from.
 * A benchmark, not a test: the figures depend on the machine's load.
 *
 *   live_surface SCENE [--at T] [--reps N] [--threads N]
 *
 * Prints, per cell, the median and smallest wall time of N rebuilds, their thread CPU time and
 * the triangles, and the load average. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <omp.h>

#include "bench_util.h"
#include "cli/omp_env.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "pfsph/surface_mesh.h"

static double now(clockid_t c)
{
    struct timespec t;
    clock_gettime(c, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: live_surface SCENE [--at T] [--reps N] [--threads N]\n");
        return 2;
    }
    double at = 1.0;
    int reps = 5, threads = 2;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--at")) at = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--reps")) reps = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--threads")) threads = atoi(argv[i + 1]);
    }
    if (reps < 1 || reps > 100) reps = 5;
    omp_set_num_threads(threads);
    static pfsph_scene sc;
    pfsph_error err = {0};
    pfsph_sim *sim = NULL;
    if (pfsph_scene_load(&sc, argv[1], &err) || pfsph_sim_create(&sim, &sc, &err)) {
        fprintf(stderr, "live_surface: %s\n", err.msg);
        return 2;
    }
    /* frame by frame at the scene's rate, as the viewer steps */
    const double fps = sc.fps > 0 ? sc.fps : 25;
    long frame = 0;
    while (pfsph_sim_time(sim) < at - 1e-12) {
        const double tf = (double)(frame + 1) / fps, t = pfsph_sim_time(sim);
        int rc = t < tf - 1e-12 * fmax(1.0, tf) ? pfsph_sim_step(sim, tf, &err) : PFSPH_OK;
        if (!rc && pfsph_sim_time(sim) >= tf - 1e-12 * fmax(1.0, tf)) {
            rc = pfsph_sim_advance(sim, tf, &err);
            frame++;
        }
        if (rc) {
            fprintf(stderr, "live_surface: %s\n", err.msg);
            return 3;
        }
    }
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *ps = c->fluid;
    double *x = malloc(3 * (ps->n ? ps->n : 1) * sizeof *x);
    if (!x) return 1;
    for (size_t i = 0; i < ps->n; i++) x[3 * i] = ps->x[i], x[3 * i + 1] = ps->y[i], x[3 * i + 2] = ps->z[i];
    printf("%s at t = %.3f s: %zu fluid particles, load average %.1f\n", argv[1], pfsph_sim_time(sim), ps->n,
           bench_load_average());
    omp_set_num_threads(1); /* the viewer's surface thread runs serial */
    /* the viewer's cells (vsurf.c), then isotropic kernels (no PCA) for comparison */
    const double cells[] = {0.5, 0.75, 1.0, 1.25, 1.0, 1.25};
    for (int k = 0; k < 6; k++) {
        pfsph_surface_opts o;
        pfsph_surface_opts_default(&o, 2 * sc.particle_radius);
        o.cell = cells[k];
        o.isotropic = k >= 4;
        double part[4] = {0, 0, 0, 0};
        double wall[100], cpu[100];
        size_t ntris = 0;
        for (int r = 0; r < reps; r++) {
            pfsph_surface_mesh m;
            double w0 = now(CLOCK_MONOTONIC), c0 = now(CLOCK_THREAD_CPUTIME_ID);
            if (pfsph_surface_reconstruct(x, ps->phase, ps->n, &o, &m, &err)) {
                fprintf(stderr, "live_surface: %s\n", err.msg);
                return 1;
            }
            cpu[r] = now(CLOCK_THREAD_CPUTIME_ID) - c0;
            wall[r] = now(CLOCK_MONOTONIC) - w0;
            ntris = m.ntris;
            for (int q = 0; q < 4; q++) part[q] += m.seconds[q] / reps;
            pfsph_surface_mesh_free(&m);
        }
        qsort(wall, (size_t)reps, sizeof *wall, cmp_double);
        qsort(cpu, (size_t)reps, sizeof *cpu, cmp_double);
        printf("  cell %.2f d%s: %zu triangles, wall median %.1f ms (min %.1f), thread CPU median %.1f ms (min "
               "%.1f); wall: kernels %.1f, field %.1f, marching %.1f, merge %.1f ms\n",
               cells[k], o.isotropic ? " isotropic" : "", ntris, 1e3 * wall[reps / 2], 1e3 * wall[0],
               1e3 * cpu[reps / 2], 1e3 * cpu[0], 1e3 * part[0], 1e3 * part[1], 1e3 * part[2], 1e3 * part[3]);
    }
    printf("load average after: %.1f\n", bench_load_average());
    free(x);
    pfsph_sim_destroy(sim);
    return 0;
}
