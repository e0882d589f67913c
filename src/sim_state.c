/* The simulation's state seen from outside: clock, counts, statistics, and the state a
 * checkpoint saves and restores (fluid, bodies, emitters, diffuse material). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim_internal.h"

double pfsph_sim_time(const pfsph_sim *sim) { return sim->st.time; }
uint64_t pfsph_sim_steps(const pfsph_sim *sim) { return sim->st.step; }
const pfsph_ctx *pfsph_sim_ctx(const pfsph_sim *sim) { return &sim->ctx; }
const pfsph_scene *pfsph_sim_scene(const pfsph_sim *sim) { return &sim->scene; }
const pfsph_step_stats *pfsph_sim_stats(const pfsph_sim *sim) { return &sim->st.stats; }
const double *pfsph_sim_stage_seconds(const pfsph_sim *sim) { return sim->stage_s; }
const double *pfsph_sim_stage_cpu_seconds(const pfsph_sim *sim) { return sim->stage_cpu; }
size_t pfsph_sim_removed(const pfsph_sim *sim) { return sim->st.removed; }
void pfsph_sim_diffuse_counts(const pfsph_sim *sim, size_t counts[3])
{
    counts[0] = counts[1] = counts[2] = 0;
    if (sim->st.df) pfsph_diffuse_counts(sim->st.df, counts);
}

const pfsph_particles *pfsph_sim_diffuse(const pfsph_sim *sim)
{
    return sim->st.df ? pfsph_diffuse_particles(sim->st.df) : NULL;
}
double pfsph_sim_sound_speed(const pfsph_sim *sim) { return sim->sound_speed; }
const pfsph_emitters *pfsph_sim_emitters(const pfsph_sim *sim) { return sim->st.em; }

int pfsph_sim_restore_emitters(pfsph_sim *sim, int n, const pfsph_emitter_state *st, double t, pfsph_error *err)
{
    if (n != pfsph_emitters_count(sim->st.em))
        return pfsph_fail(err, PFSPH_EINPUT, "restore: %d emitters, the scene has %d", n,
                          pfsph_emitters_count(sim->st.em));
    for (int i = 0; i < n; i++) {
        int rc = pfsph_emitters_set_state(sim->st.em, i, &st[i], t, err);
        if (rc) return rc;
    }
    return PFSPH_OK;
}
const pfsph_bodies *pfsph_sim_bodies(const pfsph_sim *sim) { return sim->st.bodies; }

int pfsph_sim_restore_bodies(pfsph_sim *sim, int nbodies, const pfsph_body_state *st, const uint32_t *ids, size_t n,
                             pfsph_error *err)
{
    pfsph_particles *b = &sim->boundary;
    if (nbodies != pfsph_bodies_count(sim->st.bodies))
        return pfsph_fail(err, PFSPH_EINPUT, "restore: %d bodies, the scene has %d", nbodies,
                          pfsph_bodies_count(sim->st.bodies));
    if (!nbodies) return PFSPH_OK;
    if (n > b->n) return pfsph_fail(err, PFSPH_EINPUT, "restore: %zu boundary particles, the scene has %zu", n, b->n);
    for (int i = 0; i < nbodies; i++) {
        double s = 0;
        for (int a = 0; a < 3; a++) s += st[i].x[a] + st[i].v[a] + st[i].w[a];
        s += st[i].q[0] + st[i].q[1] + st[i].q[2] + st[i].q[3];
        if (!isfinite(s)) return pfsph_fail(err, PFSPH_EINPUT, "restore: body %d has a non-finite state", i);
        double qn =
            st[i].q[0] * st[i].q[0] + st[i].q[1] * st[i].q[1] + st[i].q[2] * st[i].q[2] + st[i].q[3] * st[i].q[3];
        if (!(fabs(qn - 1) < 1e-6))
            return pfsph_fail(err, PFSPH_EINPUT, "restore: body %d's orientation is not a unit quaternion (norm^2 %g)",
                              i, qn);
    }
    /* where each id sits now */
    uint32_t *where = malloc((b->next_id ? b->next_id : 1) * sizeof(uint32_t));
    uint32_t *perm = malloc((n ? n : 1) * sizeof(uint32_t));
    if (!where || !perm) {
        free(where);
        free(perm);
        return pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory");
    }
    memset(where, 0xff, (b->next_id ? b->next_id : 1) * sizeof(uint32_t));
    for (size_t j = 0; j < b->n; j++)
        if (b->id[j] < b->next_id) where[b->id[j]] = (uint32_t)j;
    int rc = PFSPH_OK;
    for (size_t j = 0; j < n && !rc; j++) {
        if (ids[j] >= b->next_id || where[ids[j]] == UINT32_MAX)
            rc = pfsph_fail(err, PFSPH_EINPUT, "restore: unknown or repeated boundary particle id %u", ids[j]);
        else {
            perm[j] = where[ids[j]];
            where[ids[j]] = UINT32_MAX;
        }
    }
    if (!rc && pfsph_particles_permute(b, perm, n, NULL)) rc = pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory");
    free(where);
    free(perm);
    if (rc) return rc;
    for (int i = 0; i < nbodies; i++) pfsph_bodies_set_state(sim->st.bodies, i, &st[i], b);
    if (pfsph_grid_sort(&sim->bgrid, b, NULL)) return pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory");
    if (!sim->scene.nbodies) pfsph_grid_release_scratch(&sim->bgrid); /* static walls */
    return PFSPH_OK;
}
void pfsph_sim_add_stage_time(pfsph_sim *sim, int stage, double seconds)
{
    if (stage >= 0 && stage < PFSPH_NSTAGES) sim->stage_s[stage] += seconds;
}

