/* The program under mpirun: rank 0 reads the scene, runs the serial driver (src/run.c) on a
 * distributed simulation and alone writes the run directory; the other ranks follow its
 * commands (create, step, frame, end). docs/cluster.md. */
#include "mpi/mpi_cli.h"

#include <cjson/cJSON.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpi/decomp.h"
#include "pfsph/sim.h"

static pfsph_decomp g_D;
static int g_rank, g_size = 1, g_on;

static void finish(void)
{
    int done = 0;
    MPI_Finalized(&done);
    if (!done) MPI_Finalize();
}

void pfsph_mpi_start(int *argc, char ***argv)
{
    MPI_Init(argc, argv);
    atexit(finish);
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_size);
    /* one voice: rank 0 prints (usage errors, progress, the agreed error); PFSPH_MPI_VERBOSE=1
     * keeps the others' output, for debugging */
    if (g_rank > 0 && !getenv("PFSPH_MPI_VERBOSE")) {
        if (!freopen("/dev/null", "w", stdout)) return;
        if (!freopen("/dev/null", "w", stderr)) return;
    }
}

int pfsph_mpi_rank(void) { return g_rank; }
int pfsph_mpi_size(void) { return g_size; }

int pfsph_mpi_check_scene(const pfsph_scene *s, pfsph_error *err)
{
    if (g_size < 2) return PFSPH_OK;
    if (pfsph_cost_env_mode() < 0) /* the cut: src/mpi/cost.c */
        return pfsph_fail(err, PFSPH_EINPUT, "PFSPH_MPI_CUT: \"%s\" is not a cut (\"cost\", the default, or \"count\")",
                          getenv("PFSPH_MPI_CUT"));
    const char *no = NULL, *key = NULL;
    const char *solver = pfsph_scene_solver_name(s);
    if (strcmp(solver, "pcisph") && strcmp(solver, "wcsph") && strcmp(solver, "dfsph") && strcmp(solver, "iisph"))
        no = "this solver", key = "$.solver.type";
    if (!no) return PFSPH_OK;
    return pfsph_fail(err, PFSPH_EINPUT,
                      "%s: %s: %s%s%s%s not supported under MPI yet (%d ranks; docs/cluster.md lists what is): run it "
                      "with one process",
                      s->source, key, no, !strcmp(no, "this solver") ? " \"" : "",
                      !strcmp(no, "this solver") ? solver : "", !strcmp(no, "this solver") ? "\"" : "", g_size);
}

