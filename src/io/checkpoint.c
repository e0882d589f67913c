/* Checkpoint files (docs/checkpoints.md): a 40-byte header (magic, version, precision, scene
 * hash, payload length, payload CRC32, header CRC32) followed by the payload (frame, clock,
 * counters, the fluid set and the diffuse set), all little-endian. */
#include "pfsph/checkpoint.h"

#include "pfsph/bodies.h"
#include "pfsph/emitter.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "io/io_internal.h"
#include "pfsph/io.h"

static const unsigned char MAGIC[8] = {'P', 'F', 'S', 'P', 'H', 'C', 'K', 'P'};
enum { HEADER_LEN = 40 };

/* ---- scene hash ---- */

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

/* ---- encoding ---- */

/* The encoder writes either into one buffer (pfsph_checkpoint_encode) or through a small
 * staging buffer into a file, the particle arrays straight from the simulation: a checkpoint
 * written to disk then needs no copy of the state in memory (46 bytes per fluid particle, more
 * than a tenth of a run's peak at 493k particles). */
typedef struct wbuf {
    unsigned char *p; /* the whole checkpoint (memory) or the staging buffer (file) */
    size_t len;       /* bytes in p */
    FILE *f;          /* NULL: in memory */
    size_t flushed;   /* bytes already in f */
    uint32_t crc;     /* running CRC32 of the payload sent to f */
    int bad;          /* a write to f failed (errno in err_no) */
    int err_no;
} wbuf;

enum { STAGE_BYTES = 1 << 16 };

/* zlib's crc32 takes uInt lengths: feed large pieces in parts */
static uint32_t crc_more(uint32_t crc, const unsigned char *p, size_t n)
{
    while (n) {
        size_t k = n > (1u << 30) ? (1u << 30) : n;
        crc = (uint32_t)crc32(crc, p, (uInt)k);
        p += k;
        n -= k;
    }
    return crc;
}

static void w_send(wbuf *w, const void *v, size_t n)
{
    if (w->bad || !n) return;
    w->crc = crc_more(w->crc, v, n);
    if (fwrite(v, 1, n, w->f) != n) {
        w->bad = 1;
        w->err_no = errno ? errno : EIO;
    }
    w->flushed += n;
}

static void w_flush(wbuf *w)
{
    if (w->f && w->len) {
        w_send(w, w->p, w->len);
        w->len = 0;
    }
}

static void w_raw(wbuf *w, const void *v, size_t n)
{
    if (w->f && w->len + n > STAGE_BYTES) w_flush(w);
    pfsph__put_le(w->p + w->len, v, n);
    w->len += n;
}
static void w_u8(wbuf *w, uint8_t v) { w_raw(w, &v, 1); }
static void w_u32(wbuf *w, uint32_t v) { w_raw(w, &v, 4); }
static void w_i32(wbuf *w, int32_t v) { w_raw(w, &v, 4); }
static void w_u64(wbuf *w, uint64_t v) { w_raw(w, &v, 8); }
static void w_f64(wbuf *w, double v) { w_raw(w, &v, 8); }

/* n bytes already in file order (little-endian host, or bytes) */
static void w_bulk(wbuf *w, const void *v, size_t n)
{
    if (!w->f) {
        if (n) memcpy(w->p + w->len, v, n);
        w->len += n;
        return;
    }
    w_flush(w);
    w_send(w, v, n);
}

static size_t set_bytes(size_t n) { return 8 + 4 + n * (PFSPH_NFIELDS * sizeof(pfsph_real) + 2 + 4); }

static void w_set(wbuf *w, const pfsph_particles *ps)
{
    w_u64(w, ps->n);
    w_u32(w, ps->next_id);
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        if (pfsph__host_le()) {
            w_bulk(w, ps->f[k], ps->n * sizeof(pfsph_real));
        } else {
            for (size_t i = 0; i < ps->n; i++) w_raw(w, &ps->f[k][i], sizeof(pfsph_real));
        }
    }
    w_bulk(w, ps->phase, ps->n);
    w_bulk(w, ps->bubble, ps->n);
    if (pfsph__host_le()) w_bulk(w, ps->id, ps->n * 4);
    else
        for (size_t i = 0; i < ps->n; i++) w_u32(w, ps->id[i]);
}

