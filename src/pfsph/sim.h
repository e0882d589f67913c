/* The simulation: particle sets, grids, solver state and the time step loop. Stages receive a
 * pfsph_ctx, the read-mostly view of the current state, so that a stage can be tested alone
 * on a hand-made particle set. */
#ifndef PFSPH_SIM_H
#define PFSPH_SIM_H

#include "core/stage.h"
#include "pfsph/ctx.h"
#include "pfsph/scene.h"

typedef struct pfsph_sim pfsph_sim;

/* Build particles from the scene. Scene is copied. */
int pfsph_sim_create(pfsph_sim **out, const pfsph_scene *scene, pfsph_error *err);
/* Set-up progress: after each phase of the set-up, what it did and the wall and CPU seconds
 * (all threads) it took (a 1.9e8-particle scene takes minutes to set up; the program prints
 * the slow phases). */
typedef void (*pfsph_setup_fn)(const char *done, double wall_s, double cpu_s, void *user);
int pfsph_sim_create_ex(pfsph_sim **out, const pfsph_scene *scene, pfsph_setup_fn note, void *user, pfsph_error *err);
void pfsph_sim_destroy(pfsph_sim *sim);
/* Advance by one time step, never past t_limit. */
int pfsph_sim_step(pfsph_sim *sim, double t_limit, pfsph_error *err);
/* Advance to exactly time t. */
int pfsph_sim_advance(pfsph_sim *sim, double t, pfsph_error *err);
/* Before the first frame of a fresh run: sort, sum densities and set the Tait (equation of state)
 * pressures, so frame 0 carries real values. */
void pfsph_sim_prime_output(pfsph_sim *sim);

/* Surface layers of the fluid as it is now (src/pfsph/surface_detect.h): out[i] in 0
 * (interior) .. layers, fluid order; boundary particles cover; with bubbles each bubble on its
 * own. For the frames' `surface_layer` field. Returns PFSPH_OK or PFSPH_ENOMEM. */
int pfsph_sim_surface_layers(const pfsph_sim *sim, int layers, uint8_t *out);

/* The fields a frame carries that the step does not keep, computed now by the output stages
 * (surface layers; with pair forces the mechanical pressure) into buffers the simulation owns,
 * valid until the next step: read them with the two functions below. */
int pfsph_sim_output(pfsph_sim *sim, pfsph_error *err);
const uint8_t *pfsph_sim_output_surface_layer(const pfsph_sim *sim);
/* NULL without pair forces. */
const pfsph_real *pfsph_sim_output_mechanical_pressure(const pfsph_sim *sim);

/* The schedule (core/stage.h): insert a stage before (after = 0) or after (after = 1) the stage
 * called anchor, e.g. a halo exchange around the density stage. If the stage has a create, it is
 * called now and its state destroyed with the simulation; else state is handed to run as given.
 * Insert before the first step: the step's arrays are laid out again (and zeroed) when the
 * stage asks for scratch or breaks a hand-over that shared arrays. PFSPH_EINPUT: no such anchor,
 * a name already in use, a full schedule. */
int pfsph_sim_insert_stage(pfsph_sim *sim, const char *anchor, int after, const pfsph_stage_ops *stage, void *state,
                           pfsph_error *err);
int pfsph_sim_stage_count(const pfsph_sim *sim);
/* The i-th stage's name (NULL past the end). */
const char *pfsph_sim_stage_name(const pfsph_sim *sim, int i);
/* What the stages share, for a stage inserted from outside (core/stage.h). */
pfsph_step *pfsph_sim_step_state(pfsph_sim *sim);

double pfsph_sim_time(const pfsph_sim *sim);
uint64_t pfsph_sim_steps(const pfsph_sim *sim);
const pfsph_ctx *pfsph_sim_ctx(const pfsph_sim *sim);
/* The scene as the simulation runs it (pair-force targets resolved). */
const pfsph_scene *pfsph_sim_scene(const pfsph_sim *sim);
/* Point the model part of a context (gravity, domain, seed, phases, pair-force and diffuse
 * parameters) at a scene, which must outlive it: the simulation does this, and so can a test
 * that builds a context by hand. */
