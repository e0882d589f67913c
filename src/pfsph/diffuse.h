/* Diffuse material (Liu et al. 2018, "Symmetry" 10:86, Sections 4-5 and Algorithm 1): spray,
 * foam and bubbles generated from a diffusion entropy of the fluid (kinetic energy x weighted
 * velocity difference), emitted in a cylinder along each emitter's path, advected one-way
 * through the fluid velocity field and removed when their lifetime runs out. The fluid is only
 * read, never written. Parameters and their units: docs/diffuse.md. */
#ifndef PFSPH_DIFFUSE_H
#define PFSPH_DIFFUSE_H

#include <stdbool.h>

#include "pfsph/particles.h"
#include "pfsph/ctx.h"

typedef struct pfsph_diffuse pfsph_diffuse;

/* Create the diffuse system of a simulation: parameters from ctx->scene->diffuse, kernel, grid
 * and masses read from ctx at each step. Returns PFSPH_OK or PFSPH_ENOMEM / PFSPH_EINPUT. */
int pfsph_diffuse_create(pfsph_diffuse **out, const pfsph_ctx *ctx, pfsph_error *err);
void pfsph_diffuse_destroy(pfsph_diffuse *d);

/* One step of Algorithm 1 (lines 12-26), called after the fluid was integrated to time+dt:
 * ctx->dt is the step just taken, ctx->step its number, fluid x, v are at t+dt and ctx->grid
 * holds the cell ranges of the fluid order built at time t (NOTES 19). Order: advect, classify
 * and age existing diffuse particles; remove expired ones and those outside the domain; then
 * emit new ones (their x, v are already at t+dt, Eqs. 21-22). Never writes the fluid. */
void pfsph_diffuse_step(pfsph_diffuse *d, const pfsph_ctx *ctx);
/* The same with the caller's per-fluid-particle arrays (each at least ctx->fluid->n): old[3]
 * for the start-of-step positions, emit for the emitters' counts; they hold nothing before or
 * after the call. */
void pfsph_diffuse_step_in(pfsph_diffuse *d, const pfsph_ctx *ctx, pfsph_real *const old[3], uint32_t *emit);

/* The live diffuse particles: phase[] = type (enum pfsph_diffuse_type), aux[] = remaining
 * lifetime [s], id stable for a particle's life and never reused. Owned by d. */
const pfsph_particles *pfsph_diffuse_particles(const pfsph_diffuse *d);
void pfsph_diffuse_counts(const pfsph_diffuse *d, size_t counts[3]);
/* Total created and refused (cap reached) since creation. */
void pfsph_diffuse_totals(const pfsph_diffuse *d, uint64_t *created, uint64_t *refused);

/* Replace the live set and the totals (checkpoint restore, docs/checkpoints.md): every field of
 * ps is copied, ids and next_id included. Returns PFSPH_OK, PFSPH_ENOMEM, or PFSPH_EINPUT when
 * ps holds more than max_particles or an unknown type. */
int pfsph_diffuse_import(pfsph_diffuse *d, const pfsph_particles *ps, uint64_t created, uint64_t refused);
/* A distributed run's side (src/mpi/, docs/cluster.md): the live set, the count of its first
 * part (the particles of the last sort; the rest are the step's new ones, in id order), and the
 * run's totals (the same on every rank). */
pfsph_particles *pfsph__diffuse_set(pfsph_diffuse *d, size_t **nold, uint64_t **created, uint64_t **refused);

/* Insert a diffuse particle (tests, restarts). Returns its index or -1 (cap or ENOMEM). */
long pfsph_diffuse_add(pfsph_diffuse *d, const pfsph_real x[3], const pfsph_real v[3], int type, pfsph_real lifetime);

/* Diffusion potentials of one fluid particle i (Eqs. 9, 13, 15; NOTES 13-14), evaluated with
 * the same neighbour rules as the step: v_diff [m/s], E [J], R_D in [0, 1]. For tests. */
void pfsph_diffuse_potentials(pfsph_diffuse *d, const pfsph_ctx *ctx, size_t i, double *v_diff, double *energy,
                              double *rate);

/* Eq. 14 with NOTES 14: 0 below lo, 1 above hi, linear between. */
static inline double pfsph_diffuse_phi(double m, double lo, double hi)
{
    if (m <= lo) return 0.0;
    if (m >= hi) return 1.0;
    return (m - lo) / (hi - lo);
}

#endif
