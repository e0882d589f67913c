/* The simulation object: builds particle sets from a scene, and runs the time step as a
 * schedule of stages (core/stage.h), each exported by the module that owns its physics
 * (physics/stages.h). This file builds the schedule and runs the loop: it keeps the clock, times
 * each stage and reports blow-ups, once for all (docs/architecture.md). */
#include "pfsph/sim.h"

#include <math.h>
#include <stdarg.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pfsph/dist.h"
#include "pfsph/surface_detect.h"
#include "physics/boundary.h"
#include "physics/density.h"
#include "physics/eos.h"
#include "physics/stages.h"
#include "physics/viscosity.h"
#include "scene/shapes.h"
#include "sim_internal.h"

static double now(void) { return omp_get_wtime(); }
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static void build_schedule(pfsph_sim *sim);
static int plan_buffers(pfsph_sim *sim);

/* The wall models of the solids (ctx.h): model 0 is the default (no slip, the fluid's
 * viscosity; bodies too), a solid that says otherwise gets the model of its setting, shared
 * with the solids that say the same. */
static void wall_models(pfsph_ctx *c, const pfsph_scene *s, uint8_t *of_solid)
{
    _Static_assert(PFSPH_MAX_SOLIDS + 1 <= PFSPH_MAX_WALLS, "a wall model per solid");
    c->nwalls = 1;
    c->wall_scale[0] = 1;
    c->wall_nu[0] = 0;
    c->wall_nu_max = 0;
    for (int i = 0; i < s->nsolids; i++) {
        const pfsph_solid *o = &s->solids[i];
        pfsph_real a = 1, b = 0;
        if (o->slip == PFSPH_FREE_SLIP) a = 0;
        else if (o->own_viscosity) a = 0, b = (pfsph_real)o->viscosity;
        int w = 0;
        while (w < c->nwalls && !(c->wall_scale[w] == a && c->wall_nu[w] == b)) w++;
        if (w == c->nwalls) {
            c->wall_scale[w] = a;
            c->wall_nu[w] = b;
            c->nwalls++;
            if (b > c->wall_nu_max) c->wall_nu_max = b;
        }
        of_solid[i] = (uint8_t)w;
    }
}

static int build_particles(const pfsph_scene *s, double d, const uint8_t *solid_wall, pfsph_particles *fluid,
                           pfsph_particles *boundary, pfsph_bodies **bodies, pfsph_error *err)
{
    /* Boundary volumes. A wall of two or more layers at the fluid's spacing continues the
     * fluid's lattice, so V_b = V0 gives exactly the rest density next to it. Akinci's
     * V_b = 1 / sum_k W_bk stands in for a missing half-space and suits one layer; on thicker
     * walls it counts the wall up to 1.4x, and PCISPH cannot then settle a 3D tank (4.9%
     * start compression in the corners; diverged at step 1). aux = -1 marks the particles
     * whose Akinci volume is computed once the boundary grid exists. */
    const pfsph_real v0 = (pfsph_real)(s->dim == 2 ? d * d : d * d * d);
    for (int i = 0; i < s->nsolids; i++) {
        size_t first = boundary->n;
        if (pfsph__sample_solid(s, &s->solids[i], d, boundary) < 0)
            return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling solids");
        for (size_t j = first; j < boundary->n; j++) {
            boundary->aux[j] = s->solids[i].layers > 1 ? v0 : -1;
            boundary->wall[j] = solid_wall[i];
        }
    }
    /* bodies after the static solids: their boundary ids follow (pfsph_bodies_first_id) */
    if (s->nbodies) {
        int rc = pfsph_bodies_create(bodies, s, d, boundary, err);
        if (rc) return rc;
    }
    for (int i = 0; i < s->nblocks; i++) {
        size_t first = fluid->n;
        if (pfsph__sample_scene_block(s, i, d, fluid) < 0)
            return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling fluid");
        /* drop fluid particles inside or too close to a solid or a body (their boundary
         * particles sit d/2 inside the surface; one nearer than 0.4 d would start compressed) */
        /* the distances in parallel (a byte per particle while the block is built; minutes on
         * one thread at 1.9e8 particles), the compaction in order */
        const size_t nb = fluid->n - first;
        uint8_t *keep = malloc(nb ? nb : 1);
        if (!keep) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling fluid");
#pragma omp parallel for schedule(static)
        for (size_t j = first; j < fluid->n; j++) {
            double p[3] = {fluid->x[j], fluid->y[j], fluid->z[j]};
            uint8_t k1 = 1;
            for (int k = 0; k < s->nsolids && k1; k++)
                if (pfsph__solid_distance(&s->solids[k], s->dim, (double)d, p) < 0.4 * d) k1 = 0;
            for (int k = 0; k < s->nbodies && k1; k++)
                if (pfsph_bodies_distance(*bodies, k, p) < 0.4 * d) k1 = 0;
            keep[j - first] = k1;
        }
        size_t w = first;
        for (size_t j = first; j < fluid->n; j++) {
            if (!keep[j - first]) continue;
            if (w != j) {
                for (int f = 0; f < PFSPH_NFIELDS; f++) fluid->f[f][w] = fluid->f[f][j];
                fluid->phase[w] = fluid->phase[j];
            }
            fluid->bubble[w] = s->blocks[i].bubble >= 0 ? (uint8_t)(s->blocks[i].bubble + 1) : 0;
            fluid->id[w] = (uint32_t)w;
            w++;
        }
        free(keep);
        fluid->n = w;
        fluid->next_id = (uint32_t)w;
    }
    return PFSPH_OK;
}

