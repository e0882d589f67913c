/* The rigid bodies' stages: the fluid's forces on them from this step's pressure (Akinci 2012),
 * and their ODE step, which moves their boundary particles. */
#include <math.h>
#include <stdio.h>

#include "pfsph/bodies.h"
#include "physics/solver.h"
#include "physics/stages.h"

/* fluid forces on the bodies from this step's pressure, before the fluid moves */
static int body_forces_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    const pfsph_real *p = st->solver->wall_pressure
        ? st->solver->wall_pressure(st->solver_state, st->ctx, st->solver_scratch)
        : st->ctx->fluid->p;
    pfsph_bodies_fluid_forces(st->bodies, st->ctx, p);
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_body_forces = {.name = "body_forces",
                                                 .slot = PFSPH_STAGE_BODIES,
                                                 .reads = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_DENSITY |
                                                     PFSPH_D_PRESSURE | PFSPH_D_SOLVER,
                                                 .writes = PFSPH_D_BODIES,
                                                 .run = body_forces_run};

static int bodies_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    pfsph_particles *b = st->ctx->boundary;
    pfsph_bodies_step(st->bodies, b, st->time, st->ctx->dt);
    for (int i = 0; i < pfsph_bodies_count(st->bodies); i++) {
        pfsph_body_state bs;
        pfsph_bodies_get_state(st->bodies, i, &bs);
        double q = bs.x[0] + bs.x[1] + bs.x[2] + bs.v[0] + bs.v[1] + bs.v[2] + bs.w[0] + bs.w[1] + bs.w[2];
        if (!isfinite(q) || sqrt(bs.v[0] * bs.v[0] + bs.v[1] * bs.v[1] + bs.v[2] * bs.v[2]) > st->vbound) {
            bad->particle = SIZE_MAX;
            snprintf(bad->what, sizeof bad->what, "body \"%s\" at %.4g %.4g %.4g moves at %.4g %.4g %.4g m/s",
                     pfsph_bodies_name(st->bodies, i), bs.x[0], bs.x[1], bs.x[2], bs.v[0], bs.v[1], bs.v[2]);
            bad->hint = "a body much lighter than the fluid it displaces, or too large a time step (lower time.cfl)";
            return PFSPH_EUNSTABLE;
        }
    }
    if (pfsph_grid_sort(st->ctx->bgrid, b, NULL))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sorting the boundary particles");
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_bodies = {.name = "bodies",
                                            .slot = PFSPH_STAGE_BODIES,
                                            .reads = PFSPH_D_BODIES | PFSPH_D_DT,
                                            .writes = PFSPH_D_BODIES | PFSPH_D_BOUNDARY,
                                            .run = bodies_run};
