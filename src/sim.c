/* The simulation object: builds particle sets from a scene and runs the time step as a table
 * of stages (grid -> density -> time step -> [divergence] -> non-pressure forces -> pair forces
 * -> pressure -> body forces -> integrate -> diffuse -> bodies). Stages live in src/physics and
 * the pressure solvers behind src/physics/solver.h; this file orders them, keeps the clock,
 * times each stage and reports blow-ups, once for all (docs/architecture.md). */
#include "pfsph/sim.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/reduce.h"
#include "pfsph/bodies.h"
#include "pfsph/diffuse.h"
#include "pfsph/emitter.h"
#include "pfsph/film.h"
#include "pfsph/surface_detect.h"
#include "pfsph/pairwise.h"
#include "pfsph/thermostat.h"
#include "physics/boundary.h"
#include "core/nlist.h"
#include "physics/density.h"
#include "physics/eos.h"
#include "physics/solver.h"
#include "physics/viscosity.h"
#include "scene/shapes.h"

const char *const pfsph_stage_names[PFSPH_NSTAGES] = {"grid",      "density", "forces", "pairwise", "pressure",
                                                      "integrate", "diffuse", "bodies", "film",     "output"};

/* per-step scratch of the step itself, one value per fluid particle; the solver's follow */
enum { SCR_AX, SCR_AY, SCR_AZ, SCR_ND, SCR_APX, SCR_APY, SCR_APZ, SCR_EK, SCR_COMMON };
#define SCR_MAX (SCR_COMMON + 17) /* + the solver's (at most 14) + the thermostat's 3 */

/* What a stage that found a blow-up reports; the step turns it into the one message format. */
typedef struct blowup_info {
    size_t particle;  /* fluid index, or SIZE_MAX when no particle is to blame */
    char what[256];   /* "speed [m/s] 12.3" */
    const char *hint; /* likely cause; NULL: the solver's */
} blowup_info;

typedef struct stage {
    const char *name; /* in blow-up messages */
    int slot;         /* enum pfsph_stage: where its time is counted */
    int (*run)(pfsph_sim *sim, blowup_info *bad, pfsph_error *err);
} stage;
#define MAX_STAGES 16

struct pfsph_sim {
    pfsph_scene scene;
    pfsph_ctx ctx;
    pfsph_particles fluid, boundary;
    pfsph_grid grid, bgrid;
    pfsph_nlist nlist, nlist_b; /* fluid and boundary neighbours, built each step when the
                                 * solver asks (neighbour_lists) */
    pfsph_real *scr[SCR_MAX];   /* per-step scratch: SCR_COMMON of ours, then the solver's */
    int nscr;
    int scr_noise;  /* first of the thermostat's 3 arrays (its accelerations), or -1 */
    size_t scr_cap; /* entries in each scratch array */
    const pfsph_solver_ops *solver;
    void *solver_state;
    double sound_speed;
    double amax;           /* largest acceleration of the last step */
    double amax_np;        /* largest non-pressure acceleration of the last step (or the solver's
                             * bound without viscosity: np_cap_without_viscosity) */
    double gmag;           /* |gravity| */
    double vbound;         /* speeds above this are a blow-up */
    double t_limit;        /* the step in progress never passes this time */
    size_t removed_before; /* removed count before this step's sort */
    pfsph_pairwise *pw;
    pfsph_diffuse *df;
    pfsph_film *film; /* bubbles in air, or NULL */
    pfsph_bodies *bodies;
    pfsph_emitters *em; /* NULL: the scene has no emitter */
    stage stages[MAX_STAGES];
    int nstages;
    double time;
    uint64_t step;
    size_t removed;
    pfsph_step_stats stats;
    double stage_s[PFSPH_NSTAGES];
    double stage_cpu[PFSPH_NSTAGES]; /* process CPU time per slot (benchmarks on a loaded machine) */
};

/* compression (rho / rho0 - 1) that stops a run as unstable */
#define PFSPH_DENSITY_ERROR_LIMIT 0.5

static double now(void) { return omp_get_wtime(); }
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static double max_speed(const pfsph_particles *f, size_t *worst);
static void build_stages(pfsph_sim *sim);

/* Grid cells. Without pair forces cells of h, queries one cell each way. With them cells of
 * max(h, k h / 3): for k <= 3 the h-radius stages walk what plain SPH walks and the pair forces
 * ceil(k) cells each way. Cells of k h made the h stages walk (3 k h)^3 (2.6x the candidates);
 * cells of h / 2 made them walk 25 short rows instead of 9 (docs/benchmarks.md, pairwise). */
static pfsph_real grid_cell(const pfsph_scene *s, pfsph_real h, int *reach, int *reach_far)
{
    if (!s->pairwise.enabled) {
        *reach = *reach_far = 1;
        return h;
    }
    pfsph_real R = pfsph_pairwise_radius(s, h);
    pfsph_real cell = h > R / 3 ? h : R / 3;
    *reach = (int)ceil((double)h / (double)cell - 1e-6);
    *reach_far = (int)ceil((double)R / (double)cell - 1e-6);
    if (*reach < 1) *reach = 1;
    if (*reach_far < *reach) *reach_far = *reach;
    /* shifting moves particles after the sort: h queries need room beyond h (pairwise.h) */
    if (s->pairwise.shift.D > 0 || s->pairwise.shift.A > 0) *reach = *reach_far;
    return cell;
}

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
        size_t w = first;
        for (size_t j = first; j < fluid->n; j++) {
            double p[3] = {fluid->x[j], fluid->y[j], fluid->z[j]};
            int keep = 1;
            for (int k = 0; k < s->nsolids && keep; k++)
                if (pfsph__solid_distance(&s->solids[k], s->dim, (double)d, p) < 0.4 * d) keep = 0;
            for (int k = 0; k < s->nbodies && keep; k++)
                if (pfsph_bodies_distance(*bodies, k, p) < 0.4 * d) keep = 0;
            if (!keep) continue;
            if (w != j) {
                for (int f = 0; f < PFSPH_NFIELDS; f++) fluid->f[f][w] = fluid->f[f][j];
                fluid->phase[w] = fluid->phase[j];
            }
            fluid->bubble[w] = s->blocks[i].bubble >= 0 ? (uint8_t)(s->blocks[i].bubble + 1) : 0;
            fluid->id[w] = (uint32_t)w;
            w++;
        }
        fluid->n = w;
        fluid->next_id = (uint32_t)w;
    }
    return PFSPH_OK;
}

/* Nozzle exit points closer than 0.4 d to a static solid are left out, as fluid block sites are
 * (build_particles): a particle there would start half a spacing into the wall's particles. */
typedef struct site_filter {
    const pfsph_scene *s;
    double d;
} site_filter;

static bool keep_site(const double x[3], void *user)
{
    const site_filter *f = user;
    for (int k = 0; k < f->s->nsolids; k++)
        if (pfsph__solid_distance(&f->s->solids[k], f->s->dim, f->d, x) < 0.4 * f->d) return false;
    return true;
}

static int emitters_create(pfsph_emitters **em, const pfsph_scene *s, const pfsph_ctx *c, pfsph_error *err)
{
    site_filter sf = {s, 2 * s->particle_radius};
    return pfsph_emitters_create(em, s->emitters, s->nemitters, c, keep_site, &sf, s->source, err);
}

