/* The simulation's private state, shared by the files of the simulation layer (sim.c: create,
 * schedule and loop; sim_estimate.c; sim_state.c; sim_control.c). */
#ifndef PFSPH_SIM_INTERNAL_H
#define PFSPH_SIM_INTERNAL_H

#include "core/nlist.h"
#include "core/stage.h"
#include "pfsph/bodies.h"
#include "pfsph/diffuse.h"
#include "pfsph/emitter.h"
#include "pfsph/film.h"
#include "pfsph/pairwise.h"
#include "pfsph/sim.h"
#include "physics/solver.h"

/* The step's per-fluid-particle arrays: ctx->ax.., ctx->nd and the pressure accelerations, then
 * (sim->scr_*) the stages' shared scratch, the thermostat's 3, pair_a's 3 when they cannot live
 * in ap's arrays, and the solver's. */
enum { SCR_AX, SCR_AY, SCR_AZ, SCR_ND, SCR_APX, SCR_APY, SCR_APZ, SCR_COMMON };
#define SCR_MAX (SCR_COMMON + 32)
#define MAX_STAGES 32

/* A stage in the schedule and its state; owned: the schedule created it and destroys it. */
typedef struct pfsph__sched {
    const pfsph_stage_ops *ops;
    void *state;
    int owned;
} pfsph__sched;

struct pfsph_sim {
    pfsph_scene scene;
    pfsph_ctx ctx;
    pfsph_step st; /* what the stages share (core/stage.h) */
    pfsph_particles fluid, boundary;
    pfsph_grid grid, bgrid;
    pfsph_nlist nlist, nlist_b; /* fluid and boundary neighbours, built each step when the
                                 * solver asks (neighbour_lists) */
    pfsph_real *scr[SCR_MAX];
    int nscr;
    int scr_stage, nscr_stage; /* the stages' shared scratch */
    int scr_noise;             /* first of the thermostat's 3 arrays (its accelerations), or -1 */
    int scr_pair;              /* first of pair_a's 3 arrays, or -1: they live in ap's */
    int scr_solver;            /* first of the solver's */
    int nscr_solver4;          /* the last of the solver's that hold 4 values per particle */
    size_t scr_cap;            /* entries in each scratch array */
    double sound_speed;
    pfsph__sched stages[MAX_STAGES];
    int nstages;
    pfsph__sched out_stages[4]; /* frame-derived fields (pfsph_sim_output) */
    int nout;
    size_t out_cap;
    double stage_s[PFSPH_NSTAGES];
    double stage_cpu[PFSPH_NSTAGES]; /* process CPU time per slot (benchmarks on a loaded machine) */
};

/* (Re)allocate the step's arrays for n fluid particles (zeroed) and point the step at them. */
int pfsph__sim_alloc_scratch(pfsph_sim *sim, size_t n);
/* Grid cells: h without pair forces, else max(h, k h / 3); the h and k h reaches in cells. */
pfsph_real pfsph__grid_cell(const pfsph_scene *s, pfsph_real h, int *reach, int *reach_far);
/* The emitters of a scene, their exit points filtered against the static solids. */
int pfsph__sim_emitters_create(pfsph_emitters **em, const pfsph_scene *s, const pfsph_ctx *c, pfsph_error *err);
/* The viscosity each phase's step applies (the scene's, or the pair-force correction's). */
void pfsph__sim_apply_viscosity(pfsph_ctx *c, const pfsph_scene *s);

#endif
