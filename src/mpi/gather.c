/* The frame time of a distributed run (docs/cluster.md, "Driving"): every rank's figures and the
 * diffuse set to the root, and, where the scene's frame needs the whole fluid on the root, the
 * gather of every rank's owned particles in the serial order. Split out of decomp.c. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "mpi/decomp.h"
#include "mpi/wire.h"
#include "pfsph/thermostat.h"
#include "sim_internal.h"

static void frame_figures(pfsph_decomp *D);
static void diffuse_to_root(pfsph_decomp *D);

/* With the thermostat: stats.csv's kinetic temperature, pfsph_thermostat_measure's bits. Its two
 * sums are sequential (each particle added to the running sum in the serial order), so no
 * reduction tree gives them: each rank continues the running sums of the ranks before it over
 * its own particles (a slice of the serial order) and passes them on, the last rank's the
 * serial sums. The path is as long as the serial loop (two passes over the fluid, which the
 * root alone made after a gather) plus 2 (N - 1) messages of 32 and 8 bytes. */
static void frame_kT(pfsph_decomp *D)
{
    pfsph_ctx *c = &D->sim->ctx;
    if (!(pfsph_thermostat_kT(c) > 0)) return;
    const pfsph_particles *f = c->fluid;
    const size_t lo = D->d.own_lo, hi = D->d.own_hi, n = D->d.nglobal;
    const int r = D->rank, last = D->size - 1;
    double acc[4] = {0, 0, 0, 0}, e = 0;
    if (r > 0) MPI_Recv(acc, 4, MPI_DOUBLE, r - 1, 33, D->comm, MPI_STATUS_IGNORE);
    pfsph__thermostat_moments(f, c->mass, lo, hi, acc);
    if (r < last) MPI_Send(acc, 4, MPI_DOUBLE, r + 1, 33, D->comm);
    MPI_Bcast(acc, 4, MPI_DOUBLE, last, D->comm);
    const double vc[3] = {acc[1] / acc[0], acc[2] / acc[0], acc[3] / acc[0]};
    if (r > 0) MPI_Recv(&e, 1, MPI_DOUBLE, r - 1, 34, D->comm, MPI_STATUS_IGNORE);
    e = pfsph__thermostat_spread(f, c->mass, c->dim, lo, hi, vc, e);
    if (r < last) MPI_Send(&e, 1, MPI_DOUBLE, r + 1, 34, D->comm);
    else if (r) MPI_Send(&e, 1, MPI_DOUBLE, 0, 35, D->comm);
    if (r == 0 && last) MPI_Recv(&e, 1, MPI_DOUBLE, last, 35, D->comm, MPI_STATUS_IGNORE);
    D->d.kT_frame = n < 2 ? 0 : e / ((double)c->dim * (double)(n - 1));
}

int pfsph_decomp_frame(pfsph_decomp *D, pfsph_error *err)
{
    if (D->root_all || D->gathered || D->framed) return PFSPH_OK;
    if (!pfsph_mpi_frames_collective(D)) return pfsph_decomp_gather(D, err);
    frame_figures(D);
    diffuse_to_root(D);
    frame_kT(D);
    D->framed = 1;
    return PFSPH_OK;
}

/* Every rank's figures to the root (summary.json), as of this frame. */
static void frame_figures(pfsph_decomp *D)
{
    pfsph_mpi_fig mine = {D->steps,
                          D->d.own_hi - D->d.own_lo,
                          D->own_min,
                          D->own_max,
                          D->halo_particles,
                          D->halo_calls,
                          D->bytes_sent,
                          D->migr_bytes,
                          D->messages,
                          D->sim->boundary.n,
                          D->walls_max,
                          D->wall_trims,
                          D->wall_fetches,
                          D->wall_bytes,
                          D->resident_max,
                          0,
                          0,
                          0,
                          D->ckpt_bytes,
                          D->ckpt_read};
    if (D->sim->st.df) {
        size_t *no;
        uint64_t *cr, *rf;
        mine.diffuse = pfsph__diffuse_set(D->sim->st.df, &no, &cr, &rf)->n;
    }
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) == 0) mine.peak_rss_kb = (uint64_t)ru.ru_maxrss;
    FILE *sm = fopen("/proc/self/statm", "r");
    unsigned long pages_all, pages_res;
    if (sm && fscanf(sm, "%lu %lu", &pages_all, &pages_res) == 2)
        mine.rss_kb = (uint64_t)pages_res * (uint64_t)sysconf(_SC_PAGESIZE) / 1024;
    if (sm) fclose(sm);
    MPI_Gather(&mine, sizeof mine, MPI_BYTE, D->fig, sizeof mine, MPI_BYTE, 0, D->comm);
    pfsph_cost_gather(D); /* the ranks' cost figures, beside */
}

/* The diffuse particles, in the serial order, to the root, which keeps them: the next step's
 * diffuse stage sends each to the owner of its cell again. */