/* A context with what emitters read (lattice, domain, phases), for the estimate. */
static void emitter_ctx(const pfsph_scene *s, pfsph_ctx *c)
{
    memset(c, 0, sizeof *c);
    double d = 2 * s->particle_radius;
    c->dim = s->dim;
    c->spacing = (pfsph_real)d;
    c->V0 = (pfsph_real)(s->dim == 2 ? d * d : d * d * d);
    pfsph_ctx_set_model(c, s);
    for (int p = 0; p < s->nphases; p++) c->rest_density[p] = (pfsph_real)s->phases[p].rest_density;
}

int pfsph_scene_emitted_max(const pfsph_scene *s, double t, size_t *n, pfsph_error *err)
{
    *n = 0;
    if (!s->nemitters) return PFSPH_OK;
    pfsph_ctx c;
    emitter_ctx(s, &c);
    pfsph_emitters *em = NULL;
    int rc = emitters_create(&em, s, &c, err);
    if (rc) return rc;
    *n = pfsph_emitters_max(em, t);
    pfsph_emitters_destroy(em);
    return PFSPH_OK;
}

int pfsph_scene_emitters_info(const pfsph_scene *s, pfsph_emitter_info *info, pfsph_error *err)
{
    if (!s->nemitters) return PFSPH_OK;
    pfsph_ctx c;
    emitter_ctx(s, &c);
    pfsph_emitters *em = NULL;
    int rc = emitters_create(&em, s, &c, err);
    if (rc) return rc;
    for (int i = 0; i < s->nemitters; i++) pfsph_emitters_info(em, i, &info[i]);
    pfsph_emitters_destroy(em);
    return PFSPH_OK;
}

double pfsph_scene_emitter_speed(const pfsph_scene *s)
{
    pfsph_emitter_info info[PFSPH_MAX_EMITTERS];
    pfsph_error err;
    if (!s->nemitters || pfsph_scene_emitters_info(s, info, &err)) return 0;
    const double g =
        sqrt(s->gravity[0] * s->gravity[0] + s->gravity[1] * s->gravity[1] + s->gravity[2] * s->gravity[2]);
    double v = 0;
    for (int i = 0; i < s->nemitters; i++) {
        const double *c = s->emitters[i].center;
        double drop = 0;
        if (g > 0)
            for (int k = 0; k < (1 << s->dim); k++) { /* the domain's corners */
                double dh = 0;
                for (int a = 0; a < s->dim; a++) {
                    double corner = (k >> a) & 1 ? s->domain_max[a] : s->domain_min[a];
                    dh += (corner - c[a]) * s->gravity[a] / g;
                }
                drop = fmax(drop, dh);
            }
        v = fmax(v, sqrt(info[i].speed * info[i].speed + 2 * g * drop));
    }
    return v;
}

int pfsph_scene_estimate(const pfsph_scene *s, size_t *n_fluid, size_t *n_boundary, size_t *bytes, pfsph_error *err)
{
    double d = 2 * s->particle_radius;
    long nf = 0, nb = 0;
    for (int i = 0; i < s->nblocks; i++) {
        long c = pfsph__sample_scene_block(s, i, d, NULL);
        if (c < 0) return pfsph_fail(err, PFSPH_EINPUT, "cannot sample block %d", i);
        nf += c;
    }
    long nf_max = nf;
    for (int i = 0; i < s->nsolids; i++) {
        long c = pfsph__sample_solid(s, &s->solids[i], d, NULL);
        if (c < 0) return pfsph_fail(err, PFSPH_EINPUT, "cannot sample solid %d", i);
        nb += c;
    }
    if (s->nbodies) {
        /* bodies are sampled for real: this also reads and checks their mesh files, so that
         * `pfsph check` reports a bad OBJ file */
        pfsph_particles tmp;
        pfsph_bodies *B = NULL;
        if (pfsph_particles_init(&tmp, 1024)) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
        int rc = pfsph_bodies_create(&B, s, d, &tmp, err);
        nb += (long)tmp.n;
        pfsph_bodies_destroy(B);
        pfsph_particles_free(&tmp);
        if (rc) return rc;
    }
    /* emitters: the most they can have added by the scene's end (the arrays are reserved for it) */
    if (s->nemitters) {
        size_t ne = 0;
        int rc = pfsph_scene_emitted_max(s, s->end_time, &ne, err);
        if (rc) return rc;
        nf_max += (long)ne;
    }
    pfsph_real h = (pfsph_real)(s->support_factor * d);
    int r1, r2;
    double cell = grid_cell(s, h, &r1, &r2);
    double cells = 1;
    for (int a = 0; a < s->dim; a++) cells *= ceil((s->domain_max[a] - s->domain_min[a]) / cell + 8);
    /* Per particle: its set at up to twice its size (the arrays grow by doubling), the grid's
     * sort scratch (key, perm, tmp; 1.25x), and for fluid the step scratch (checkpoints and the
     * last good frame go to disk through a small buffer, docs/checkpoints.md). Measured:
     * tests/unit/test_estimate.c. In double: the estimate may exceed size_t, so it saturates. */
    const double P = (double)pfsph_particles_bytes_per_particle();
    const double sort = 1.25 * (2 * sizeof(uint32_t) + sizeof(pfsph_real));
    const pfsph_solver_ops *ops = pfsph_solver_find(pfsph_scene_solver_name(s));
    const int nthermo = s->pairwise.enabled && s->pairwise.thermo.enabled ? 3 : 0;
    /* neighbour lists: a full neighbourhood within h (pi q^2 in 2D, 4/3 pi q^3 in 3D, q = h / d)
     * and a quarter more for compression near walls and in splashes; boundary lists: half a
     * neighbourhood for every fluid particle (a particle on a wall has about half) */
    const double q = s->support_factor, full = s->dim == 2 ? 3.14159 * q * q : 4.18879 * q * q * q;
    const double nlist = ops && ops->neighbour_lists
        ? pfsph_nlist_bytes_per_particle(1.25 * full, 1) + pfsph_nlist_bytes_per_particle(0.5 * full, 1)
        : 0;
    const int nscr = SCR_COMMON + (ops ? ops->nscratch + 3 * ops->nscratch4 : 0) + nthermo; /* packed: 4 each */
    const double per_fluid = 2 * P + nscr * sizeof(pfsph_real) + sort + nlist;
    const double per_boundary = 2 * P + sort;
    const double grid_bytes = 2 * (cells + 1) * sizeof(uint32_t); /* fluid and boundary grids */
    const double part_bytes = (double)nf_max * per_fluid + (double)nb * per_boundary;
    if (n_fluid) *n_fluid = (size_t)nf;
    if (n_boundary) *n_boundary = (size_t)nb;
    if (bytes) *bytes = part_bytes + grid_bytes >= (double)SIZE_MAX ? SIZE_MAX : (size_t)(part_bytes + grid_bytes);
    if (nf_max + nb > (long)UINT32_MAX)
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: the scene makes %ld particles (%ld fluid), more than the %u one run "
                          "can index; enlarge particle_radius or shrink the fluid",
                          s->source, nf_max + nb, nf_max, UINT32_MAX);
    /* a grid the program cannot index, or one that dwarfs the particles: the domain is to blame */
    if (cells > (double)((size_t)1 << 31) || (grid_bytes > (double)(1u << 30) && grid_bytes > 16 * part_bytes))
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: $.domain: the neighbour grids over the domain need %.3g cells of "
                          "%.3g m (%.3g GiB) for %ld particles; shrink $.domain to where the fluid can go (a grid "
                          "holds at most 2^31 cells, and at most 16x the particles' memory above 1 GiB)",
                          s->source, cells, cell, grid_bytes / 1073741824.0, nf + nb);
    return PFSPH_OK;
}

