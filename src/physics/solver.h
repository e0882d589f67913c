/* The pressure-solver interface and its registry. A solver is one file defining a table row: its
 * name, its scene keys with defaults and ranges, and the functions the pressure stages call.
 * Adding a solver is that file and its name in PFSPH_SOLVERS (solver.c): docs/architecture.md. */
#ifndef PFSPH_SOLVER_H
#define PFSPH_SOLVER_H

#include "pfsph/ctx.h"

/* One scene key of a solver, under $.solver: its default and the accepted range. The scene
 * stores the values in the order of the row's keys (pfsph_scene.solver_settings). */
typedef struct pfsph_solver_key {
    const char *name;
    double def, min, max;
    int integer; /* non-zero: an integer; PFSPH_KEY_AUTO_BOOL: a choice */
    const char *doc;
} pfsph_solver_key;

/* A key's `integer` for a choice the scene writes as true, false or "auto", stored 1, -1 and 0
 * (min -1, max 1; "auto" is 0 so that a scene without the key keeps its hash). */
#define PFSPH_KEY_AUTO_BOOL 2

/* The scene's solver settings, resolved by the simulation (sound speed chosen, pressure
 * scale decided), so that a solver reads no scene. */
typedef struct pfsph_solver_config {
    double sound_speed; /* c [m/s] of the densest phase (scene value or automatic) */
    double c_fast;      /* sound speed of the lightest phase (= sound_speed unless rho_common) */
    double gamma;       /* Tait exponent */
    double rho_common;  /* > 0: one Tait pressure scale for all phases [kg/m^3]; 0: per phase */
    double cfl;
    const double *settings; /* the solver's own keys' values, in the order of its row's keys */
    int lists;              /* the run builds neighbour lists (pfsph__sim_lists): else its scratch is
                             * walk_nscratch's layout */
} pfsph_solver_config;

/* What one solve reports (stats.csv columns). */
typedef struct pfsph_solve_stats {
    int iterations;         /* density (pressure) iterations of this step */
    int div_iterations;     /* iterations of a pre_forces solve (divergence-free solvers) */
    double density_err_avg; /* mean compression (rho - rho0) / rho0, compressed side only */
} pfsph_solve_stats;

