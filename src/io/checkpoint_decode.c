/* Reading checkpoints (docs/checkpoints.md): every check of a file, header, checksums, scene
 * hash, counts and values, before the simulation is touched, then the restore. */
#include "io/checkpoint_format.h"

#include "pfsph/bodies.h"
#include "pfsph/emitter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "io/io_internal.h"

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

int pfsph__checkpoint_check_set(const pfsph_particles *ps, size_t i0, const char *name, const char *what,
                                pfsph_error *err)
{
    for (size_t i = 0; i < ps->n; i++)
        if (ps->id[i] >= ps->next_id)
            return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %s particle id %u not below next id %u", name,
                              what, ps->id[i], ps->next_id);
    for (int k = 0; k < PFSPH_NFIELDS; k++)
        for (size_t i = 0; i < ps->n; i++)
            if (!isfinite((double)ps->f[k][i]))
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "%s: corrupt checkpoint: %s particle %zu has a non-finite "
                                  "field (%g)",
                                  name, what, i0 + i, (double)ps->f[k][i]);
    return PFSPH_OK;
}

/* Read a particle set; ps is initialised here (free with pfsph_particles_free). */
static int r_set(rbuf *r, pfsph_particles *ps, const char *name, const char *what, pfsph_error *err)
{
    memset(ps, 0, sizeof(*ps));
    uint64_t n = r_u64(r);
    uint32_t next_id = r_u32(r);
    const size_t per = PFSPH__CKPT_PER_PARTICLE;
    if (r->bad || n > (r->len - r->pos) / per)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: %s particle count %llu exceeds the file", name,
                          what, (unsigned long long)n);
    if (pfsph_particles_init(ps, (size_t)n ? (size_t)n : 1) != PFSPH_OK)
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory for %llu %s particles", name, (unsigned long long)n,
                          what);
    for (int k = 0; k < PFSPH__CKPT_ARRAYS; k++) {
        const void *p;
        const size_t es = pfsph__checkpoint_array(ps, k, 0, &p);
        if (pfsph__host_le() || es == 1) {
            memcpy((void *)p, r->p + r->pos, (size_t)n * es);
            r->pos += (size_t)n * es;
        } else {
            for (size_t i = 0; i < n; i++) r_raw(r, (char *)p + i * es, es);
        }
    }
    ps->n = (size_t)n;
    ps->next_id = next_id;
    int rc = pfsph__checkpoint_check_set(ps, 0, name, what, err);
    if (rc) pfsph_particles_free(ps);
    return rc;
}

/* The fluid's count and next id, its arrays elided (a reader of ranges: el->fluid holds this
 * process's range, read and checked by the caller). */
static int r_elided(rbuf *r, const pfsph__ckpt_elided *el, pfsph_particles *ps, const char *name, pfsph_error *err)
{
    uint64_t n = r_u64(r);
    uint32_t next_id = r_u32(r);
    if (r->bad || n != (el->file_len - r->len) / PFSPH__CKPT_PER_PARTICLE ||
        n * PFSPH__CKPT_PER_PARTICLE != el->file_len - r->len)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: fluid particle count %llu does not fit the file",
                          name, (unsigned long long)n);
    *ps = *el->fluid;
    ps->next_id = next_id;
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

int pfsph__checkpoint_read_elided(pfsph_sim *sim, const void *data, size_t len, const char *name, long expect_frame,
                                  const pfsph__ckpt_elided *el, pfsph_checkpoint_info *info, pfsph_error *err)
{
    int rc;
    const unsigned char *b = data;
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    if (len < PFSPH__CKPT_HEADER)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: truncated checkpoint (%zu bytes, the header alone is %d)", name, len,
                          PFSPH__CKPT_HEADER);
    if (memcmp(b, PFSPH__CKPT_MAGIC, 8) != 0)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: not a pfsph checkpoint (bad magic)", name);
    rbuf r = {b, len, 8, 0};
    uint32_t version = r_u32(&r);
    uint32_t real_size = r_u32(&r);
    uint64_t hash = r_u64(&r);
    uint64_t payload = r_u64(&r);
    uint32_t pcrc = r_u32(&r);
    uint32_t hcrc = r_u32(&r);
    if ((uint32_t)crc32(crc32(0L, Z_NULL, 0), b, 36) != hcrc)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint: header checksum mismatch", name);
    if (version < PFSPH_CHECKPOINT_VERSION)
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: checkpoint format version %u, written by an older pfsph (this one reads version %u "
                          "only): resume it with the pfsph that wrote it, or run the scene afresh",
                          name, version, PFSPH_CHECKPOINT_VERSION);
    if (version != PFSPH_CHECKPOINT_VERSION)
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: checkpoint format version %u, written by a newer pfsph (this one reads version %u)",
                          name, version, PFSPH_CHECKPOINT_VERSION);
    if (real_size != sizeof(pfsph_real))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: checkpoint written in %s precision, this pfsph is built for %s", name,
                          real_size == 8 ? "double" : "float", PFSPH_REAL_NAME);
    const uint64_t flen = el ? el->file_len : len; /* the file's length */
    if (payload != flen - PFSPH__CKPT_HEADER)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: %s checkpoint: %llu bytes, the header says %llu", name,
                          flen - PFSPH__CKPT_HEADER < payload ? "truncated" : "corrupt", (unsigned long long)flen,
                          (unsigned long long)(payload + PFSPH__CKPT_HEADER));
    uint32_t crc = el ? el->crc : (uint32_t)crc32(0L, Z_NULL, 0);
    for (size_t off = PFSPH__CKPT_HEADER; !el && off < len;) {
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
    rc = el ? r_elided(&r, el, &fluid, name, err) : r_set(&r, &fluid, name, "fluid", err);
    if (rc) return rc;
    /* fluid particles are added only by emitters: the ids are those the scene made, then one per
     * emitted particle (checked below, once the emitters' counts are read) */
    const int nem = pfsph_emitters_count(pfsph_sim_emitters(sim));
    if ((nem ? fluid.next_id < c->fluid->next_id : fluid.next_id != c->fluid->next_id) || st.removed > fluid.next_id) {
        rc = pfsph_fail(err, PFSPH_EINPUT,
                        "%s: corrupt checkpoint: fluid next id %u and %zu removed, the scene "
                        "makes %u fluid particles",
                        name, fluid.next_id, st.removed, c->fluid->next_id);
        if (!el) pfsph_particles_free(&fluid);
        return rc;
    }
    uint8_t has_d = r_u8(&r);
    uint64_t created = 0, refused = 0;
    if (has_d) {
        created = r_u64(&r);
        refused = r_u64(&r);
        if ((rc = r_set(&r, &diff, name, "diffuse", err))) {
            if (!el) pfsph_particles_free(&fluid);
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
    if (!el) pfsph_particles_free(&fluid);
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

int pfsph__checkpoint_read(pfsph_sim *sim, const void *data, size_t len, const char *name, long expect_frame,
                           pfsph_checkpoint_info *info, pfsph_error *err)
{
    return pfsph__checkpoint_read_elided(sim, data, len, name, expect_frame, NULL, info, err);
}

int pfsph_checkpoint_decode(pfsph_sim *sim, const void *data, size_t len, const char *name, pfsph_checkpoint_info *info,
                            pfsph_error *err)
{
    return pfsph__checkpoint_read(sim, data, len, name, -1, info, err);
}