/* Payload size of sim's state. */
static size_t payload_bytes(const pfsph_sim *sim)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *df = pfsph_sim_diffuse(sim);
    size_t payload = 4 + 4 + 4 + 4 + 8 * 5 + 8 * 5 + 4 + 4 + 8 * PFSPH_NSTAGES + set_bytes(c->fluid->n) + 1;
    if (df) payload += 16 + set_bytes(df->n);
    /* bodies: count, 13 doubles each, then the boundary set's order (its positions follow from
     * the bodies' poses, but the order decides summation order: bit-exact resume) */
    const int nbod = pfsph_bodies_count(pfsph_sim_bodies(sim));
    const int nem = pfsph_emitters_count(pfsph_sim_emitters(sim));
    if (nem) payload += 4 + (size_t)nem * 32; /* only with emitters: the format of other scenes is unchanged */
    payload += 4;
    if (nbod) payload += 4 + (size_t)nbod * 13 * 8 + 8 + 4 * c->boundary->n;
    return payload;
}

/* The payload, after HEADER_LEN bytes that w already holds or has sent. */
static void w_payload(wbuf *w, const pfsph_sim *sim, int frame)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *df = pfsph_sim_diffuse(sim);
    pfsph_sim_state st;
    pfsph_sim_get_state(sim, &st);
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    const int nbod = pfsph_bodies_count(B);
    const pfsph_emitters *E = pfsph_sim_emitters(sim);
    const int nem = pfsph_emitters_count(E);
    w_i32(w, frame);
    w_i32(w, omp_get_max_threads());
    w_i32(w, c->dim);
    w_u32(w, (uint32_t)c->nphases);
    w_f64(w, st.time);
    w_u64(w, st.step);
    w_f64(w, st.amax);
    w_f64(w, st.amax_np);
    w_u64(w, st.removed);
    w_f64(w, st.stats.dt);
    w_f64(w, st.stats.vmax);
    w_f64(w, st.stats.density_err_avg);
    w_f64(w, st.stats.density_err_max);
    w_f64(w, st.stats.ekin);
    w_i32(w, st.stats.iterations);
    w_u32(w, PFSPH_NSTAGES);
    for (int k = 0; k < PFSPH_NSTAGES; k++) w_f64(w, st.stage_s[k]);
    w_set(w, c->fluid);
    w_u8(w, df != NULL);
    if (df) {
        uint64_t created, refused;
        pfsph_sim_diffuse_totals(sim, &created, &refused);
        w_u64(w, created);
        w_u64(w, refused);
        w_set(w, df);
    }
    w_u32(w, (uint32_t)nbod);
    if (nbod) {
        /* the sampled particle count: a mesh file edited since (not in the scene hash) shows */
        w_u32(w, pfsph_bodies_particle_count(B));
        for (int i = 0; i < nbod; i++) {
            pfsph_body_state bs;
            pfsph_bodies_get_state(B, i, &bs);
            for (int a = 0; a < 3; a++) w_f64(w, bs.x[a]);
            for (int a = 0; a < 4; a++) w_f64(w, bs.q[a]);
            for (int a = 0; a < 3; a++) w_f64(w, bs.v[a]);
            for (int a = 0; a < 3; a++) w_f64(w, bs.w[a]);
        }
        w_u64(w, c->boundary->n);
        for (size_t j = 0; j < c->boundary->n; j++) w_u32(w, c->boundary->id[j]);
    }
    if (nem) {
        w_u32(w, (uint32_t)nem);
        for (int i = 0; i < nem; i++) {
            pfsph_emitter_state es;
            pfsph_emitters_get_state(E, i, &es);
            w_f64(w, es.debt);
            w_u64(w, es.emitted);
            w_u64(w, es.refused);
            w_u64(w, es.pushed);
        }
    }
}

/* The 40-byte header into out. */
static void make_header(unsigned char *out, const pfsph_sim *sim, size_t payload, uint32_t pcrc)
{
    wbuf w = {out, 0, NULL, 0, 0, 0, 0};
    w_bulk(&w, MAGIC, 8);
    w_u32(&w, PFSPH_CHECKPOINT_VERSION);
    w_u32(&w, (uint32_t)sizeof(pfsph_real));
    w_u64(&w, pfsph_scene_hash(pfsph_sim_scene(sim)));
    w_u64(&w, payload);
    w_u32(&w, pcrc);
    uint32_t hcrc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), out, 36);
    w_u32(&w, hcrc);
}

