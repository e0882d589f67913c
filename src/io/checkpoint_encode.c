/* Writing checkpoints (docs/checkpoints.md): the 40-byte header and the payload, into memory
 * (pfsph_checkpoint_encode) or streamed into a file from the simulation's own arrays. */
#include "io/checkpoint_format.h"

#include "pfsph/bodies.h"
#include "pfsph/emitter.h"

#include <errno.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "io/io_internal.h"

/* The encoder writes either into one buffer (pfsph_checkpoint_encode) or through a small
 * staging buffer into a file, the particle arrays straight from the simulation: a checkpoint
 * written to disk then needs no copy of the state in memory (46 bytes per fluid particle, more
 * than a tenth of a run's peak at 493k particles). */
typedef struct wbuf {
    unsigned char *p;      /* the whole checkpoint (memory) or the staging buffer (sink) */
    size_t len;            /* bytes in p */
    pfsph__ckpt_sink sink; /* NULL: in memory */
    void *user;
    size_t flushed; /* bytes already sent to the sink */
    uint32_t crc;   /* running CRC32 of the bytes sent to the sink */
    int bad;        /* the sink failed (errno in err_no) */
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
    int e = w->sink(w->user, v, n);
    if (e) {
        w->bad = 1;
        w->err_no = e;
    }
    w->flushed += n;
}

static void w_flush(wbuf *w)
{
    if (w->sink && w->len) {
        w_send(w, w->p, w->len);
        w->len = 0;
    }
}

static void w_raw(wbuf *w, const void *v, size_t n)
{
    if (w->sink && w->len + n > STAGE_BYTES) w_flush(w);
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
    if (!w->sink) {
        if (n) memcpy(w->p + w->len, v, n);
        w->len += n;
        return;
    }
    w_flush(w);
    w_send(w, v, n);
}

static size_t set_bytes(size_t n) { return 8 + 4 + n * PFSPH__CKPT_PER_PARTICLE; }

size_t pfsph__checkpoint_array(const pfsph_particles *ps, int k, size_t i0, const void **p)
{
    if (k < PFSPH_NFIELDS) {
        *p = ps->f[k] + i0;
        return sizeof(pfsph_real);
    }
    if (k == PFSPH_NFIELDS) {
        *p = ps->phase + i0;
        return 1;
    }
    if (k == PFSPH_NFIELDS + 1) {
        *p = ps->bubble + i0;
        return 1;
    }
    *p = ps->id + i0;
    return 4;
}

/* the arrays of a set, each as the file holds it (little-endian) */
static void w_arrays(wbuf *w, const pfsph_particles *ps)
{
    for (int k = 0; k < PFSPH__CKPT_ARRAYS; k++) {
        const void *p;
        const size_t es = pfsph__checkpoint_array(ps, k, 0, &p);
        if (pfsph__host_le() || es == 1) {
            w_bulk(w, p, ps->n * es);
        } else {
            for (size_t i = 0; i < ps->n; i++) w_raw(w, (const char *)p + i * es, es);
        }
    }
}

static void w_set(wbuf *w, const pfsph_particles *ps)
{
    w_u64(w, ps->n);
    w_u32(w, ps->next_id);
    w_arrays(w, ps);
}

/* Payload size of sim's state. */
static size_t payload_bytes(const pfsph_sim *sim, uint64_t nfluid)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *df = pfsph_sim_diffuse(sim);
    size_t payload = 4 + 4 + 4 + 4 + 8 * 5 + 8 * 5 + 4 + 4 + 8 * PFSPH_NSTAGES + set_bytes((size_t)nfluid) + 1;
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

/* The payload up to the fluid's arrays: the clock, the stage seconds, the fluid's count and next id. */
static void w_head(wbuf *w, const pfsph_sim *sim, int frame, uint64_t nfluid)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    pfsph_sim_state st;
    pfsph_sim_get_state(sim, &st);
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
    w_u64(w, nfluid);
    w_u32(w, c->fluid->next_id);
}

/* The payload after the fluid's arrays: the diffuse set, the bodies, the emitters. */
static void w_tail(wbuf *w, const pfsph_sim *sim)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *df = pfsph_sim_diffuse(sim);
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    const int nbod = pfsph_bodies_count(B);
    const pfsph_emitters *E = pfsph_sim_emitters(sim);
    const int nem = pfsph_emitters_count(E);
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

/* The whole payload, after PFSPH__CKPT_HEADER bytes that w already holds or has sent. */
static void w_payload(wbuf *w, const pfsph_sim *sim, int frame)
{
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    w_head(w, sim, frame, f->n);
    w_arrays(w, f);
    w_tail(w, sim);
}

void pfsph__checkpoint_header(unsigned char *out, const pfsph_sim *sim, uint64_t payload, uint32_t pcrc)
{
    wbuf w = {out, 0, NULL, NULL, 0, 0, 0, 0};
    w_bulk(&w, PFSPH__CKPT_MAGIC, 8);
    w_u32(&w, PFSPH_CHECKPOINT_VERSION);
    w_u32(&w, (uint32_t)sizeof(pfsph_real));
    w_u64(&w, pfsph_scene_hash(pfsph_sim_scene(sim)));
    w_u64(&w, payload);
    w_u32(&w, pcrc);
    uint32_t hcrc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), out, 36);
    w_u32(&w, hcrc);
}

