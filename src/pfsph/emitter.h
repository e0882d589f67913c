/* Emitters: nozzles that feed particles of one phase into a running simulation (issue 12,
 * part 3; docs/emitters.md). A nozzle's exit plane is normal to one axis; its openings are the
 * scene lattice's sites of that plane inside a disc, a rectangle (3D) or a segment (2D).
 * Particles enter layer by layer: the volume owed grows by rate x dt, and each whole layer owed
 * enters at the sites, already moved along the jet by the fraction of a layer still owed, so
 * that consecutive layers are one spacing apart and the emitted volume is rate x time to within
 * one layer. A site with a particle closer than 0.8 d is skipped for that layer (refused). The
 * nozzle is a velocity inlet: particles in the slab one spacing deep in front of the opening
 * that move out slower than the jet get the jet's velocity, so that nothing blocks it for good. */
#ifndef PFSPH_EMITTER_H
#define PFSPH_EMITTER_H

#include <stdbool.h>

#include "pfsph/ctx.h"

/* What a checkpoint stores of one emitter: all a resumed run needs to continue bit for bit. */
typedef struct pfsph_emitter_state {
    double debt;      /* layers owed, in [0, 1) between steps (volume owed / layer volume) */
    uint64_t emitted; /* particles created (each took a fluid id) */
    uint64_t refused; /* sites skipped because a particle was closer than 0.8 d */
    uint64_t pushed;  /* particles in front of the opening given the jet's velocity (inlet) */
} pfsph_emitter_state;

/* What an emitter resolved to on the lattice (for `pfsph check` and the docs). */
typedef struct pfsph_emitter_info {
    size_t sites;      /* particles per layer */
    double speed;      /* entry speed along the direction [m/s] */
    double rate;       /* volume rate [m^3/s, m^2/s in 2D]: sites V0 v_n / d */
    double layer_rate; /* layers per second: v_n / d */
} pfsph_emitter_info;

typedef struct pfsph_emitters pfsph_emitters;

/* Which exit points a nozzle may use (the simulation leaves out those within 0.4 d of a solid,
 * as it does for fluid blocks); NULL: all. */
typedef bool (*pfsph_site_filter)(const double x[3], void *user);

/* Resolve n nozzles on the lattice of ctx (dim, spacing, domain), keeping the sites `keep`
 * accepts; `source` names the scene in messages ("<source>: $.emitters[i]: ..."). PFSPH_EINPUT
 * for a nozzle without a site inside the domain or a rate that needs an entry speed above
 * 1000 m/s. n = 0 gives *out = NULL. */
int pfsph_emitters_create(pfsph_emitters **out, const pfsph_emitter_params *p, int n, const pfsph_ctx *ctx,
                          pfsph_site_filter keep, void *user, const char *source, pfsph_error *err);
void pfsph_emitters_destroy(pfsph_emitters *em);
int pfsph_emitters_count(const pfsph_emitters *em);
void pfsph_emitters_info(const pfsph_emitters *em, int i, pfsph_emitter_info *info);
/* The most particles all emitters together can have created by time t [s]. */
size_t pfsph_emitters_max(const pfsph_emitters *em, double t);
/* The most particles the step [t0, t0 + dt] can add (reserve this much before _step). */
size_t pfsph_emitters_due(const pfsph_emitters *em, double t0, double dt);
/* Emit what the step [t0, t0 + dt] owes into ctx->fluid, whose capacity must hold
 * pfsph_emitters_due more. *vmax_in receives the largest entry speed used (0: none emitted).
 * Returns the number of particles added. Deterministic: emitters in scene order, layers oldest
 * first, sites in lattice order; ids from fluid->next_id. */
size_t pfsph_emitters_step(pfsph_emitters *em, pfsph_particles *fluid, const pfsph_ctx *ctx, double t0, double dt,
                           double *vmax_in);
void pfsph_emitters_get_state(const pfsph_emitters *em, int i, pfsph_emitter_state *st);
/* Check a state against emitter i at time t (a checkpoint's): PFSPH_EINPUT with a message when
 * it cannot be this emitter's. _set_state checks, then installs it. */
int pfsph_emitters_check_state(const pfsph_emitters *em, int i, const pfsph_emitter_state *st, double t,
                               pfsph_error *err);
int pfsph_emitters_set_state(pfsph_emitters *em, int i, const pfsph_emitter_state *st, double t, pfsph_error *err);

#endif