int pfsph_checkpoint_encode(const pfsph_sim *sim, int frame, void **data, size_t *len, pfsph_error *err)
{
    *data = NULL;
    *len = 0;
    const size_t payload = payload_bytes(sim);
    const size_t total = HEADER_LEN + payload;
    unsigned char *buf = malloc(total);
    if (!buf) return pfsph_fail(err, PFSPH_ENOMEM, "checkpoint: out of memory for %zu bytes", total);
    wbuf w = {buf, HEADER_LEN, NULL, 0, 0, 0, 0};
    w_payload(&w, sim, frame);
    if (w.len != total) {
        free(buf);
        return pfsph_fail(err, PFSPH_EINPUT, "checkpoint: internal size mismatch (%zu != %zu)", w.len, total);
    }
    make_header(buf, sim, payload, crc_more((uint32_t)crc32(0L, Z_NULL, 0), buf + HEADER_LEN, payload));
    *data = buf;
    *len = total;
    return PFSPH_OK;
}

/* The checkpoint into f (opened for writing at its start); *len its size. */
static int encode_file(const pfsph_sim *sim, int frame, FILE *f, const char *path, size_t *len, pfsph_error *err)
{
    const size_t payload = payload_bytes(sim);
    const size_t total = HEADER_LEN + payload;
    unsigned char *stage = malloc(STAGE_BYTES);
    if (!stage) return pfsph_fail(err, PFSPH_ENOMEM, "checkpoint: out of memory");
    unsigned char head[HEADER_LEN] = {0};
    wbuf w = {stage, 0, f, 0, 0, 0, 0};
    if (fwrite(head, 1, HEADER_LEN, f) != HEADER_LEN) w.bad = 1, w.err_no = errno ? errno : EIO;
    w.flushed = HEADER_LEN;
    w.crc = (uint32_t)crc32(0L, Z_NULL, 0);
    w_payload(&w, sim, frame);
    w_flush(&w);
    free(stage);
    if (!w.bad && w.flushed != total)
        return pfsph_fail(err, PFSPH_EINPUT, "checkpoint: internal size mismatch (%zu != %zu)", w.flushed, total);
    if (!w.bad) {
        make_header(head, sim, payload, w.crc);
        if (fseek(f, 0, SEEK_SET) != 0 || fwrite(head, 1, HEADER_LEN, f) != HEADER_LEN)
            w.bad = 1, w.err_no = errno ? errno : EIO;
    }
    if (w.bad) return pfsph_fail(err, PFSPH_EIO, "%s: write failed: %s", path, strerror(w.err_no));
    *len = total;
    return PFSPH_OK;
}

/* ---- decoding ---- */

typedef struct rbuf {
    const unsigned char *p;
    size_t len, pos;
    int bad;
} rbuf;

static int r_need(rbuf *r, size_t n)
{
    if (r->bad || n > r->len - r->pos) {
        r->bad = 1;
        return 0;
    }
    return 1;
}
static void r_raw(rbuf *r, void *v, size_t n)
{
    if (!r_need(r, n)) {
        memset(v, 0, n);
        return;
    }
    pfsph__get_le(v, r->p + r->pos, n);
    r->pos += n;
}
static uint8_t r_u8(rbuf *r)
{
    uint8_t v = 0;
    if (r_need(r, 1)) v = r->p[r->pos++];
    return v;
}
static uint32_t r_u32(rbuf *r)
{
    uint32_t v;
    r_raw(r, &v, 4);
    return v;
}
static int32_t r_i32(rbuf *r)
{
    int32_t v;
    r_raw(r, &v, 4);
    return v;
}
static uint64_t r_u64(rbuf *r)
{
    uint64_t v;
    r_raw(r, &v, 8);
    return v;
}
static double r_f64(rbuf *r)
{
    double v;
    r_raw(r, &v, 8);
    return v;
}

