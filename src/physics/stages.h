/* The stages the modules export (each defined next to the physics it runs), for the schedule in
 * src/sim.c. A new stage: define `const pfsph_stage_ops pfsph_stage_<name>` in its module and
 * declare it here (docs/architecture.md). */
#ifndef PFSPH_STAGES_H
#define PFSPH_STAGES_H

#include "core/stage.h"

extern const pfsph_stage_ops pfsph_stage_grid;            /* core/grid.c: sort, removal */
extern const pfsph_stage_ops pfsph_stage_shift;           /* physics/pairwise.c: particle shifting */
extern const pfsph_stage_ops pfsph_stage_film;            /* physics/film.c: bubbles' surface and film */
extern const pfsph_stage_ops pfsph_stage_density;         /* physics/density.c: Eq. 23 (+ lists) */
extern const pfsph_stage_ops pfsph_stage_pair_density;    /* physics/pairwise.c: Eq. 23 in the pair walk */
extern const pfsph_stage_ops pfsph_stage_timestep;        /* physics/timestep.c: dt */
extern const pfsph_stage_ops pfsph_stage_divergence;      /* physics/solver.c: the solver's pre_forces */
extern const pfsph_stage_ops pfsph_stage_forces;          /* physics/viscosity.c: gravity, viscosity */
extern const pfsph_stage_ops pfsph_stage_forces_eos;      /* physics/viscosity.c: the same + EOS pressure */
extern const pfsph_stage_ops pfsph_stage_pairwise;        /* physics/pairwise.c: the pair pass */
extern const pfsph_stage_ops pfsph_stage_pairwise_add;    /* physics/pairwise.c: pair_a into ax.. */
extern const pfsph_stage_ops pfsph_stage_pressure;        /* physics/solver.c: solve */
extern const pfsph_stage_ops pfsph_stage_pressure_report; /* physics/solver.c: after forces_eos */
extern const pfsph_stage_ops pfsph_stage_body_forces;     /* physics/body_stages.c: fluid on bodies */
extern const pfsph_stage_ops pfsph_stage_integrate;       /* physics/integrate.c: symplectic Euler */
extern const pfsph_stage_ops pfsph_stage_diffuse;         /* physics/diffuse.c: spray, foam, bubbles */
extern const pfsph_stage_ops pfsph_stage_bodies;          /* physics/body_stages.c: ODE step */
extern const pfsph_stage_ops pfsph_stage_emit;            /* physics/emitter.c: new fluid */

/* physics/pairwise.c: Eq. 23 and the lists within h in the pair walk (the interactive PCISPH) */
extern const pfsph_stage_ops pfsph_stage_pair_density_lists;

/* Output stages: fields a frame carries that the step does not keep, computed when a frame is
 * written (pfsph_sim_output) into the step's output buffers (out_layer, out_mech_p). */
extern const pfsph_stage_ops pfsph_stage_surface_layers;      /* core/surface_detect.c */
extern const pfsph_stage_ops pfsph_stage_mechanical_pressure; /* physics/pairwise.c */

/* The mechanical pressure into out (fluid->n values), with the pressure the solver pushed with:
 * DFSPH's divergence solve pushes too (its wall_pressure); with its density pressure alone the
 * interior of a 3D drop read -15 Pa for +133 Pa. PFSPH_OK or PFSPH_ENOMEM. */
int pfsph__mechanical_pressure(const pfsph_step *st, pfsph_real *out);

/* The density's blow-up check, shared by the density stages: rho from the number density; a
 * compression of half the rest density again stops the run. */
int pfsph__density_check(pfsph_step *st, pfsph_blowup *bad);

#endif
