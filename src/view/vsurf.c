/* Live mode's liquid surface (app.h): the library's reconstruction (pfsph_surface_reconstruct,
 * docs/surfaces.md; in 2D the outline, pfsph_surface_contour2d, drawn as a band) rebuilt on a worker thread of its own from a copy of the drawn snapshot's
 * fluid, at a marching cell chosen from the measured time of the last rebuilds so that one
 * rebuild fits a 1/30 s frame; the simulation never waits for it. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "view/app.h"

/* Marching cells (/ d) from fine to coarse; the field and the marching scale with the cells on
 * the surface, (1 / cell)^2, the kernels (PCA) with the particles. */
static const double CELL[PFSPH_VSURF_LEVELS] = {0.5, 0.75, 1.0, 1.25};

/* Phases drawn as a surface: fluids and gases (each gas a closed region of its own, a bubble). */
bool pfsph_vsurf_meshes_phase(const pfsph_scene *sc, int ph)
{
    return ph >= 0 && ph < sc->nphases && sc->phases[ph].kind != PFSPH_PHASE_SOLID;
}

/* Adapt the level to the rebuild just measured (lock held): coarser at once when over the
 * budget, finer after five rebuilds that would fit at the finer cell too; at the coarsest level,
 * three rebuilds in a row over the budget give up (particles) until a retry 5 s later. */
static void adapt(pfsph_vsurf *S, double sec)
{
    S->last_s = sec;
    S->avg_s = S->nbuilt ? 0.7 * S->avg_s + 0.3 * sec : sec;
    S->nbuilt++;
    double now = omp_get_wtime();
    if (now - S->rate_t0 >= 0.5) {
        S->rate = (double)(S->nbuilt - S->rate_n0) / (now - S->rate_t0);
        S->rate_t0 = now;
        S->rate_n0 = S->nbuilt;
    }
    S->cell = CELL[S->level];
    if (sec > S->budget) {
        S->under = 0;
        if (S->level + 1 < PFSPH_VSURF_LEVELS) S->level++;
        else if (++S->over >= 3) {
            S->gave_up = true;
            S->retry_at = omp_get_wtime() + 5.0;
            S->over = 0;
        }
        return;
    }
    S->over = 0;
    /* the finer cell's cost: about (c / c_finer)^2 of the surface part, which is at most the
     * whole: finer when even that fits in 60 % of the budget */
    if (S->level > 0) {
        double r = CELL[S->level] / CELL[S->level - 1];
        if (sec * r * r < 0.6 * S->budget) {
            if (++S->under >= 5) {
                S->level--;
                S->under = 0;
            }
        } else {
            S->under = 0;
        }
    }
}

/* 2D: the outline (pfsph_surface_contour2d) as a band of triangles of half-width w along the
 * vertex normals, in the plane z, so that the mesh path draws it over the particles. */
static int contour_band(const double *x, const uint8_t *ph, size_t n, const pfsph_surface_opts *o, double w, double z,
                        pfsph_surface_mesh *m, pfsph_error *err)
{
    pfsph_surface_contour c;
    int rc = pfsph_surface_contour2d(x, ph, n, o, &c, err);
    if (rc) return rc;
    m->nverts = 2 * c.nverts;
    m->ntris = 2 * c.nsegs;
    m->v = malloc((m->nverts ? m->nverts : 1) * 3 * sizeof *m->v);
    m->n = malloc((m->nverts ? m->nverts : 1) * 3 * sizeof *m->n);
    m->tri = malloc((m->ntris ? m->ntris : 1) * 3 * sizeof *m->tri);
    m->phase = malloc(m->ntris ? m->ntris : 1);
    if (!m->v || !m->n || !m->tri || !m->phase) {
        pfsph_surface_contour_free(&c);
        pfsph_surface_mesh_free(m);
        memset(m, 0, sizeof *m);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    }
    for (size_t i = 0; i < c.nverts; i++)
        for (int side = 0; side < 2; side++) {
            double sg = side ? w : -w;
            double *v = m->v + 3 * (2 * i + (size_t)side);
            v[0] = c.v[3 * i] + sg * c.n[3 * i];
            v[1] = c.v[3 * i + 1] + sg * c.n[3 * i + 1];
            v[2] = z;
            float *nn = m->n + 3 * (2 * i + (size_t)side);
            nn[0] = nn[1] = 0, nn[2] = 1; /* facing the camera: flat */
        }
    for (size_t sgi = 0; sgi < c.nsegs; sgi++) {
        uint32_t a = 2 * c.seg[2 * sgi], b = 2 * c.seg[2 * sgi + 1];
        uint32_t *t = m->tri + 6 * sgi;
        t[0] = a, t[1] = b, t[2] = b + 1, t[3] = a, t[4] = b + 1, t[5] = a + 1;
        m->phase[2 * sgi] = m->phase[2 * sgi + 1] = c.phase[sgi];
    }
    pfsph_surface_contour_free(&c);
    return PFSPH_OK;
}

