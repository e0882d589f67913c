/* Particle sets stored as structure of arrays. One set per kind (fluid, boundary, diffuse).
 * Every per-particle array that must follow a particle when the set is reordered lives here;
 * per-step scratch arrays belong to the stage that uses them. In 2D the z arrays hold zeros. */
#ifndef PFSPH_PARTICLES_H
#define PFSPH_PARTICLES_H

#include "pfsph/types.h"

/* Real-valued persistent fields, in the order of the union below (the public pfsph_field,
 * include/pfsph.h, is what an embedder reads them through). */
enum pfsph_field_slot {
    PFSPH_F_X,
    PFSPH_F_Y,
    PFSPH_F_Z,
    PFSPH_F_VX,
    PFSPH_F_VY,
    PFSPH_F_VZ,
    PFSPH_F_RHO,  /* density [kg/m^3] */
    PFSPH_F_P,    /* pressure [Pa] */
    PFSPH_F_AUX,  /* per-set extra: boundary volume [m^d] / diffuse remaining lifetime [s] */
    PFSPH_F_FILM, /* fluid: liquid volume fraction of a bubble's film particle (PF Sec. 4.2.2,
                   * the a, b of Eq. 24; 0 for every other particle); 0 in other sets */
    PFSPH_NFIELDS
};

typedef struct pfsph_particles {
    size_t n;   /* live particles */
    size_t cap; /* allocated */
    union {
        pfsph_real *f[PFSPH_NFIELDS];
        struct {
            pfsph_real *x, *y, *z;
            pfsph_real *vx, *vy, *vz;
            pfsph_real *rho, *p;
            pfsph_real *aux;
            pfsph_real *film;
        };
    };
    uint8_t *phase;  /* index into the phase table (fluid/boundary) or diffuse type */
    uint8_t *wall;   /* boundary: its solid's wall model (pfsph_ctx wall tables; 0 = the
                     * default, no slip with the fluid's viscosity); 0 in other sets */
    uint8_t *bubble; /* fluid: 0, or k + 1 for a particle of bubble k (a block with a "bubble"
                      * key, docs/film.md); 0 in other sets */
    uint32_t *id;    /* stable id, assigned at creation, never reused within a run */
    uint32_t next_id;
} pfsph_particles;

/* Allocate room for cap particles (zeroed); returns PFSPH_OK or PFSPH_ENOMEM. */
int pfsph_particles_init(pfsph_particles *ps, size_t cap);
void pfsph_particles_free(pfsph_particles *ps);
/* Grow capacity to at least cap, keeping contents. */
int pfsph_particles_reserve(pfsph_particles *ps, size_t cap);
/* Append one particle (grows if needed); v may be NULL. Returns its index or -1 on ENOMEM. */
long pfsph_particles_push(pfsph_particles *ps, const pfsph_real x[3], const pfsph_real v[3], uint8_t phase);
/* Permute: new[i] = old[perm[i]] for i < n_new; n becomes n_new (drops particles not in perm).
 * tmp is scratch of at least n*sizeof(pfsph_real) bytes (NULL: allocated internally). */
int pfsph_particles_permute(pfsph_particles *ps, const uint32_t *perm, size_t n_new, void *tmp);
/* Bytes used per particle of capacity (for memory estimates). */
size_t pfsph_particles_bytes_per_particle(void);

#endif