static int alloc_scratch(pfsph_sim *sim, size_t n)
{
    if (!n) n = 1;
    const int w0 = SCR_COMMON + sim->solver->nscratch - sim->solver->nscratch4, w1 = SCR_COMMON + sim->solver->nscratch;
    for (int k = 0; k < sim->nscr; k++) {
        const size_t m = k >= w0 && k < w1 ? 4 * n : n; /* the solver's packed arrays */
        pfsph_real *q = realloc(sim->scr[k], m * sizeof(pfsph_real));
        if (!q) return PFSPH_ENOMEM;
        memset(q, 0, m * sizeof(pfsph_real));
        sim->scr[k] = q;
    }
    sim->scr_cap = n;
    pfsph_ctx *c = &sim->ctx;
    c->ax = sim->scr[SCR_AX];
    c->ay = sim->scr[SCR_AY];
    c->az = sim->scr[SCR_AZ];
    c->nd = sim->scr[SCR_ND];
    return PFSPH_OK;
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
    const size_t n = sim->fluid.n;
    uint8_t *work = layers > 1 ? malloc(n ? n : 1) : NULL;
    if (layers > 1 && !work) return PFSPH_ENOMEM;
    /* particles moved since the step's sort by at most a step's travel: one cell more each way
     * keeps every neighbour within the radius in the ranges walked */
    int reach = sim->grid.reach + 1;
    pfsph_surface_opts o = {.radius = 0,
                            .layers = layers,
                            .group = sim->film ? sim->fluid.bubble : NULL,
                            .boundary = true,
                            .reach = reach > 3 ? 3 : reach};
    pfsph_surface_detect(&sim->ctx, &o, out, work);
    free(work);
    return PFSPH_OK;
}

int pfsph_sim_mechanical_pressure(const pfsph_sim *sim, pfsph_real *out)
{
    if (!sim->pw) return PFSPH_EINPUT;
    double *vir = malloc((sim->fluid.n ? sim->fluid.n : 1) * sizeof(double));
    if (!vir) return PFSPH_ENOMEM;
    /* the pressure the solver pushed with: DFSPH's divergence solve pushes too (its wall_pressure);
     * with its density pressure alone the interior of a 3D drop read -15 Pa for +133 Pa */
    const pfsph_real *p = sim->solver->wall_pressure && sim->fluid.n
        ? sim->solver->wall_pressure(sim->solver_state, &sim->ctx, sim->scr + SCR_COMMON)
        : NULL;
    pfsph_pairwise_mechanical_pressure(sim->pw, &sim->ctx, p, vir, out);
    free(vir);
    return PFSPH_OK;
}

void pfsph_ctx_set_model(pfsph_ctx *c, const pfsph_scene *s)
{
    for (int a = 0; a < 3; a++) {
        c->gravity[a] = s->gravity[a];
        c->domain_min[a] = s->domain_min[a];
        c->domain_max[a] = s->domain_max[a];
    }
    c->seed = s->seed;
    c->nphases = s->nphases;
    c->phases = s->phases;
    c->pairwise = &s->pairwise;
    c->diffuse = &s->diffuse;
    c->film = &s->film;
}

/* The viscosity each phase's step applies: the scene's, or with pair forces resolved the Morris
 * viscosity of the viscosity correction (params.h, docs/thermostat.md). */
static void apply_viscosity(pfsph_ctx *c, const pfsph_scene *s)
{
    for (int p = 0; p < s->nphases; p++)
        c->nu[p] = (pfsph_real)(s->pairwise.enabled && s->pairwise.resolved ? s->pairwise.nu_morris[p]
                                                                            : s->phases[p].viscosity);
}

int pfsph_sim_create(pfsph_sim **out, const pfsph_scene *scene, pfsph_error *err)
{
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
    sim->solver = pfsph_solver_find(pfsph_scene_solver_name(s));
    if (!sim->solver) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: $.solver.type: no solver called \"%s\"", s->source,
                        pfsph_scene_solver_name(s));
        goto fail;
    }
    sim->nscr = SCR_COMMON + sim->solver->nscratch;
    sim->scr_noise = -1;
    if (s->pairwise.enabled && s->pairwise.thermo.enabled) {
        sim->scr_noise = sim->nscr;
        sim->nscr += 3;
    }
    if (sim->nscr > SCR_MAX) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "solver %s needs %d scratch arrays, at most %d", sim->solver->name,
                        sim->solver->nscratch, SCR_MAX - SCR_COMMON);
        goto fail;
    }
    for (int p = 0; p < s->nphases; p++) {
        c->rest_density[p] = (pfsph_real)s->phases[p].rest_density;
        c->mass[p] = (pfsph_real)(s->phases[p].rest_density * (double)c->V0);
        c->nu[p] = (pfsph_real)s->phases[p].viscosity;
    }
    if (s->pairwise.enabled && (rc = pfsph_pairwise_resolve(s, c->spacing, c->h, err)) != PFSPH_OK) goto fail;
    apply_viscosity(c, s);

    if ((rc = pfsph_particles_init(&sim->fluid, 1024)) || (rc = pfsph_particles_init(&sim->boundary, 1024))) {
        pfsph_fail(err, rc, "out of memory");
        goto fail;
    }
    uint8_t solid_wall[PFSPH_MAX_SOLIDS];
    wall_models(c, s, solid_wall);
    if ((rc = build_particles(s, d, solid_wall, &sim->fluid, &sim->boundary, &sim->bodies, err))) goto fail;
    /* Emitters: the fluid arrays (and below, the step's scratch) are reserved for the most they
     * can add by the scene's end, so that a step never allocates; a longer run (--end) grows
     * them geometrically (st_emit). */
    if (s->nemitters) {
        if ((rc = emitters_create(&sim->em, s, c, err))) goto fail;
        if ((rc = pfsph_particles_reserve(&sim->fluid, sim->fluid.n + pfsph_emitters_max(sim->em, s->end_time))))
            goto nomem;
    }
    c->fluid = &sim->fluid;
    c->boundary = &sim->boundary;

    /* The grid spans the domain and every boundary particle, plus a cell of margin; fluid
     * particles leaving the domain itself are removed. */
    int reach, reach_far;
    pfsph_real cell = grid_cell(s, c->h, &reach, &reach_far);
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
    pfsph__boundary_volumes(&sim->boundary, &sim->bgrid, &c->kern);
    for (size_t i = 0; i < sim->boundary.n; i++)
        sim->boundary.rho[i] = (pfsph_real)s->phases[sim->boundary.phase[i]].rest_density;
    if ((rc = alloc_scratch(sim, sim->em ? sim->fluid.cap : sim->fluid.n))) goto nomem;

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
    if ((rc = sim->solver->create(&sim->solver_state, c, cfg, err))) goto fail;
    double g = sqrt(s->gravity[0] * s->gravity[0] + s->gravity[1] * s->gravity[1] + s->gravity[2] * s->gravity[2]);
    sim->amax = g;
    sim->amax_np = g;
    sim->gmag = g;
    size_t worst0;
    sim->stats.vmax = max_speed(&sim->fluid, &worst0);
    sim->vbound = sim->solver->speed_bound(sim->solver_state, c);

    if (s->film.nbubbles > 0 && sim->fluid.n) {
        if (pfsph_grid_sort(&sim->grid, &sim->fluid, &sim->removed)) goto nomem;
        if ((rc = pfsph_film_create(&sim->film, c, &s->film, s->source, err))) goto fail;
        if (pfsph_film_update(sim->film, c) < 0) goto nomem; /* frame 0 carries the film */
    }
    if (s->pairwise.enabled && (rc = pfsph_pairwise_create(&sim->pw, c, err))) goto fail;
    if (s->diffuse.enabled && (rc = pfsph_diffuse_create(&sim->df, c, err))) goto fail;
    /* The first step's force criterion needs the accelerations the pair forces give: from |g|
     * alone (0 without gravity) PCISPH took dt_max and blew up at step 0 (issue 11). */
    if (sim->pw && sim->fluid.n) {
        if (pfsph_grid_sort(&sim->grid, &sim->fluid, &sim->removed)) goto nomem;
        pfsph__number_density(c, sim->fluid.x, sim->fluid.y, sim->fluid.z, c->nd);
        pfsph__nonpressure(c);
        pfsph_pairwise_apply(sim->pw, c);
        double a2 = 0;
        for (size_t i = 0; i < sim->fluid.n; i++)
            a2 = fmax(a2, (double)c->ax[i] * c->ax[i] + (double)c->ay[i] * c->ay[i] + (double)c->az[i] * c->az[i]);
        sim->amax = sim->amax_np = fmax(g, sqrt(a2));
        if (sim->solver->np_cap_without_viscosity) sim->amax_np = g + pfsph_pairwise_amax(sim->pw);
    }
    build_stages(sim);
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
    if (sim->solver && sim->solver_state) sim->solver->destroy(sim->solver_state);
    if (sim->pw) pfsph_pairwise_destroy(sim->pw);
    if (sim->df) pfsph_diffuse_destroy(sim->df);
    pfsph_film_destroy(sim->film);
    pfsph_bodies_destroy(sim->bodies);
    pfsph_emitters_destroy(sim->em);
    pfsph_particles_free(&sim->fluid);
    pfsph_particles_free(&sim->boundary);
    pfsph_grid_free(&sim->grid);
    pfsph_grid_free(&sim->bgrid);
    pfsph_nlist_free(&sim->nlist);
    pfsph_nlist_free(&sim->nlist_b);
    for (int k = 0; k < SCR_MAX; k++) free(sim->scr[k]);
    free(sim);
}

