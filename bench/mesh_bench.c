/* Surface reconstruction throughput: a block of fluid on a jittered lattice (a dam-break column)
 * meshed several times; prints particles per second per core (wall) and per CPU-second, the time
 * split, and the sparse grid's memory per surface particle. Results are recorded in
 * docs/benchmarks.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <omp.h>

#include "pfsph/rng.h"
#include "pfsph/surface_mesh.h"

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y);
}

int main(int argc, char **argv)
{
    long nx = 60, ny = 80, nz = 60;
    int reps = 5, threads = 0;
    double jitter = 0.1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc && sscanf(argv[++i], "%ldx%ldx%ld", &nx, &ny, &nz) == 3 &&
            nx > 0 && ny > 0 && nz > 0)
            continue;
        if (!strcmp(argv[i], "--reps") && i + 1 < argc && (reps = atoi(argv[++i])) > 0) continue;
        if (!strcmp(argv[i], "--threads") && i + 1 < argc && (threads = atoi(argv[++i])) > 0) continue;
        if (!strcmp(argv[i], "--jitter") && i + 1 < argc) {
            jitter = atof(argv[++i]);
            continue;
        }
        fprintf(stderr,
                "usage: mesh_bench [--size NXxNYxNZ] [--reps N] [--threads N] [--jitter F]\n"
                "Meshes a block of NX x NY x NZ particles (default 60x80x60) --reps times.\n");
        return 2;
    }
    if (threads) omp_set_num_threads(threads);
    const double d = 0.01;
    size_t n = (size_t)(nx * ny * nz), k = 0;
    double *x = malloc(3 * n * sizeof *x);
    if (!x) return 1;
    for (long i = 0; i < nx; i++)
        for (long j = 0; j < ny; j++)
            for (long l = 0; l < nz; l++, k++) {
                double u[4];
                pfsph_rng_uniform4(1, (uint32_t)k, 0, 0, u);
                x[3 * k] = i * d + jitter * d * (u[0] - 0.5);
                x[3 * k + 1] = j * d + jitter * d * (u[1] - 0.5);
                x[3 * k + 2] = l * d + jitter * d * (u[2] - 0.5);
            }
    pfsph_surface_opts o;
    pfsph_surface_opts_default(&o, d);
    double *t = malloc((size_t)reps * sizeof *t), *cpu = malloc((size_t)reps * sizeof *cpu);
    pfsph_surface_mesh m = {0};
    for (int r = 0; r < reps; r++) {
        pfsph_surface_mesh_free(&m);
        pfsph_error err;
        double t0 = omp_get_wtime();
        clock_t c0 = clock(); /* CPU time of all threads: the figure that holds on a loaded machine */
        if (pfsph_surface_reconstruct(x, NULL, n, &o, &m, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        t[r] = omp_get_wtime() - t0;
        cpu[r] = (double)(clock() - c0) / CLOCKS_PER_SEC;
    }
    qsort(t, (size_t)reps, sizeof *t, cmp);
    qsort(cpu, (size_t)reps, sizeof *cpu, cmp);
    int nt = omp_get_max_threads();
    printf("mesh_bench: %zu particles (%ldx%ldx%ld, jitter %.2f d), %d threads, %d reps\n", n, nx, ny, nz, jitter, nt,
           reps);
    printf("  time min %.3f s, median %.3f s, max %.3f s\n", t[0], t[reps / 2], t[reps - 1]);
    printf("  throughput %.3g particles/s per core (median; min..max %.3g..%.3g)\n", n / t[reps / 2] / nt,
           n / t[reps - 1] / nt, n / t[0] / nt);
    printf("  CPU time (all threads) median %.3f s: %.3g particles per CPU-second (min..max %.3g..%.3g)\n",
           cpu[reps / 2], n / cpu[reps / 2], n / cpu[reps - 1], n / cpu[0]);
    printf("  mesh %zu vertices, %zu faces; %zu surface particles; grid %zu blocks kept, %zu at peak, %.1f MB "
           "(%.0f B per surface particle)\n",
           m.nverts, m.ntris, m.surface_particles, m.blocks, m.blocks_peak, m.grid_bytes / 1e6,
           (double)m.grid_bytes / (double)(m.surface_particles ? m.surface_particles : 1));
    printf("  last run: kernels (PCA, smoothing) %.3f s, field and grid growth %.3f s, marching %.3f s, "
           "merge %.3f s\n",
           m.seconds[0], m.seconds[1], m.seconds[2], m.seconds[3]);
    pfsph_surface_mesh_free(&m);
    free(t);
    free(cpu);
    free(x);
    return 0;
}