/* Read a particle set; ps is initialised here (free with pfsph_particles_free). */
static int r_set(rbuf *r, pfsph_particles *ps, const char *name, const char *what, pfsph_error *err)
{
    memset(ps, 0, sizeof(*ps));
    uint64_t n = r_u64(r);
    uint32_t next_id = r_u32(r);
    const size_t per = PFSPH_NFIELDS * sizeof(pfsph_real) + 2 + 4;
    if (r->bad || n > (r->len - r->pos) / per)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %s particle count %llu exceeds the file", name,
                          what, (unsigned long long)n);
    if (pfsph_particles_init(ps, (size_t)n ? (size_t)n : 1) != PFSPH_OK)
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory for %llu %s particles", name, (unsigned long long)n,
                          what);
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        if (pfsph__host_le()) {
            memcpy(ps->f[k], r->p + r->pos, (size_t)n * sizeof(pfsph_real));
            r->pos += (size_t)n * sizeof(pfsph_real);
        } else {
            for (size_t i = 0; i < n; i++) r_raw(r, &ps->f[k][i], sizeof(pfsph_real));
        }
    }
    memcpy(ps->phase, r->p + r->pos, (size_t)n);
    r->pos += (size_t)n;
    memcpy(ps->bubble, r->p + r->pos, (size_t)n);
    r->pos += (size_t)n;
    for (size_t i = 0; i < n; i++) ps->id[i] = r_u32(r);
    ps->n = (size_t)n;
    ps->next_id = next_id;
    for (size_t i = 0; i < ps->n; i++)
        if (ps->id[i] >= next_id) {
            const uint32_t id = ps->id[i]; /* read before the arrays go */
            pfsph_particles_free(ps);
            return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %s particle id %u not below next id %u", name,
                              what, id, next_id);
        }
    for (int k = 0; k < PFSPH_NFIELDS; k++)
        for (size_t i = 0; i < ps->n; i++)
            if (!isfinite((double)ps->f[k][i])) {
                const double v = (double)ps->f[k][i];
                pfsph_particles_free(ps);
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "%s: corrupt checkpoint: %s particle %zu has a non-finite "
                                  "field (%g)",
                                  name, what, i, v);
            }
    return PFSPH_OK;
}

/* The clock and counters against the scene: the frame within what a run can hold (and the
 * file name's frame when there is one), the time on that frame, finite non-negative rates. */
static int check_clock(const pfsph_scene *s, int32_t fr, long expect_frame, int32_t threads, const pfsph_sim_state *st,
                       const char *name, pfsph_error *err)
{
    if (fr < 0 || fr > PFSPH_MAX_FRAMES)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: frame %d is outside 0..%d", name, (int)fr,
                          PFSPH_MAX_FRAMES);
    if (expect_frame >= 0 && fr != expect_frame)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: it holds frame %d, its name says %ld", name,
                          (int)fr, expect_frame);
    if (!isfinite(st->time) || !(fabs(st->time * s->fps - fr) <= 1e-6 * (1 + fr)))
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: corrupt checkpoint: time %g s is not the time of frame %d at "
                          "%g fps",
                          name, st->time, (int)fr, s->fps);
    if (threads < 1 || threads > 65536)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: thread count %d", name, (int)threads);
    /* steps are at least dt_min long, except one shortened step per frame */
    if (s->dt_min > 0 && (double)st->step > st->time / s->dt_min + fr + 1)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %llu steps in %g s with dt_min %g s", name,
                          (unsigned long long)st->step, st->time, s->dt_min);
    const struct {
        const char *what;
        double v;
    } rates[] = {{"amax", st->amax},
                 {"amax_np", st->amax_np},
                 {"dt", st->stats.dt},
                 {"vmax", st->stats.vmax},
                 {"density_err_avg", st->stats.density_err_avg},
                 {"density_err_max", st->stats.density_err_max},
                 {"ekin", st->stats.ekin}};
    for (size_t k = 0; k < sizeof rates / sizeof rates[0]; k++)
        if (!(rates[k].v >= 0) || !isfinite(rates[k].v))
            return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %s is %g", name, rates[k].what, rates[k].v);
    if (st->stats.dt > s->dt_max * (1 + 1e-9))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: dt %g s above time.dt_max %g s", name,
                          st->stats.dt, s->dt_max);
    const double max_iter = pfsph_scene_solver_setting(s, "max_iterations"); /* NAN: not an iterative solver */
    if (st->stats.iterations < 0 || st->stats.iterations > (isnan(max_iter) ? 0 : max_iter))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %d pressure iterations", name,
                          (int)st->stats.iterations);
    for (int k = 0; k < PFSPH_NSTAGES; k++)
        if (!(st->stage_s[k] >= 0) || !isfinite(st->stage_s[k]))
            return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: stage seconds %g", name, st->stage_s[k]);
    return PFSPH_OK;
}