/* The step's arrays, in the layout plan_buffers chose; pair_a in ap's arrays when the schedule
 * allows it (no stage between the pair walk and the pairwise stage touches ap). */
int pfsph__sim_alloc_scratch(pfsph_sim *sim, size_t n)
{
    if (!n) n = 1;
    const int w1 = sim->nscr_solver4 ? sim->scr_solver + sim->st.solver->nscratch : 0, w0 = w1 - sim->nscr_solver4;
    for (int k = 0; k < sim->nscr; k++) {
        const size_t m = k >= w0 && k < w1 ? 4 * n : n; /* the solver's packed arrays */
        pfsph_real *q = realloc(sim->scr[k], m * sizeof(pfsph_real));
        if (!q) return PFSPH_ENOMEM;
        memset(q, 0, m * sizeof(pfsph_real));
        sim->scr[k] = q;
    }
    sim->scr_cap = n;
    pfsph_ctx *c = &sim->ctx;
    pfsph_step *st = &sim->st;
    c->ax = sim->scr[SCR_AX];
    c->ay = sim->scr[SCR_AY];
    c->az = sim->scr[SCR_AZ];
    c->nd = sim->scr[SCR_ND];
    for (int a = 0; a < 3; a++) {
        st->ap[a] = sim->scr[SCR_APX + a];
        st->pair_a[a] = sim->scr_pair >= 0 ? sim->scr[sim->scr_pair + a] : st->ap[a];
        st->noise[a] = sim->scr_noise >= 0 ? sim->scr[sim->scr_noise + a] : NULL;
    }
    st->scratch = sim->scr + sim->scr_stage;
    st->solver_scratch = sim->scr + sim->scr_solver;
    return PFSPH_OK;
}

/* Room for n fluid particles: the fluid's arrays (grown by half at least) and the step's. */
static int reserve_fluid(pfsph_step *st, size_t n, pfsph_error *err)
{
    pfsph_sim *sim = st->owner;
    pfsph_particles *f = &sim->fluid;
    if (n > f->cap) {
        size_t cap = f->cap + f->cap / 2;
        if (cap < n) cap = n;
        if (pfsph_particles_reserve(f, cap))
            return pfsph_fail(err, PFSPH_ENOMEM, "out of memory growing the fluid to %zu particles", cap);
    }
    if (f->cap > sim->scr_cap && pfsph__sim_alloc_scratch(sim, f->cap))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory growing the step's scratch to %zu particles", f->cap);
    return PFSPH_OK;
}

/* The fluid sorted outside the step (set-up), in the accelerations' arrays as the grid stage
 * sorts it. */
static int sort_fluid(pfsph_sim *sim)
{
    pfsph_ctx *c = &sim->ctx;
    return pfsph_grid_sort_in(&sim->grid, &sim->fluid, &sim->st.removed, (uint32_t *)c->ax, (uint32_t *)c->ay, c->az);
}

static void auto_sound_speed(pfsph_sim *sim)
{
    const pfsph_scene *s = &sim->scene;
    double g = sqrt(s->gravity[0] * s->gravity[0] + s->gravity[1] * s->gravity[1] + s->gravity[2] * s->gravity[2]);
    double lo = INFINITY, hi = -INFINITY, v2 = 0;
    const pfsph_particles *f = &sim->fluid;
    for (size_t i = 0; i < f->n; i++) {
        /* height along gravity (y when there is none) */
        double hgt =
            g > 0 ? -(f->x[i] * s->gravity[0] + f->y[i] * s->gravity[1] + f->z[i] * s->gravity[2]) / g : f->y[i];
        if (hgt < lo) lo = hgt;
        if (hgt > hi) hi = hgt;
        double w = (double)f->vx[i] * f->vx[i] + (double)f->vy[i] * f->vy[i] + (double)f->vz[i] * f->vz[i];
        if (w > v2) v2 = w;
    }
    double H = f->n ? hi - lo + sim->ctx.spacing : 0;
    double vref = fmax(sqrt(2 * g * H), sqrt(v2));
    /* emitted fluid: its entry speed plus a fall from the nozzle to the domain's lowest corner */
    if (s->nemitters) vref = fmax(vref, pfsph_scene_emitter_speed(s));
    if (vref <= 0) vref = 1; /* no gravity, no motion: assume flows of order 1 m/s */
    sim->sound_speed = s->sound_speed > 0 ? s->sound_speed : 10 * vref;
}

