/* Live mode (app.h): the simulation steps on a worker thread with pfsph_sim_step (the code
 * `pfsph run` uses) and publishes a copy of its particles after every step into a triple
 * buffer; the main thread draws the newest copy, so the window stays responsive during a long
 * step. Changes of gravity, pair coefficients and dragged bodies are queued and applied by the
 * worker between two steps. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "pfsph/bodies.h"
#include "view/app.h"

/* Copy the particles of s whose id is in [lo, hi) into d (d grows; NULL s empties d). */
static int set_copy(pfsph_particles *d, const pfsph_particles *s, uint32_t lo, uint32_t hi)
{
    d->n = 0;
    if (!s) return PFSPH_OK;
    if (!d->cap && pfsph_particles_init(d, s->n ? s->n : 1)) return PFSPH_ENOMEM;
    if (s->n > d->cap && pfsph_particles_reserve(d, s->n)) return PFSPH_ENOMEM;
    if (lo == 0 && hi == UINT32_MAX) {
        for (int k = 0; k < PFSPH_NFIELDS; k++)
            if (s->n) memcpy(d->f[k], s->f[k], s->n * sizeof(pfsph_real));
        if (s->n) {
            memcpy(d->phase, s->phase, s->n);
            memcpy(d->id, s->id, s->n * sizeof(uint32_t));
        }
        d->n = s->n;
        return PFSPH_OK;
    }
    size_t m = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (s->id[i] < lo || s->id[i] >= hi) continue;
        for (int k = 0; k < PFSPH_NFIELDS; k++) d->f[k][m] = s->f[k][i];
        d->phase[m] = s->phase[i];
        d->id[m] = s->id[i];
        m++;
    }
    d->n = m;
    return PFSPH_OK;
}

/* Snapshot of the simulation into f (worker thread, no lock needed: f is the worker's). */
int pfsph_vlive_publish_into(pfsph_vlive *L, pfsph_vframe *f)
{
    const pfsph_ctx *c = pfsph_sim_ctx(L->sim);
    const pfsph_bodies *B = pfsph_sim_bodies(L->sim);
    uint32_t b0 = B ? pfsph_bodies_first_id(B) : UINT32_MAX;
    int rc = set_copy(&f->fluid, c->fluid, 0, UINT32_MAX);
    if (!rc) rc = set_copy(&f->walls, c->boundary, 0, b0);
    if (!rc) rc = set_copy(&f->bodies, B ? c->boundary : NULL, b0, UINT32_MAX);
    if (!rc) rc = set_copy(&f->diffuse, pfsph_sim_diffuse(L->sim), 0, UINT32_MAX);
    f->time = pfsph_sim_time(L->sim);
    f->steps = pfsph_sim_steps(L->sim);
    f->nb = pfsph_bodies_count(B);
    if (f->nb > PFSPH_VMAX_BODIES) f->nb = PFSPH_VMAX_BODIES;
    for (int i = 0; i < f->nb; i++) {
        pfsph_body_state bs;
        pfsph_bodies_get_state(B, i, &bs);
        memcpy(f->bx[i], bs.x, sizeof bs.x);
        f->draggable[i] = pfsph_bodies_draggable(B, i);
    }
    return rc;
}

static void publish(pfsph_vlive *L)
{
    int rc = pfsph_vlive_publish_into(L, &L->fr[L->iw]);
    pthread_mutex_lock(&L->mu);
    if (rc) {
        L->failed = true;
        snprintf(L->msg, sizeof L->msg, "out of memory copying the particles");
    } else {
        int t = L->iw;
        L->iw = L->ir;
        L->ir = t;
        L->fresh = true;
        L->published++;
    }
    pthread_cond_broadcast(&L->cv);
    pthread_mutex_unlock(&L->mu);
}

/* Apply the queued changes (lock held): between two steps, so each acts from the next step. */
static void apply_cmds(pfsph_vlive *L)
{
    for (int i = 0; i < L->ncmd; i++) {
        const pfsph_vcmd *q = &L->cmd[i];
        pfsph_error err = {0};
        int rc = PFSPH_OK;
        switch (q->kind) {
        case PFSPH_VCMD_GRAVITY: rc = pfsph_sim_set_gravity(L->sim, q->v, &err); break;
        case PFSPH_VCMD_COEF: rc = pfsph_sim_set_pair_coefficient(L->sim, q->a, q->b, q->v[0], &err); break;
        case PFSPH_VCMD_SIGMA: rc = pfsph_sim_set_pair_sigma(L->sim, q->a, q->b, q->v[0], &err); break;
        case PFSPH_VCMD_DRAG: rc = pfsph_sim_drag_body(L->sim, q->a, q->v, &err); break;
        case PFSPH_VCMD_RELEASE: rc = pfsph_sim_drag_body(L->sim, q->a, NULL, &err); break;
        default: rc = pfsph_sim_set_pair_contact_angle(L->sim, q->a, q->b, q->v[0], &err); break;
        }
        if (rc) snprintf(L->msg, sizeof L->msg, "refused: %s", err.msg);
    }
    /* how long the oldest change waited for the step in progress (docs/viewer.md: a change acts
     * from the next step, so within a frame of 1-3 steps) */
    if (L->ncmd) {
        double lat = omp_get_wtime() - L->cmd_t0;
        L->applied += (uint64_t)L->ncmd;
        L->lat_last = lat;
        if (lat > L->lat_max) L->lat_max = lat;
        L->applied_step = pfsph_sim_steps(L->sim);
    }
    L->ncmd = 0;
}