/* Largest speed; index of the fastest (or of a non-finite) particle in *worst. */
static double max_speed(const pfsph_particles *f, size_t *worst)
{
    double vmax = 0;
    size_t wi = 0;
    int bad = 0;
#pragma omp parallel
    {
        double lv = 0;
        size_t li = 0;
        int lbad = 0;
#pragma omp for schedule(static) nowait
        for (size_t i = 0; i < f->n; i++) {
            double v2 = (double)f->vx[i] * f->vx[i] + (double)f->vy[i] * f->vy[i] + (double)f->vz[i] * f->vz[i];
            if (!isfinite(v2) || !isfinite(f->x[i] + f->y[i] + f->z[i])) {
                if (!lbad || i < li) li = i;
                lbad = 1;
            } else if (!lbad && (v2 > lv || (v2 == lv && i < li))) {
                lv = v2;
                li = i;
            }
        }
#pragma omp critical
        {
            if (lbad && (!bad || li < wi)) {
                bad = 1;
                wi = li;
            } else if (!bad && !lbad && (lv > vmax || (lv == vmax && li < wi))) {
                vmax = lv;
                wi = li;
            }
        }
    }
    *worst = wi;
    return bad ? NAN : sqrt(vmax);
}

/* One message format for every blow-up: step, time, stage, what, where, likely cause. */
static int report_blowup(pfsph_sim *sim, const char *stage_name, const blowup_info *b, pfsph_error *err)
{
    const pfsph_particles *f = &sim->fluid;
    const char *hint = b->hint ? b->hint : sim->solver->hint(sim->solver_state, &sim->ctx);
    size_t i = b->particle;
    if (i < f->n)
        return pfsph_fail(err, PFSPH_EUNSTABLE,
                          "simulation unstable at step %llu, t = %.6g s, stage %s: %s at particle id %u "
                          "(phase '%s', position %.4g %.4g %.4g); likely cause: %s",
                          (unsigned long long)sim->step, sim->time, stage_name, b->what, f->id[i],
                          sim->scene.phases[f->phase[i]].name, (double)f->x[i], (double)f->y[i], (double)f->z[i], hint);
    return pfsph_fail(err, PFSPH_EUNSTABLE,
                      "simulation unstable at step %llu, t = %.6g s, stage %s: %s; likely cause: %s",
                      (unsigned long long)sim->step, sim->time, stage_name, b->what, hint);
}

static int unstable(blowup_info *b, size_t i, const char *what, double value)
{
    b->particle = i;
    snprintf(b->what, sizeof b->what, "%s %.6g", what, value);
    return PFSPH_EUNSTABLE;
}

static double choose_dt(pfsph_sim *sim, double vmax, double t_limit, int *collapsed)
{
    const pfsph_scene *s = &sim->scene;
    const double d = sim->ctx.spacing;
    double dt = fmin(s->dt_max, sim->solver->dt_limit(sim->solver_state, &sim->ctx, vmax, sim->amax, sim->amax_np));
    double numax = 0;
    for (int p = 0; p < s->nphases; p++) numax = fmax(numax, s->phases[p].viscosity);
    if (numax > 0) dt = fmin(dt, 0.125 * d * d / numax); /* viscous diffusion */
    *collapsed = dt < s->dt_min;
    if (dt < s->dt_min) dt = s->dt_min;
    /* Land on t_limit in equal steps: the rest of the interval divided into the fewest steps
     * not longer than dt. A single shortened last step would kick PCISPH, whose pressure
     * scales as 1/dt^2: frames fell exactly on those short steps and showed 2-3.5x the
     * hydrostatic pressure. */
    double rem = t_limit - sim->time;
    if (rem <= dt) return rem;
    double steps = ceil(rem / dt - 1e-9);
    return rem / steps;
}

/* ---- the stages, in the order of the table built by build_stages ---- */

static int st_grid(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    sim->removed_before = sim->removed;
    sim->ctx.nlist = sim->ctx.nlist_b = NULL; /* the sort reorders the particles: lists are built again after it */
    pfsph_grid_sort(&sim->grid, &sim->fluid, &sim->removed);
    return PFSPH_OK;
}

/* particle shifting, if the scene asks (docs/pairwise.md); uses last step's ctx->dt */
static int st_shift(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_pairwise_shift(sim->pw, &sim->ctx);
    return PFSPH_OK;
}

/* bubbles in air: each bubble's surface layer and its film fraction (PF Section 4.2.2), on the
 * positions this step's forces see */
static int st_film(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    if (pfsph_film_update(sim->film, &sim->ctx) < 0)
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory in the film stage");
    return PFSPH_OK;
}