typedef struct pfsph_solver_ops {
    const char *name;             /* as in the scene's solver.type */
    const pfsph_solver_key *keys; /* its own scene keys (NULL when none) */
    int nkeys;                    /* at most PFSPH_SOLVER_MAX_KEYS */
    /* Optional: checks across keys (v in the order of keys); on failure points *key at the key
     * to blame (under $.solver), writes a message and returns non-zero. */
    int (*check)(const double *v, const char **key, char *msg, size_t len);
    /* Optional: what `pfsph check` says of a density ratio > 1 between fluid phases under this
     * solver (common_scale: "pressure_scale": "common"), written to buf or a constant; NULL:
     * nothing to add. */
    const char *(*ratio_advice)(double ratio, int common_scale, char *buf, size_t len);
    int nscratch;  /* per-fluid-particle scratch arrays the solver needs */
    int nscratch4; /* the last nscratch4 of them hold 4 values per particle (packed x, y, z, w) */
    /* Non-zero: the solver's scratch holds nothing from one call to the next (each call writes
     * what it reads), so it lies in the stages' shared scratch instead of arrays of its own
     * (nscratch4 must be 0). */
    int scratch_per_call;
    /* Non-zero: the solver walks the neighbours many times per step, from neighbour lists
     * (ctx->nlist, built after the density stage; memory: src/core/nlist.h) or, when ctx->nlist
     * is NULL, by grid walks with the same terms in the same order (physics/neighbours.h). Its
     * key "neighbour_lists" (true, false, "auto") chooses: pfsph__sim_lists (sim_estimate.c). */
    int neighbour_lists;
    /* Optional, with neighbour_lists: the scratch when the run walks the grid instead (config.lists
     * 0): walk_nscratch arrays of one value in place of nscratch / nscratch4. They carry values from
     * pre_forces to solve, so they lie in the stages' shared scratch only when no stage between
     * the first and the last stage that write PFSPH_D_SOLVER asks for scratch, else in arrays of
     * their own (src/sim.c, plan_buffers). A call may also use what holds nothing during it (the
     * solver's file says what). walk_near_bytes: bytes the solver keeps per fluid particle within h
     * of a wall particle in that layout (the estimate counts them). 0: nscratch's layout always. */
    int walk_nscratch;
    int walk_near_bytes;
    /* Non-zero: amax_np, the non-pressure acceleration dt_limit receives, leaves viscosity out:
     * |g| + the largest pair-force acceleration (an upper bound of |g + a_pair|). Viscosity
     * smooths velocities; it compresses nothing that the solve must undo (DFSPH, docs/solvers.md). */
    int np_cap_without_viscosity;
    /* Optional (may be NULL): the pressure from the density alone (an equation of state),
     * written to fluid->p. Given, and without pair forces (which read last step's p), the
     * schedule fuses: the forces stage writes p and computes the pressure acceleration in the
     * viscosity's neighbour walk (one walk instead of two; viscosity.c), and the pressure stage
     * calls `report` instead of `solve`. A solver with eos must have report. */
    void (*eos)(void *state, const pfsph_ctx *ctx);
    /* With eos: the stats of a step whose pressure the forces stage computed. */
    void (*report)(void *state, const pfsph_ctx *ctx, pfsph_real *const *scratch, pfsph_solve_stats *out);
    /* Solver state for the fluid of ctx; NULL state is allowed. */
    int (*create)(void **state, const pfsph_ctx *ctx, const pfsph_solver_config *cfg, pfsph_error *err);
    void (*destroy)(void *state); /* NULL is a no-op */
    /* Optional (may be NULL): called after the density stage and the choice of ctx->dt, before
     * the non-pressure forces: where a divergence-free solver (DFSPH) corrects the velocities. The
     * pressure accelerations' arrays ap hold nothing yet: it may use them as scratch. Returns
     * PFSPH_OK or PFSPH_ENOMEM. */
    int (*pre_forces)(void *state, const pfsph_ctx *ctx, pfsph_real *const ap[3], pfsph_real *const *scratch,
                      pfsph_solve_stats *out);
    /* Pressure accelerations a_p for the step ctx->dt, given ctx->nd (number density at x),
     * ctx->ax.. (non-pressure accelerations); writes fluid->p and ap[0..2]; the integrator then
     * applies v += dt (a + a_p), x += dt v. A solver may hand over a + a_p in ap and -0 in
     * ctx->ax.. instead (the integrator's sum is then the same bits: DFSPH without lists). */
    void (*solve)(void *state, const pfsph_ctx *ctx, pfsph_real *const ap[3], pfsph_real *const *scratch,
                  pfsph_solve_stats *out);
    /* Optional (may be NULL: fluid->p): the pressure whose wall term (Akinci 2012) the fluid
     * felt this step, for the reaction on rigid bodies; called after solve. DFSPH returns the
     * sum of its divergence and density pressures. */
    const pfsph_real *(*wall_pressure)(void *state, const pfsph_ctx *ctx, pfsph_real *const *scratch);
    /* Largest time step the solver allows [s], from the largest speed vmax of the fluid and
     * bodies [m/s] and last step's largest total and non-pressure accelerations [m/s^2]. The
     * simulation adds dt_max, viscous diffusion and the landing on frame times. */
    double (*dt_limit)(const void *state, const pfsph_ctx *ctx, double vmax, double amax, double amax_np);
    /* Speeds above this are a blow-up [m/s], for the step ctx->dt (0 before the first). */
    double (*speed_bound)(const void *state, const pfsph_ctx *ctx);
    /* The likely cause of a blow-up under this solver at ctx's step, for the message. */
    const char *(*hint)(const void *state, const pfsph_ctx *ctx);
} pfsph_solver_ops;

/* The solver called name, or NULL. */
const pfsph_solver_ops *pfsph_solver_find(const char *name);
/* The i-th solver of the table (NULL past the end): for listings and tests. */
const pfsph_solver_ops *pfsph_solver_at(int i);
/* The index of key in the row's keys, or -1. */
int pfsph_solver_key_index(const pfsph_solver_ops *ops, const char *key);

/* Most solvers the registry holds (solver.c checks it at compile time). */
#define PFSPH_MAX_SOLVERS 16

/* Shared by the solvers that remove the density error within one step (PCISPH, IISPH): with a
 * tiny dt their pressure speeds grow as 1/dt without harm, so a speed is a blow-up only above
 * 20 c and once the particle also moves half a spacing in the step (issue 15 item 5). */
double pfsph__speed_bound_one_step(double c, const pfsph_ctx *ctx);

/* Shared by the iterative solvers' `check`: min_iterations <= max_iterations. */
int pfsph__check_iterations(double min_iter, double max_iter, const char **key, char *msg, size_t len);

/* Shared by the solvers: the force criterion 0.25 sqrt(d / a) (Monaghan 1992), infinite for a
 * = 0. */
double pfsph__dt_force(double spacing, double a);

/* The interactive mode's force criterion (PCISPH): 0.35 sqrt(d / a). Measured on the 3D
 * interactive wetting and double-bubble scenes (docs/interactive.md): 0.35 runs 3 and 2 steps per
 * frame stably; 0.5 blew up in the third step of the wetting scene (cube corners). */
#define PFSPH_DT_FORCE_INTERACTIVE 0.35
double pfsph__dt_force_interactive(double spacing, double a);

#endif
