/* Diffuse material (Liu et al. 2018, "Symmetry" 10:86, Sections 4-5 and Algorithm 1): spray,
 * foam and bubbles generated from a diffusion entropy of the fluid (kinetic energy x weighted
 * velocity difference), emitted in a cylinder along each emitter's path, advected one-way
 * through the fluid velocity field and removed when their lifetime runs out. The fluid is only
 * read, never written. Parameters and their units: docs/diffuse.md. */
#ifndef PFSPH_DIFFUSE_H
#define PFSPH_DIFFUSE_H

#include <stdbool.h>

#include "pfsph/particles.h"
#include "pfsph/types.h"

struct pfsph_ctx;

/* Diffuse particle types, stored in pfsph_particles.phase. */
enum pfsph_diffuse_type { PFSPH_DIFFUSE_SPRAY = 0, PFSPH_DIFFUSE_FOAM = 1,
                          PFSPH_DIFFUSE_BUBBLE = 2, PFSPH_DIFFUSE_NTYPES = 3 };

/* Per-type weights of Eq. 24 and Eq. 29. */
typedef struct pfsph_diffuse_coupling {
    double k_ext; /* weight of gravity g dt [-] */
    double k_b;   /* buoyancy: adds -k_b g dt [-]; a bubble rises when k_b > k_ext */
    double k_cp;  /* fraction of (v_fluid - v_d) applied per step, in [0, 1] [-] */
    double k_t;   /* lifetime falls by k_t dt per step [-] */
} pfsph_diffuse_coupling;

typedef struct pfsph_diffuse_params {
    bool enabled;
    long max_particles;    /* cap on live diffuse particles; new ones are refused beyond it */
    double sampling_rate;  /* k_max of Eq. 16 [1/s]: particles per second per emitter at R_D=1 */
    double phi_v_min, phi_v_max; /* Eq. 14 limits for v_diff of Eq. 13 [m/s] */
    double phi_e_min, phi_e_max; /* Eq. 14 limits for E of Eq. 9 [J] */
    double energy_mass;    /* mass in Eq. 9 [kg]; 0: the fluid particle's own mass */
    double emit_radius;    /* cylinder radius r of Eq. 19 [m]; 0: the particle radius */
    double emit_radius_scale; /* s_r (paper's k_r magnification, NOTES 16) [-] */
    double emit_height_scale; /* s_h (paper's k_h magnification) [-] */
    double lifetime_min, lifetime_max; /* initial lifetime uniform in [min, max] [s] */
    int foam_min_neighbors; /* fewer fluid neighbours within h: spray; -1: automatic */
    int foam_max_neighbors; /* more: bubble; -1: automatic (NOTES 18) */
    pfsph_diffuse_coupling type[PFSPH_DIFFUSE_NTYPES]; /* spray, foam, bubble */
} pfsph_diffuse_params;

/* Defaults: docs/diffuse.md (the paper's Section 6 values where it gives them). */
void pfsph_diffuse_defaults(pfsph_diffuse_params *p);

/* Thresholds after resolving the automatic (-1) ones for a kernel support h and spacing d in
 * dim dimensions: 0.2 and 2/3 of the fluid neighbour count of a full support (the paper's 6 and
 * 20 of 30). */
void pfsph_diffuse_thresholds(const pfsph_diffuse_params *p, int dim, double h, double spacing,
                              int *foam_min, int *foam_max);

typedef struct pfsph_diffuse pfsph_diffuse;

/* Create the diffuse system of a simulation: parameters from ctx->scene->diffuse, kernel, grid
 * and masses read from ctx at each step. Returns PFSPH_OK or PFSPH_ENOMEM / PFSPH_EINPUT. */
int pfsph_diffuse_create(pfsph_diffuse **out, const struct pfsph_ctx *ctx, pfsph_error *err);
void pfsph_diffuse_destroy(pfsph_diffuse *d);

/* One step of Algorithm 1 (lines 12-26), called after the fluid was integrated to time+dt:
 * ctx->dt is the step just taken, ctx->step its number, fluid x, v are at t+dt and ctx->grid
 * holds the cell ranges of the fluid order built at time t (NOTES 19). Order: advect, classify
 * and age existing diffuse particles; remove expired ones and those outside the domain; then
 * emit new ones (their x, v are already at t+dt, Eqs. 21-22). Never writes the fluid. */
void pfsph_diffuse_step(pfsph_diffuse *d, const struct pfsph_ctx *ctx);

/* The live diffuse particles: phase[] = type (enum pfsph_diffuse_type), aux[] = remaining
 * lifetime [s], id stable for a particle's life and never reused. Owned by d. */
const pfsph_particles *pfsph_diffuse_particles(const pfsph_diffuse *d);
void pfsph_diffuse_counts(const pfsph_diffuse *d, size_t counts[3]);
/* Total created and refused (cap reached) since creation. */
void pfsph_diffuse_totals(const pfsph_diffuse *d, uint64_t *created, uint64_t *refused);

/* Replace the live set and the totals (checkpoint restore, docs/checkpoints.md): every field of
 * ps is copied, ids and next_id included. Returns PFSPH_OK, PFSPH_ENOMEM, or PFSPH_EINPUT when
 * ps holds more than max_particles or an unknown type. */
int pfsph_diffuse_import(pfsph_diffuse *d, const pfsph_particles *ps, uint64_t created,
                         uint64_t refused);

/* Insert a diffuse particle (tests, restarts). Returns its index or -1 (cap or ENOMEM). */
long pfsph_diffuse_add(pfsph_diffuse *d, const pfsph_real x[3], const pfsph_real v[3], int type,
                       pfsph_real lifetime);

/* Diffusion potentials of one fluid particle i (Eqs. 9, 13, 15; NOTES 13-14), evaluated with
 * the same neighbour rules as the step: v_diff [m/s], E [J], R_D in [0, 1]. For tests. */
void pfsph_diffuse_potentials(pfsph_diffuse *d, const struct pfsph_ctx *ctx, size_t i,
                              double *v_diff, double *energy, double *rate);

/* Eq. 14 with NOTES 14: 0 below lo, 1 above hi, linear between. */
static inline double pfsph_diffuse_phi(double m, double lo, double hi)
{
    if (m <= lo) return 0.0;
    if (m >= hi) return 1.0;
    return (m - lo) / (hi - lo);
}

/* Plot n_spray, n_foam, n_bubble (and their sum) over time from a stats CSV with a header line
 * naming the columns "time", "n_spray", "n_foam", "n_bubble", as a PNG like the paper's Fig. 14.
 * Written atomically. */
int pfsph_diffuse_plot(const char *stats_csv, const char *png_path, pfsph_error *err);

#endif