static void report(pfsph_dist *d, void *json)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    cJSON *m = cJSON_AddObjectToObject(json, "mpi");
    if (!m) return;
    cJSON_AddNumberToObject(m, "ranks", D->size);
    cJSON_AddStringToObject(
        m, "output",
        pfsph_mpi_frames_collective(D)
            ? "fluid frames written collectively (MPI-IO), each rank its slice; checkpoints written "
              "and read by every rank (MPI-IO)"
            : "frames gathered to rank 0 rank by rank through a bounded buffer, written by it; "
              "checkpoints written and read by every rank (MPI-IO)");
    /* what happened: frame times written collectively, gathers of the whole fluid to rank 0 */
    cJSON_AddNumberToObject(m, "frames_written_collectively", (double)D->frames_collective);
    cJSON_AddNumberToObject(m, "fluid_gathers", (double)D->gathers);
    cJSON *cut = cJSON_AddObjectToObject(m, "cut"); /* src/mpi/cut.c: the histogram of occupied cells */
    if (cut) {
        cJSON_AddNumberToObject(cut, "coarse_buckets", (double)D->C.buckets);
        cJSON_AddNumberToObject(cut, "grid_cells", (double)D->ncells);
        cJSON_AddNumberToObject(cut, "reductions_last_step", D->C.rounds);
        cJSON_AddNumberToObject(cut, "counters_last_step", (double)D->C.hist_counters);
        cJSON_AddNumberToObject(cut, "checked_against_dense", (double)D->cuts_checked);
        /* by measured cost (src/mpi/cost.c) or by particle count (PFSPH_MPI_CUT=count) */
        cJSON_AddStringToObject(cut, "by", D->cost.by_cost ? "cost" : "count");
        cJSON_AddNumberToObject(cut, "weighted_cuts", (double)D->cost.weighted_cuts);
    }
    /* the ranks' work: CPU s outside the decomposition's code, the largest against the mean */
    double wmax = 0, wsum = 0;
    for (int q = 0; q < D->size; q++) {
        wsum += D->cost.fig[q].work_cpu;
        if (D->cost.fig[q].work_cpu > wmax) wmax = D->cost.fig[q].work_cpu;
    }
    if (wsum > 0) cJSON_AddNumberToObject(m, "work_imbalance_max_over_mean", wmax * D->size / wsum);
    cJSON *ranks = cJSON_AddArrayToObject(m, "per_rank");
    for (int q = 0; q < D->size && ranks; q++) {
        const pfsph_mpi_fig *f = &D->fig[q];
        const double st = f->steps ? (double)f->steps : 1;
        cJSON *r = cJSON_CreateObject();
        cJSON_AddNumberToObject(r, "rank", q);
        cJSON_AddNumberToObject(r, "steps", (double)f->steps);
        cJSON_AddNumberToObject(r, "owned_last", (double)f->owned);
        cJSON_AddNumberToObject(r, "owned_min", (double)f->own_min);
        cJSON_AddNumberToObject(r, "owned_max", (double)f->own_max);
        cJSON_AddNumberToObject(r, "halo_particles_per_step", (double)f->halo_particles / st);
        cJSON_AddNumberToObject(r, "halo_refreshes_per_step", (double)f->halo_calls / st);
        cJSON_AddNumberToObject(r, "halo_bytes_sent_per_step", (double)f->bytes_sent / st);
        cJSON_AddNumberToObject(r, "exchange_bytes_sent_per_step", (double)f->migr_bytes / st);
        cJSON_AddNumberToObject(r, "messages_sent_per_step", (double)f->messages / st);
        cJSON_AddNumberToObject(r, "walls_held", (double)f->walls);
        cJSON_AddNumberToObject(r, "walls_held_max", (double)f->walls_max);
        cJSON_AddNumberToObject(r, "walls_of_scene", (double)D->walls_total);
        cJSON_AddNumberToObject(r, "wall_window_cuts", (double)f->wall_trims);
        cJSON_AddNumberToObject(r, "wall_window_fetches", (double)f->wall_fetches);
        cJSON_AddNumberToObject(r, "wall_bytes_sent", (double)f->wall_bytes);
        cJSON_AddNumberToObject(r, "resident_particles_max", (double)f->resident_max);
        cJSON_AddNumberToObject(r, "diffuse_held_at_frame", (double)f->diffuse);
        cJSON_AddNumberToObject(r, "checkpoint_bytes_written", (double)f->ckpt_bytes);
        cJSON_AddNumberToObject(r, "checkpoint_bytes_read", (double)f->ckpt_read);
        cJSON_AddNumberToObject(r, "rss_mib_at_last_frame", (double)f->rss_kb / 1024.0);
        cJSON_AddNumberToObject(r, "peak_rss_mib", (double)f->peak_rss_kb / 1024.0);
        const pfsph_cost_fig *k = &D->cost.fig[q]; /* src/mpi/cost.c */
        const double ms = k->samples ? 1e3 / (double)k->samples : 0;
        cJSON_AddNumberToObject(r, "steps_measured", (double)k->samples);
        cJSON_AddNumberToObject(r, "work_cpu_s", k->work_cpu);
        cJSON_AddNumberToObject(r, "work_cpu_ms_per_step", k->work_cpu * ms);
        cJSON_AddNumberToObject(r, "work_cpu_ms_most_in_a_step", k->step_max * 1e3);
        cJSON_AddNumberToObject(r, "decomposition_cpu_s", k->comm_cpu);
        cJSON_AddNumberToObject(r, "work_us_per_owned_particle", k->per_particle * 1e6);
        cJSON_AddNumberToObject(r, "cut_weight_last", (double)k->weight);
        cJSON_AddItemToArray(ranks, r);
    }
}

