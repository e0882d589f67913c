/* A rank's measured cost: process CPU time (every OpenMP thread) outside the decomposition's code,
 * so that neither the exchange and halo copies nor the waiting in a collective count as work;
 * per owned particle and step, an exponential mean over steps. The cut weighs each rank's
 * particles by it (an integer, relative to the costliest rank: docs/cluster.md). */
#include "mpi/cost.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mpi/decomp.h"

/* the exponential mean's weight of a new step: a time constant of 4 steps, short against the
 * flow's changes (hundreds of steps), long enough to damp one noisy step */
#define COST_ALPHA 0.25
/* steps measured before the cost decides the cut (the particle count decides until then) */
#define COST_WARM 2

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void pfsph_cost_enter(pfsph_decomp *D)
{
    pfsph_cost *k = &D->cost;
    if (k->depth++) return;
    const double t = cpu_now();
    if (k->open) k->step_cpu += t - k->mark;
    k->open = 0;
    k->mark = t;
}

void pfsph_cost_leave(pfsph_decomp *D)
{
    pfsph_cost *k = &D->cost;
    if (--k->depth) return;
    const double t = cpu_now();
    k->comm_cpu += t - k->mark;
    k->mark = t;
    k->open = 1;
}

void pfsph_cost_drop(pfsph_decomp *D) { D->cost.open = 0; }

void pfsph_cost_sample(pfsph_decomp *D, int first)
{
    pfsph_cost *k = &D->cost;
    const double s = k->step_cpu;
    k->step_cpu = 0;
    if (first) return;
    k->work_cpu += s;
    if (s > k->step_max) k->step_max = s;
    k->samples++;
    if (!k->own) return; /* nothing to divide by: the last mean stays */
    const double c = s / (double)k->own;
    k->per_particle = k->per_particle > 0 ? k->per_particle + COST_ALPHA * (c - k->per_particle) : c;
}

double pfsph_cost_local(const pfsph_decomp *D)
{
    const pfsph_cost *k = &D->cost;
    if (!k->by_cost) return 0;
    /* the tests' knob: half the ranks, alternating every step, skew times as costly as the others */
    if (k->skew > 1) return 1 + (k->skew - 1) * (double)((D->steps + (uint64_t)D->rank) & 1);
    return k->samples >= COST_WARM ? k->per_particle : 0;
}

void pfsph_cost_weigh(pfsph_decomp *D, double max_per_particle)
{
    pfsph_cost *k = &D->cost;
    /* every rank sees the same maximum (a MAX is exact in any order): all weigh, or none */
    if (!k->by_cost || !(max_per_particle > 0) || !isfinite(max_per_particle)) {
        k->weight = 0;
        return;
    }
    const double c = pfsph_cost_local(D), w = floor((double)PFSPH_CUT_WEIGHT_MAX * c / max_per_particle + 0.5);
    k->weight = w >= 1 ? (uint64_t)w : 1; /* c <= max: at most PFSPH_CUT_WEIGHT_MAX */
}

void pfsph_cost_gather(pfsph_decomp *D)
{
    const pfsph_cost *k = &D->cost;
    pfsph_cost_fig mine = {k->samples,     D->C.weighted ? k->weight : 0, k->work_cpu, k->comm_cpu, k->step_max,
                           k->per_particle};
    MPI_Gather(&mine, sizeof mine, MPI_BYTE, k->fig, sizeof mine, MPI_BYTE, 0, D->comm);
}

int pfsph_cost_env_mode(void)
{
    const char *v = getenv("PFSPH_MPI_CUT");
    if (!v || !strcmp(v, "cost")) return 1;
    return !strcmp(v, "count") ? 0 : -1;
}

/* ---- the hooks, timed: their time (and the waiting in them) is the decomposition's ---- */

#define D_OF(d) ((pfsph_decomp *)(d))

static void t_halo(pfsph_dist *d, pfsph_real *const *a, int n)
{
    pfsph_cost_enter(D_OF(d));
    D_OF(d)->cost.hooks.halo(d, a, n);
    pfsph_cost_leave(D_OF(d));
}

static double t_sum(pfsph_dist *d, const pfsph_real *a)
{
    pfsph_cost_enter(D_OF(d));
    const double s = D_OF(d)->cost.hooks.sum(d, a);
    pfsph_cost_leave(D_OF(d));
    return s;
}

static void t_count(pfsph_dist *d, long *v, int n)
{
    pfsph_cost_enter(D_OF(d));
    D_OF(d)->cost.hooks.count(d, v, n);
    pfsph_cost_leave(D_OF(d));
}

static void t_allsum(pfsph_dist *d, double *a, size_t n)
{
    pfsph_cost_enter(D_OF(d));
    D_OF(d)->cost.hooks.allsum(d, a, n);
    pfsph_cost_leave(D_OF(d));
}

static void t_any(pfsph_dist *d, uint8_t *f, size_t n)
{
    pfsph_cost_enter(D_OF(d));
    D_OF(d)->cost.hooks.any(d, f, n);
    pfsph_cost_leave(D_OF(d));
}

static void t_scan(pfsph_dist *d, const uint64_t *v, int n, uint64_t *before, uint64_t *total)
{
    pfsph_cost_enter(D_OF(d));
    D_OF(d)->cost.hooks.scan(d, v, n, before, total);
    pfsph_cost_leave(D_OF(d));
}

static void t_migrate(pfsph_dist *d, pfsph_particles *ps, size_t *nold, const uint32_t *key)
{
    pfsph_cost_enter(D_OF(d));
    D_OF(d)->cost.hooks.migrate(d, ps, nold, key);
    pfsph_cost_leave(D_OF(d));
}

static int t_agree(pfsph_dist *d, int rc, pfsph_error *err)
{
    pfsph_cost_enter(D_OF(d));
    rc = D_OF(d)->cost.hooks.agree(d, rc, err);
    pfsph_cost_leave(D_OF(d));
    return rc;
}

int pfsph_cost_init(pfsph_decomp *D)
{
    pfsph_cost *k = &D->cost;
    memset(k, 0, sizeof *k);
    k->fig = calloc((size_t)D->size, sizeof *k->fig);
    int mode = pfsph_cost_env_mode(); /* the program refused anything else (pfsph_mpi_check_scene) */
    MPI_Bcast(&mode, 1, MPI_INT, 0, D->comm);
    k->by_cost = mode != 0;
    const char *s = getenv("PFSPH_MPI_COST_SKEW");
    k->skew = s ? atof(s) : 0;
    k->hooks = D->d;
    D->d.halo = t_halo;
    D->d.sum = t_sum;
    D->d.count = t_count;
    D->d.allsum = t_allsum;
    D->d.any = t_any;
    D->d.scan = t_scan;
    D->d.migrate = t_migrate;
    D->d.agree = t_agree;
    return k->fig ? PFSPH_OK : PFSPH_ENOMEM;
}