int pfsph_sim_surface_layers(const pfsph_sim *sim, int layers, uint8_t *out)
{
    return pfsph__surface_layers(&sim->ctx, sim->st.film != NULL, layers, out);
}

int pfsph_sim_mechanical_pressure(const pfsph_sim *sim, pfsph_real *out)
{
    if (!sim->st.pw) return PFSPH_EINPUT;
    return pfsph__mechanical_pressure(&sim->st, out);
}

void pfsph_ctx_set_model(pfsph_ctx *c, const pfsph_scene *s)
{
    for (int a = 0; a < 3; a++) {
        c->gravity[a] = s->gravity[a];
        c->domain_min[a] = s->domain_min[a];
        c->domain_max[a] = s->domain_max[a];
    }
    c->seed = s->seed;
    c->interactive = s->mode == PFSPH_MODE_INTERACTIVE;
    c->nphases = s->nphases;
    c->phases = s->phases;
    c->pairwise = &s->pairwise;
    c->diffuse = &s->diffuse;
    c->film = &s->film;
}

/* The viscosity each phase's step applies: the scene's, or with pair forces resolved the Morris
 * viscosity of the viscosity correction (params.h, docs/thermostat.md). */
void pfsph__sim_apply_viscosity(pfsph_ctx *c, const pfsph_scene *s)
{
    for (int p = 0; p < s->nphases; p++)
        c->nu[p] = (pfsph_real)(s->pairwise.enabled && s->pairwise.resolved ? s->pairwise.nu_morris[p]
                                                                            : s->phases[p].viscosity);
}

/* A phase of the set-up is over: tell the caller what it did and how long it took. */
typedef struct setup_clock {
    pfsph_setup_fn note;
    void *user;
    double t, cpu;
} setup_clock;

static void setup_done(setup_clock *k, const char *fmt, ...)
{
    if (!k->note) return;
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    const double t = now(), cpu = cpu_now();
    k->note(msg, t - k->t, cpu - k->cpu, k->user);
    k->t = t;
    k->cpu = cpu;
}

int pfsph_sim_create(pfsph_sim **out, const pfsph_scene *scene, pfsph_error *err)
{
    return pfsph_sim_create_ex(out, scene, NULL, NULL, err);
}