/* rho from the number density; a blow-up check */
static int density_check(pfsph_sim *sim, blowup_info *bad)
{
    pfsph_ctx *c = &sim->ctx;
    pfsph_particles *f = &sim->fluid;
    const size_t n = f->n;
    pfsph_real ndmax = 0;
#pragma omp parallel for schedule(static) reduction(max : ndmax)
    for (size_t i = 0; i < n; i++) {
        f->rho[i] = c->mass[f->phase[i]] * c->nd[i];
        if (c->nd[i] > ndmax) ndmax = c->nd[i];
    }
    /* A particle compressed by half again its rest density means the pressure solve has lost
     * control (PCISPH aims at 0.5%, WCSPH at Mach 0.1 stays near 1%): stop before the pressure
     * solve turns it into NaN. */
    if ((double)ndmax / (double)c->nd0 - 1 > PFSPH_DENSITY_ERROR_LIMIT) {
        size_t wi = 0;
        for (size_t i = 1; i < n; i++)
            if (c->nd[i] > c->nd[wi]) wi = i;
        return unstable(bad, wi, "relative density error", (double)ndmax / (double)c->nd0 - 1);
    }
    return PFSPH_OK;
}

/* Number density; with neighbour lists (solvers that walk the neighbours many times a step)
 * the density's walk also counts them and the lists are filled: positions stay put until the
 * integration. */
static int st_density(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    pfsph_ctx *c = &sim->ctx;
    pfsph_particles *f = &sim->fluid;
    c->nlist = c->nlist_b = NULL;
    if (sim->solver->neighbour_lists) {
        const double q = (double)c->h / (double)c->spacing; /* a full neighbourhood, and a quarter */
        const double guess = 1.25 * (c->dim == 2 ? 3.14159 * q * q : 4.18879 * q * q * q);
        int rc = pfsph__number_density_list(c, c->nd, &sim->nlist, &sim->nlist_b, guess);
        if (rc)
            return pfsph_fail(err, rc, "cannot build the neighbour lists (%s)",
                              rc == PFSPH_ENOMEM ? "out of memory" : "internal error");
        c->nlist = &sim->nlist;
        c->nlist_b = &sim->nlist_b;
    } else {
        pfsph__number_density(c, f->x, f->y, f->z, c->nd);
    }
    return density_check(sim, bad);
}

/* With pair forces and a solver without neighbour lists (WCSPH, PCISPH): the density in the
 * pair forces' walk, whose k h neighbourhood holds the h one (one walk instead of two: the
 * density pass was ~7 % of a pair-force step). The pair accelerations wait in the pressure
 * accelerations' arrays, which nothing reads or writes before the pressure stage (st_forces
 * computes no pressure with pair forces, and these solvers have no pre_forces) and which
 * st_pairwise_add empties into ctx->ax. */
static int st_density_pairs(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)err;
    pfsph_ctx *c = &sim->ctx;
    c->nlist = c->nlist_b = NULL;
    pfsph_real *const pa[3] = {sim->scr[SCR_APX], sim->scr[SCR_APY], sim->scr[SCR_APZ]};
    pfsph_pairwise_apply_density(sim->pw, c, c->nd, pa);
    return density_check(sim, bad);
}

static int st_timestep(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)err;
    pfsph_ctx *c = &sim->ctx;
    /* the last step's integration measured vmax (and stopped on non-finite values); only a
     * removal in the sort can lower it */
    size_t worst = 0;
    double vmax = sim->removed != sim->removed_before ? max_speed(&sim->fluid, &worst) : sim->stats.vmax;
    int collapsed;
    double dt =
        choose_dt(sim, sim->bodies ? fmax(vmax, pfsph_bodies_vmax(sim->bodies)) : vmax, sim->t_limit, &collapsed);
    if (collapsed) {
        vmax = max_speed(&sim->fluid, &worst);
        return unstable(bad, worst, "time step fell below time.dt_min; speed", vmax);
    }
    c->dt = dt;
    c->time = sim->time;
    c->step = sim->step;
    sim->vbound = sim->solver->speed_bound(sim->solver_state, c);
    return PFSPH_OK;
}

static int st_divergence(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_solve_stats out = {0, 0, 0};
    sim->solver->pre_forces(sim->solver_state, &sim->ctx, sim->scr + SCR_COMMON, &out);
    sim->stats.div_iterations = out.div_iterations;
    return PFSPH_OK;
}

static int st_forces(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_real *nz[3] = {NULL, NULL, NULL};
    if (sim->scr_noise >= 0)
        for (int a = 0; a < 3; a++) nz[a] = sim->scr[sim->scr_noise + a];
    if (sim->solver->eos && !sim->pw) { /* pressure in the same walk (solver.h, eos) */
        pfsph_real *const ap[3] = {sim->scr[SCR_APX], sim->scr[SCR_APY], sim->scr[SCR_APZ]};
        sim->solver->eos(sim->solver_state, &sim->ctx);
        pfsph__forces_and_pressure(&sim->ctx, sim->scr_noise >= 0 ? nz : NULL, sim->fluid.p, ap);
    } else if (sim->scr_noise >= 0) { /* with the thermostat's random forces, fused (viscosity.c) */
        pfsph__nonpressure_thermo(&sim->ctx, nz);
    } else {
        pfsph__nonpressure(&sim->ctx);
    }
    return PFSPH_OK;
}

static int st_pairwise(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_pairwise_apply(sim->pw, &sim->ctx);
    return PFSPH_OK;
}

/* the pair accelerations st_density_pairs computed, added as pfsph_pairwise_apply adds them */
static int st_pairwise_add(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_ctx *c = &sim->ctx;
    const pfsph_real *px = sim->scr[SCR_APX], *py = sim->scr[SCR_APY], *pz = sim->scr[SCR_APZ];
    const size_t n = sim->fluid.n;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        c->ax[i] += px[i];
        c->ay[i] += py[i];
        c->az[i] += pz[i];
    }
    return PFSPH_OK;
}

static int st_pressure(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_real *const ap[3] = {sim->scr[SCR_APX], sim->scr[SCR_APY], sim->scr[SCR_APZ]};
    pfsph_solve_stats out = {0, 0, 0};
    if (sim->solver->eos && !sim->pw) sim->solver->report(sim->solver_state, &sim->ctx, sim->scr + SCR_COMMON, &out);
    else sim->solver->solve(sim->solver_state, &sim->ctx, ap, sim->scr + SCR_COMMON, &out);
    sim->stats.iterations = out.iterations;
    sim->stats.density_err_avg = out.density_err_avg;
    return PFSPH_OK;
}

/* fluid forces on the bodies from this step's pressure, before the fluid moves */
static int st_body_forces(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    const pfsph_real *p = sim->solver->wall_pressure
        ? sim->solver->wall_pressure(sim->solver_state, &sim->ctx, sim->scr + SCR_COMMON)
        : sim->fluid.p;
    pfsph_bodies_fluid_forces(sim->bodies, &sim->ctx, p);
    return PFSPH_OK;
}

