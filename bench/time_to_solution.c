/* Time-to-solution benchmark: runs a scene (default bench/dam_break_7k.json, the SPlisHSPlasH
 * DamBreakModel geometry) with a chosen solver to a given end time and prints the wall time,
 * steps, mean time step and the time per stage, so that solvers can be compared on what a user
 * waits for rather than per step. No output files. Figures: docs/benchmarks.md. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>
#include <omp.h>

#include "bench_util.h"
#include "cli/omp_env.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"

static void usage(void)
{
    fprintf(stderr,
            "usage: time_to_solution [--scene FILE] [--solver wcsph|pcisph|dfsph] [--end T]\n"
            "                        [--threads N]\n"
            "Runs FILE (default bench/dam_break_7k.json relative to the working directory)\n"
            "to time T [s] (default: the scene's end) with the solver given (default: the\n"
            "scene's) and prints wall time, steps and time per stage.\n");
}

int main(int argc, char **argv)
{
    pfsph_omp_wait_default(argv); /* as pfsph does */
    const char *scene = "bench/dam_break_7k.json", *solver = NULL;
    double end = 0;
    int threads = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--scene") && v) {
            scene = v;
            i++;
        } else if (!strcmp(a, "--solver") && v) {
            solver = v;
            i++;
        } else if (!strcmp(a, "--end") && v) {
            end = atof(v);
            i++;
        } else if (!strcmp(a, "--threads") && v) {
            threads = atoi(v);
            i++;
        } else {
            usage();
            return !strcmp(a, "--help") || !strcmp(a, "-h") ? 0 : 2;
        }
    }
    static pfsph_scene s;
    pfsph_error err = {0};
    if (pfsph_scene_load(&s, scene, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    if (solver) {
        /* through the parser, so that per-solver defaults (tolerance) apply as in a scene file */
        char *text = NULL;
        FILE *fp = fopen(scene, "rb");
        long len = -1;
        if (fp && !fseek(fp, 0, SEEK_END)) len = ftell(fp);
        if (fp && len >= 0 && !fseek(fp, 0, SEEK_SET) && (text = calloc((size_t)len + 1, 1)))
            len = (long)fread(text, 1, (size_t)len, fp);
        if (fp) fclose(fp);
        cJSON *root = text ? cJSON_Parse(text) : NULL;
        cJSON *sol = root ? cJSON_GetObjectItem(root, "solver") : NULL;
        if (!sol) cJSON_AddItemToObject(root, "solver", sol = cJSON_CreateObject());
        cJSON_DeleteItemFromObject(sol, "type");
        cJSON_AddStringToObject(sol, "type", solver);
        char *patched = root ? cJSON_PrintUnformatted(root) : NULL;
        int prc = patched ? pfsph_scene_parse(&s, patched, scene, &err) : PFSPH_EINPUT;
        if (prc) fprintf(stderr, "%s\n", patched ? err.msg : "cannot read the scene");
        free(text);
        free(patched);
        cJSON_Delete(root);
        if (prc) return 2;
    }
    if (end <= 0) end = s.end_time;
    if (threads > 0) omp_set_num_threads(threads);
    pfsph_sim *sim;
    if (pfsph_sim_create(&sim, &s, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    const double t0 = omp_get_wtime();
    const double c0 = bench_cpu_seconds();
    /* pfsph_sim_advance's loop, stepped here so that the solver iterations can be summed */
    int rc = PFSPH_OK;
    unsigned long long its = 0, div_its = 0;
    while (rc == PFSPH_OK && pfsph_sim_time(sim) < end - 1e-12 * (end > 1 ? end : 1)) {
        rc = pfsph_sim_step(sim, end, &err);
        its += (unsigned long long)pfsph_sim_stats(sim)->iterations;
        div_its += (unsigned long long)pfsph_sim_stats(sim)->div_iterations;
    }
    const double wall = omp_get_wtime() - t0, cpu = bench_cpu_seconds() - c0;
    if (rc) fprintf(stderr, "%s\n", err.msg);
    const unsigned long long steps = (unsigned long long)pfsph_sim_steps(sim);
    printf("%s, %s, %zu fluid particles, %d threads: %.3f s simulated in %.2f s wall, %llu steps "
           "(mean dt %.3g s, %.2f ms per step)\n",
           s.name, pfsph_scene_solver_name(&s), pfsph_sim_ctx(sim)->fluid->n, omp_get_max_threads(),
           pfsph_sim_time(sim), wall, steps, steps ? pfsph_sim_time(sim) / (double)steps : 0,
           steps ? 1e3 * wall / (double)steps : 0);
    printf("  cpu (user + sys) %.2f s; solver iterations per step: %.2f (divergence %.2f)\n", cpu,
           steps ? (double)its / (double)steps : 0, steps ? (double)div_its / (double)steps : 0);
    const double *st = pfsph_sim_stage_seconds(sim);
    printf("  per stage [s]:");
    for (int k = 0; k < PFSPH_NSTAGES; k++)
        if (st[k] > 0) printf(" %s %.2f", pfsph_stage_names[k], st[k]);
    printf("\n");
    const double *sc = pfsph_sim_stage_cpu_seconds(sim);
    printf("  per stage, CPU [s]:");
    for (int k = 0; k < PFSPH_NSTAGES; k++)
        if (sc[k] > 0) printf(" %s %.4f", pfsph_stage_names[k], sc[k]);
    printf("\n");
    pfsph_sim_destroy(sim);
    return rc ? 3 : 0;
}