void pfsph_ctx_set_model(pfsph_ctx *c, const pfsph_scene *s);
const pfsph_step_stats *pfsph_sim_stats(const pfsph_sim *sim);
/* Mechanical pressure of every fluid particle (pfsph_pairwise_mechanical_pressure) into out
 * (fluid->n entries). PFSPH_EINPUT without pair forces, PFSPH_ENOMEM. */
int pfsph_sim_mechanical_pressure(const pfsph_sim *sim, pfsph_real *out);
/* Seconds spent per stage so far. */
/* Process CPU time per stage slot since creation [s] (not checkpointed; for benchmarks: with
 * one thread it is the stage's own CPU time, whatever else loads the machine). */
const double *pfsph_sim_stage_cpu_seconds(const pfsph_sim *sim);
const double *pfsph_sim_stage_seconds(const pfsph_sim *sim);
size_t pfsph_sim_removed(const pfsph_sim *sim);
/* After fluid velocities were written between steps (include/pfsph.h, pfsph_sim_field_write):
 * the next step's time step follows the speeds as they are now, not the last step's measure. */
void pfsph_sim_velocities_written(pfsph_sim *sim);
/* Account time spent outside the step (output) to a stage. */
void pfsph_sim_add_stage_time(pfsph_sim *sim, int stage, double seconds);
/* Speed of sound used by WCSPH (scene value or the automatic one) [m/s]. */
double pfsph_sim_sound_speed(const pfsph_sim *sim);
/* Diffuse particles (NULL when off). */
const pfsph_particles *pfsph_sim_diffuse(const pfsph_sim *sim);
/* Live diffuse particles per type (spray, foam, bubble); zeros when off. */
void pfsph_sim_diffuse_counts(const pfsph_sim *sim, size_t counts[3]);
/* The clock and counters of a simulation besides its particle sets: what a checkpoint saves
 * (docs/checkpoints.md). The sound speed, the boundary and the grids are rebuilt from the scene. */
typedef struct pfsph_sim_state {
    double time;
    uint64_t step;
    double amax;            /* largest acceleration of the last step (next step's dt) */
    double amax_np;         /* largest non-pressure acceleration of the last step */
    size_t removed;         /* fluid particles removed so far */
    pfsph_step_stats stats; /* stats.vmax feeds the next step's dt */
    double stage_s[PFSPH_NSTAGES];
} pfsph_sim_state;

void pfsph_sim_get_state(const pfsph_sim *sim, pfsph_sim_state *st);
/* Diffuse totals (zeros when off). */
void pfsph_sim_diffuse_totals(const pfsph_sim *sim, uint64_t *created, uint64_t *refused);
/* Put a saved state into a simulation created from the same scene: st, every field of the fluid
 * set (ids, phases, next_id included, in the given order) and, when diffuse is on, the diffuse
 * set and totals (diffuse must then be non-NULL). On error the simulation is unchanged except
 * after PFSPH_ENOMEM. */
int pfsph_sim_restore(pfsph_sim *sim, const pfsph_sim_state *st, const pfsph_particles *fluid,
                      const pfsph_particles *diffuse, uint64_t created, uint64_t refused, pfsph_error *err);

/* Rigid bodies (NULL when the scene has none); see bodies.h. */
struct pfsph_bodies;
struct pfsph_body_state;
const struct pfsph_bodies *pfsph_sim_bodies(const pfsph_sim *sim);
/* Restore body states and the boundary set's order (a checkpoint's; ids, n of them) after
 * pfsph_sim_restore. */
int pfsph_sim_restore_bodies(pfsph_sim *sim, int nbodies, const struct pfsph_body_state *st,
                             const uint32_t *boundary_ids, size_t n, pfsph_error *err);