/* symplectic Euler; the largest acceleration feeds the next step's force criterion */
static int st_integrate(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)err;
    pfsph_ctx *c = &sim->ctx;
    pfsph_particles *f = &sim->fluid;
    const size_t n = f->n;
    const pfsph_real *apx = sim->scr[SCR_APX], *apy = sim->scr[SCR_APY], *apz = sim->scr[SCR_APZ];
    const double dt = c->dt;
    const pfsph_real fdt = (pfsph_real)dt;
    double amax2 = 0, anp2 = 0;
    c->nlist = c->nlist_b = NULL; /* the particles move: this step's lists no longer hold */
    pfsph_real *ek = sim->scr[SCR_EK];
    double emax = 0, v2max = 0;
    int bad_ = 0;
    /* The thermostat's random accelerations scale as dt^(-1/2) (their velocity kick as
     * dt^(1/2)): left in the force criteria they would shrink the next step without end. */
    const bool noise = sim->scr_noise >= 0 && pfsph_thermostat_kT(c) > 0;
    const pfsph_real *nx = noise ? sim->scr[sim->scr_noise] : NULL, *ny = noise ? sim->scr[sim->scr_noise + 1] : NULL,
                     *nz = noise ? sim->scr[sim->scr_noise + 2] : NULL;
#pragma omp parallel for schedule(static) reduction(max : amax2, anp2, emax, v2max) reduction(| : bad_)
    for (size_t i = 0; i < n; i++) {
        pfsph_real bx = c->ax[i], by = c->ay[i], bz = c->az[i];
        if (noise) {
            bx -= nx[i];
            by -= ny[i];
            bz -= nz[i];
        }
        double b2 = (double)bx * bx + (double)by * by + (double)bz * bz;
        if (b2 > anp2) anp2 = b2;
        pfsph_real cx = bx + apx[i], cy = by + apy[i], cz = bz + apz[i];
        double a2 = (double)cx * cx + (double)cy * cy + (double)cz * cz;
        if (a2 > amax2) amax2 = a2;
        pfsph_real axi = c->ax[i] + apx[i], ayi = c->ay[i] + apy[i], azi = c->az[i] + apz[i];
        f->vx[i] += fdt * axi;
        f->vy[i] += fdt * ayi;
        f->vz[i] += fdt * azi;
        f->x[i] += fdt * f->vx[i];
        f->y[i] += fdt * f->vy[i];
        f->z[i] += fdt * f->vz[i];
        double e = (double)c->nd[i] / (double)c->nd0 - 1;
        if (e > emax) emax = e;
        ek[i] =
            (pfsph_real)0.5 * c->mass[f->phase[i]] * (f->vx[i] * f->vx[i] + f->vy[i] * f->vy[i] + f->vz[i] * f->vz[i]);
        double v2 = (double)f->vx[i] * f->vx[i] + (double)f->vy[i] * f->vy[i] + (double)f->vz[i] * f->vz[i];
        if (!isfinite(v2) || !isfinite(f->x[i] + f->y[i] + f->z[i])) bad_ = 1;
        else if (v2 > v2max) v2max = v2;
    }
    sim->amax = sqrt(amax2);
    sim->amax_np = sim->solver->np_cap_without_viscosity ? sim->gmag + pfsph_pairwise_amax(sim->pw) : sqrt(anp2);
    sim->stats.ekin = pfsph__sum(ek, n);
    sim->stats.density_err_max = emax;
    sim->stats.dt = dt;
    double vmax = bad_ ? NAN : sqrt(v2max);
    sim->stats.vmax = vmax;
    if (bad_ || vmax > sim->vbound) {
        size_t worst;
        vmax = max_speed(f, &worst); /* rare: find the particle to name */
        if (!isfinite(vmax)) return unstable(bad, worst, "non-finite velocity or position", vmax);
        return unstable(bad, worst, "speed [m/s]", vmax);
    }
    return PFSPH_OK;
}

static int st_diffuse(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_diffuse_step(sim->df, &sim->ctx);
    return PFSPH_OK;
}

/* New particles at the nozzles, after everything moved (emitter.c). Their entry speed counts in
 * the next step's CFL condition through stats.vmax. */
static int st_emit(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    (void)bad;
    pfsph_particles *f = &sim->fluid;
    size_t due = pfsph_emitters_due(sim->em, sim->time, sim->ctx.dt);
    if (!due) {
        pfsph_emitters_step(sim->em, f, &sim->ctx, sim->time, sim->ctx.dt, &(double){0}); /* keeps the debt */
        return PFSPH_OK;
    }
    if (f->n + due > f->cap) { /* past the reserved end time: grow by half at least */
        size_t cap = f->cap + f->cap / 2;
        if (cap < f->n + due) cap = f->n + due;
        if (pfsph_particles_reserve(f, cap))
            return pfsph_fail(err, PFSPH_ENOMEM, "out of memory growing the fluid to %zu particles", cap);
    }
    if (f->cap > sim->scr_cap && alloc_scratch(sim, f->cap))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory growing the step's scratch to %zu particles", f->cap);
    double vin = 0;
    pfsph_emitters_step(sim->em, f, &sim->ctx, sim->time, sim->ctx.dt, &vin);
    if (vin > sim->stats.vmax) sim->stats.vmax = vin;
    return PFSPH_OK;
}

static int st_bodies(pfsph_sim *sim, blowup_info *bad, pfsph_error *err)
{
    pfsph_bodies_step(sim->bodies, &sim->boundary, sim->time, sim->ctx.dt);
    for (int i = 0; i < pfsph_bodies_count(sim->bodies); i++) {
        pfsph_body_state bs;
        pfsph_bodies_get_state(sim->bodies, i, &bs);
        double q = bs.x[0] + bs.x[1] + bs.x[2] + bs.v[0] + bs.v[1] + bs.v[2] + bs.w[0] + bs.w[1] + bs.w[2];
        if (!isfinite(q) || sqrt(bs.v[0] * bs.v[0] + bs.v[1] * bs.v[1] + bs.v[2] * bs.v[2]) > sim->vbound) {
            bad->particle = SIZE_MAX;
            snprintf(bad->what, sizeof bad->what, "body \"%s\" at %.4g %.4g %.4g moves at %.4g %.4g %.4g m/s",
                     pfsph_bodies_name(sim->bodies, i), bs.x[0], bs.x[1], bs.x[2], bs.v[0], bs.v[1], bs.v[2]);
            bad->hint = "a body much lighter than the fluid it displaces, or too large a time step (lower time.cfl)";
            return PFSPH_EUNSTABLE;
        }
    }
    if (pfsph_grid_sort(&sim->bgrid, &sim->boundary, NULL))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sorting the boundary particles");
    return PFSPH_OK;
}

