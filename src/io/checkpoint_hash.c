/* The scene hash a checkpoint carries (docs/checkpoints.md): FNV-1a over every scene value that
 * changes the simulation, so that a resume refuses another scene. The solver is hashed as its
 * name and its settings array (no per-solver case). */
#include "pfsph/checkpoint.h"

#include <string.h>

#include "io/io_internal.h"

typedef struct hasher {
    uint64_t h;
} hasher;

static void h_bytes(hasher *s, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) {
        s->h ^= b[i];
        s->h *= 1099511628211ull;
    }
}
static void h_u64(hasher *s, uint64_t v)
{
    unsigned char b[8];
    pfsph__put_le(b, &v, 8);
    h_bytes(s, b, 8);
}
static void h_int(hasher *s, long long v) { h_u64(s, (uint64_t)v); }
static void h_f64(hasher *s, double v)
{
    uint64_t u;
    if (v == 0) v = 0; /* -0 == 0 */
    memcpy(&u, &v, 8);
    h_u64(s, u);
}
static void h_vec(hasher *s, const double *v, int n)
{
    for (int i = 0; i < n; i++) h_f64(s, v[i]);
}
static void h_str(hasher *s, const char *str)
{
    size_t n = strnlen(str, PFSPH_NAME_LEN);
    h_u64(s, n);
    h_bytes(s, str, n);
}