int pfsph_sim_create_ex(pfsph_sim **out, const pfsph_scene *scene, pfsph_setup_fn note, void *user, pfsph_error *err)
{
    setup_clock clk = {note, user, now(), cpu_now()};
    *out = NULL;
    pfsph_sim *sim = calloc(1, sizeof(*sim));
    if (!sim) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    sim->scene = *scene;
    pfsph_scene *s = &sim->scene;
    pfsph_ctx *c = &sim->ctx;
    int rc;
    double d = 2 * s->particle_radius;
    c->dim = s->dim;
    c->spacing = (pfsph_real)d;
    c->h = (pfsph_real)(s->support_factor * d);
    c->V0 = (pfsph_real)(s->dim == 2 ? d * d : d * d * d);
    c->nd0 = (pfsph_real)1 / c->V0;
    pfsph_kernel_init(&c->kern, s->dim, c->h);
    pfsph_ctx_set_model(c, s);
    sim->st.solver = pfsph_solver_find(pfsph_scene_solver_name(s));
    if (!sim->st.solver) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: $.solver.type: no solver called \"%s\"", s->source,
                        pfsph_scene_solver_name(s));
        goto fail;
    }
    sim->st.ctx = c;
    sim->st.owner = sim;
    sim->st.reserve = reserve_fluid;
    sim->st.nlist = &sim->nlist;
    sim->st.nlist_b = &sim->nlist_b;
    sim->st.dt_min = s->dt_min;
    sim->st.dt_max = s->dt_max;
    for (int p = 0; p < s->nphases; p++) sim->st.nu_max = fmax(sim->st.nu_max, s->phases[p].viscosity);
    for (int p = 0; p < s->nphases; p++) {
        c->rest_density[p] = (pfsph_real)s->phases[p].rest_density;
        c->mass[p] = (pfsph_real)(s->phases[p].rest_density * (double)c->V0);
        c->nu[p] = (pfsph_real)s->phases[p].viscosity;
    }
    if (s->pairwise.enabled && (rc = pfsph_pairwise_resolve(s, c->spacing, c->h, err)) != PFSPH_OK) goto fail;
    pfsph__sim_apply_viscosity(c, s);
    /* the viscous step limit: a pair of two fluid phases applies the harmonic mean of their
     * dynamic viscosities over the lighter one's density, up to twice its own nu
     * (viscosity.h); within one phase this is its nu, so single-fluid scenes keep their step */
    for (int a = 0; a < s->nphases; a++)
        for (int b = 0; b < s->nphases; b++)
            if (a != b && s->phases[a].kind != PFSPH_PHASE_SOLID && s->phases[b].kind != PFSPH_PHASE_SOLID)
                sim->st.nu_max = fmax(sim->st.nu_max, (double)pfsph__visc_pair_nu(c, a, b));

    if ((rc = pfsph_particles_init(&sim->fluid, 1024)) || (rc = pfsph_particles_init(&sim->boundary, 1024))) {
        pfsph_fail(err, rc, "out of memory");
        goto fail;
    }
    uint8_t solid_wall[PFSPH_MAX_SOLIDS];
    wall_models(c, s, solid_wall);
    if ((rc = build_particles(s, d, solid_wall, &sim->fluid, &sim->boundary, &sim->st.bodies, err))) goto fail;
    setup_done(&clk, "sampled %zu fluid and %zu boundary particles", sim->fluid.n, sim->boundary.n);
    /* Emitters: the fluid arrays (and below, the step's scratch) are reserved for the most they
     * can add by the scene's end, so that a step never allocates; a longer run (--end) grows
     * them geometrically (st_emit). */
    if (s->nemitters) {
        if ((rc = pfsph__sim_emitters_create(&sim->st.em, s, c, err))) goto fail;
        if ((rc = pfsph_particles_reserve(&sim->fluid, sim->fluid.n + pfsph_emitters_max(sim->st.em, s->end_time))))
            goto nomem;
    }
    c->fluid = &sim->fluid;
    c->boundary = &sim->boundary;

    /* The grid spans the domain and every boundary particle, plus a cell of margin; fluid
     * particles leaving the domain itself are removed. */
    int reach, reach_far;
    pfsph_real cell = pfsph__grid_cell(s, c->h, &reach, &reach_far);
    pfsph_real lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = (pfsph_real)s->domain_min[a];
        hi[a] = (pfsph_real)s->domain_max[a];
    }
    const pfsph_real *bp[3] = {sim->boundary.x, sim->boundary.y, sim->boundary.z};
    for (size_t i = 0; i < sim->boundary.n; i++)
        for (int a = 0; a < s->dim; a++) {
            if (bp[a][i] < lo[a]) lo[a] = bp[a][i];
            if (bp[a][i] > hi[a]) hi[a] = bp[a][i];
        }
    for (int a = 0; a < s->dim; a++) {
        lo[a] -= cell;
        hi[a] += cell;
    }
    if (s->dim == 2) lo[2] = hi[2] = 0;
    if ((rc = pfsph_grid_init(&sim->grid, s->dim, lo, hi, cell)) ||
        (rc = pfsph_grid_init(&sim->bgrid, s->dim, lo, hi, cell))) {
        pfsph_fail(err, rc,
                   "the domain needs too many grid cells (%.3g m cells); enlarge "
                   "particle_radius or shrink the domain",
                   (double)cell);
        goto fail;
    }
    sim->grid.reach = sim->bgrid.reach = reach;
    sim->bgrid.want_near = 1; /* the boundary is sparse: passes skip walks that find no cell */
    sim->grid.reach_far = sim->bgrid.reach_far = reach_far;
    for (int a = 0; a < s->dim; a++) {
        sim->grid.keep_lo[a] = (pfsph_real)s->domain_min[a];
        sim->grid.keep_hi[a] = (pfsph_real)s->domain_max[a];
    }
    c->grid = &sim->grid;
    c->bgrid = &sim->bgrid;
    if ((rc = pfsph_grid_sort(&sim->bgrid, &sim->boundary, NULL))) goto nomem;
    if (!s->nbodies) pfsph_grid_release_scratch(&sim->bgrid); /* static walls: sorted once */
    pfsph__boundary_volumes(&sim->boundary, &sim->bgrid, &c->kern);
    for (size_t i = 0; i < sim->boundary.n; i++)
        sim->boundary.rho[i] = (pfsph_real)s->phases[sim->boundary.phase[i]].rest_density;
    setup_done(&clk, "sorted the boundary into %zu grid cells, its volumes", sim->bgrid.ncells);
    /* neighbour lists or grid walks (the same bits): for the most fluid the run will hold, as
     * the estimate counts it; before the schedule (the interactive PCISPH's lists unfuse it) and
     * the scratch (the solver's depends on it) */
    const double n_most = (double)sim->fluid.n + (sim->st.em ? (double)pfsph_emitters_max(sim->st.em, s->end_time) : 0);
    sim->st.lists = pfsph__sim_lists(s, n_most);
    /* the schedule decides the step's arrays; it needs the model's objects, so until they
     * exist it is planned from the scene (what it will hold), and built at the end */
    build_schedule(sim);
    if ((rc = plan_buffers(sim))) goto fail;
    if ((rc = pfsph__sim_alloc_scratch(sim, sim->st.em ? sim->fluid.cap : sim->fluid.n))) goto nomem;

    auto_sound_speed(sim);
    pfsph_solver_config cfg_, *cfg = &cfg_; /* the solver keeps what it needs */
    memset(cfg, 0, sizeof *cfg);
    cfg->sound_speed = sim->sound_speed;
    cfg->gamma = s->gamma;
    cfg->rho_common = 0;
    cfg->c_fast = sim->sound_speed;
    double rlo, rhi;
    if (s->pressure_scale == PFSPH_PRESSURE_COMMON && pfsph_scene_density_range(s, &rlo, &rhi) && rlo > 0) {
        cfg->rho_common = rhi;
        cfg->c_fast = sim->sound_speed * sqrt(rhi / rlo); /* c^2 = B gamma rho_common / rho0 */
    }
    cfg->settings = s->solver_settings;
    cfg->cfl = s->cfl;
    cfg->lists = sim->st.lists;
    if ((rc = sim->st.solver->create(&sim->st.solver_state, c, cfg, err))) goto fail;
    double g = sqrt(s->gravity[0] * s->gravity[0] + s->gravity[1] * s->gravity[1] + s->gravity[2] * s->gravity[2]);
    sim->st.amax = g;
    sim->st.amax_np = g;
    sim->st.gmag = g;
    size_t worst0;
    sim->st.stats.vmax = pfsph__max_speed(&sim->fluid, &worst0);
    sim->st.vbound = sim->st.solver->speed_bound(sim->st.solver_state, c);

    if (s->film.nbubbles > 0 && sim->fluid.n) {
        if (sort_fluid(sim)) goto nomem;
        if ((rc = pfsph_film_create(&sim->st.film, c, &s->film, s->source, err))) goto fail;
        if (pfsph_film_update(sim->st.film, c) < 0) goto nomem; /* frame 0 carries the film */
    }
    if (s->pairwise.enabled && (rc = pfsph_pairwise_create(&sim->st.pw, c, err))) goto fail;
    if (s->diffuse.enabled && (rc = pfsph_diffuse_create(&sim->st.df, c, err))) goto fail;
    /* The first step's force criterion needs the accelerations the pair forces give: from |g|
     * alone (0 without gravity) PCISPH took dt_max and blew up at step 0 (issue 11). */
    if (sim->st.pw && sim->fluid.n) {
        if (sort_fluid(sim)) goto nomem;
        pfsph__number_density(c, sim->fluid.x, sim->fluid.y, sim->fluid.z, c->nd);
        pfsph__nonpressure(c);
        pfsph_pairwise_apply(sim->st.pw, c);
        double a2 = 0;
        for (size_t i = 0; i < sim->fluid.n; i++)
            a2 = fmax(a2, (double)c->ax[i] * c->ax[i] + (double)c->ay[i] * c->ay[i] + (double)c->az[i] * c->az[i]);
        sim->st.amax = sim->st.amax_np = fmax(g, sqrt(a2));
        if (sim->st.solver->np_cap_without_viscosity) sim->st.amax_np = g + pfsph_pairwise_amax(sim->st.pw);
    }
    build_schedule(sim);
    if ((rc = plan_buffers(sim))) goto fail;
    setup_done(&clk, "the solver's and stages' arrays");
    /* under mpirun the decomposition takes the simulation over (src/mpi/, docs/cluster.md) */
    if (pfsph__dist_process && (rc = pfsph__dist_process->attach(pfsph__dist_process, sim, err))) goto fail;
    *out = sim;
    return PFSPH_OK;
