/* What a scene will need before it is built: particle counts, memory, the grid's cells, the
 * emitters' totals and entry speeds (`pfsph check`, the memory check of `pfsph run`). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/nlist.h"
#include "scene/shapes.h"
#include "sim_internal.h"

/* Grid cells. Without pair forces cells of h, queries one cell each way. With them cells of
 * max(h, k h / 3): for k <= 3 the h-radius stages walk what plain SPH walks and the pair forces
 * ceil(k) cells each way. Cells of k h made the h stages walk (3 k h)^3 (2.6x the candidates);
 * cells of h / 2 made them walk 25 short rows instead of 9 (docs/benchmarks.md, pairwise). */
pfsph_real pfsph__grid_cell(const pfsph_scene *s, pfsph_real h, int *reach, int *reach_far)
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

int pfsph__sim_emitters_create(pfsph_emitters **em, const pfsph_scene *s, const pfsph_ctx *c, pfsph_error *err)
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
    int rc = pfsph__sim_emitters_create(&em, s, &c, err);
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
    int rc = pfsph__sim_emitters_create(&em, s, &c, err);
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

/* Neighbour lists: a full neighbourhood within h (pi q^2 in 2D, 4/3 pi q^3 in 3D, q = h / d)
 * and a quarter more for compression near walls and in splashes; boundary lists: half a
 * neighbourhood for every fluid particle (a particle on a wall has about half). At most what
 * they hold: 537 B per fluid particle in 3D at q = 2, where the bench's dam break holds 228. */
static double nlist_neighbours(const pfsph_scene *s)
{
    const double q = s->support_factor;
    return s->dim == 2 ? 3.14159 * q * q : 4.18879 * q * q * q;
}

static double nlist_bytes_per_particle(const pfsph_scene *s)
{
    const double full = nlist_neighbours(s);
    double b = pfsph_nlist_bytes_per_particle(1.25 * full, 1) + pfsph_nlist_bytes_per_particle(0.5 * full, 1);
    /* the interactive PCISPH's pairs of an iteration: x_ij and dW/r per entry, 1/8 slack
     * (pcisph_lists.h, pfsph_pcisph_pairs) */
    const pfsph_solver_ops *ops = pfsph_solver_find(pfsph_scene_solver_name(s));
    if (ops && s->mode == PFSPH_MODE_INTERACTIVE && !strcmp(ops->name, "pcisph"))
        b += 1.125 * 4 * sizeof(pfsph_real) * (1.25 + 0.5) * full;
    return b;
}

static double physical_memory(void)
{
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGE_SIZE)
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    if (pages > 0 && size > 0) return (double)pages * (double)size;
#endif
    return 8.0 * 1073741824.0; /* unknown: a small workstation's */
}

/* Lists where they fit comfortably: "auto" builds them while their estimate is at most a quarter
 * of this machine's memory (and their entries fit the lists' 32-bit offsets); above, the grid
 * walks give the same bits at 0.4x the solver's speed (docs/solvers.md, "Neighbour lists"). */
