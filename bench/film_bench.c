/* Cost of bubbles in air (docs/film.md): the film stage (surface detection per bubble + the
 * film fraction, PF Section 4.2.2) as a share of a PCISPH step with pair forces, in CPU time
 * (the machine is shared: wall time would measure the neighbours' load). Two cases:
 *   film_bench SCENE.json [--steps N]   a scene from a file (scenes/pf_double_bubble_*.json)
 *   film_bench --drop N [--steps N]     one 3D bubble of about N particles (a droplet whose
 *                                       outer layer is film; N = 100000 for the drop)
 * After one warm-up step, --steps steps (default 10) run on one thread; printed: CPU per step,
 * per stage slot, the film slot's share, and the outputs' surface detection (two layers, once
 * per frame) against a step. Results: docs/film.md. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pfsph/scene.h"
#include "pfsph/sim.h"

static double cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    const char *file = NULL;
    long drop = 0;
    int steps = 10;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--steps") && i + 1 < argc) steps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--drop") && i + 1 < argc) drop = atol(argv[++i]);
        else if (argv[i][0] != '-') file = argv[i];
        else {
            fprintf(stderr, "usage: film_bench SCENE.json | --drop N  [--steps N]\n");
            return 2;
        }
    }
    omp_set_num_threads(1);
    pfsph_scene *s = malloc(sizeof *s);
    pfsph_error err = {0};
    int rc;
    if (file) {
        rc = pfsph_scene_load(s, file, &err);
    } else {
        if (drop <= 0) drop = 100000;
        /* radius for N particles of d = 1 cm: (3 N / 4 pi)^(1/3) d */
        const double R = cbrt(3.0 * (double)drop / (4 * 3.14159265358979)) * 0.01;
        char json[2048];
        snprintf(json, sizeof json,
                 "{\"dimension\": 3, \"particle_radius\": 0.005, \"gravity\": [0, 0, 0],"
                 " \"domain\": {\"min\": [-%g, -%g, -%g], \"max\": [%g, %g, %g]}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"soap\", \"kind\": \"fluid\", \"viscosity\": 0.005},"
                 " {\"name\": \"air\", \"kind\": \"gas\", \"rest_density\": 1000, \"viscosity\": 0.005}],"
                 " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0, 0], \"radius\": %g, \"phase\": \"air\","
                 " \"bubble\": {\"film\": \"soap\", \"thickness\": 0.005}}],"
                 " \"pairwise\": {\"coefficients\": [{\"phases\": [\"soap\", \"soap\"], \"sigma\": 4},"
                 " {\"phases\": [\"air\", \"air\"], \"sigma\": 2}, {\"phases\": [\"soap\", \"air\"], \"sigma\": 0}]}}",
                 2 * R, 2 * R, 2 * R, 2 * R, 2 * R, 2 * R, R);
        rc = pfsph_scene_parse(s, json, "drop", &err);
    }
    if (rc) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    pfsph_scene_set_solver(s, "pcisph");
    pfsph_sim *sim = NULL;
    if ((rc = pfsph_sim_create(&sim, s, &err))) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    const size_t n = pfsph_sim_ctx(sim)->fluid->n;
    if ((rc = pfsph_sim_step(sim, 1e9, &err))) { /* warm-up */
        fprintf(stderr, "%s\n", err.msg);
        return 3;
    }
    double st0[PFSPH_NSTAGES];
    memcpy(st0, pfsph_sim_stage_cpu_seconds(sim), sizeof st0);
    const double c0 = cpu();
    for (int k = 0; k < steps; k++)
        if ((rc = pfsph_sim_step(sim, 1e9, &err))) {
            fprintf(stderr, "%s\n", err.msg);
            return 3;
        }
    const double total = cpu() - c0;
    const double *st1 = pfsph_sim_stage_cpu_seconds(sim);
    printf("%s: %zu fluid particles, %d steps, %.4f s CPU per step (one thread)\n", file ? file : "3D bubble drop", n,
           steps, total / steps);
    for (int k = 0; k < PFSPH_NSTAGES; k++)
        if (st1[k] - st0[k] > 0)
            printf("  %-10s %8.4f s per step  %5.1f %%\n", pfsph_stage_names[k], (st1[k] - st0[k]) / steps,
                   100 * (st1[k] - st0[k]) / total);
    /* the frames' two-layer detection, once per frame */
    uint8_t *layer = malloc(n ? n : 1);
    const double c1 = cpu();
    pfsph_sim_surface_layers(sim, 2, layer);
    const double det = cpu() - c1;
    size_t n1 = 0, n2 = 0;
    for (size_t i = 0; i < n; i++) n1 += layer[i] == 1, n2 += layer[i] == 2;
    printf("  film stage share of a step: %.2f %%; output's two-layer detection %.4f s (%.1f %% of a step; "
           "layers: %zu + %zu particles)\n",
           100 * (st1[PFSPH_STAGE_FILM] - st0[PFSPH_STAGE_FILM]) / total, det, 100 * det / (total / steps), n1, n2);
    free(layer);
    pfsph_sim_destroy(sim);
    free(s);
    return 0;
}