void pfsph__checkpoint_sizes(const pfsph_sim *sim, uint64_t nfluid, size_t *head, size_t *payload)
{
    *head = 4 + 4 + 4 + 4 + 8 * 5 + 8 * 5 + 4 + 4 + 8 * PFSPH_NSTAGES + 8 + 4; /* w_head */
    *payload = payload_bytes(sim, nfluid);
}

/* head or tail through a sink (the parts a writer of slices needs) */
static int w_part(const pfsph_sim *sim, int frame, uint64_t nfluid, int tail, pfsph__ckpt_sink sink, void *user,
                  uint32_t *crc, size_t *len)
{
    unsigned char *stage = malloc(STAGE_BYTES);
    if (!stage) return ENOMEM;
    wbuf w = {stage, 0, sink, user, 0, *crc, 0, 0};
    if (tail) w_tail(&w, sim);
    else w_head(&w, sim, frame, nfluid);
    w_flush(&w);
    free(stage);
    *crc = w.crc;
    if (len) *len = w.flushed;
    return w.bad ? w.err_no : 0;
}

int pfsph__checkpoint_head(const pfsph_sim *sim, int frame, uint64_t nfluid, pfsph__ckpt_sink sink, void *user,
                           uint32_t *crc)
{
    return w_part(sim, frame, nfluid, 0, sink, user, crc, NULL);
}

int pfsph__checkpoint_tail(const pfsph_sim *sim, pfsph__ckpt_sink sink, void *user, uint32_t *crc, size_t *len)
{
    return w_part(sim, 0, 0, 1, sink, user, crc, len);
}

int pfsph_checkpoint_encode(const pfsph_sim *sim, int frame, void **data, size_t *len, pfsph_error *err)
{
    *data = NULL;
    *len = 0;
    const size_t payload = payload_bytes(sim, pfsph_sim_ctx(sim)->fluid->n);
    const size_t total = PFSPH__CKPT_HEADER + payload;
    unsigned char *buf = malloc(total);
    if (!buf) return pfsph_fail(err, PFSPH_ENOMEM, "checkpoint: out of memory for %zu bytes", total);
    wbuf w = {buf, PFSPH__CKPT_HEADER, NULL, NULL, 0, 0, 0, 0};
    w_payload(&w, sim, frame);
    if (w.len != total) {
        free(buf);
        return pfsph_fail(err, PFSPH_EINPUT, "checkpoint: internal size mismatch (%zu != %zu)", w.len, total);
    }
    pfsph__checkpoint_header(buf, sim, payload,
                             crc_more((uint32_t)crc32(0L, Z_NULL, 0), buf + PFSPH__CKPT_HEADER, payload));
    *data = buf;
    *len = total;
    return PFSPH_OK;
}

static int file_sink(void *user, const void *p, size_t n)
{
    return fwrite(p, 1, n, (FILE *)user) == n ? 0 : errno ? errno : EIO;
}

/* The checkpoint into f (opened for writing at its start); *len its size. */
int pfsph__checkpoint_write(const pfsph_sim *sim, int frame, FILE *f, const char *path, size_t *len, pfsph_error *err)
{
    const size_t payload = payload_bytes(sim, pfsph_sim_ctx(sim)->fluid->n);
    const size_t total = PFSPH__CKPT_HEADER + payload;
    unsigned char *stage = malloc(STAGE_BYTES);
    if (!stage) return pfsph_fail(err, PFSPH_ENOMEM, "checkpoint: out of memory");
    unsigned char head[PFSPH__CKPT_HEADER] = {0};
    wbuf w = {stage, 0, file_sink, f, 0, 0, 0, 0};
    if (fwrite(head, 1, PFSPH__CKPT_HEADER, f) != PFSPH__CKPT_HEADER) w.bad = 1, w.err_no = errno ? errno : EIO;
    w.flushed = PFSPH__CKPT_HEADER;
    w.crc = (uint32_t)crc32(0L, Z_NULL, 0);
    w_payload(&w, sim, frame);
    w_flush(&w);
    free(stage);
    if (!w.bad && w.flushed != total)
        return pfsph_fail(err, PFSPH_EINPUT, "checkpoint: internal size mismatch (%zu != %zu)", w.flushed, total);
    if (!w.bad) {
        pfsph__checkpoint_header(head, sim, payload, w.crc);
        if (fseek(f, 0, SEEK_SET) != 0 || fwrite(head, 1, PFSPH__CKPT_HEADER, f) != PFSPH__CKPT_HEADER)
            w.bad = 1, w.err_no = errno ? errno : EIO;
    }
    if (w.bad) return pfsph_fail(err, PFSPH_EIO, "%s: write failed: %s", path, strerror(w.err_no));
    *len = total;
    return PFSPH_OK;
}