nomem:
    pfsph_fail(err, PFSPH_ENOMEM, "out of memory building the simulation");
fail:
    pfsph_sim_destroy(sim);
    return rc ? rc : PFSPH_ENOMEM;
}

void pfsph_sim_destroy(pfsph_sim *sim)
{
    if (!sim) return;
    for (int k = 0; k < sim->nstages; k++)
        if (sim->stages[k].owned && sim->stages[k].ops->destroy) sim->stages[k].ops->destroy(sim->stages[k].state);
    if (sim->st.solver && sim->st.solver_state) sim->st.solver->destroy(sim->st.solver_state);
    if (sim->st.pw) pfsph_pairwise_destroy(sim->st.pw);
    if (sim->st.df) pfsph_diffuse_destroy(sim->st.df);
    pfsph_film_destroy(sim->st.film);
    pfsph_bodies_destroy(sim->st.bodies);
    pfsph_emitters_destroy(sim->st.em);
    pfsph_particles_free(&sim->fluid);
    pfsph_particles_free(&sim->boundary);
    pfsph_grid_free(&sim->grid);
    pfsph_grid_free(&sim->bgrid);
    pfsph_nlist_free(&sim->nlist);
    pfsph_nlist_free(&sim->nlist_b);
    for (int k = 0; k < SCR_MAX; k++) free(sim->scr[k]);
    free(sim->st.out_layer);
    free(sim->st.out_mech_p);
    free(sim);
}

