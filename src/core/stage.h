/* The stage interface: one time step is a schedule of stages, each exported by the module that
 * owns its physics, run in order by the simulation's loop (src/sim.c), which times them and
 * turns a blow-up they report into the one message. docs/architecture.md: adding a stage. */
#ifndef PFSPH_STAGE_H
#define PFSPH_STAGE_H

#include <stddef.h>
#include <stdint.h>

#include "pfsph/ctx.h"

/* Timing slots of summary.json ("stages"): several stages may count into one. */
enum pfsph_stage {
    PFSPH_STAGE_GRID,
    PFSPH_STAGE_DENSITY,
    PFSPH_STAGE_FORCES,
    PFSPH_STAGE_PAIRWISE,
    PFSPH_STAGE_PRESSURE,
    PFSPH_STAGE_INTEGRATE,
    PFSPH_STAGE_DIFFUSE,
    PFSPH_STAGE_BODIES,
    PFSPH_STAGE_FILM,
    PFSPH_STAGE_OUTPUT,
    PFSPH_NSTAGES
};
extern const char *const pfsph_stage_names[PFSPH_NSTAGES];

typedef struct pfsph_step_stats {
    double dt;
    double vmax;            /* m/s */
    double density_err_avg; /* mean of (rho - rho0) / rho0 over fluid, compressed side only */
    double density_err_max;
    double ekin;        /* J */
    int iterations;     /* pressure iterations of the last step (PCISPH, DFSPH density solve) */
    int div_iterations; /* divergence-solve iterations of the last step (0 without one) */
} pfsph_step_stats;

/* What a stage reads and writes: the schedule checks its hand-overs with these, and the loop
 * drops the neighbour lists after a stage that moves or reorders particles. */
enum pfsph_data {
    PFSPH_D_ORDER = 1u << 0,     /* which particle sits where: the grid sort, removal, emission */
    PFSPH_D_POS = 1u << 1,       /* fluid positions */
    PFSPH_D_VEL = 1u << 2,       /* fluid velocities */
    PFSPH_D_DENSITY = 1u << 3,   /* ctx->nd and fluid->rho */
    PFSPH_D_PRESSURE = 1u << 4,  /* fluid->p */
    PFSPH_D_ACC = 1u << 5,       /* ctx->ax.. (non-pressure accelerations) */
    PFSPH_D_AP = 1u << 6,        /* step->ap (pressure accelerations) */
    PFSPH_D_PAIR_ACC = 1u << 7,  /* step->pair_a (pair accelerations handed to the pairwise stage) */
    PFSPH_D_NOISE = 1u << 8,     /* step->noise (the thermostat's random accelerations) */
    PFSPH_D_DT = 1u << 9,        /* ctx->dt, the step's clock */
    PFSPH_D_NLIST = 1u << 10,    /* ctx->nlist (neighbour lists) */
    PFSPH_D_BOUNDARY = 1u << 11, /* boundary particles (bodies move them) */
    PFSPH_D_BODIES = 1u << 12,   /* rigid body state and forces */
    PFSPH_D_DIFFUSE = 1u << 13,  /* diffuse particles */
    PFSPH_D_FILM = 1u << 14,     /* film fractions and surface layers of bubbles */
    PFSPH_D_STATS = 1u << 15,    /* step->stats and the step's acceleration bounds */
    PFSPH_D_SOLVER = 1u << 16,   /* the pressure solver's own state and scratch */
    PFSPH_D_OUTPUT = 1u << 17,   /* step->out_layer, out_mech_p */
};

struct pfsph_solver_ops;
struct pfsph_pairwise;
struct pfsph_diffuse;
struct pfsph_film;
struct pfsph_bodies;
struct pfsph_emitters;
struct pfsph_nlist;

/* What one time step shares between its stages: the context, the step's named buffers (one value
 * per fluid particle, valid for the step), the model's objects, the clock and the statistics. A
 * buffer is written by one stage and read by later ones as their reads/writes declare. */
