/* Structure-of-arrays particle storage: allocation, growth, append and permutation. */
#include "pfsph/particles.h"

#include <stdlib.h>
#include <string.h>

/* The new room is zeroed by calloc, not by writing it: a large calloc maps fresh pages that
 * stay out of the resident set until a particle is written there, so room reserved by doubling
 * (up to twice the particles while a scene is built) or for emitters costs address space, not
 * memory (realloc + memset touched it all: 147 -> B per particle at 2e7, docs/benchmarks.md). */
static void *grow(void *p, size_t old_bytes, size_t new_bytes)
{
    if (new_bytes <= old_bytes) return p;
    unsigned char *q = calloc(new_bytes, 1);
    if (!q) return NULL;
    if (old_bytes) memcpy(q, p, old_bytes);
    free(p);
    return q;
}

int pfsph_particles_reserve(pfsph_particles *ps, size_t cap)
{
    if (cap <= ps->cap) return PFSPH_OK;
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        void *q = grow(ps->f[k], ps->cap * sizeof(pfsph_real), cap * sizeof(pfsph_real));
        if (!q) return PFSPH_ENOMEM;
        ps->f[k] = q;
    }
    void *q = grow(ps->phase, ps->cap, cap);
    if (!q) return PFSPH_ENOMEM;
    ps->phase = q;
    q = grow(ps->wall, ps->cap, cap);
    if (!q) return PFSPH_ENOMEM;
    ps->wall = q;
    q = grow(ps->bubble, ps->cap, cap);
    if (!q) return PFSPH_ENOMEM;
    ps->bubble = q;
    q = grow(ps->id, ps->cap * sizeof(uint32_t), cap * sizeof(uint32_t));
    if (!q) return PFSPH_ENOMEM;
    ps->id = q;
    ps->cap = cap;
    return PFSPH_OK;
}

int pfsph_particles_init(pfsph_particles *ps, size_t cap)
{
    memset(ps, 0, sizeof(*ps));
    return pfsph_particles_reserve(ps, cap);
}

void pfsph_particles_free(pfsph_particles *ps)
{
    if (!ps) return;
    for (int k = 0; k < PFSPH_NFIELDS; k++) free(ps->f[k]);
    free(ps->phase);
    free(ps->wall);
    free(ps->bubble);
    free(ps->id);
    memset(ps, 0, sizeof(*ps));
}

long pfsph_particles_push(pfsph_particles *ps, const pfsph_real x[3], const pfsph_real v[3], uint8_t phase)
{
    if (ps->n == ps->cap) {
        size_t cap = ps->cap ? ps->cap * 2 : 1024;
        if (pfsph_particles_reserve(ps, cap) != PFSPH_OK) return -1;
    }
    size_t i = ps->n++;
    for (int k = 0; k < PFSPH_NFIELDS; k++) ps->f[k][i] = 0;
    ps->x[i] = x[0];
    ps->y[i] = x[1];
    ps->z[i] = x[2];
    if (v) {
        ps->vx[i] = v[0];
        ps->vy[i] = v[1];
        ps->vz[i] = v[2];
    }
    ps->phase[i] = phase;
    ps->wall[i] = 0;
    ps->bubble[i] = 0;
    ps->id[i] = ps->next_id++;
    return (long)i;
}

int pfsph_particles_permute(pfsph_particles *ps, const uint32_t *perm, size_t n_new, void *tmp)
{
    void *own = NULL;
    size_t n = ps->n > n_new ? ps->n : n_new;
    if (!tmp) {
        own = malloc((n ? n : 1) * sizeof(pfsph_real));
        if (!own) return PFSPH_ENOMEM;
        tmp = own;
    }
    pfsph_real *t = tmp;
    /* one parallel region for all fields: a region per field cost a quarter of a small
     * scene's wall time on a loaded machine (thread wake-ups) */
    uint32_t *tu = tmp;
    uint8_t *tb = tmp;
    uint8_t *const bytes[3] = {ps->phase, ps->wall, ps->bubble};
    /* the integer fields in the same region too: serial, they were 1 % of a WCSPH step's
     * instructions, which caps the speed-up of two threads (docs/benchmarks.md) */
#pragma omp parallel
    {
        for (int k = 0; k < PFSPH_NFIELDS; k++) {
            pfsph_real *a = ps->f[k];
#pragma omp for schedule(static)
            for (size_t i = 0; i < n_new; i++) t[i] = a[perm[i]];
#pragma omp for schedule(static)
            for (size_t i = 0; i < n_new; i++) a[i] = t[i];
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < n_new; i++) tu[i] = ps->id[perm[i]];
#pragma omp for schedule(static)
        for (size_t i = 0; i < n_new; i++) ps->id[i] = tu[i];
        for (int k = 0; k < 3; k++) {
#pragma omp for schedule(static)
            for (size_t i = 0; i < n_new; i++) tb[i] = bytes[k][perm[i]];
#pragma omp for schedule(static)
            for (size_t i = 0; i < n_new; i++) bytes[k][i] = tb[i];
        }
    }
    ps->n = n_new;
    free(own);
    return PFSPH_OK;
}

size_t pfsph_particles_bytes_per_particle(void)
{
    return PFSPH_NFIELDS * sizeof(pfsph_real) + 3 * sizeof(uint8_t) + sizeof(uint32_t);
}