/* One message format for every blow-up: step, time, stage, what, where, likely cause. */
static int report_blowup(pfsph_sim *sim, const char *stage_name, const pfsph_blowup *b, pfsph_error *err)
{
    const pfsph_particles *f = &sim->fluid;
    const char *hint = b->hint ? b->hint : sim->st.solver->hint(sim->st.solver_state, &sim->ctx);
    size_t i = b->particle;
    if (i < f->n)
        return pfsph_fail(err, PFSPH_EUNSTABLE,
                          "simulation unstable at step %llu, t = %.6g s, stage %s: %s at particle id %u "
                          "(phase '%s', position %.4g %.4g %.4g); likely cause: %s",
                          (unsigned long long)sim->st.step, sim->st.time, stage_name, b->what, f->id[i],
                          sim->scene.phases[f->phase[i]].name, (double)f->x[i], (double)f->y[i], (double)f->z[i], hint);
    return pfsph_fail(err, PFSPH_EUNSTABLE,
                      "simulation unstable at step %llu, t = %.6g s, stage %s: %s; likely cause: %s",
                      (unsigned long long)sim->st.step, sim->st.time, stage_name, b->what, hint);
}

/* ---- the schedule ---- */

/* The step as data: only the stages this scene needs, in order. Before the model's objects
 * exist (sim_create plans the arrays first) the scene says which will. */
static void build_schedule(pfsph_sim *sim)
{
    const pfsph_scene *s = &sim->scene;
    const pfsph_solver_ops *solver = sim->st.solver;
    const bool pw = s->pairwise.enabled, film = s->film.nbubbles > 0 && sim->fluid.n, bodies = s->nbodies > 0,
               df = s->diffuse.enabled, em = s->nemitters > 0;
    /* the density in the pair walk (one k h walk instead of an h walk and a k h walk) */
    const bool fused = pw && !solver->neighbour_lists && !solver->pre_forces && !sim->st.lists;
    /* the same for the interactive PCISPH, whose lists (within h) the pair walk also fills */
    const bool fused_lists = pw && !solver->neighbour_lists && !solver->pre_forces && sim->st.lists;
    int n = 0;
#define ADD(stage) sim->stages[n++] = (pfsph__sched){&(stage), NULL, 0}
    ADD(pfsph_stage_grid);
    if (pw) ADD(pfsph_stage_shift);
    if (film) ADD(pfsph_stage_film);
    if (fused) ADD(pfsph_stage_pair_density);
    else if (fused_lists) ADD(pfsph_stage_pair_density_lists);
    else ADD(pfsph_stage_density);
    ADD(pfsph_stage_timestep);
    if (solver->pre_forces) ADD(pfsph_stage_divergence);
    /* a solver with an equation of state: its pressure in the forces' walk (not with pair forces:
     * their stage sits between the two and reads last step's pressure) */
    const bool eos = solver->eos && !pw;
    if (eos) ADD(pfsph_stage_forces_eos);
    else ADD(pfsph_stage_forces);
    if (fused || fused_lists) ADD(pfsph_stage_pairwise_add);
    else if (pw) ADD(pfsph_stage_pairwise);
    if (eos) ADD(pfsph_stage_pressure_report);
    else ADD(pfsph_stage_pressure);
    if (bodies) ADD(pfsph_stage_body_forces);
    ADD(pfsph_stage_integrate);
    if (df) ADD(pfsph_stage_diffuse);
    if (bodies) ADD(pfsph_stage_bodies);
    if (em) ADD(pfsph_stage_emit);
#undef ADD
    sim->nstages = n;
    sim->nout = 0;
    if (sim->scene.output.surface_layer)
        sim->out_stages[sim->nout++] = (pfsph__sched){&pfsph_stage_surface_layers, NULL, 0};
    if (pw) sim->out_stages[sim->nout++] = (pfsph__sched){&pfsph_stage_mechanical_pressure, NULL, 0};
}

/* The step's arrays for this schedule: the stages' shared scratch (the most one stage asks),
 * the thermostat's, and pair_a's own arrays only when a stage between the pair walk and the
 * pairwise stage reads or writes ap (else they live in ap's arrays: an explicit hand-over,
 * checked here). The solver's: in the shared scratch when they hold nothing from one call to
 * the next, or (without lists, walk_nscratch) when no stage between the solver's first and last
 * asks for scratch (checked here too); else arrays of their own. Reallocates (zeroed) when the
 * layout changes. */