/* The emitters' states against the scene's nozzles, before the simulation is touched. */
static int check_emitters(const pfsph_emitters *E, int n, const pfsph_emitter_state *st, double t, const char *name,
                          pfsph_error *err)
{
    for (int i = 0; i < n; i++)
        if (pfsph_emitters_check_state(E, i, &st[i], t, err)) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %s", name, msg);
        }
    return PFSPH_OK;
}

static int decode(pfsph_sim *sim, const void *data, size_t len, const char *name, long expect_frame,
                  pfsph_checkpoint_info *info, pfsph_error *err)
{
    int rc;
    const unsigned char *b = data;
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    if (len < HEADER_LEN)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: truncated checkpoint (%zu bytes, the header alone is %d)", name, len,
                          HEADER_LEN);
    if (memcmp(b, MAGIC, 8) != 0) return pfsph_fail(err, PFSPH_EINPUT, "%s: not a pfsph checkpoint (bad magic)", name);
    rbuf r = {b, len, 8, 0};
    uint32_t version = r_u32(&r);
    uint32_t real_size = r_u32(&r);
    uint64_t hash = r_u64(&r);
    uint64_t payload = r_u64(&r);
    uint32_t pcrc = r_u32(&r);
    uint32_t hcrc = r_u32(&r);
    if ((uint32_t)crc32(crc32(0L, Z_NULL, 0), b, 36) != hcrc)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: header checksum mismatch", name);
    if (version != PFSPH_CHECKPOINT_VERSION)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: checkpoint format version %u, this pfsph reads version %u", name,
                          version, PFSPH_CHECKPOINT_VERSION);
    if (real_size != sizeof(pfsph_real))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: checkpoint written in %s precision, this pfsph is built for %s", name,
                          real_size == 8 ? "double" : "float", PFSPH_REAL_NAME);
    if (payload != len - HEADER_LEN)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: %s checkpoint: %zu bytes, the header says %llu", name,
                          len - HEADER_LEN < payload ? "truncated" : "corrupt", len,
                          (unsigned long long)(payload + HEADER_LEN));
    uint32_t crc = (uint32_t)crc32(0L, Z_NULL, 0);
    for (size_t off = HEADER_LEN; off < len;) {
        size_t n = len - off > (1u << 30) ? (1u << 30) : len - off;
        crc = (uint32_t)crc32(crc, b + off, (uInt)n);
        off += n;
    }
    if (crc != pcrc)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: checksum mismatch (CRC32 %08x, expected %08x)",
                          name, crc, pcrc);
    if (hash != pfsph_scene_hash(pfsph_sim_scene(sim)))
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: checkpoint belongs to another scene (scene hash %016llx, "
                          "this scene %016llx)",
                          name, (unsigned long long)hash, (unsigned long long)pfsph_scene_hash(pfsph_sim_scene(sim)));

    int32_t fr = r_i32(&r);
    int32_t threads = r_i32(&r);
    int32_t dim = r_i32(&r);
    uint32_t nph = r_u32(&r);
    pfsph_sim_state st;
    memset(&st, 0, sizeof st);
    st.time = r_f64(&r);
    st.step = r_u64(&r);
    st.amax = r_f64(&r);
    st.amax_np = r_f64(&r);
    st.removed = (size_t)r_u64(&r);
    st.stats.dt = r_f64(&r);
    st.stats.vmax = r_f64(&r);
    st.stats.density_err_avg = r_f64(&r);
    st.stats.density_err_max = r_f64(&r);
    st.stats.ekin = r_f64(&r);
    st.stats.iterations = r_i32(&r);
    uint32_t nst = r_u32(&r);
    for (uint32_t k = 0; k < nst && !r.bad; k++) {
        double v = r_f64(&r);
        if (k < PFSPH_NSTAGES) st.stage_s[k] = v;
    }
    if (r.bad || dim != c->dim || nph != (uint32_t)c->nphases || nst > 64)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: bad dimension (%d) or phase count (%u)", name,
                          (int)dim, nph);
    if ((rc = check_clock(pfsph_sim_scene(sim), fr, expect_frame, threads, &st, name, err))) return rc;
    pfsph_particles fluid, diff;
    memset(&diff, 0, sizeof diff);
    rc = r_set(&r, &fluid, name, "fluid", err);
    if (rc) return rc;
    /* fluid particles are added only by emitters: the ids are those the scene made, then one per
     * emitted particle (checked below, once the emitters' counts are read) */
    const int nem = pfsph_emitters_count(pfsph_sim_emitters(sim));
    if ((nem ? fluid.next_id < c->fluid->next_id : fluid.next_id != c->fluid->next_id) || st.removed > fluid.next_id) {
        rc = pfsph_fail(err, PFSPH_EINPUT,
                        "%s: corrupt checkpoint: fluid next id %u and %zu removed, the scene "
                        "makes %u fluid particles",
                        name, fluid.next_id, st.removed, c->fluid->next_id);
        pfsph_particles_free(&fluid);
        return rc;
    }
    uint8_t has_d = r_u8(&r);
    uint64_t created = 0, refused = 0;
    if (has_d) {
        created = r_u64(&r);
        refused = r_u64(&r);
        if ((rc = r_set(&r, &diff, name, "diffuse", err))) {
            pfsph_particles_free(&fluid);
            return rc;
        }
    }
    uint32_t nbod = r_u32(&r);
    pfsph_body_state *bst = NULL;
    uint32_t *bids = NULL;
    uint64_t nbid = 0;
    uint32_t nbp = 0;
    if (!r.bad && nbod > 0 && nbod <= PFSPH_MAX_BODIES) {
        nbp = r_u32(&r);
        bst = calloc(nbod, sizeof *bst);
        for (uint32_t i = 0; bst && i < nbod; i++) {
            for (int a = 0; a < 3; a++) bst[i].x[a] = r_f64(&r);
            for (int a = 0; a < 4; a++) bst[i].q[a] = r_f64(&r);
            for (int a = 0; a < 3; a++) bst[i].v[a] = r_f64(&r);
            for (int a = 0; a < 3; a++) bst[i].w[a] = r_f64(&r);
        }
        nbid = r_u64(&r);
        if (bst && !r.bad && nbid <= (r.len - r.pos) / 4) {
            bids = malloc((nbid ? nbid : 1) * sizeof *bids);
            for (uint64_t j = 0; bids && j < nbid; j++) bids[j] = r_u32(&r);
        } else r.bad = 1;
        if (!bst || !bids) r.bad = 1;
    } else if (nbod > PFSPH_MAX_BODIES) r.bad = 1;
    pfsph_emitter_state est[PFSPH_MAX_EMITTERS];
    uint64_t emitted = 0;
    if (nem && !r.bad) {
        if (r_u32(&r) != (uint32_t)nem) r.bad = 1;
        for (int i = 0; i < nem && !r.bad; i++) {
            est[i].debt = r_f64(&r);
            est[i].emitted = r_u64(&r);
            est[i].refused = r_u64(&r);
            est[i].pushed = r_u64(&r);
            emitted += est[i].emitted;
        }
    }
    if (r.bad || r.pos != r.len) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: payload length does not match its contents", name);
    } else if ((int)nbod != pfsph_bodies_count(pfsph_sim_bodies(sim))) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: checkpoint has %u bodies, the scene %d", name, nbod,
                        pfsph_bodies_count(pfsph_sim_bodies(sim)));
    } else if (nbod && nbp != pfsph_bodies_particle_count(pfsph_sim_bodies(sim))) {
        rc = pfsph_fail(err, PFSPH_EINPUT,
                        "%s: checkpoint has %u body particles, the scene makes %u (a mesh file "
                        "changed?)",
                        name, nbp, pfsph_bodies_particle_count(pfsph_sim_bodies(sim)));
    } else if (nem && (uint64_t)fluid.next_id != (uint64_t)c->fluid->next_id + emitted) {
        rc = pfsph_fail(err, PFSPH_EINPUT,
                        "%s: corrupt checkpoint: fluid next id %u, the scene makes %u fluid "
                        "particles and its emitters made %llu",
                        name, fluid.next_id, c->fluid->next_id, (unsigned long long)emitted);
    } else if (nem && check_emitters(pfsph_sim_emitters(sim), nem, est, st.time, name, err)) {
        rc = PFSPH_EINPUT;
    } else if ((has_d != 0) != (pfsph_sim_diffuse(sim) != NULL)) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: checkpoint %s diffuse particles but the scene has them %s", name,
                        has_d ? "has" : "has no", has_d ? "off" : "on");
    } else {
        rc = pfsph_sim_restore(sim, &st, &fluid, has_d ? &diff : NULL, created, refused, err);
        if (!rc && nbod) rc = pfsph_sim_restore_bodies(sim, (int)nbod, bst, bids, (size_t)nbid, err);
        if (!rc && nem) rc = pfsph_sim_restore_emitters(sim, nem, est, st.time, err);
        if (rc) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            pfsph_fail(err, rc, "%s: %s", name, msg);
        }
    }
    pfsph_particles_free(&fluid);
    if (has_d) pfsph_particles_free(&diff);
    free(bst);
    free(bids);
    if (!rc && info) {
        info->frame = fr;
        info->threads = threads;
        info->time = st.time;
        info->step = st.step;
    }
    return rc;
}

