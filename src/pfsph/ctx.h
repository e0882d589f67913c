/* The simulation context: the read-mostly view of the current state that every stage
 * receives (particle sets, grids, kernel, per-phase tables, the model's parameters, clock).
 * Core data: physics stages include this, never the scene or the simulation. */
#ifndef PFSPH_CTX_H
#define PFSPH_CTX_H

#include "pfsph/grid.h"
#include "pfsph/kernel.h"
#include "pfsph/params.h"
#include "pfsph/particles.h"

#define PFSPH_MAX_WALLS 80 /* wall models: the default and one per solid at most */

/* What every stage may read. Fluid arrays are in grid order (grid sorted this step). */
typedef struct pfsph_ctx {
    int dim;
    pfsph_real spacing;        /* initial particle spacing d = 2 r [m] */
    pfsph_real h;              /* SPH support radius [m] */
    pfsph_real V0;             /* rest particle volume d^dim */
    pfsph_real nd0;            /* rest number density 1 / V0 */
    pfsph_kernel kern;         /* support h */
    pfsph_particles *fluid;    /* fluid and gas particles */
    pfsph_particles *boundary; /* static solid particles; aux = Akinci volume [m^d] */
    pfsph_grid *grid;          /* fluid grid; cell >= max radius in use */
    pfsph_grid *bgrid;         /* boundary grid, same geometry */
    /* Fluid neighbours within h of each fluid particle (src/core/nlist.h), built this step after
     * the density stage when the solver asks for lists; NULL otherwise. */
    const struct pfsph_nlist *nlist;
    const struct pfsph_nlist *nlist_b; /* the same step's boundary neighbours within h */
    pfsph_real mass[PFSPH_MAX_PHASES]; /* particle mass per phase: rho0 * V0 */
    pfsph_real rest_density[PFSPH_MAX_PHASES];
    pfsph_real nu[PFSPH_MAX_PHASES]; /* kinematic viscosity per phase */
    /* Wall friction per wall model w (the boundary set's `wall`): a fluid particle of viscosity
     * nu feels the Akinci friction of viscosity wall_scale[w] nu + wall_nu[w] from a wall
     * particle of model w (no slip: 1, 0; free slip: 0, 0; a solid's own viscosity: 0, nu_w).
     * nwalls <= 1: every wall is the default, and the friction loop skips the table. */
    int nwalls;
    pfsph_real wall_scale[PFSPH_MAX_WALLS], wall_nu[PFSPH_MAX_WALLS];
    pfsph_real wall_nu_max;   /* largest wall_nu */
    pfsph_real *ax, *ay, *az; /* per-step non-pressure acceleration of fluid particles */
    pfsph_real *nd;           /* per-step number density of fluid particles (Eq. 23) */
    /* the model (copied from the scene by the simulation; physics never sees the scene) */
    double gravity[3];                   /* m/s^2 */
    double domain_min[3], domain_max[3]; /* fluid leaving it is removed */
    uint64_t seed;                       /* for counter-based random numbers */
    int interactive;                     /* the scene's mode is "interactive" (docs/interactive.md) */
    int nphases;
    const pfsph_phase *phases;             /* nphases entries */
    const pfsph_pairwise_params *pairwise; /* resolved; pairwise->enabled may be false */
    const pfsph_diffuse_params *diffuse;
    const pfsph_film_params *film; /* bubbles in air; NULL or nbubbles 0: none */
    double time, dt;
    uint64_t step;
    struct pfsph_dist *dist; /* a distributed run's decomposition (pfsph/dist.h); NULL: serial */
} pfsph_ctx;

#endif