/* Emitters (NULL when the scene has none); see emitter.h. */
struct pfsph_emitters;
struct pfsph_emitter_state;
struct pfsph_emitter_info;
const struct pfsph_emitters *pfsph_sim_emitters(const pfsph_sim *sim);
/* Restore the emitters' states (a checkpoint's, at time t [s]), checked against the scene's. */
int pfsph_sim_restore_emitters(pfsph_sim *sim, int n, const struct pfsph_emitter_state *st, double t, pfsph_error *err);

/* Number of particles and bytes a scene would need, without allocating them. n_fluid: the
 * fluid it starts with; bytes: with the most its emitters can add by the scene's end. */
int pfsph_scene_estimate(const pfsph_scene *s, size_t *n_fluid, size_t *n_boundary, size_t *bytes, pfsph_error *err);
/* Whether a run of s with at most n_fluid fluid particles builds neighbour lists: the solver's
 * "neighbour_lists" key, or with "auto" whether their estimate fits a quarter of this machine's
 * memory (docs/solvers.md, "Neighbour lists"); 0 for a solver without lists. */
int pfsph__sim_lists(const pfsph_scene *s, double n_fluid);
/* The most particles the scene's emitters can have added by time t [s] (0 without emitters);
 * PFSPH_EINPUT (message with the JSON path) for a nozzle the lattice cannot feed. */
int pfsph_scene_emitted_max(const pfsph_scene *s, double t, size_t *n, pfsph_error *err);
/* The fastest emitted fluid can get: its entry speed plus a fall from the nozzle to the domain's
 * lowest corner [m/s]; 0 without emitters. Sets the automatic sound speed and the renderer's
 * fixed speed scale of scenes that start (nearly) empty. */
double pfsph_scene_emitter_speed(const pfsph_scene *s);
/* What each emitter resolves to on the lattice (s->nemitters entries: sites, speed, rate). */
int pfsph_scene_emitters_info(const pfsph_scene *s, struct pfsph_emitter_info *info, pfsph_error *err);

/* ---- changing the model while it runs (the live viewer's interface; docs/viewer.md) ----
 * Each takes effect at the next pfsph_sim_step, as if the scene had said so from the start;
 * none may be called while a step runs. On error (PFSPH_EINPUT, message naming the value) the
 * simulation is unchanged. */

/* Gravity [m/s^2] (2D: g[2] is ignored and kept 0); rigid bodies follow. */
int pfsph_sim_set_gravity(pfsph_sim *sim, const double g[3], pfsph_error *err);
/* Pair-force coefficient c of phases a and b (both orders), replacing any sigma or contact-angle
 * target the scene gave that pair; targets of other pairs are resolved again (a contact angle
 * follows its fluid's cohesion). Units as in params.h; c finite and >= 0. Pair forces must be on. */
int pfsph_sim_set_pair_coefficient(pfsph_sim *sim, int a, int b, double c, pfsph_error *err);
/* Surface tension target [N/m] of a fluid pair (a == b: against the unsimulated air). */
int pfsph_sim_set_pair_sigma(pfsph_sim *sim, int a, int b, double sigma, pfsph_error *err);
/* Static contact-angle target [degrees, 0..180] of a fluid phase on a solid phase. */
int pfsph_sim_set_pair_contact_angle(pfsph_sim *sim, int a, int b, double deg, pfsph_error *err);
/* Drag rigid body `body` towards target [m] from the next step on. The speed limit vmax is a
 * tenth of the sound speed (the flow speed the scene is set up for) or a fifth of the blow-up
 * speed bound, the smaller. A kinematic body without keyframes moves there in a straight line
 * at most vmax and stays where it is left. A dynamic body is pulled by a critically damped
 * 5 Hz spring on its centre of mass, added to the fluid's force, gravity and contacts in each
 * step; the pull drives it towards vmax at most, it hangs g / (2 pi 5 Hz)^2 = 1 cm below the
 * target under gravity, and moves on freely when let go. Keyframed bodies are refused
 * (PFSPH_EINPUT). target NULL lets go. */
int pfsph_sim_drag_body(pfsph_sim *sim, int body, const double target[3], pfsph_error *err);

#endif
