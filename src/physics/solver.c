/* The registry of pressure solvers, looked up by the scene's solver name. A solver is one file
 * defining `const pfsph_solver_ops pfsph_solver_<name>` and one word in PFSPH_SOLVERS. */
#include "physics/solver.h"

#include "physics/stages.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The registry: one word per solver, in the order `pfsph check` and the docs list them. */
#define PFSPH_SOLVERS(X) X(wcsph) X(pcisph) X(dfsph) X(iisph)

#define PFSPH_SOLVER_DECLARE(n) extern const pfsph_solver_ops pfsph_solver_##n;
PFSPH_SOLVERS(PFSPH_SOLVER_DECLARE)
#define PFSPH_SOLVER_ROW(n) &pfsph_solver_##n,
static const pfsph_solver_ops *const solvers[] = {PFSPH_SOLVERS(PFSPH_SOLVER_ROW) NULL};
_Static_assert(sizeof solvers / sizeof *solvers - 1 <= PFSPH_MAX_SOLVERS, "raise PFSPH_MAX_SOLVERS");

const pfsph_solver_ops *pfsph_solver_find(const char *name)
{
    for (int i = 0; name && solvers[i]; i++)
        if (!strcmp(solvers[i]->name, name)) return solvers[i];
    return NULL;
}

const pfsph_solver_ops *pfsph_solver_at(int i)
{
    return i >= 0 && i < (int)(sizeof solvers / sizeof *solvers) - 1 ? solvers[i] : NULL;
}

int pfsph_solver_key_index(const pfsph_solver_ops *ops, const char *key)
{
    for (int k = 0; ops && key && k < ops->nkeys; k++)
        if (!strcmp(ops->keys[k].name, key)) return k;
    return -1;
}

double pfsph__speed_bound_one_step(double c, const pfsph_ctx *ctx)
{
    const double b = 20 * c;
    return ctx->dt > 0 ? fmax(b, 0.5 * (double)ctx->spacing / ctx->dt) : b;
}

double pfsph__dt_force(double spacing, double a) { return a > 0 ? 0.25 * sqrt(spacing / a) : INFINITY; }

double pfsph__dt_force_interactive(double spacing, double a)
{
    return a > 0 ? PFSPH_DT_FORCE_INTERACTIVE * sqrt(spacing / a) : INFINITY;
}

int pfsph__check_iterations(double min_iter, double max_iter, const char **key, char *msg, size_t len)
{
    if (min_iter <= max_iter) return 0;
    *key = "min_iterations";
    snprintf(msg, len, "min_iterations (%d) is greater than max_iterations (%d)", (int)min_iter, (int)max_iter);
    return 1;
}

/* ---- the pressure solver's stages ---- */

/* a divergence-free solver (DFSPH) corrects the velocities before the non-pressure forces */
static int divergence_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    pfsph_solve_stats out = {0, 0, 0};
    int rc = st->solver->pre_forces(st->solver_state, st->ctx, st->ap, st->solver_scratch, &out);
    if (rc) return pfsph_fail(err, rc, "out of memory in the %s solver's divergence solve", st->solver->name);
    st->stats.div_iterations = out.div_iterations;
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_divergence = {.name = "divergence",
                                                .slot = PFSPH_STAGE_PRESSURE,
                                                .reads = PFSPH_D_POS | PFSPH_D_DENSITY | PFSPH_D_NLIST | PFSPH_D_DT,
                                                /* ap: its scratch (pre_forces) */
                                                .writes = PFSPH_D_VEL | PFSPH_D_AP | PFSPH_D_SOLVER | PFSPH_D_STATS,
                                                .run = divergence_run};

static int pressure_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    pfsph_solve_stats out = {0, 0, 0};
    st->solver->solve(st->solver_state, st->ctx, st->ap, st->solver_scratch, &out);
    st->stats.iterations = out.iterations;
    st->stats.density_err_avg = out.density_err_avg;
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_pressure = {
    .name = "pressure",
    .slot = PFSPH_STAGE_PRESSURE,
    .reads = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_DENSITY | PFSPH_D_ACC | PFSPH_D_NLIST | PFSPH_D_DT,
    /* ACC: a solver may hand a_np over in ap (solver.h) */
    .writes = PFSPH_D_PRESSURE | PFSPH_D_AP | PFSPH_D_ACC | PFSPH_D_SOLVER | PFSPH_D_STATS,
    .run = pressure_run};

/* the forces stage computed the pressure (pfsph_stage_forces_eos): the solver only reports */
static int pressure_report_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    pfsph_solve_stats out = {0, 0, 0};
    st->solver->report(st->solver_state, st->ctx, st->solver_scratch, &out);
    st->stats.iterations = out.iterations;
    st->stats.density_err_avg = out.density_err_avg;
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_pressure_report = {.name = "pressure",
                                                     .slot = PFSPH_STAGE_PRESSURE,
                                                     .reads = PFSPH_D_DENSITY,
                                                     .writes = PFSPH_D_SOLVER | PFSPH_D_STATS,
                                                     .run = pressure_report_run};
