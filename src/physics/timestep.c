/* The time step: the solver's own limit (CFL, force criterion, its caps), the scene's dt_max,
 * the viscous limit, dt_min as the blow-up floor, and the landing on frame times in equal steps. */
#include <math.h>

#include "pfsph/bodies.h"
#include "physics/solver.h"
#include "physics/stages.h"

static double choose_dt(const pfsph_step *st, double vmax, int *collapsed)
{
    const double d = st->ctx->spacing;
    double dt = fmin(st->dt_max, st->solver->dt_limit(st->solver_state, st->ctx, vmax, st->amax, st->amax_np));
    if (st->nu_max > 0) dt = fmin(dt, 0.125 * d * d / st->nu_max); /* viscous diffusion */
    *collapsed = dt < st->dt_min;
    if (dt < st->dt_min) dt = st->dt_min;
    /* Land on t_limit in equal steps: the rest of the interval divided into the fewest steps
     * not longer than dt. A single shortened last step would kick PCISPH, whose pressure
     * scales as 1/dt^2: frames fell exactly on those short steps and showed 2-3.5x the
     * hydrostatic pressure. */
    double rem = st->t_limit - st->time;
    if (rem <= dt) return rem;
    double steps = ceil(rem / dt - 1e-9);
    return rem / steps;
}

static int timestep_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)err;
    pfsph_ctx *c = st->ctx;
    /* the last step's integration measured vmax (and stopped on non-finite values); only a
     * removal in the sort can lower it */
    size_t worst = 0;
    double vmax = st->removed != st->removed_before ? pfsph__max_speed(c->fluid, &worst) : st->stats.vmax;
    int collapsed;
    double dt = choose_dt(st, st->bodies ? fmax(vmax, pfsph_bodies_vmax(st->bodies)) : vmax, &collapsed);
    if (collapsed) {
        vmax = pfsph__max_speed(c->fluid, &worst);
        return pfsph__blowup(bad, worst, "time step fell below time.dt_min; speed", vmax);
    }
    c->dt = dt;
    c->time = st->time;
    c->step = st->step;
    st->vbound = st->solver->speed_bound(st->solver_state, c);
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_timestep = {.name = "timestep",
                                              .slot = PFSPH_STAGE_FORCES,
                                              .reads = PFSPH_D_VEL | PFSPH_D_STATS | PFSPH_D_BODIES,
                                              .writes = PFSPH_D_DT,
                                              .run = timestep_run};