int pfsph_checkpoint_decode(pfsph_sim *sim, const void *data, size_t len, const char *name, pfsph_checkpoint_info *info,
                            pfsph_error *err)
{
    return decode(sim, data, len, name, -1, info, err);
}

/* ---- files ---- */

static long name_frame(const char *name);

static int save(const char *path, const pfsph_sim *sim, int frame, int durable, size_t *bytes, pfsph_error *err)
{
    pfsph__afile a;
    int rc = pfsph__afile_open(&a, path, err);
    if (rc) return rc;
    size_t len = 0;
    if ((rc = encode_file(sim, frame, a.f, path, &len, err))) {
        pfsph__afile_abort(&a);
        return rc;
    }
    rc = pfsph__afile_finish(&a, durable, err);
    if (!rc && bytes) *bytes = len;
    return rc;
}

int pfsph_checkpoint_save(const char *path, const pfsph_sim *sim, int frame, size_t *bytes, pfsph_error *err)
{
    return save(path, sim, frame, 1, bytes, err);
}

int pfsph_checkpoint_stash(const char *path, const pfsph_sim *sim, int frame, pfsph_error *err)
{
    return save(path, sim, frame, 0, NULL, err);
}

int pfsph_checkpoint_keep(const char *stash, const char *dest, pfsph_error *err)
{
    return pfsph__rename_durable(stash, dest, err);
}