static int begin(void)
{
    if (pfsph_decomp_init(&g_D, MPI_COMM_WORLD)) return 2;
    g_D.d.report = report;
    pfsph__dist_process = &g_D.d;
    g_on = 1;
    return 0;
}

int pfsph_mpi_share_scene(int status, const char *text, const char *source)
{
    if (g_size < 2) return status;
    MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (status) return status;
    long long len[2] = {(long long)strlen(text) + 1, (long long)strlen(source) + 1};
    MPI_Bcast(len, 2, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
    MPI_Bcast((void *)text, (int)len[0], MPI_CHAR, 0, MPI_COMM_WORLD);
    MPI_Bcast((void *)source, (int)len[1], MPI_CHAR, 0, MPI_COMM_WORLD);
    return begin();
}

int pfsph_mpi_follow(int threads, int (*exit_code)(int))
{
    int status = 0;
    MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (status) return status; /* rank 0 refused the scene and said why */
    long long len[2];
    MPI_Bcast(len, 2, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
    char *text = malloc((size_t)len[0]), *source = malloc((size_t)len[1]);
    if (!text || !source) MPI_Abort(MPI_COMM_WORLD, 1);
    MPI_Bcast(text, (int)len[0], MPI_CHAR, 0, MPI_COMM_WORLD);
    MPI_Bcast(source, (int)len[1], MPI_CHAR, 0, MPI_COMM_WORLD);
    static pfsph_scene s;
    pfsph_error err = {0};
    /* rank 0 parsed the same text: this cannot fail where it did not */
    if (pfsph_scene_parse(&s, text, source, &err)) MPI_Abort(MPI_COMM_WORLD, 1);
    free(text);
    free(source);
    if (threads > 0) omp_set_num_threads(threads);
    else if (s.threads > 0) omp_set_num_threads(s.threads);
    begin();
    pfsph_sim *sim = NULL;
    int rc = PFSPH_OK;
    for (;;) {
        pfsph_mpi_cmd c;
        pfsph_decomp_cmd(&g_D, &c);
        if (c.cmd == PFSPH_MPI_CREATE) {
            rc = pfsph_sim_create(&sim, &s, &err);
            /* failed before it attached: answer the attach's agreement ourselves */
            if (rc && !g_D.sim) rc = g_D.d.agree(&g_D.d, rc, &err);
        } else if (c.cmd == PFSPH_MPI_STEP) {
            rc = pfsph_sim_step(sim, c.t, &err);
        } else if (c.cmd == PFSPH_MPI_FRAME) {
            rc = pfsph_decomp_frame(&g_D, &err);
        } else if (c.cmd == PFSPH_MPI_WRITE) {
            rc = pfsph_mpi_frame_follow(&g_D, &c, &err);
        } else if (c.cmd == PFSPH_MPI_GATHER) {
            rc = pfsph_decomp_gather(&g_D, &err);
        } else if (c.cmd == PFSPH_MPI_SAVE) {
            rc = pfsph_decomp_save(&g_D, NULL, 0, 0, NULL, &err);
        } else if (c.cmd == PFSPH_MPI_LOAD) {
            /* a rejected checkpoint is not the end: the root tries the previous one or ends the run */
            pfsph_decomp_load(&g_D, NULL, 0, NULL, &err);
        } else {
            rc = c.rc;
            break;
        }
        if (rc) break; /* agreed by every rank: rank 0 reports it */
    }
    pfsph_sim_destroy(sim);
    return exit_code(rc);
}

void pfsph_mpi_end(int rc)
{
    if (!g_on || g_rank != 0 || g_D.failed) return;
    pfsph_mpi_cmd c = {PFSPH_MPI_END, rc, 0};
    pfsph_decomp_cmd(&g_D, &c);
}