static void *worker(void *arg)
{
    pfsph_vsurf *S = arg;
    omp_set_num_threads(1); /* one core at most: the simulation keeps the others */
    pthread_mutex_lock(&S->mu);
    while (!S->quit) {
        if (!S->job) {
            pthread_cond_wait(&S->cv, &S->mu);
            continue;
        }
        pfsph_surface_opts o;
        pfsph_surface_opts_default(&o, S->spacing);
        o.cell = CELL[S->level];
        const int level = S->level;
        pthread_mutex_unlock(&S->mu);
        pfsph_surface_mesh *m = &S->mesh[S->iw];
        pfsph_surface_mesh_free(m);
        memset(m, 0, sizeof *m);
        pfsph_error err = {0};
        double t0 = omp_get_wtime();
        int rc = !S->n    ? PFSPH_OK
            : S->dim == 2 ? contour_band(S->x, S->ph, S->n, &o, 0.25 * S->spacing, S->spacing, m, &err)
                          : pfsph_surface_reconstruct(S->x, S->ph, S->n, &o, m, &err);
        double sec = omp_get_wtime() - t0;
        pthread_mutex_lock(&S->mu);
        S->job = false;
        if (rc) {
            pfsph_surface_mesh_free(m);
            memset(m, 0, sizeof *m);
            snprintf(S->msg, sizeof S->msg, "surface: %s", err.msg);
            S->failed = true;
        } else {
            S->mesh_time[S->iw] = S->job_time;
            S->mesh_cell[S->iw] = CELL[level];
            int t = S->iw;
            S->iw = S->ir;
            S->ir = t;
            S->fresh = true;
            if (S->n) adapt(S, sec);
            S->next_post = S->post_wall + fmax(1.0 / 30, 2 * sec);
        }
        pthread_cond_broadcast(&S->cv);
    }
    pthread_mutex_unlock(&S->mu);
    return NULL;
}

int pfsph_vsurf_start(pfsph_vsurf *S, const pfsph_scene *sc)
{
    memset(S, 0, sizeof *S);
    S->spacing = 2 * sc->particle_radius;
    S->dim = sc->dim;
    S->budget = 1.0 / 30;
    S->ir = 1;
    S->posted_time = -1;
    if (pthread_mutex_init(&S->mu, NULL)) return -1;
    if (pthread_cond_init(&S->cv, NULL)) {
        pthread_mutex_destroy(&S->mu);
        return -1;
    }
    if (pthread_create(&S->th, NULL, worker, S)) {
        pthread_cond_destroy(&S->cv);
        pthread_mutex_destroy(&S->mu);
        return -1;
    }
    S->started = true;
    return 0;
}

void pfsph_vsurf_stop(pfsph_vsurf *S)
{
    if (!S->started) return;
    pthread_mutex_lock(&S->mu);
    S->quit = true;
    pthread_cond_broadcast(&S->cv);
    pthread_mutex_unlock(&S->mu);
    pthread_join(S->th, NULL);
    pthread_cond_destroy(&S->cv);
    pthread_mutex_destroy(&S->mu);
    for (int k = 0; k < 2; k++) pfsph_surface_mesh_free(&S->mesh[k]);
    free(S->x);
    free(S->ph);
    S->started = false;
}

/* Hand the drawn snapshot's liquid to the worker when it is idle and the snapshot is newer than
 * the last one handed over (main thread; the copy takes about 0.1 ms per 10k particles). */
bool pfsph_vsurf_post(pfsph_vsurf *S, const pfsph_scene *sc, const pfsph_vframe *f)
{
    bool posted = false;
    pthread_mutex_lock(&S->mu);
    if (S->gave_up && omp_get_wtime() >= S->retry_at) S->gave_up = false;
    /* at most one rebuild per 1/30 s, and a core at most half busy with them (the next one
     * not before twice the last one's time after its start): the simulation keeps the rest;
     * a screenshot (sync) waits for every frame's mesh instead */
    const double now = omp_get_wtime();
    const bool due = S->sync || now >= S->next_post;
    if (!S->job && due && !S->gave_up && !S->failed && (f->steps != S->posted_steps || f->time != S->posted_time)) {
        const pfsph_particles *ps = &f->fluid;
        if (ps->n > S->cap) {
            double *x = realloc(S->x, 3 * ps->n * sizeof *x);
            uint8_t *ph = x ? realloc(S->ph, ps->n) : NULL;
            if (x) S->x = x;
            if (ph) S->ph = ph;
            if (x && ph) S->cap = ps->n;
        }
        if (ps->n <= S->cap) {
            size_t m = 0;
            for (size_t i = 0; i < ps->n; i++) {
                if (!pfsph_vsurf_meshes_phase(sc, ps->phase[i])) continue;
                if (!isfinite(ps->x[i]) || !isfinite(ps->y[i]) || !isfinite(ps->z[i])) continue;
                S->x[3 * m] = ps->x[i];
                S->x[3 * m + 1] = ps->y[i];
                S->x[3 * m + 2] = ps->z[i];
                S->ph[m++] = ps->phase[i];
            }
            S->n = m;
            S->job = true;
            S->job_time = f->time;
            S->posted_steps = f->steps;
            S->posted_time = f->time;
            S->post_wall = now;
            posted = true;
            pthread_cond_broadcast(&S->cv);
        }
    }
    pthread_mutex_unlock(&S->mu);
    return posted;
}

/* Wait until the worker has finished what it was handed (screenshots: the mesh of the frame). */
void pfsph_vsurf_wait(pfsph_vsurf *S)
{
    pthread_mutex_lock(&S->mu);
    while (S->job) pthread_cond_wait(&S->cv, &S->mu);
    pthread_mutex_unlock(&S->mu);
}

/* The newest finished mesh, if newer than the one taken last: swapped into *out (main thread;
 * *out's old mesh goes back to the worker to be freed). */
bool pfsph_vsurf_take(pfsph_vsurf *S, pfsph_surface_mesh *out, double *time, double *cell)
{
    bool got = false;
    pthread_mutex_lock(&S->mu);
    if (S->fresh) {
        pfsph_surface_mesh t = *out;
        *out = S->mesh[S->ir];
        S->mesh[S->ir] = t;
        *time = S->mesh_time[S->ir];
        *cell = S->mesh_cell[S->ir];
        S->fresh = false;
        got = true;
    }
    pthread_mutex_unlock(&S->mu);
    return got;
}