int pfsph_checkpoint_load(const char *path, pfsph_sim *sim, pfsph_checkpoint_info *info, pfsph_error *err)
{
    unsigned char *data;
    size_t len;
    int rc = pfsph__read_file(path, &data, &len, err);
    if (rc) return rc;
    const char *base = strrchr(path, '/');
    rc = decode(sim, data, len, path, name_frame(base ? base + 1 : path), info, err);
    free(data);
    return rc;
}

void pfsph_checkpoint_path(char *buf, size_t cap, const char *run_dir, int frame)
{
    snprintf(buf, cap, "%s/checkpoints/ckpt_%05d.bin", run_dir, frame);
}

/* Frame of a checkpoint file name "ckpt_<digits>.bin", or -1. */
static long name_frame(const char *name)
{
    if (strncmp(name, "ckpt_", 5) != 0) return -1;
    const char *p = name + 5;
    long v = 0;
    int digits = 0;
    while (*p >= '0' && *p <= '9') {
        if (v > 100000000) return -1;
        v = v * 10 + (*p++ - '0');
        digits++;
    }
    if (!digits || strcmp(p, ".bin") != 0) return -1;
    return v;
}

static int cmp_desc(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return x < y ? 1 : x > y ? -1 : 0;
}

/* Frames of the checkpoints in RUN/checkpoints, newest first (malloc'ed; *n entries). */
static int list_checkpoints(const char *run_dir, long **out, size_t *n, pfsph_error *err)
{
    char dir[PFSPH_PATH_LEN + 64];
    snprintf(dir, sizeof dir, "%s/checkpoints", run_dir);
    *out = NULL;
    *n = 0;
    DIR *d = opendir(dir);
    if (!d) {
        if (errno == ENOENT) return PFSPH_OK;
        return pfsph_fail(err, PFSPH_EIO, "%s: cannot list: %s", dir, strerror(errno));
    }
    size_t cap = 0;
    long *v = NULL;
    struct dirent *e;
    while ((e = readdir(d))) {
        long f = name_frame(e->d_name);
        if (f < 0) continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 16;
            long *q = realloc(v, cap * sizeof(long));
            if (!q) {
                free(v);
                closedir(d);
                return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            }
            v = q;
        }
        v[(*n)++] = f;
    }
    closedir(d);
    if (*n) qsort(v, *n, sizeof(long), cmp_desc);
    *out = v;
    return PFSPH_OK;
}