static void diffuse_to_root(pfsph_decomp *D)
{
    if (!D->sim->st.df) return;
    size_t *nold;
    uint64_t *cr, *rf;
    pfsph_particles *ds = pfsph__diffuse_set(D->sim->st.df, &nold, &cr, &rf);
    D->d.migrate(&D->d, ds, nold, NULL);
}

int pfsph_decomp_gather(pfsph_decomp *D, pfsph_error *err)
{
    if (D->root_all || D->gathered) return PFSPH_OK;
    if (!D->framed) frame_figures(D); /* after a collective frame: sent with it */
    D->gathers++;
    pfsph_sim *sim = D->sim;
    pfsph_ctx *c = &sim->ctx;
    pfsph_particles *f = c->fluid;
    /* the last rank's owned particles end with those the emitters added since the sort (they
     * follow every other in the global order, and have no cell of the sort) */
    const size_t lo = D->d.own_lo, m = D->d.own_hi - D->d.own_lo, N = D->d.nglobal, N0 = D->gofs[D->size];
    uint32_t *key = realloc(D->key, (m ? m : 1) * sizeof(uint32_t));
    if (!key) MPI_Abort(D->comm, 1); /* the root waits in the gather */
    D->key = key;
    /* the cells of this step's sort (the particles have moved since): the root's grid for the
     * frame's walks (surface layers, pressures) */
    const pfsph_grid *g = c->grid;
    for (size_t k = D->cut[D->rank]; k < D->cut[D->rank + 1]; k++)
        for (uint32_t i = g->start[k]; i < g->start[k + 1]; i++) key[i - lo] = (uint32_t)k;
    uint32_t *allkey = NULL;
    int *kcount = D->scount, *kdispl = D->sdispl;
    for (int q = 0; q < D->size; q++) {
        kcount[q] = (int)(D->gofs[q + 1] - D->gofs[q]);
        kdispl[q] = (int)D->gofs[q];
    }
    if (D->rank == 0 && !(allkey = malloc((N ? N : 1) * sizeof(uint32_t)))) MPI_Abort(D->comm, 1);
    MPI_Gatherv(key, kcount[D->rank], MPI_UINT32_T, allkey, kcount, kdispl, MPI_UINT32_T, 0, D->comm);
    /* the particles, rank by rank in runs of at most GATHER_RUN through one bounded buffer: no
     * copy of the whole fluid besides the root's arrays. The root's own particles are already in
     * their global places (its slice starts at global index 0). */
    if (grow(D->rank == 0 ? &D->rbuf : &D->sbuf, D->rank == 0 ? &D->rcap : &D->scap, GATHER_RUN * REC))
        MPI_Abort(D->comm, 1);
    if (D->rank == 0) {
        pfsph_real *keep = NULL; /* the number density of the root's own particles, if the reserve moves it */
        const size_t own = D->d.own_hi;
        if (N > f->cap && !(keep = malloc((own ? own : 1) * sizeof(pfsph_real)))) MPI_Abort(D->comm, 1);
        if (keep) memcpy(keep, c->nd, own * sizeof(pfsph_real));
        if (sim->st.reserve(&sim->st, N, err)) MPI_Abort(D->comm, 1);
        if (keep) memcpy(c->nd, keep, own * sizeof(pfsph_real));
        free(keep);
        for (int q = 1; q < D->size; q++) {
            const uint64_t e = q == D->size - 1 ? N : D->gofs[q + 1];
            for (uint64_t o = D->gofs[q]; o < e; o += GATHER_RUN) {
                const size_t k = e - o < GATHER_RUN ? (size_t)(e - o) : GATHER_RUN;
                MPI_Recv(D->rbuf, (int)(k * REC), MPI_BYTE, q, 30, D->comm, MPI_STATUS_IGNORE);
                for (size_t i = 0; i < k; i++) unpack(D->rbuf + i * REC, f, c->nd, (size_t)o + i);
            }
        }
        D->root_own_hi = own;
        f->n = N;
        uint32_t *start = c->grid->start;
        memset(start, 0, (D->ncells + 1) * sizeof(uint32_t));
        for (size_t i = 0; i < N0; i++) start[allkey[i] + 1]++;
        for (size_t k = 0; k < D->ncells; k++) start[k + 1] += start[k];
        free(allkey);
        D->d.own_lo = 0;
        D->d.own_hi = N;
    } else {
        for (size_t o = 0; o < m; o += GATHER_RUN) {
            const size_t k = m - o < GATHER_RUN ? m - o : GATHER_RUN;
            for (size_t i = 0; i < k; i++) pack(D->sbuf + i * REC, f, c->nd, lo + o + i);
            MPI_Send(D->sbuf, (int)(k * REC), MPI_BYTE, 0, 30, D->comm);
        }
    }
    if (!D->framed) diffuse_to_root(D);
    /* every rank keeps its slice: the next exchange goes on from it (the root's own particles
     * are untouched at the front of its arrays), only the clock is shared again */
    D->gathered = 1;
    D->d.fluid_whole = 1;
    return PFSPH_OK;
}
