/* Distributed runs: what the step asks of a domain decomposition (src/mpi/, docs/cluster.md).
 * The library never includes MPI: a decomposition fills these hooks and the context points at
 * them (ctx->dist); NULL in a serial run, where every helper below is the serial code. */
#ifndef PFSPH_DIST_H
#define PFSPH_DIST_H

#include <stddef.h>
#include <stdint.h>

#include "pfsph/particles.h"
#include "pfsph/types.h"

struct pfsph_sim;
struct pfsph_checkpoint_info;

typedef struct pfsph_dist pfsph_dist;
struct pfsph_dist {
    /* The local fluid is a contiguous slice of the serial (global, sorted) order: halo copies,
     * then the particles this rank owns, [own_lo, own_hi), then halo copies again. */
    size_t own_lo, own_hi;
    size_t nglobal;          /* fluid particles of all ranks */
    size_t cell_lo, cell_hi; /* the grid cells this rank owns (the step's cut) */
    int rank, nranks;        /* this process, and how many; the last rank takes the emitters' new
                       * particles: they follow every other in the global order */
    /* refresh the halo copies of k per-fluid-particle arrays from their owners */
    void (*halo)(pfsph_dist *d, pfsph_real *const *a, int k);
    /* pfsph__sum of the global array whose owned part is a[own_lo, own_hi): the same bits */
    double (*sum)(pfsph_dist *d, const pfsph_real *a);
    /* k counters, each the sum of every rank's (exact: integers) */
    void (*count)(pfsph_dist *d, long *v, int k);
    /* a[i] summed over the ranks, in place: exact, in any order, where one rank holds the value
     * and the others -0.0 (x + -0.0 == x for every x) */
    void (*allsum)(pfsph_dist *d, double *a, size_t n);
    /* flags[i] |= every rank's flags[i] (a logical or over the ranks, in place) */
    void (*any)(pfsph_dist *d, uint8_t *flags, size_t n);
    /* the exclusive prefix over the ranks (in rank order) and the total of k <= 8 counters */
    void (*scan)(pfsph_dist *d, const uint64_t *v, int k, uint64_t *before, uint64_t *total);
    /* Move a particle set that is not the fluid (diffuse particles) between ranks: particle i
     * goes to the rank that owns cell key[i] of the step's cut (UINT32_MAX: it stays); key NULL:
     * every particle goes to the root. The set is [0, *nold), a part in the global order, then
     * [*nold, n), new particles in id order; a rank receives the first parts in rank order, then
     * the new parts merged by id, and *nold becomes the count of the first. */
    void (*migrate)(pfsph_dist *d, pfsph_particles *ps, size_t *nold, const uint32_t *key);
    /* every rank's status after a stage: the first failure (its message) on all ranks */
    int (*agree)(pfsph_dist *d, int rc, pfsph_error *err);
    /* a step begins (the root tells the other ranks to follow) */
    void (*step_begin)(pfsph_dist *d, double t_limit);
    /* a frame time reached: the root gathers the whole fluid in the serial order, or, where the
     * scene's fluid frames can be written collectively, only the frame's figures */
    int (*frame)(pfsph_dist *d, pfsph_error *err);
    /* the root holds every fluid particle (the start, a resume, after a gather): the serial code
     * applies; else each rank holds its slice and the fluid frames are written collectively */
    int fluid_whole;
    /* with the thermostat, while the root holds its slice only (!fluid_whole): the fluid's kinetic
     * temperature at the last frame (pfsph_thermostat_measure's bits), computed by every rank */
    double kT_frame;
    /* the root only (src/run.c): the fluid frames of `frame` into dir, every rank its slice */
    int (*write_fluid)(pfsph_dist *d, const char *dir, int frame, double time, pfsph_error *err);
    /* the root only: gather the whole fluid now (a checkpoint after a collective frame) */
    int (*gather)(pfsph_dist *d, pfsph_error *err);
    /* the decomposition's figures into summary.json (a cJSON object) */
    void (*report)(pfsph_dist *d, void *json);
    /* A checkpoint file written by every rank, each its part of the fluid (the serial file's
     * bytes; atomic through a temporary name; durable: fsynced), *bytes (may be NULL) its size;
     * and one read by every rank, each a range of the serial order (checked as the serial
     * reader does, the frame against expect_frame when >= 0). NULL: the serial code. */
    int (*save)(pfsph_dist *d, const char *path, int frame, int durable, size_t *bytes, pfsph_error *err);
    int (*load)(pfsph_dist *d, const char *path, long expect_frame, struct pfsph_checkpoint_info *info,
                pfsph_error *err);
    /* a simulation was created: take it over (insert the stages, share the work) */
    int (*attach)(pfsph_dist *d, struct pfsph_sim *sim, pfsph_error *err);
};

/* The process's decomposition (set by the program when it runs under mpirun), NULL: serial. */
extern pfsph_dist *pfsph__dist_process;

#endif