uint64_t pfsph_scene_hash(const pfsph_scene *s)
{
    hasher H = {14695981039346656037ull};
    hasher *h = &H;
    h_int(h, (long long)sizeof(pfsph_real));
    h_int(h, s->dim);
    h_f64(h, s->particle_radius);
    h_f64(h, s->support_factor);
    h_vec(h, s->gravity, 3);
    h_vec(h, s->domain_min, 3);
    h_vec(h, s->domain_max, 3);
    h_str(h, s->solver);
    h_f64(h, s->cfl);
    h_f64(h, s->dt_min);
    h_f64(h, s->dt_max);
    h_f64(h, s->fps);
    h_u64(h, s->seed);
    h_f64(h, s->sound_speed);
    h_f64(h, s->gamma);
    if (s->pressure_scale) h_int(h, s->pressure_scale); /* older checkpoints stay resumable */
    h_vec(h, s->solver_settings, PFSPH_SOLVER_MAX_KEYS);
    h_int(h, s->nphases);
    for (int i = 0; i < s->nphases && i < PFSPH_MAX_PHASES; i++) {
        const pfsph_phase *p = &s->phases[i];
        h_str(h, p->name);
        h_int(h, p->kind);
        h_f64(h, p->rest_density);
        h_f64(h, p->viscosity);
    }
    h_int(h, s->nblocks);
    for (int i = 0; i < s->nblocks && i < PFSPH_MAX_BLOCKS; i++) {
        const pfsph_block *b = &s->blocks[i];
        h_int(h, b->shape);
        h_int(h, b->phase);
        h_vec(h, b->min, 3);
        h_vec(h, b->max, 3);
        h_vec(h, b->center, 3);
        h_f64(h, b->radius);
        h_f64(h, b->height);
        h_int(h, b->axis);
        h_vec(h, b->velocity, 3);
        if (b->bubble >= 0) { /* a bubble's film (docs/film.md); only then: older hashes stay */
            const int k = b->bubble;
            h_int(h, s->film.gas[k]);
            h_int(h, s->film.film[s->film.gas[k]]);
            h_f64(h, s->film.thickness[k]);
            h_f64(h, s->film.thickness[k] > 0 ? 0.0 : s->film.volume[k]);
        }
    }
    h_int(h, s->nsolids);
    for (int i = 0; i < s->nsolids && i < PFSPH_MAX_SOLIDS; i++) {
        const pfsph_solid *b = &s->solids[i];
        h_int(h, b->shape);
        h_int(h, b->phase);
        h_vec(h, b->min, 3);
        h_vec(h, b->max, 3);
        h_vec(h, b->center, 3);
        h_vec(h, b->normal, 3);
        h_f64(h, b->radius);
        h_f64(h, b->height);
        h_int(h, b->axis);
        h_int(h, b->layers);
        h_int(h, b->open_top);
        if (b->slip || b->own_viscosity) { /* only then, so that older checkpoints stay resumable */
            h_int(h, b->slip);
            h_int(h, b->own_viscosity);
            h_f64(h, b->viscosity);
        }
    }
    /* pairwise: what the scene states (c is filled in by pfsph_pairwise_resolve, c_set is not) */
    const pfsph_pairwise_params *pw = &s->pairwise;
    h_int(h, pw->enabled);
    if (pw->enabled) {
        h_f64(h, pw->k);
        h_int(h, pw->filter);
        h_f64(h, pw->eta);
        h_f64(h, pw->eps_min);
        h_int(h, pw->center);
        /* the thermostat (on by default since issue 11): a checkpoint written before it
         * existed belongs to a different model and is refused */
        h_int(h, pw->thermo.enabled);
        if (pw->visc_correct) h_int(h, 1); /* only then: older checkpoints stay resumable */
        h_f64(h, pw->thermo.kT);
        h_f64(h, pw->thermo.reduced);
        for (int a = 0; a < s->nphases && a < PFSPH_MAX_PHASES; a++)
            for (int b = 0; b < s->nphases && b < PFSPH_MAX_PHASES; b++) {
                h_int(h, pw->c_set[a][b]);
                if (pw->c_set[a][b]) h_f64(h, pw->c[a][b]);
                h_int(h, pw->sigma_set[a][b]);
                if (pw->sigma_set[a][b]) h_f64(h, pw->sigma[a][b]);
                h_int(h, pw->angle_set[a][b]);
                if (pw->angle_set[a][b]) h_f64(h, pw->angle_deg[a][b]);
            }
    }
    const pfsph_diffuse_params *d = &s->diffuse;
    h_int(h, d->enabled);
    if (d->enabled) {
        h_int(h, d->max_particles);
        h_f64(h, d->sampling_rate);
        h_f64(h, d->phi_v_min);
        h_f64(h, d->phi_v_max);
        h_f64(h, d->phi_e_min);
        h_f64(h, d->phi_e_max);
        h_f64(h, d->energy_mass);
        h_f64(h, d->emit_radius);
        h_f64(h, d->emit_radius_scale);
        h_f64(h, d->emit_height_scale);
        h_f64(h, d->lifetime_min);
        h_f64(h, d->lifetime_max);
        h_int(h, d->foam_min_neighbors);
        h_int(h, d->foam_max_neighbors);
        for (int t = 0; t < PFSPH_DIFFUSE_NTYPES; t++) {
            h_f64(h, d->type[t].k_ext);
            h_f64(h, d->type[t].k_b);
            h_f64(h, d->type[t].k_cp);
            h_f64(h, d->type[t].k_t);
        }
    }
    /* bodies: only when there are some, so scenes without bodies keep their hash */
    if (s->nbodies) {
        h_int(h, s->nbodies);
        for (int i = 0; i < s->nbodies && i < PFSPH_MAX_BODIES; i++) {
            const pfsph_body_def *b = &s->bodies[i];
            h_str(h, b->name);
            h_int(h, b->shape);
            h_int(h, b->phase);
            h_vec(h, b->half, 3);
            h_f64(h, b->radius);
            h_f64(h, b->height);
            h_int(h, b->axis);
            h_str(h, b->mesh);
            h_f64(h, b->scale);
            h_vec(h, b->position, 3);
            h_vec(h, b->rotation, 3);
            h_vec(h, b->velocity, 3);
            h_vec(h, b->angular_velocity, 3);
            h_f64(h, b->density);
            h_f64(h, b->mass);
            h_f64(h, b->friction);
            h_f64(h, b->restitution);
            h_int(h, b->layers);
            h_vec(h, b->inertia, 3);
            h_int(h, b->kinematic);
            h_int(h, b->nkeys);
            for (int k = 0; k < b->nkeys && k < PFSPH_MAX_KEYFRAMES; k++) {
                h_f64(h, b->keys[k].t);
                h_vec(h, b->keys[k].position, 3);
                h_vec(h, b->keys[k].rotation, 3);
            }
        }
    }
    /* emitters: only when there are some, so scenes without them keep their hash */
    if (s->nemitters) {
        h_int(h, s->nemitters);
        for (int i = 0; i < s->nemitters && i < PFSPH_MAX_EMITTERS; i++) {
            const pfsph_emitter_params *e = &s->emitters[i];
            h_int(h, e->shape);
            h_int(h, e->phase);
            h_vec(h, e->center, 3);
            h_vec(h, e->direction, 3);
            h_int(h, e->axis);
            h_f64(h, e->radius);
            h_vec(h, e->size, 2);
            h_f64(h, e->speed);
            h_f64(h, e->rate);
            h_f64(h, e->start);
            h_f64(h, isfinite(e->stop) ? e->stop : -1);
            if (e->bubble) h_int(h, e->bubble); /* only when set: older emitter scenes keep their hash */
        }
    }
    return H.h;
}