static int plan_buffers(pfsph_sim *sim)
{
    const pfsph_scene *s = &sim->scene;
    int nstage = 0, pair_own = 0, from = -1, solver_first = -1, solver_last = -1;
    for (int k = 0; k < sim->nstages; k++) {
        const pfsph_stage_ops *o = sim->stages[k].ops;
        if (o->nscratch > nstage) nstage = o->nscratch;
        if (from >= 0 && (o->reads & PFSPH_D_PAIR_ACC)) from = -1; /* handed over */
        if (from >= 0 && ((o->reads | o->writes) & PFSPH_D_AP)) pair_own = 1;
        if (o->writes & PFSPH_D_PAIR_ACC) from = k;
        if (o->writes & PFSPH_D_SOLVER) {
            if (solver_first < 0) solver_first = k;
            solver_last = k;
        }
    }
    const int thermo = s->pairwise.enabled && s->pairwise.thermo.enabled;
    const pfsph_solver_ops *so = sim->st.solver;
    const int walk = so->walk_nscratch > 0 && !sim->st.lists;
    int kept_free = 1; /* no stage between the solver's first and last asks for scratch */
    for (int k = solver_first + 1; k < solver_last; k++)
        if (sim->stages[k].ops->nscratch) kept_free = 0;
    const int nsolver = walk ? so->walk_nscratch : so->nscratch, nsolver4 = walk ? 0 : so->nscratch4;
    const int shared = walk ? kept_free : so->scratch_per_call && !so->nscratch4; /* in the stages' scratch */
    if (shared && nsolver > nstage) nstage = nsolver;
    int stage0 = SCR_COMMON, noise0 = stage0 + nstage, pair0 = noise0 + (thermo ? 3 : 0),
        solver0 = shared ? stage0 : pair0 + (pair_own ? 3 : 0),
        total = shared ? pair0 + (pair_own ? 3 : 0) : solver0 + nsolver;
    if (total > SCR_MAX) return PFSPH_ENOMEM;
    const int same = sim->nscr == total && sim->scr_stage == stage0 && sim->nscr_stage == nstage &&
        sim->scr_noise == (thermo ? noise0 : -1) && sim->scr_pair == (pair_own ? pair0 : -1) &&
        sim->scr_solver == solver0 && sim->nscr_solver4 == nsolver4;
    if (same) return PFSPH_OK;
    for (int k = total; k < SCR_MAX; k++) {
        free(sim->scr[k]);
        sim->scr[k] = NULL;
    }
    sim->nscr = total;
    sim->scr_stage = stage0;
    sim->nscr_stage = nstage;
    sim->scr_noise = thermo ? noise0 : -1;
    sim->scr_pair = pair_own ? pair0 : -1;
    sim->scr_solver = solver0;
    sim->nscr_solver4 = nsolver4;
    return sim->scr_cap ? pfsph__sim_alloc_scratch(sim, sim->scr_cap) : PFSPH_OK;
}

int pfsph_sim_insert_stage(pfsph_sim *sim, const char *anchor, int after, const pfsph_stage_ops *stage, void *state,
                           pfsph_error *err)
{
    if (!stage || !stage->name || !stage->run)
        return pfsph_fail(err, PFSPH_EINPUT, "insert stage: a stage needs a name and a run function");
    if (stage->slot < 0 || stage->slot >= PFSPH_NSTAGES)
        return pfsph_fail(err, PFSPH_EINPUT, "insert stage \"%s\": timing slot %d out of range", stage->name,
                          stage->slot);
    if (sim->nstages >= MAX_STAGES)
        return pfsph_fail(err, PFSPH_EINPUT, "insert stage \"%s\": the schedule holds at most %d stages", stage->name,
                          MAX_STAGES);
    int at = -1;
    for (int k = 0; k < sim->nstages; k++) {
        if (!strcmp(sim->stages[k].ops->name, stage->name))
            return pfsph_fail(err, PFSPH_EINPUT, "insert stage: the schedule already has a stage \"%s\"", stage->name);
        if (anchor && !strcmp(sim->stages[k].ops->name, anchor)) at = after ? k + 1 : k;
    }
    if (at < 0)
        return pfsph_fail(err, PFSPH_EINPUT, "insert stage \"%s\": no stage \"%s\" in the schedule", stage->name,
                          anchor ? anchor : "(null)");
    int owned = 0;
    if (stage->create) {
        int rc = stage->create(&state, &sim->st, err);
        if (rc) return rc;
        owned = 1;
    }
    memmove(&sim->stages[at + 1], &sim->stages[at], (size_t)(sim->nstages - at) * sizeof sim->stages[0]);
    sim->stages[at] = (pfsph__sched){stage, state, owned};
    sim->nstages++;
    int rc = plan_buffers(sim);
    return rc ? pfsph_fail(err, rc, "insert stage \"%s\": out of memory for its scratch", stage->name) : PFSPH_OK;
}

int pfsph_sim_stage_count(const pfsph_sim *sim) { return sim->nstages; }

