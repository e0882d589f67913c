/* Shape relaxation of a free block of pair-force liquid (docs/thermostat.md, "Elongated drops");
 * the study tool behind the rectangle and box tests, not a test.
 *
 *   pf_shape dim n_long n_short [theta=0.01] [t_end=8] [solver=pcisph] [nu=3e-3] [seed=1]
 *            [k=1.7 (2D) / 1.3867 (3D)] [sigma=4] [dt_sample=0.05]
 *
 * A lattice block of n_long x n_short (x n_short) particles (d = 1 cm, no gravity) runs to
 * t_end; every dt_sample it prints t, the moment ratio (smallest / largest principal second
 * moment), the fraction of kernel-neighbour pairs (r < h) closer than d/2 and the kinetic
 * energy. PF_SOLVEX adds solver keys (e.g. ', "tolerance": 0.001'), PF_PW pairwise keys. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "pfsph/eigen.h"
#include "pfsph/sim.h"

static void measure(const pfsph_ctx *c, double *ratio, double *close)
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
    if (c->dim == 2) {
        const double C2[2][2] = {{C[0][0], C[0][1]}, {C[0][1], C[1][1]}};
        double w[2], v[2][2];
        pfsph_eigen_sym2(C2, w, v);
        *ratio = fmin(w[0], w[1]) / fmax(w[0], w[1]);
    } else {
        double w[3], v[3][3];
        pfsph_eigen_sym3(C, w, v);
        *ratio = fmin(w[0], fmin(w[1], w[2])) / fmax(w[0], fmax(w[1], w[2]));
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
    *close = nh ? (double)nc / (double)nh : 0;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: pf_shape dim n_long n_short [theta t_end solver nu seed k sigma dt]\n");
        return 2;
    }
    const int dim = atoi(argv[1]), nl = atoi(argv[2]), ns = atoi(argv[3]);
    const double theta = argc > 4 ? atof(argv[4]) : 0.01;
    const double t_end = argc > 5 ? atof(argv[5]) : 8;
    const char *solver = argc > 6 ? argv[6] : "pcisph";
    const char *nu = argc > 7 ? argv[7] : "0.003";
    const int seed = argc > 8 ? atoi(argv[8]) : 1;
    const char *k = argc > 9 ? argv[9] : (dim == 2 ? "1.7" : "1.3867");
    const char *sig = argc > 10 ? argv[10] : "4";
    const double dts = argc > 11 ? atof(argv[11]) : 0.05;
    omp_set_num_threads(1);
    const double d = 0.01, a = 0.5 * nl * d, b = 0.5 * ns * d;
    char thermo[128], json[4096];
    if (theta > 0) snprintf(thermo, sizeof thermo, "\"thermostat\": {\"reduced_temperature\": %g},", theta);
    else snprintf(thermo, sizeof thermo, "\"thermostat\": false,");
    if (dim == 2)
        snprintf(json, sizeof json,
                 "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
                 " \"domain\": {\"min\": [-1, -1], \"max\": [1, 1]},"
                 " \"solver\": {\"type\": \"%s\"%s}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"viscosity\": %s}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [%g, %g], \"max\": [%g, %g]}],"
                 " \"pairwise\": {%s %s \"k\": %s, \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": "
                 "%s}]}}",
                 seed, solver, getenv("PF_SOLVEX") ? getenv("PF_SOLVEX") : "", nu, -a, -b, a, b,
                 getenv("PF_PW") ? getenv("PF_PW") : "", thermo, k, sig);
    else
        snprintf(json, sizeof json,
                 "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": 0.005, \"gravity\": [0, 0, 0],"
                 " \"domain\": {\"min\": [-0.5, -0.5, -0.5], \"max\": [0.5, 0.5, 0.5]},"
                 " \"solver\": {\"type\": \"%s\"%s}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"viscosity\": %s}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}],"
                 " \"pairwise\": {%s %s \"k\": %s, \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": "
                 "%s}]}}",
                 seed, solver, getenv("PF_SOLVEX") ? getenv("PF_SOLVEX") : "", nu, -a, -b, -b, a, b, b,
                 getenv("PF_PW") ? getenv("PF_PW") : "", thermo, k, sig);
    static pfsph_scene s;
    pfsph_error err = {0};
    if (pfsph_scene_parse(&s, json, "pf_shape", &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    pfsph_sim *sim = NULL;
    if (pfsph_sim_create(&sim, &s, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    double r, cl;
    measure(c, &r, &cl);
    printf("# n %zu\n%.3f %.5f %.5f 0\n", c->fluid->n, 0.0, r, cl);
    const int nsamp = (int)lround(t_end / dts);
    const clock_t c0 = clock();
    for (int i = 1; i <= nsamp; i++) {
        if (pfsph_sim_advance(sim, dts * i, &err) != PFSPH_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        measure(c, &r, &cl);
        printf("%.3f %.5f %.5f %.4g\n", pfsph_sim_time(sim), r, cl, pfsph_sim_stats(sim)->ekin);
        fflush(stdout);
    }
    printf("# cpu %.1f s, steps %llu, removed %zu\n", (double)(clock() - c0) / CLOCKS_PER_SEC,
           (unsigned long long)pfsph_sim_steps(sim), pfsph_sim_removed(sim));
    pfsph_sim_destroy(sim);
    return 0;
}
