/* A rank's measured cost (docs/cluster.md, "The cut by measured cost"): the CPU time it spends
 * outside the decomposition's own code (its part of the physics, not its waiting in collectives),
 * per owned particle, smoothed over steps; from it the integer weight of its particles at the next
 * cut, so that the cut is exact and the same on every rank. */
#ifndef PFSPH_MPI_COST_H
#define PFSPH_MPI_COST_H

#include <stdint.h>

#include "pfsph/dist.h"

typedef struct pfsph_decomp pfsph_decomp;

/* One rank's figures for summary.json, gathered by the root at every frame. */
typedef struct pfsph_cost_fig {
    uint64_t samples, weight;  /* steps measured; its particles' weight at the last cut (0: count) */
    double work_cpu, comm_cpu; /* CPU s outside / inside the decomposition's code */
    double step_max;           /* the costliest step's CPU s outside it */
    double per_particle;       /* the smoothed CPU s per owned particle and step */
} pfsph_cost_fig;

typedef struct pfsph_cost {
    int by_cost;         /* PFSPH_MPI_CUT: 1 "cost" (the default), 0 "count" (every particle weighs 1) */
    double skew;         /* PFSPH_MPI_COST_SKEW (tests), > 1: a synthetic cost replaces the measured one */
    int depth, open;     /* nesting of the decomposition's code; a measured interval is open */
    double mark;         /* the CPU clock when the decomposition's code was last left */
    double step_cpu;     /* CPU outside the decomposition since the step's exchange */
    double work_cpu;     /* over the run: the measured steps' CPU outside the decomposition */
    double comm_cpu;     /* over the run: CPU inside it (exchange, halo, sums, waiting in collectives) */
    double step_max;     /* the largest step's CPU outside the decomposition (figures) */
    uint64_t samples;    /* steps measured */
    uint64_t own;        /* particles owned in the step being measured */
    double per_particle; /* smoothed CPU seconds per owned particle and step; 0: none yet */
    uint64_t weight;     /* this rank's particles' weight at the next cut; 0: the count cut */
    uint64_t weighted_cuts;
    pfsph_cost_fig *fig; /* size; the root: every rank's, as of the last frame */
    /* the hooks of the decomposition, timed by the wrappers cost.c installs */
    pfsph_dist hooks;
} pfsph_cost;

/* Read PFSPH_MPI_CUT (the root's, broadcast) and PFSPH_MPI_COST_SKEW and wrap the hooks D->d holds
 * so that their time counts as the decomposition's. Collective. PFSPH_ENOMEM or 0. */
int pfsph_cost_init(pfsph_decomp *D);
/* PFSPH_MPI_CUT's value on this rank: 1 cost, 0 count, -1 neither (the program refuses it) */
int pfsph_cost_env_mode(void);
/* The decomposition's code begins or ends (nested calls count once). */
void pfsph_cost_enter(pfsph_decomp *D);
void pfsph_cost_leave(pfsph_decomp *D);
/* The interval since the decomposition's code was last left is not the step's work (the driver's
 * frame writing, a command's wait): the root's commands begin with this. */
void pfsph_cost_drop(pfsph_decomp *D);
/* The step's exchange begins: the last step's work is one sample (own: the particles this rank
 * owned in it; first: it was the first step after a start or a resume, not measured). */
void pfsph_cost_sample(pfsph_decomp *D, int first);
/* In the step's maxima (one MPI_Allreduce(MAX) the step makes anyway): this rank's cost per
 * particle, and from the largest the weight of its particles at the next cut. */
double pfsph_cost_local(const pfsph_decomp *D);
void pfsph_cost_weigh(pfsph_decomp *D, double max_per_particle);
/* Every rank's figures to the root (a frame's gather, collective). */
void pfsph_cost_gather(pfsph_decomp *D);

#endif