const char *pfsph_sim_stage_name(const pfsph_sim *sim, int i)
{
    return i >= 0 && i < sim->nstages ? sim->stages[i].ops->name : NULL;
}

pfsph_step *pfsph_sim_step_state(pfsph_sim *sim) { return &sim->st; }

/* ---- the loop ---- */

int pfsph_sim_step(pfsph_sim *sim, double t_limit, pfsph_error *err)
{
    sim->st.t_limit = t_limit;
    pfsph_dist *dist = sim->ctx.dist;
    if (dist) dist->step_begin(dist, t_limit);
    double t0 = now(), c0 = cpu_now();
    for (int k = 0; k < sim->nstages; k++) {
        const pfsph__sched *e = &sim->stages[k];
        pfsph_blowup bad = {SIZE_MAX, "", NULL};
        int rc = e->ops->run(e->state, &sim->st, &bad, err);
        /* the lists hold for the positions and the order they were built on */
        if (e->ops->writes & (PFSPH_D_POS | PFSPH_D_ORDER)) sim->ctx.nlist = sim->ctx.nlist_b = NULL;
        double t1 = now(), c1 = cpu_now();
        sim->stage_s[e->ops->slot] += t1 - t0;
        sim->stage_cpu[e->ops->slot] += c1 - c0;
        t0 = t1;
        c0 = c1;
        if (rc == PFSPH_EUNSTABLE && bad.what[0]) rc = report_blowup(sim, e->ops->name, &bad, err);
        if (dist) rc = dist->agree(dist, rc, err); /* every rank stops, with the one message */
        if (rc) return rc;
    }
    sim->st.time += sim->ctx.dt;
    sim->st.step++;
    return PFSPH_OK;
}

int pfsph_sim_advance(pfsph_sim *sim, double t, pfsph_error *err)
{
    /* tolerance: frame times are sums of doubles */
    while (sim->st.time < t - 1e-12 * fmax(1.0, fabs(t))) {
        int rc = pfsph_sim_step(sim, t, err);
        if (rc) return rc;
    }
    sim->st.time = fmax(sim->st.time, t);
    /* a distributed run: the root gathers the fluid for the frame and the checkpoint */
    return sim->ctx.dist ? sim->ctx.dist->frame(sim->ctx.dist, err) : PFSPH_OK;
}

/* Frame 0's densities and pressures (issue 14): the grid sort and density summation a step
 * begins with, and the Tait pressure of that density (the iterative solvers' own pressures need a
 * step). Sorting an unsorted set here or in the first step gives the same order. */
void pfsph_sim_prime_output(pfsph_sim *sim)
{
    pfsph_blowup bad;
    pfsph_error err;
    const pfsph_scene *s = &sim->scene;
    pfsph_stage_grid.run(NULL, &sim->st, &bad, &err);
    sim->ctx.nlist = sim->ctx.nlist_b = NULL;
    pfsph_stage_density.run(NULL, &sim->st, &bad, &err); /* a blow-up is the first step's to report */
    double rlo, rhi, rho_common = 0;
    if (s->pressure_scale == PFSPH_PRESSURE_COMMON && pfsph_scene_density_range(s, &rlo, &rhi) && rlo > 0)
        rho_common = rhi;
    pfsph__tait(&sim->ctx, sim->ctx.nd, sim->sound_speed * sim->sound_speed / s->gamma, s->gamma, rho_common,
                sim->fluid.p);
}

/* The frame-derived fields, by the output stages, into buffers the writer reads. */
int pfsph_sim_output(pfsph_sim *sim, pfsph_error *err)
{
    const size_t n = sim->fluid.n ? sim->fluid.n : 1;
    if (n > sim->out_cap) {
        const bool lay = sim->scene.output.surface_layer;
        uint8_t *l = lay ? realloc(sim->st.out_layer, n) : sim->st.out_layer;
        if (l) sim->st.out_layer = l;
        pfsph_real *m = sim->st.pw ? realloc(sim->st.out_mech_p, n * sizeof(pfsph_real)) : sim->st.out_mech_p;
        if (m) sim->st.out_mech_p = m;
        if ((lay && !l) || (sim->st.pw && !m))
            return pfsph_fail(err, PFSPH_ENOMEM, "out of memory for a frame's fields");
        sim->out_cap = n;
    }
    for (int k = 0; k < sim->nout; k++) {
        pfsph_blowup bad = {SIZE_MAX, "", NULL};
        int rc = sim->out_stages[k].ops->run(sim->out_stages[k].state, &sim->st, &bad, err);
        if (rc) return rc;
    }
    return PFSPH_OK;
}

const uint8_t *pfsph_sim_output_surface_layer(const pfsph_sim *sim) { return sim->st.out_layer; }
const pfsph_real *pfsph_sim_output_mechanical_pressure(const pfsph_sim *sim)
{
    return sim->st.pw ? sim->st.out_mech_p : NULL;
}