/* The step as data: only the stages this scene needs, in order. */
static void build_stages(pfsph_sim *sim)
{
    int n = 0;
#define ADD(nm, sl, fn) sim->stages[n++] = (stage){nm, sl, fn}
    ADD("grid", PFSPH_STAGE_GRID, st_grid);
    if (sim->pw) ADD("pairwise", PFSPH_STAGE_PAIRWISE, st_shift);
    if (sim->film) ADD("film", PFSPH_STAGE_FILM, st_film);
    /* the density in the pair walk (st_density_pairs), counted with the pair forces */
    const bool fused = sim->pw && !sim->solver->neighbour_lists && !sim->solver->pre_forces;
    if (fused) ADD("density", PFSPH_STAGE_PAIRWISE, st_density_pairs);
    else ADD("density", PFSPH_STAGE_DENSITY, st_density);
    ADD("timestep", PFSPH_STAGE_FORCES, st_timestep);
    if (sim->solver->pre_forces) ADD("divergence", PFSPH_STAGE_PRESSURE, st_divergence);
    ADD("forces", PFSPH_STAGE_FORCES, st_forces);
    if (fused) ADD("pairwise", PFSPH_STAGE_PAIRWISE, st_pairwise_add);
    else if (sim->pw) ADD("pairwise", PFSPH_STAGE_PAIRWISE, st_pairwise);
    ADD("pressure", PFSPH_STAGE_PRESSURE, st_pressure);
    if (sim->bodies) ADD("bodies", PFSPH_STAGE_BODIES, st_body_forces);
    ADD("integrate", PFSPH_STAGE_INTEGRATE, st_integrate);
    if (sim->df) ADD("diffuse", PFSPH_STAGE_DIFFUSE, st_diffuse);
    if (sim->bodies) ADD("bodies", PFSPH_STAGE_BODIES, st_bodies);
    if (sim->em) ADD("emit", PFSPH_STAGE_INTEGRATE, st_emit);
#undef ADD
    sim->nstages = n;
}

int pfsph_sim_step(pfsph_sim *sim, double t_limit, pfsph_error *err)
{
    sim->t_limit = t_limit;
    double t0 = now(), c0 = cpu_now();
    for (int k = 0; k < sim->nstages; k++) {
        const stage *st = &sim->stages[k];
        blowup_info bad = {SIZE_MAX, "", NULL};
        int rc = st->run(sim, &bad, err);
        double t1 = now(), c1 = cpu_now();
        sim->stage_s[st->slot] += t1 - t0;
        sim->stage_cpu[st->slot] += c1 - c0;
        t0 = t1;
        c0 = c1;
        if (rc == PFSPH_EUNSTABLE && bad.what[0]) return report_blowup(sim, st->name, &bad, err);
        if (rc) return rc;
    }
    sim->time += sim->ctx.dt;
    sim->step++;
    return PFSPH_OK;
}

int pfsph_sim_advance(pfsph_sim *sim, double t, pfsph_error *err)
{
    /* tolerance: frame times are sums of doubles */
    while (sim->time < t - 1e-12 * fmax(1.0, fabs(t))) {
        int rc = pfsph_sim_step(sim, t, err);
        if (rc) return rc;
    }
    sim->time = fmax(sim->time, t);
    return PFSPH_OK;
}

double pfsph_sim_time(const pfsph_sim *sim) { return sim->time; }
uint64_t pfsph_sim_steps(const pfsph_sim *sim) { return sim->step; }
const pfsph_ctx *pfsph_sim_ctx(const pfsph_sim *sim) { return &sim->ctx; }
const pfsph_scene *pfsph_sim_scene(const pfsph_sim *sim) { return &sim->scene; }
const pfsph_step_stats *pfsph_sim_stats(const pfsph_sim *sim) { return &sim->stats; }
const double *pfsph_sim_stage_seconds(const pfsph_sim *sim) { return sim->stage_s; }
const double *pfsph_sim_stage_cpu_seconds(const pfsph_sim *sim) { return sim->stage_cpu; }
size_t pfsph_sim_removed(const pfsph_sim *sim) { return sim->removed; }
void pfsph_sim_diffuse_counts(const pfsph_sim *sim, size_t counts[3])
{
    counts[0] = counts[1] = counts[2] = 0;
    if (sim->df) pfsph_diffuse_counts(sim->df, counts);
}

const pfsph_particles *pfsph_sim_diffuse(const pfsph_sim *sim)
{
    return sim->df ? pfsph_diffuse_particles(sim->df) : NULL;
}
double pfsph_sim_sound_speed(const pfsph_sim *sim) { return sim->sound_speed; }
const pfsph_emitters *pfsph_sim_emitters(const pfsph_sim *sim) { return sim->em; }

int pfsph_sim_restore_emitters(pfsph_sim *sim, int n, const pfsph_emitter_state *st, double t, pfsph_error *err)
{
    if (n != pfsph_emitters_count(sim->em))
        return pfsph_fail(err, PFSPH_EINPUT, "restore: %d emitters, the scene has %d", n,
                          pfsph_emitters_count(sim->em));
    for (int i = 0; i < n; i++) {
        int rc = pfsph_emitters_set_state(sim->em, i, &st[i], t, err);
        if (rc) return rc;
    }
    return PFSPH_OK;
}
const pfsph_bodies *pfsph_sim_bodies(const pfsph_sim *sim) { return sim->bodies; }

int pfsph_sim_restore_bodies(pfsph_sim *sim, int nbodies, const pfsph_body_state *st, const uint32_t *ids, size_t n,
                             pfsph_error *err)
{
    pfsph_particles *b = &sim->boundary;
    if (nbodies != pfsph_bodies_count(sim->bodies))
        return pfsph_fail(err, PFSPH_EINPUT, "restore: %d bodies, the scene has %d", nbodies,
                          pfsph_bodies_count(sim->bodies));
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
    for (int i = 0; i < nbodies; i++) pfsph_bodies_set_state(sim->bodies, i, &st[i], b);
    if (pfsph_grid_sort(&sim->bgrid, b, NULL)) return pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory");
    return PFSPH_OK;
}
void pfsph_sim_add_stage_time(pfsph_sim *sim, int stage, double seconds)
{
    if (stage >= 0 && stage < PFSPH_NSTAGES) sim->stage_s[stage] += seconds;
}

void pfsph_sim_get_state(const pfsph_sim *sim, pfsph_sim_state *st)
{
    memset(st, 0, sizeof(*st));
    st->time = sim->time;
    st->step = sim->step;
    st->amax = sim->amax;
    st->amax_np = sim->amax_np;
    st->removed = sim->removed;
    st->stats = sim->stats;
    memcpy(st->stage_s, sim->stage_s, sizeof st->stage_s);
}