void pfsph_sim_get_state(const pfsph_sim *sim, pfsph_sim_state *st)
{
    memset(st, 0, sizeof(*st));
    st->time = sim->st.time;
    st->step = sim->st.step;
    st->amax = sim->st.amax;
    st->amax_np = sim->st.amax_np;
    st->removed = sim->st.removed;
    st->stats = sim->st.stats;
    memcpy(st->stage_s, sim->stage_s, sizeof st->stage_s);
}

void pfsph_sim_diffuse_totals(const pfsph_sim *sim, uint64_t *created, uint64_t *refused)
{
    uint64_t c = 0, r = 0;
    if (sim->st.df) pfsph_diffuse_totals(sim->st.df, &c, &r);
    if (created) *created = c;
    if (refused) *refused = r;
}

int pfsph_sim_restore(pfsph_sim *sim, const pfsph_sim_state *st, const pfsph_particles *fluid,
                      const pfsph_particles *diffuse, uint64_t created, uint64_t refused, pfsph_error *err)
{
    const pfsph_scene *s = &sim->scene;
    for (size_t i = 0; i < fluid->n; i++)
        if (fluid->phase[i] >= s->nphases || s->phases[fluid->phase[i]].kind == PFSPH_PHASE_SOLID)
            return pfsph_fail(err, PFSPH_EINPUT,
                              "restore: fluid particle %zu has phase %d, not a fluid phase of the scene", i,
                              fluid->phase[i]);
    for (size_t i = 0; i < fluid->n; i++)
        if (fluid->bubble[i] > s->film.nbubbles || !(fluid->film[i] >= 0 && fluid->film[i] <= 1) ||
            (fluid->film[i] > 0 && !fluid->bubble[i]))
            return pfsph_fail(err, PFSPH_EINPUT,
                              "restore: fluid particle %zu has bubble %d and film fraction %g; the "
                              "scene has %d bubbles",
                              i, fluid->bubble[i], (double)fluid->film[i], s->film.nbubbles);
    if (sim->st.df && !diffuse)
        return pfsph_fail(err, PFSPH_EINPUT, "restore: the scene has diffuse particles on but the state has none");
    if (!sim->st.df && diffuse && diffuse->n)
        return pfsph_fail(err, PFSPH_EINPUT, "restore: the state has diffuse particles but the scene has diffuse off");
    if (!(st->time >= 0) || !isfinite(st->time)) return pfsph_fail(err, PFSPH_EINPUT, "restore: bad time %g", st->time);
    pfsph_particles *f = &sim->fluid;
    if (fluid->n > f->cap && pfsph_particles_reserve(f, fluid->n) != PFSPH_OK)
        return pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory for %zu fluid particles", fluid->n);
    if (fluid->n > sim->scr_cap && pfsph__sim_alloc_scratch(sim, fluid->n) != PFSPH_OK)
        return pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory for %zu fluid particles", fluid->n);
    if (sim->st.df) {
        int rc = pfsph_diffuse_import(sim->st.df, diffuse, created, refused);
        if (rc == PFSPH_ENOMEM)
            return pfsph_fail(err, rc, "restore: out of memory for %zu diffuse particles", diffuse->n);
        if (rc)
            return pfsph_fail(err, rc,
                              "restore: %zu diffuse particles exceed diffuse.max_particles or carry an unknown type",
                              diffuse->n);
    }
    for (int k = 0; k < PFSPH_NFIELDS; k++)
        if (fluid->n) memcpy(f->f[k], fluid->f[k], fluid->n * sizeof(pfsph_real));
    if (fluid->n) {
        memcpy(f->phase, fluid->phase, fluid->n);
        memcpy(f->bubble, fluid->bubble, fluid->n);
        memcpy(f->id, fluid->id, fluid->n * sizeof(uint32_t));
    }
    f->n = fluid->n;
    f->next_id = fluid->next_id;
    sim->st.time = st->time;
    sim->st.step = st->step;
    sim->st.amax = st->amax;
    sim->st.amax_np = st->amax_np;
    sim->st.removed = st->removed;
    sim->st.stats = st->stats;
    memcpy(sim->stage_s, st->stage_s, sizeof sim->stage_s);
    sim->ctx.time = st->time;
    sim->ctx.step = st->step;
    sim->ctx.dt = st->stats.dt;
    return PFSPH_OK;
}

/* fluid velocities written between steps (the embedding API): the next dt from today's speeds */
void pfsph_sim_velocities_written(pfsph_sim *sim)
{
    size_t worst;
    sim->st.stats.vmax = pfsph__max_speed(&sim->fluid, &worst);
}