void *pfsph_vlive_main(void *arg)
{
    pfsph_vlive *L = arg;
    if (L->threads > 0) omp_set_num_threads(L->threads);
    const pfsph_scene *s0 = L->scene0;
    const double fps = s0->fps > 0 ? s0->fps : 25;
    long frame = 0;
    double w0 = omp_get_wtime();
    uint64_t st0 = 0;
    double t0 = pfsph_sim_time(L->sim); /* simulated time at w0 */
    publish(L);
    pthread_mutex_lock(&L->mu);
    while (!L->quit) {
        if (L->reset) {
            L->reset = false;
            L->ncmd = 0;
            pfsph_sim *fresh = NULL;
            pfsph_error err = {0};
            pthread_mutex_unlock(&L->mu);
            int rc = pfsph_sim_create(&fresh, s0, &err);
            pthread_mutex_lock(&L->mu);
            if (rc) {
                snprintf(L->msg, sizeof L->msg, "reset failed: %s", err.msg);
                continue;
            }
            pfsph_sim_destroy(L->sim);
            L->sim = fresh;
            L->failed = false;
            L->end_noted = false;
            L->msg[0] = 0;
            frame = 0;
            st0 = 0;
            t0 = 0;
            w0 = omp_get_wtime();
            pthread_mutex_unlock(&L->mu);
            publish(L);
            pthread_mutex_lock(&L->mu);
            continue;
        }
        apply_cmds(L);
        if (L->failed || (L->paused && !L->step_once)) {
            L->sps = 0;
            L->rtf = 0;
            pthread_cond_wait(&L->cv, &L->mu);
            w0 = omp_get_wtime();
            st0 = pfsph_sim_steps(L->sim);
            t0 = pfsph_sim_time(L->sim);
            continue;
        }
        L->step_once = false;
        pthread_mutex_unlock(&L->mu);
        /* frame times as `pfsph run` lands on them, so that the steps are the same */
        const double tf = (double)(frame + 1) / fps;
        pfsph_error err = {0};
        int rc = PFSPH_OK;
        if (pfsph_sim_time(L->sim) < tf - 1e-12 * fmax(1.0, tf)) rc = pfsph_sim_step(L->sim, tf, &err);
        if (!rc && pfsph_sim_time(L->sim) >= tf - 1e-12 * fmax(1.0, tf)) {
            rc = pfsph_sim_advance(L->sim, tf, &err);
            frame++;
        }
        if (!rc) publish(L);
        double now = omp_get_wtime();
        pthread_mutex_lock(&L->mu);
        if (rc) {
            L->failed = true;
            snprintf(L->msg, sizeof L->msg, "%s", err.msg);
            continue;
        }
        if (now - w0 >= 0.5) {
            uint64_t st = pfsph_sim_steps(L->sim);
            L->sps = (double)(st - st0) / (now - w0);
            L->rtf = (pfsph_sim_time(L->sim) - t0) / (now - w0);
            st0 = st;
            t0 = pfsph_sim_time(L->sim);
            w0 = now;
        }
        if (!L->end_noted && pfsph_sim_time(L->sim) >= s0->end_time - 1e-12) {
            L->end_noted = true;
            L->paused = true;
            snprintf(L->msg, sizeof L->msg, "reached the scene's end time %g s; space continues", s0->end_time);
        }
    }
    pthread_mutex_unlock(&L->mu);
    return NULL;
}

void pfsph_vlive_post(pfsph_vlive *L, const pfsph_vcmd *q)
{
    pthread_mutex_lock(&L->mu);
    /* a new drag target replaces one not yet applied */
    if (q->kind == PFSPH_VCMD_DRAG && L->ncmd > 0 && L->cmd[L->ncmd - 1].kind == PFSPH_VCMD_DRAG &&
        L->cmd[L->ncmd - 1].a == q->a)
        L->ncmd--;
    if (!L->ncmd) L->cmd_t0 = omp_get_wtime();
    if (L->ncmd < PFSPH_VMAX_CMDS) L->cmd[L->ncmd++] = *q;
    pthread_cond_broadcast(&L->cv);
    pthread_mutex_unlock(&L->mu);
}

/* Live mode with a screenshot: wait (up to 120 s) for a snapshot newer than the one drawn. */
void pfsph_vlive_wait_fresh(pfsph_vlive *L)
{
    pthread_mutex_lock(&L->mu);
    double t0 = omp_get_wtime();
    while (!L->fresh && !L->failed && !L->paused && omp_get_wtime() - t0 < 120) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_nsec += 50000000;
        if (ts.tv_nsec >= 1000000000) ts.tv_sec++, ts.tv_nsec -= 1000000000;
        pthread_cond_timedwait(&L->cv, &L->mu, &ts);
    }
    pthread_mutex_unlock(&L->mu);
}