void pfsph_sim_diffuse_totals(const pfsph_sim *sim, uint64_t *created, uint64_t *refused)
{
    uint64_t c = 0, r = 0;
    if (sim->df) pfsph_diffuse_totals(sim->df, &c, &r);
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
    if (sim->df && !diffuse)
        return pfsph_fail(err, PFSPH_EINPUT, "restore: the scene has diffuse particles on but the state has none");
    if (!sim->df && diffuse && diffuse->n)
        return pfsph_fail(err, PFSPH_EINPUT, "restore: the state has diffuse particles but the scene has diffuse off");
    if (!(st->time >= 0) || !isfinite(st->time)) return pfsph_fail(err, PFSPH_EINPUT, "restore: bad time %g", st->time);
    pfsph_particles *f = &sim->fluid;
    if (fluid->n > f->cap && pfsph_particles_reserve(f, fluid->n) != PFSPH_OK)
        return pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory for %zu fluid particles", fluid->n);
    if (fluid->n > sim->scr_cap && alloc_scratch(sim, fluid->n) != PFSPH_OK)
        return pfsph_fail(err, PFSPH_ENOMEM, "restore: out of memory for %zu fluid particles", fluid->n);
    if (sim->df) {
        int rc = pfsph_diffuse_import(sim->df, diffuse, created, refused);
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
    sim->time = st->time;
    sim->step = st->step;
    sim->amax = st->amax;
    sim->amax_np = st->amax_np;
    sim->removed = st->removed;
    sim->stats = st->stats;
    memcpy(sim->stage_s, st->stage_s, sizeof sim->stage_s);
    sim->ctx.time = st->time;
    sim->ctx.step = st->step;
    sim->ctx.dt = st->stats.dt;
    return PFSPH_OK;
}

/* Frame 0's densities and pressures (issue 14): the grid sort and density summation a step
 * begins with, and the Tait pressure of that density (the iterative solvers' own pressures need a
 * step). Sorting an unsorted set here or in the first step gives the same order. */
void pfsph_sim_prime_output(pfsph_sim *sim)
{
    blowup_info bad;
    pfsph_error err;
    const pfsph_scene *s = &sim->scene;
    st_grid(sim, &bad, &err);
    st_density(sim, &bad, &err); /* a blow-up is the first step's to report */
    double rlo, rhi, rho_common = 0;
    if (s->pressure_scale == PFSPH_PRESSURE_COMMON && pfsph_scene_density_range(s, &rlo, &rhi) && rlo > 0)
        rho_common = rhi;
    pfsph__tait(&sim->ctx, sim->ctx.nd, sim->sound_speed * sim->sound_speed / s->gamma, s->gamma, rho_common,
                sim->fluid.p);
}

/* ---- changing the model while it runs (sim.h; docs/viewer.md) ---- */

int pfsph_sim_set_gravity(pfsph_sim *sim, const double g[3], pfsph_error *err)
{
    for (int a = 0; a < 3; a++)
        if (!isfinite(g[a]) || fabs(g[a]) > 1e6)
            return pfsph_fail(err, PFSPH_EINPUT, "gravity %g %g %g: expected finite components of at most 1e6 m/s^2",
                              g[0], g[1], g[2]);
    for (int a = 0; a < 3; a++) sim->scene.gravity[a] = a < sim->scene.dim ? g[a] : 0;
    memcpy(sim->ctx.gravity, sim->scene.gravity, sizeof sim->ctx.gravity);
    pfsph_bodies_set_gravity(sim->bodies, sim->scene.dim, sim->scene.gravity);
    return PFSPH_OK;
}

/* Check a phase pair; `what` names the change in messages. */
static int pair_ok(const pfsph_sim *sim, int a, int b, const char *what, pfsph_error *err)
{
    const pfsph_scene *s = &sim->scene;
    if (!s->pairwise.enabled || !sim->pw)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: the scene has pair forces off (no \"pairwise\" block)", what);
    if (a < 0 || b < 0 || a >= s->nphases || b >= s->nphases)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: phase index %d or %d out of range (the scene has %d phases)", what, a,
                          b, s->nphases);
    return PFSPH_OK;
}

/* Install one pair's new statement (kind 0 c, 1 sigma, 2 angle) and resolve every target again;
 * on failure the old parameters come back. */
static int set_pair(pfsph_sim *sim, int a, int b, int kind, double v, pfsph_error *err)
{
    pfsph_pairwise_params *pp = &sim->scene.pairwise;
    pfsph_pairwise_params old = *pp;
    pp->c_set[a][b] = pp->c_set[b][a] = kind == 0;
    pp->sigma_set[a][b] = pp->sigma_set[b][a] = kind == 1;
    pp->angle_set[a][b] = pp->angle_set[b][a] = kind == 2;
    if (kind == 0) pp->c[a][b] = pp->c[b][a] = v;
    if (kind == 1) pp->sigma[a][b] = pp->sigma[b][a] = v;
    if (kind == 2) pp->angle_deg[a][b] = pp->angle_deg[b][a] = v;
    int rc = pfsph_pairwise_resolve(&sim->scene, sim->ctx.spacing, sim->ctx.h, err);
    if (rc) *pp = old;
    apply_viscosity(&sim->ctx, &sim->scene);
    return rc;
}

int pfsph_sim_set_pair_coefficient(pfsph_sim *sim, int a, int b, double c, pfsph_error *err)
{
    int rc = pair_ok(sim, a, b, "pair coefficient", err);
    if (rc) return rc;
    if (!isfinite(c) || c < 0 || c > 1e30)
        return pfsph_fail(err, PFSPH_EINPUT, "pair coefficient of \"%s\" and \"%s\": %g is not in 0..1e30",
                          sim->scene.phases[a].name, sim->scene.phases[b].name, c);
    return set_pair(sim, a, b, 0, c, err);
}

int pfsph_sim_set_pair_sigma(pfsph_sim *sim, int a, int b, double sigma, pfsph_error *err)
{
    int rc = pair_ok(sim, a, b, "surface tension", err);
    if (rc) return rc;
    const pfsph_scene *s = &sim->scene;
    if (s->phases[a].kind == PFSPH_PHASE_SOLID || s->phases[b].kind == PFSPH_PHASE_SOLID)
        return pfsph_fail(err, PFSPH_EINPUT, "surface tension of \"%s\" and \"%s\": needs two fluid phases",
                          s->phases[a].name, s->phases[b].name);
    if (!isfinite(sigma) || sigma < 0 || sigma > 1e6)
        return pfsph_fail(err, PFSPH_EINPUT, "surface tension of \"%s\" and \"%s\": %g N/m is not in 0..1e6",
                          s->phases[a].name, s->phases[b].name, sigma);
    return set_pair(sim, a, b, 1, sigma, err);
}

int pfsph_sim_set_pair_contact_angle(pfsph_sim *sim, int a, int b, double deg, pfsph_error *err)
{
    int rc = pair_ok(sim, a, b, "contact angle", err);
    if (rc) return rc;
    const pfsph_scene *s = &sim->scene;
    if ((s->phases[a].kind == PFSPH_PHASE_SOLID) == (s->phases[b].kind == PFSPH_PHASE_SOLID))
        return pfsph_fail(err, PFSPH_EINPUT, "contact angle of \"%s\" and \"%s\": needs one fluid and one solid phase",
                          s->phases[a].name, s->phases[b].name);
    if (!isfinite(deg) || deg < 0 || deg > 180)
        return pfsph_fail(err, PFSPH_EINPUT, "contact angle of \"%s\" and \"%s\": %g degrees is not in 0..180",
                          s->phases[a].name, s->phases[b].name, deg);
    return set_pair(sim, a, b, 2, deg, err);
}

int pfsph_sim_drag_body(pfsph_sim *sim, int body, const double target[3], pfsph_error *err)
{
    int nb = pfsph_bodies_count(sim->bodies);
    if (body < 0 || body >= nb) return pfsph_fail(err, PFSPH_EINPUT, "drag: no body %d (the scene has %d)", body, nb);
    if (!pfsph_bodies_draggable(sim->bodies, body))
        return pfsph_fail(err, PFSPH_EINPUT,
                          "drag: body \"%s\" is moved by keyframes; dynamic bodies and kinematic "
                          "bodies without keyframes can be dragged",
                          pfsph_bodies_name(sim->bodies, body));
    /* no faster than the flows the scene is set up for (a tenth of its sound speed, Mach 0.1),
     * and well inside the blow-up bound */
    double vmax = fmin(0.1 * sim->sound_speed, 0.2 * sim->solver->speed_bound(sim->solver_state, &sim->ctx));
    if (pfsph_bodies_drag(sim->bodies, body, target, vmax))
        return pfsph_fail(err, PFSPH_EINPUT, "drag: target %g %g %g is not finite", target[0], target[1], target[2]);
    return PFSPH_OK;
}