int pfsph_checkpoint_write_run(const char *run_dir, const pfsph_sim *sim, int frame, int keep, size_t *bytes,
                               pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/checkpoints", run_dir);
    int rc = pfsph_mkdirs(path, err);
    if (rc) return rc;
    pfsph_checkpoint_path(path, sizeof path, run_dir, frame);
    if ((rc = pfsph_checkpoint_save(path, sim, frame, bytes, err))) return rc;
    long *frames;
    size_t n;
    if (list_checkpoints(run_dir, &frames, &n, err) != PFSPH_OK) return PFSPH_OK; /* saved; pruning is best effort */
    /* Keep the one just written and the keep - 1 newest older ones. Newer ones are stale: a
     * resume starts from the newest valid checkpoint, so any newer one was rejected. */
    size_t kept = 1;
    for (size_t i = 0; i < n; i++) {
        if (frames[i] == frame) continue;
        if (frames[i] < frame && kept < (size_t)(keep > 1 ? keep : 1)) {
            kept++;
            continue;
        }
        pfsph_checkpoint_path(path, sizeof path, run_dir, (int)frames[i]);
        unlink(path);
    }
    free(frames);
    return PFSPH_OK;
}

int pfsph_checkpoint_clear(const char *run_dir, pfsph_error *err)
{
    long *frames;
    size_t n;
    int rc = list_checkpoints(run_dir, &frames, &n, err);
    if (rc) return rc;
    char path[PFSPH_PATH_LEN + 64];
    for (size_t i = 0; i < n; i++) {
        pfsph_checkpoint_path(path, sizeof path, run_dir, (int)frames[i]);
        if (unlink(path) != 0 && errno != ENOENT) {
            rc = pfsph_fail(err, PFSPH_EIO, "%s: cannot remove: %s", path, strerror(errno));
            break;
        }
    }
    free(frames);
    return rc;
}

/* Remove temporaries "ckpt_*.bin.tmp.*" left by a writer that was killed (best effort). */
static void remove_temporaries(const char *run_dir)
{
    char dir[PFSPH_PATH_LEN + 64], path[2 * PFSPH_PATH_LEN];
    snprintf(dir, sizeof dir, "%s/checkpoints", run_dir);
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strncmp(e->d_name, "ckpt_", 5) == 0 && strstr(e->d_name, ".bin.tmp.")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    closedir(d);
}

int pfsph_checkpoint_resume(const char *run_dir, pfsph_sim *sim, pfsph_checkpoint_info *info, pfsph_message_fn warn,
                            void *user, pfsph_error *err)
{
    long *frames;
    size_t n;
    remove_temporaries(run_dir);
    int rc = list_checkpoints(run_dir, &frames, &n, err);
    if (rc) return rc;
    if (n == 0) {
        memset(info, 0, sizeof(*info));
        info->frame = -1;
        return PFSPH_OK;
    }
    char path[PFSPH_PATH_LEN + 64];
    for (size_t i = 0; i < n; i++) {
        pfsph_checkpoint_path(path, sizeof path, run_dir, (int)frames[i]);
        pfsph_error e = {0};
        rc = pfsph_checkpoint_load(path, sim, info, &e);
        if (rc == PFSPH_OK) {
            free(frames);
            return PFSPH_OK;
        }
        if (rc == PFSPH_ENOMEM) {
            free(frames);
            *err = e;
            return rc;
        }
        if (warn) {
            char msg[sizeof e.msg + 64];
            snprintf(msg, sizeof msg, "%s; %s", e.msg,
                     i + 1 < n ? "trying the previous checkpoint" : "no older checkpoint left");
            warn(msg, user);
        }
    }
    free(frames);
    snprintf(path, sizeof path, "%s/checkpoints", run_dir);
    return pfsph_fail(err, PFSPH_EINPUT, "%s: no valid checkpoint to resume from (all were rejected, see above)", path);
}