int pfsph__sim_lists(const pfsph_scene *s, double n_fluid)
{
    const pfsph_solver_ops *ops = pfsph_solver_find(pfsph_scene_solver_name(s));
    /* the interactive mode's PCISPH walks them too: its corrections and the viscosity
     * (docs/interactive.md); the physical mode's PCISPH walks the grid (the fused pair density) */
    const int interactive_pci = ops && s->mode == PFSPH_MODE_INTERACTIVE && !strcmp(ops->name, "pcisph");
    if (!ops || !(ops->neighbour_lists || interactive_pci)) return 0;
    const int k = pfsph_solver_key_index(ops, "neighbour_lists");
    const double v = k >= 0 ? s->solver_settings[k] : 0;
    if (v != 0) return v > 0;
    const double entries = 1.125 * 1.25 * nlist_neighbours(s) * n_fluid;
    return entries < (double)UINT32_MAX && n_fluid * nlist_bytes_per_particle(s) <= 0.25 * physical_memory();
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
    double cell = pfsph__grid_cell(s, h, &r1, &r2);
    double cells = 1;
    for (int a = 0; a < s->dim; a++) cells *= ceil((s->domain_max[a] - s->domain_min[a]) / cell + 8);
    /* Per particle: its set (room reserved by doubling or for emitters is mapped, not resident:
     * src/core/particles.c), and for fluid the step's scratch (the grid sorts in its acceleration
     * arrays, src/core/grid.c); the boundary keeps the sort's scratch (key, perm, tmp; 1.25x)
     * only when bodies move it (checkpoints and the last good frame go to disk through a small
     * buffer, docs/checkpoints.md). Measured: tests/unit/test_estimate.c, docs/benchmarks.md.
     * In double: the estimate may exceed size_t, so it saturates. */
    const double P = (double)pfsph_particles_bytes_per_particle();
    const double sort = 1.25 * (2 * sizeof(uint32_t) + sizeof(pfsph_real));
    const pfsph_solver_ops *ops = pfsph_solver_find(pfsph_scene_solver_name(s));
    /* neighbour lists, when the run builds them; without them a solver with walk_nscratch keeps
     * that many arrays in the stages' shared scratch (no built-in stage between its first and
     * last asks for scratch: plan_buffers in src/sim.c) */
    const int lists = pfsph__sim_lists(s, (double)nf_max);
    const double nlist = lists ? nlist_bytes_per_particle(s) : 0;
    const int walk = ops && ops->walk_nscratch > 0 && !lists;
    const int nsolver = !ops ? 0
        : walk               ? ops->walk_nscratch
                             : ops->nscratch,
              nsolver4 = ops && !walk ? ops->nscratch4 : 0;
    const int shared = walk || (ops && ops->scratch_per_call && !ops->nscratch4);
    int nstage = 1; /* the stages' shared scratch: the integrator's energies */
    if (shared && nsolver > nstage) nstage = nsolver;
    const int nthermo = s->pairwise.enabled && s->pairwise.thermo.enabled ? 3 : 0;
    const int nscr = SCR_COMMON + nstage + (!shared ? nsolver + 3 * nsolver4 : 0) + nthermo; /* packed: 4 each */
    /* what the solver keeps per fluid particle near a wall in that layout (DFSPH's wall sums):
     * for as many particles as half the wall's (walls of 2 layers, wetted on one side by about a
     * layer within h where the fluid touches them; the bench's dam break has 0.12 of the wall's) */
    const double near = walk ? fmin((double)nf_max, 0.5 * (double)nb) * ops->walk_near_bytes : 0;
    /* output: the surface layers of a frame (a byte each) and, with pair forces, the
     * mechanical pressure (src/sim.c, pfsph_sim_output); frames stream through a 1 MiB buffer */
    const double out = (s->output.surface_layer ? 1 : 0) + (s->pairwise.enabled ? sizeof(pfsph_real) : 0);
    /* and 5 % for the allocator's and the pages' rounding: a 2D run of 160,000 particles held
     * 116 B per particle against 112 counted here (tests/unit/test_estimate.c) */
    const double per_fluid = 1.05 * (P + nscr * sizeof(pfsph_real) + nlist + out);
    const double per_boundary = P + (s->nbodies ? sort : 0);
    /* fluid and boundary grids: a start per cell, and the boundary's byte per cell of cells
     * near it (pfsph_grid_near) */
    const double grid_bytes = 2 * (cells + 1) * sizeof(uint32_t) + cells;
    /* diffuse material: its set at its cap, with the spatial sort's keys and permutations (two
     * of each), the permutation buffer and a keep flag (src/physics/diffuse.c); its per-fluid
     * arrays are the step's scratch */
    const double per_diffuse = P + 4 * sizeof(uint32_t) + sizeof(pfsph_real) + 1;
    const double nd_max = s->diffuse.enabled && s->diffuse.max_particles > 0 ? (double)s->diffuse.max_particles : 0;
    const double part_bytes = (double)nf_max * per_fluid + (double)nb * per_boundary + nd_max * per_diffuse + near;
    if (n_fluid) *n_fluid = (size_t)nf;
    if (n_boundary) *n_boundary = (size_t)nb;
    /* a run's fixed buffers: the frame writer's and the checkpoint encoder's (1 MiB each) */
    const double fixed = 2.0 * 1048576;
    const double total = part_bytes + grid_bytes + fixed;
    if (bytes) *bytes = total >= (double)SIZE_MAX ? SIZE_MAX : (size_t)total;
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