typedef struct pfsph_step {
    pfsph_ctx *ctx;
    pfsph_real *ap[3];          /* pressure accelerations: the solver writes them, the integrator adds them */
    pfsph_real *pair_a[3];      /* pair accelerations from the pair walk that also sums the density, for
                            * the pairwise stage; the schedule stores them in ap's arrays when no
                            * stage between the two touches ap (checked when it is built) */
    pfsph_real *noise[3];       /* the thermostat's random accelerations inside ctx->ax.. (NULL: none) */
    pfsph_real *const *scratch; /* nscratch arrays for the running stage alone */
    const struct pfsph_solver_ops *solver; /* the pressure solver */
    void *solver_state;
    pfsph_real *const *solver_scratch;   /* the solver's arrays (they live from solve to output) */
    struct pfsph_pairwise *pw;           /* NULL: no pair forces */
    struct pfsph_diffuse *df;            /* NULL: no diffuse material */
    struct pfsph_film *film;             /* NULL: no bubbles in air */
    struct pfsph_bodies *bodies;         /* NULL: no rigid bodies */
    struct pfsph_emitters *em;           /* NULL: no emitters */
    struct pfsph_nlist *nlist, *nlist_b; /* the lists' storage (ctx->nlist points here when built) */
    int lists; /* the density stage builds the lists (the solver's choice: pfsph__sim_lists) */
    /* the clock: the step begins at time and never passes t_limit */
    double time, t_limit;
    uint64_t step;
    double dt_min, dt_max; /* the scene's bounds [s] */
    double nu_max;         /* the largest viscosity of a phase [m^2/s] (the viscous step limit) */
    double amax;           /* largest acceleration of the last step */
    double amax_np;        /* largest non-pressure acceleration of the last step (or the solver's
                            * bound without viscosity: np_cap_without_viscosity) */
    double gmag;           /* |gravity| */
    double vbound;         /* speeds above this are a blow-up */
    size_t removed;        /* fluid particles removed so far (they left the domain) */
    size_t removed_before; /* removed before this step's sort */
    pfsph_step_stats stats;
    /* output buffers, filled by the output stages when a frame is written (PFSPH_D_OUTPUT) */
    uint8_t *out_layer;     /* surface layer: 0 interior, 1..2 the outer layers (docs/film.md) */
    pfsph_real *out_mech_p; /* with pair forces: solver pressure + pair virial + kinetic part [Pa] */
    /* Room for n fluid particles in every per-particle array of the step (emitters add fluid). */
    int (*reserve)(struct pfsph_step *st, size_t n, pfsph_error *err);
    void *owner; /* the simulation, for reserve */
} pfsph_step;

/* What a stage that found a blow-up reports; the loop turns it into the one message format
 * (step, time, stage, particle id, phase, position, likely cause). A stage never formats it. */
typedef struct pfsph_blowup {
    size_t particle;  /* fluid index, or SIZE_MAX when no particle is to blame */
    char what[256];   /* "speed [m/s] 12.3" */
    const char *hint; /* likely cause; NULL: the solver's */
} pfsph_blowup;

/* A stage. Only run is required. A stage's state is created once per simulation (create may
 * be NULL: no state); scratch arrays it asks for are shared by all stages and hold nothing
 * from one stage to the next. */
typedef struct pfsph_stage_ops {
    const char *name;       /* unique in a schedule; in blow-up messages */
    int slot;               /* enum pfsph_stage: where its time is counted */
    unsigned reads, writes; /* enum pfsph_data bits */
    int nscratch;           /* per-fluid-particle scratch arrays it needs while it runs */
    int (*create)(void **state, pfsph_step *st, pfsph_error *err);
    /* PFSPH_OK; PFSPH_EUNSTABLE with *bad filled for a blow-up; another code with err set */
    int (*run)(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err);
    void (*destroy)(void *state);
} pfsph_stage_ops;

/* Fill a blow-up report: particle i (SIZE_MAX: none), "what value". Returns PFSPH_EUNSTABLE. */
int pfsph__blowup(pfsph_blowup *b, size_t i, const char *what, double value);
/* Largest fluid speed; the index of the fastest (or of a non-finite) particle in *worst; NAN
 * when a velocity or position is not finite. */
double pfsph__max_speed(const pfsph_particles *f, size_t *worst);

#endif
