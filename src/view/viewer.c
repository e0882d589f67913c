/* `pfsph view`: a window (GLFW, OpenGL 3.3 core) showing a scene simulated live or the frames
 * of a finished run. Live: the simulation steps on a worker thread with pfsph_sim_step (the code
 * `pfsph run` uses) and publishes a copy of its particles after every step into a triple
 * buffer; the main thread draws the newest copy, so the window stays responsive during a long
 * step. Changes of gravity and pair coefficients are queued and applied by the worker between
 * two steps. Replay: frames read with the VTP/PLY readers. docs/viewer.md. */
#define GLFW_INCLUDE_NONE
#include "view/view.h"

#include <GLFW/glfw3.h>
#include <dirent.h>
#include <epoxy/gl.h>
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/colormap.h"
#include "pfsph/bodies.h"
#include "pfsph/io.h"
#include "pfsph/meshing.h"
#include "pfsph/render.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "view/camera.h"
#include "view/draw.h"

const char *const pfsph_view_help =
    "usage: pfsph view [SCENE | RUN_DIR] [--size WxH] [--color-by FIELD] [--frame N]\n"
    "                  [--threads N] [--paused] [--screenshot FILE.png --frames N]\n"
    "                  [--dump DIR] [--hide walls,bodies,diffuse] [--no-overlay]\n"
    "                  [--samples 1|2] [--bench SECONDS] [--particles] [--all-walls]\n"
    "\n"
    "Live mode (SCENE, a JSON file; none: the embedded default scene): the scene is simulated\n"
    "in the window, step by step, as `pfsph run` does. Replay mode (RUN_DIR, a run directory):\n"
    "its frames are played with a time slider.\n"
    "\n"
    "  --size WxH         window size (default: the scene camera's, else 960x540)\n"
    "  --color-by FIELD   phase, speed, density or pressure (default: the scene camera's)\n"
    "  --frame N          replay: start at frame N\n"
    "  --threads N        OpenMP threads of the simulation (0: the default)\n"
    "  --paused           live: start paused\n"
    "  --screenshot FILE  draw --frames N frames (live: each after at least one new step),\n"
    "                     write the last as a PNG and exit; the window stays hidden\n"
    "  --frames N         frames to draw before the screenshot (default 1)\n"
    "  --dump DIR         with --screenshot: write the particles drawn (fluid.vtp, walls.vtp)\n"
    "  --hide LIST        start with these hidden: walls, bodies, diffuse (comma separated)\n"
    "  --no-overlay       no text, legend or slider\n"
    "  --samples 1|2      samples per pixel along each axis (default 2, as `pfsph render`;\n"
    "                     1 in a window on a software renderer, for speed)\n"
    "  --bench SECONDS    draw continuously for SECONDS, print frames/s and steps/s, exit\n"
    "  --particles        replay: start with particles where the run has liquid or body meshes\n"
    "  --all-walls        3D: keep the walls that face the camera (default: cut away)\n"
    "\n"
    "Mouse: left drag orbits (2D: pans), right or middle drag (or shift + left) pans, wheel\n"
    "zooms, ctrl + left drag pulls a rigid body (live; a dynamic one on a spring, a kinematic\n"
    "one without keyframes along the cursor); replay:\n"
    "click or drag the slider. Keys: space pause/play, N single step (live) or\n"
    "next frame, P previous frame, Home/End first/last frame, R reset, C colour field,\n"
    "W walls, B bodies, D diffuse, X cut-away of the walls facing the camera (3D), M meshes /\n"
    "particles (replay), F reset the camera, S save pfsph_view_NNN.png, H help, Esc or Q quit.\n"
    "Live only:\n"
    "G gravity on/off, [ and ] turn gravity by 15 degrees, Tab next phase pair, + and - raise\n"
    "or lower its coefficient / surface tension (x1.25) or contact angle (10 degrees).\n";

enum { BY_PHASE, BY_SPEED, BY_DENSITY, BY_PRESSURE, BY_COUNT };
static const char *const BY_NAME[BY_COUNT] = {"phase", "speed", "density", "pressure"};
static const char *const BY_UNIT[BY_COUNT] = {"", "M/S", "KG/M3", "PA"};

/* ---- particle sets of one drawn frame ------------------------------------------------- */

#define VIEW_MAX_BODIES 64
typedef struct vframe {
    pfsph_particles fluid, walls, bodies, diffuse;
    int nb;                        /* rigid bodies (live), at most VIEW_MAX_BODIES */
    double bx[VIEW_MAX_BODIES][3]; /* their centres */
    bool draggable[VIEW_MAX_BODIES];
    double time;
    uint64_t steps;
    int number; /* replay: the frame number */
    /* replay: the frame's liquid surface (frames/liquid_NNNNN.ply) and the bodies' meshes
     * (frames/surfaces_NNNNN.ply), ntris 0 where absent; mesh_new: not yet sent to the GPU */
    pfsph_surface_mesh liquid, bmesh;
    bool mesh_new;
} vframe;

static void vframe_free(vframe *f)
{
    pfsph_particles_free(&f->fluid);
    pfsph_particles_free(&f->walls);
    pfsph_particles_free(&f->bodies);
    pfsph_particles_free(&f->diffuse);
    pfsph_surface_mesh_free(&f->liquid);
    pfsph_surface_mesh_free(&f->bmesh);
}

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

/* ---- live mode: the simulation thread --------------------------------------------------- */

enum { CMD_GRAVITY, CMD_COEF, CMD_SIGMA, CMD_ANGLE, CMD_DRAG, CMD_RELEASE };
typedef struct vcmd {
    int kind, a, b;
    double v[3];
} vcmd;
#define MAX_CMDS 64

typedef struct live {
    pthread_t th;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    const pfsph_scene *scene0; /* as loaded: what reset goes back to */
    pfsph_sim *sim;
    int threads;
    vframe fr[3]; /* triple buffer: the worker's, the newest ready, the drawn one */
    int iw, ir, idr;
    bool fresh; /* fr[ir] is newer than fr[idr] */
    bool quit, paused, step_once, reset, end_noted;
    vcmd cmd[MAX_CMDS];
    int ncmd;
    bool failed;
    char msg[1200];     /* the last error or refusal, for the overlay */
    double sps;         /* steps per second, over the last half second */
    uint64_t published; /* snapshots published */
} live;

/* Snapshot of the simulation into f (worker thread, no lock needed: f is the worker's). */
static int publish_into(live *L, vframe *f)
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
    if (f->nb > VIEW_MAX_BODIES) f->nb = VIEW_MAX_BODIES;
    for (int i = 0; i < f->nb; i++) {
        pfsph_body_state bs;
        pfsph_bodies_get_state(B, i, &bs);
        memcpy(f->bx[i], bs.x, sizeof bs.x);
        f->draggable[i] = pfsph_bodies_draggable(B, i);
    }
    return rc;
}

static void publish(live *L)
{
    int rc = publish_into(L, &L->fr[L->iw]);
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
static void apply_cmds(live *L)
{
    for (int i = 0; i < L->ncmd; i++) {
        const vcmd *q = &L->cmd[i];
        pfsph_error err = {0};
        int rc = PFSPH_OK;
        switch (q->kind) {
        case CMD_GRAVITY: rc = pfsph_sim_set_gravity(L->sim, q->v, &err); break;
        case CMD_COEF: rc = pfsph_sim_set_pair_coefficient(L->sim, q->a, q->b, q->v[0], &err); break;
        case CMD_SIGMA: rc = pfsph_sim_set_pair_sigma(L->sim, q->a, q->b, q->v[0], &err); break;
        case CMD_DRAG: rc = pfsph_sim_drag_body(L->sim, q->a, q->v, &err); break;
        case CMD_RELEASE: rc = pfsph_sim_drag_body(L->sim, q->a, NULL, &err); break;
        default: rc = pfsph_sim_set_pair_contact_angle(L->sim, q->a, q->b, q->v[0], &err); break;
        }
        if (rc) snprintf(L->msg, sizeof L->msg, "refused: %s", err.msg);
    }
    L->ncmd = 0;
}

static void *live_main(void *arg)
{
    live *L = arg;
    if (L->threads > 0) omp_set_num_threads(L->threads);
    const pfsph_scene *s0 = L->scene0;
    const double fps = s0->fps > 0 ? s0->fps : 25;
    long frame = 0;
    double w0 = omp_get_wtime();
    uint64_t st0 = 0;
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
            w0 = omp_get_wtime();
            pthread_mutex_unlock(&L->mu);
            publish(L);
            pthread_mutex_lock(&L->mu);
            continue;
        }
        apply_cmds(L);
        if (L->failed || (L->paused && !L->step_once)) {
            L->sps = 0;
            pthread_cond_wait(&L->cv, &L->mu);
            w0 = omp_get_wtime();
            st0 = pfsph_sim_steps(L->sim);
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
            st0 = st;
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

static void live_post(live *L, const vcmd *q)
{
    pthread_mutex_lock(&L->mu);
    /* a new drag target replaces one not yet applied */
    if (q->kind == CMD_DRAG && L->ncmd > 0 && L->cmd[L->ncmd - 1].kind == CMD_DRAG && L->cmd[L->ncmd - 1].a == q->a)
        L->ncmd--;
    if (L->ncmd < MAX_CMDS) L->cmd[L->ncmd++] = *q;
    pthread_cond_broadcast(&L->cv);
    pthread_mutex_unlock(&L->mu);
}

/* ---- replay mode: the frames of a run directory --------------------------------------- */

typedef pfsph_frame_list flist;

typedef struct replay {
    char fdir[PFSPH_PATH_LEN + 16];
    flist fluid, bnd, dif, bod;
    int cur;        /* index into fluid */
    int loaded_bnd; /* frame number of the boundary file in memory, -1 none */
    bool playing;
    double next_t; /* wall time of the next frame while playing */
} replay;

static int read_set(const char *dir, const char *prefix, int num, bool ply, pfsph_particles *ps, double *t,
                    pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/%s%05d.%s", dir, prefix, num, ply ? "ply" : "vtp");
    pfsph_particles_free(ps);
    return ply ? pfsph_read_ply(path, ps, t, err) : pfsph_read_vtp(path, ps, t, err);
}

/* Load fluid frame index k (and the boundary, bodies and diffuse files of its number). */
static int replay_load(replay *R, int k, vframe *f, pfsph_error *err)
{
    int num = R->fluid.num[k];
    int rc = read_set(R->fdir, "fluid_", num, R->fluid.ply[k], &f->fluid, &f->time, err);
    if (rc) return rc;
    int bi = -1;
    for (int i = 0; i < R->bnd.n; i++)
        if (R->bnd.num[i] <= num) bi = i;
    if (bi >= 0 && R->bnd.num[bi] != R->loaded_bnd) {
        if ((rc = read_set(R->fdir, "boundary_", R->bnd.num[bi], R->bnd.ply[bi], &f->walls, NULL, err))) return rc;
        R->loaded_bnd = R->bnd.num[bi];
    }
    int ri = pfsph_frame_list_find(&R->bod, num), di = pfsph_frame_list_find(&R->dif, num);
    f->bodies.n = f->diffuse.n = 0;
    if (ri >= 0 && (rc = read_set(R->fdir, "bodies_", num, R->bod.ply[ri], &f->bodies, NULL, err))) return rc;
    if (di >= 0 && (rc = read_set(R->fdir, "diffuse_", num, R->dif.ply[di], &f->diffuse, NULL, err))) return rc;
    /* the meshes through the io layer's reader; a liquid without normals cannot be shaded as
     * water, so it counts as absent (as in `pfsph render`) */
    pfsph_surface_mesh_free(&f->liquid);
    pfsph_surface_mesh_free(&f->bmesh);
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/liquid_%05d.ply", R->fdir, num);
    if (access(path, F_OK) == 0) {
        if ((rc = pfsph_read_surface_ply(path, &f->liquid, NULL, err))) return rc;
        if (!f->liquid.n) pfsph_surface_mesh_free(&f->liquid);
    }
    snprintf(path, sizeof path, "%s/surfaces_%05d.ply", R->fdir, num);
    if (access(path, F_OK) == 0 && (rc = pfsph_read_surface_ply(path, &f->bmesh, NULL, err))) return rc;
    f->mesh_new = true;
    f->number = num;
    R->cur = k;
    return PFSPH_OK;
}

/* ---- the application -------------------------------------------------------------------- */

typedef struct opts {
    const char *input;
    int w, h;
    const char *color_by;
    int frame;
    int threads;
    bool paused, no_overlay, particles, all_walls;
    const char *screenshot, *dump;
    bool hide_walls, hide_bodies, hide_diffuse;
    int frames;
    int samples; /* 0: automatic */
    double bench;
} opts;

typedef struct app {
    opts o;
    pfsph_scene *scene; /* live: as loaded; replay: RUN_DIR/scene.json */
    bool is_live;
    live L;
    replay R;
    vframe rf; /* replay: the frame shown */
    const vframe *shown;
    pfsph_vcam cam, cam0;
    double depth; /* scene extent, for the clip planes */
    double vref;  /* speed colour scale */
    int by;
    bool show_walls, show_bodies, show_diffuse, show_help;
    bool show_surface;                  /* replay: meshes where the run has them (M toggles) */
    bool cut_walls;                     /* 3D: the walls facing the camera cut away (X toggles) */
    pfsph_vmesh *gl_liquid, *gl_bodies; /* the shown frame's meshes on the GPU */
    float *mv;                          /* vertex staging for the uploads */
    size_t mv_cap;
    int pair_a, pair_b; /* selected phase pair (live) */
    bool gravity_off;
    double g_saved[3];
    GLFWwindow *win;
    pfsph_vdraw *draw;
    pfsph_vsprite *spr;
    size_t spr_cap;
    bool dirty;     /* redraw needed */
    bool save_next; /* S pressed: write the next frame drawn */
    int saved;      /* screenshots written with S */
    double mx, my;  /* cursor, framebuffer pixels */
    bool drag_l, drag_r, slider_drag;
    int grab; /* body dragged with ctrl + left button, -1 none */
    double grab_depth;
    double fps; /* frames drawn per second, over the last half second */
    int fb_w, fb_h;
} app;

static double field(const pfsph_particles *ps, size_t i, int by)
{
    switch (by) {
    case BY_SPEED:
        return sqrt((double)ps->vx[i] * ps->vx[i] + (double)ps->vy[i] * ps->vy[i] + (double)ps->vz[i] * ps->vz[i]);
    case BY_DENSITY: return ps->rho[i];
    default: return ps->p[i];
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The renderer's colour range: 1st..99th percentile (speed from 0, or its fixed scale), here
 * over at most 65,536 evenly spaced particles so that a large frame costs little. */
static void field_range(const app *A, const pfsph_particles *ps, int by, double *lo, double *hi)
{
    *lo = 0;
    *hi = 1;
    if (by == BY_SPEED && A->vref > 0) {
        *hi = A->vref;
        return;
    }
    if (!ps->n) return;
    size_t stride = ps->n / 65536 + 1, m = 0;
    double *v = malloc((ps->n / stride + 1) * sizeof *v);
    if (!v) return;
    for (size_t i = 0; i < ps->n; i += stride) {
        double x = field(ps, i, by);
        if (isfinite(x)) v[m++] = x;
    }
    if (m) {
        qsort(v, m, sizeof *v, cmp_double);
        *lo = by == BY_SPEED ? 0.0 : v[(size_t)(0.01 * (double)(m - 1))];
        *hi = v[(size_t)(0.99 * (double)(m - 1))];
    }
    free(v);
    if (!(*hi > *lo)) *hi = *lo + (fabs(*lo) > 0 ? 1e-3 * fabs(*lo) : 1.0);
}

/* The renderer's fixed speed scale: free fall over the first frame's fluid height, or what
 * emitted fluid reaches when more. */
static double speed_scale(const pfsph_scene *sc, const pfsph_particles *fluid)
{
    double g2 = 0, ve = pfsph_scene_emitter_speed(sc);
    for (int k = 0; k < 3; k++) g2 += sc->gravity[k] * sc->gravity[k];
    if (!(g2 > 0) || fluid->n == 0) return ve;
    double g = sqrt(g2), lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < fluid->n; i++) {
        double h = -(fluid->x[i] * sc->gravity[0] + fluid->y[i] * sc->gravity[1] +
                     (sc->dim == 3 ? fluid->z[i] * sc->gravity[2] : 0.0)) /
            g;
        if (!isfinite(h)) continue;
        lo = fmin(lo, h);
        hi = fmax(hi, h);
    }
    return fmax(ve, hi > lo ? sqrt(2 * g * (hi - lo)) : 0);
}

static const float DIFFUSE_COL[3][3] = {{0.98f, 0.98f, 0.98f}, {0.80f, 0.82f, 0.85f}, {0.55f, 0.78f, 0.98f}};

/* kind: 0 fluid, 1 walls, 2 diffuse, 3 bodies (as the renderer colours them) */
static size_t add_sprites(app *A, size_t n0, const pfsph_particles *ps, double rad, double zoff, int kind, double lo,
                          double hi, const pfsph_cutaway *cw)
{
    const pfsph_scene *sc = A->scene;
    if (n0 + ps->n > A->spr_cap) {
        size_t cap = (n0 + ps->n) * 5 / 4 + 1024;
        pfsph_vsprite *q = realloc(A->spr, cap * sizeof *q);
        if (!q) return n0;
        A->spr = q;
        A->spr_cap = cap;
    }
    size_t m = n0;
    for (size_t i = 0; i < ps->n; i++) {
        pfsph_vsprite *s = &A->spr[m];
        s->x = (float)ps->x[i];
        s->y = (float)ps->y[i];
        s->z = (float)(sc->dim == 2 ? zoff : ps->z[i]);
        if (!isfinite(s->x) || !isfinite(s->y) || !isfinite(s->z)) continue;
        if (cw) {
            const double p[3] = {ps->x[i], ps->y[i], ps->z[i]};
            if (pfsph_cutaway_hides(cw, A->cam.eye, p)) continue;
        }
        s->r = (float)rad;
        s->pad = 0;
        float col[3] = {0.8f, 0.2f, 0.8f};
        int ph = ps->phase[i];
        if (kind == 1) {
            if (ph < sc->nphases && sc->phases[ph].color_set) memcpy(col, sc->phases[ph].color, sizeof col);
            else col[0] = 0.78f, col[1] = 0.78f, col[2] = 0.80f;
        } else if (kind == 2) {
            memcpy(col, DIFFUSE_COL[ph < 3 ? ph : 0], sizeof col);
        } else if (kind == 3 || A->by == BY_PHASE) {
            if (ph < sc->nphases) memcpy(col, sc->phases[ph].color, sizeof col);
        } else {
            pfsph__viridis((field(ps, i, A->by) - lo) / (hi - lo), col);
        }
        s->cr = col[0], s->cg = col[1], s->cb = col[2];
        m++;
    }
    return m;
}

static const float INK[4] = {0.08f, 0.09f, 0.12f, 1}, PANEL[4] = {1, 1, 1, 0.72f}, RED[4] = {0.75f, 0.1f, 0.1f, 1};

static void panel_text(app *A, float x, float y, float sc, const char *s, const float col[4])
{
    float w = 4 * sc * (float)strlen(s);
    pfsph_vdraw_rect(A->draw, x - sc, y - sc, w + sc, 7 * sc, PANEL);
    pfsph_vdraw_text(A->draw, x, y, sc, s, col);
}

static void fmt_num(char *b, size_t cap, double v)
{
    if (v != 0 && (fabs(v) >= 1e4 || fabs(v) < 1e-2)) snprintf(b, cap, "%.2e", v);
    else snprintf(b, cap, "%.3g", v);
}

/* The overlay: counts and clock, the selected pair, messages, legend, slider, help. */
static void overlay(app *A, double lo, double hi)
{
    const vframe *f = A->shown;
    const pfsph_scene *sc = A->scene;
    const float s = A->fb_h >= 500 ? 2.0f : 1.0f;
    const float lh = 8 * s;
    char line[1400];
    float y = 6 * s;
    if (A->is_live) {
        pthread_mutex_lock(&A->L.mu);
        double sps = A->L.sps;
        bool paused = A->L.paused, failed = A->L.failed;
        char msg[1200];
        snprintf(msg, sizeof msg, "%s", A->L.msg);
        const pfsph_scene *cur = pfsph_sim_scene(A->L.sim);
        double g[3] = {cur->gravity[0], cur->gravity[1], cur->gravity[2]};
        char pair[300] = "";
        if (cur->pairwise.enabled) {
            const pfsph_pairwise_params *pp = &cur->pairwise;
            int a = A->pair_a, b = A->pair_b;
            char v[32];
            if (pp->angle_set[a][b]) snprintf(v, sizeof v, "ANGLE %.0f DEG", pp->angle_deg[a][b]);
            else if (pp->sigma_set[a][b]) snprintf(v, sizeof v, "SIGMA %.3g N/M", pp->sigma[a][b]);
            else snprintf(v, sizeof v, "C");
            char cv[32];
            fmt_num(cv, sizeof cv, pp->c[a][b]);
            snprintf(pair, sizeof pair, "PAIR %s-%s: %s  C=%s", cur->phases[a].name, cur->phases[b].name,
                     strcmp(v, "C") ? v : "COEFFICIENT", cv);
        }
        pthread_mutex_unlock(&A->L.mu);
        char fps[32] = "";
        if (A->fps > 0) snprintf(fps, sizeof fps, "  %.0f FPS", A->fps); /* none yet in the first half second */
        snprintf(line, sizeof line, "LIVE  T=%.4f S  STEP %llu  %.1f STEPS/S%s%s", f->time,
                 (unsigned long long)f->steps, sps, fps,
                 failed       ? "  STOPPED"
                     : paused ? "  PAUSED"
                              : "");
        panel_text(A, 6 * s, y, s, line, INK);
        y += lh;
        snprintf(line, sizeof line, "G %.3g %.3g %.3g M/S2", g[0], g[1], g[2]);
        panel_text(A, 6 * s, y + 0 * lh, s, line, INK);
        y += lh;
        if (pair[0]) {
            panel_text(A, 6 * s, y, s, pair, INK);
            y += lh;
        }
        if (msg[0]) {
            /* long messages over several lines */
            size_t per = (size_t)((A->fb_w - 12 * s) / (4 * s));
            if (per < 20) per = 20;
            size_t len = strlen(msg);
            for (size_t o = 0; o < len && y < A->fb_h / 2; o += per) {
                snprintf(line, per + 1 < sizeof line ? per + 1 : sizeof line, "%s", msg + o);
                panel_text(A, 6 * s, y, s, line, failed ? RED : INK);
                y += lh;
            }
        }
    } else {
        char fps[32] = "";
        if (A->fps > 0) snprintf(fps, sizeof fps, "  %.0f FPS", A->fps);
        snprintf(line, sizeof line, "REPLAY  FRAME %d  (%d/%d)  T=%.4f S%s%s", f->number, A->R.cur + 1, A->R.fluid.n,
                 f->time, fps, A->R.playing ? "" : "  PAUSED");
        panel_text(A, 6 * s, y, s, line, INK);
        y += lh;
    }
    snprintf(line, sizeof line, "FLUID %zu  WALLS %zu  BODIES %zu  DIFFUSE %zu%s%s%s", f->fluid.n, f->walls.n,
             f->bodies.n, f->diffuse.n, A->show_walls ? "" : "  (WALLS HIDDEN)",
             A->show_bodies ? "" : "  (BODIES HIDDEN)", A->show_diffuse ? "" : "  (DIFFUSE HIDDEN)");
    panel_text(A, 6 * s, y, s, line, INK);
    const bool meshes = !A->is_live && sc->dim == 3 && (A->rf.liquid.ntris || A->rf.bmesh.ntris);
    if (meshes) {
        y += lh;
        snprintf(line, sizeof line, "MESHES: LIQUID %zu, BODIES %zu TRIANGLES  %s", A->rf.liquid.ntris,
                 A->rf.bmesh.ntris, A->show_surface ? "(M: PARTICLES)" : "HIDDEN (M: MESHES)");
        panel_text(A, 6 * s, y, s, line, INK);
    }

    /* legend, bottom right (none for a liquid drawn as water: the field does not colour it) */
    float lw = 120 * s, bx = A->fb_w - lw - 10 * s, by = A->fb_h - (A->is_live ? 14 : 26) * s;
    if (meshes && A->show_surface && A->rf.liquid.ntris && A->by != BY_PHASE) {
        /* nothing */
    } else if (A->by == BY_PHASE) {
        float yy = by;
        for (int p = sc->nphases - 1; p >= 0; p--) {
            if (sc->phases[p].kind == PFSPH_PHASE_SOLID && !sc->phases[p].color_set) continue;
            float col[4] = {sc->phases[p].color[0], sc->phases[p].color[1], sc->phases[p].color[2], 1};
            pfsph_vdraw_rect(A->draw, bx, yy, 6 * s, 5 * s, col);
            panel_text(A, bx + 9 * s, yy, s, sc->phases[p].name, INK);
            yy -= lh;
        }
        panel_text(A, bx, yy, s, "PHASE", INK);
    } else {
        pfsph_vdraw_rect(A->draw, bx - 2 * s, by - 2 * s, lw + 4 * s, 9 * s, PANEL);
        pfsph_vdraw_colorbar(A->draw, bx, by, lw, 5 * s);
        char a[32], b[32];
        fmt_num(a, sizeof a, lo);
        fmt_num(b, sizeof b, hi);
        panel_text(A, bx, by - lh, s, a, INK);
        panel_text(A, bx + lw - 4 * s * (float)strlen(b), by - lh, s, b, INK);
        snprintf(line, sizeof line, "%s [%s]", BY_NAME[A->by], BY_UNIT[A->by]);
        panel_text(A, bx, by - 2 * lh, s, line, INK);
    }
    /* replay: the time slider along the bottom */
    if (!A->is_live && A->R.fluid.n > 0) {
        float x0 = 10 * s, x1 = A->fb_w - 10 * s, yy = A->fb_h - 10 * s;
        const float track[4] = {0.3f, 0.32f, 0.38f, 0.8f}, knob[4] = {0.95f, 0.55f, 0.1f, 1};
        pfsph_vdraw_rect(A->draw, x0, yy, x1 - x0, 3 * s, track);
        double u = A->R.fluid.n > 1 ? (double)A->R.cur / (A->R.fluid.n - 1) : 0;
        pfsph_vdraw_rect(A->draw, (float)(x0 + u * (x1 - x0)) - 3 * s, yy - 3 * s, 6 * s, 9 * s, knob);
    }
    if (A->show_help) {
        const char *p = pfsph_view_help;
        const char *mouse = strstr(p, "Mouse:");
        float yy = A->fb_h / 2.0f;
        while (mouse && *mouse && yy < A->fb_h - 30 * s) {
            size_t l = strcspn(mouse, "\n");
            snprintf(line, l + 1 < sizeof line ? l + 1 : sizeof line, "%s", mouse);
            panel_text(A, 6 * s, yy, s, line, INK);
            yy += lh;
            mouse += l;
            if (*mouse) mouse++;
        }
    } else {
        panel_text(A, 6 * s, A->fb_h - (A->is_live ? 10 : 22) * s, s, "H: HELP", INK);
    }
}

/* Room for m floats in the staging array; false when out of memory. */
static bool mv_reserve(app *A, size_t m)
{
    if (m <= A->mv_cap) return true;
    float *q = realloc(A->mv, m * sizeof *q);
    if (!q) return false;
    A->mv = q;
    A->mv_cap = m;
    return true;
}

/* The replayed frame's meshes into their vertex buffers (once per frame loaded): the liquid
 * welded, with its smooth normals and an index buffer; the bodies as separate triangles with
 * each face's own normal (boxes keep their edges, as in the renderer) in their phase's colour. */
static void upload_meshes(app *A)
{
    vframe *f = &A->rf;
    f->mesh_new = false;
    if (!A->gl_liquid) A->gl_liquid = pfsph_vmesh_create();
    if (!A->gl_bodies) A->gl_bodies = pfsph_vmesh_create();
    if (!A->gl_liquid || !A->gl_bodies) return;
    const pfsph_surface_mesh *m = &f->liquid;
    if (m->ntris && m->n && mv_reserve(A, 9 * m->nverts)) {
        for (size_t i = 0; i < m->nverts; i++) {
            float *v = A->mv + 9 * i;
            for (int k = 0; k < 3; k++) v[k] = (float)m->v[3 * i + k], v[3 + k] = m->n[3 * i + k], v[6 + k] = 0;
        }
        pfsph_vmesh_upload(A->gl_liquid, A->mv, m->nverts, m->tri, 3 * m->ntris);
    } else {
        pfsph_vmesh_upload(A->gl_liquid, NULL, 0, NULL, 0);
    }
    m = &f->bmesh;
    const pfsph_scene *sc = A->scene;
    if (m->ntris && mv_reserve(A, 27 * m->ntris)) {
        for (size_t t = 0; t < m->ntris; t++) {
            const double *p[3];
            for (int k = 0; k < 3; k++) p[k] = m->v + 3 * m->tri[3 * t + k];
            double e1[3], e2[3], nn[3];
            for (int k = 0; k < 3; k++) e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k];
            nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
            nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
            nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
            double l = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            if (l > 0)
                for (int k = 0; k < 3; k++) nn[k] /= l;
            float col[3] = {0.8f, 0.2f, 0.8f};
            int b = m->phase[t];
            if (b < sc->nbodies && sc->bodies[b].phase >= 0 && sc->bodies[b].phase < sc->nphases)
                memcpy(col, sc->phases[sc->bodies[b].phase].color, sizeof col);
            for (int c = 0; c < 3; c++) {
                float *v = A->mv + 27 * t + 9 * c;
                for (int k = 0; k < 3; k++) v[k] = (float)p[c][k], v[3 + k] = (float)nn[k], v[6 + k] = col[k];
            }
        }
        pfsph_vmesh_upload(A->gl_bodies, A->mv, 3 * m->ntris, NULL, 0);
    } else {
        pfsph_vmesh_upload(A->gl_bodies, NULL, 0, NULL, 0);
    }
}

static void draw_frame(app *A)
{
    const vframe *f = A->shown;
    const pfsph_scene *sc = A->scene;
    const bool d2 = sc->dim == 2;
    const double r = sc->particle_radius > 0 ? sc->particle_radius : 0.01;
    float view[16], proj[16];
    pfsph_vcam_matrices(&A->cam, A->fb_w, A->fb_h, A->depth, view, proj);
    pfsph_vdraw_begin(A->draw, A->fb_w, A->fb_h, view, proj, A->cam.ortho, pfsph_vcam_focal(&A->cam, A->fb_h), !d2);
    double lo = 0, hi = 1;
    if (A->by != BY_PHASE) field_range(A, &f->fluid, A->by, &lo, &hi);
    /* radii as the renderer's: 2D fluid discs a little larger than the particle, walls smaller
     * and behind (4 r) */
    size_t n = 0;
    /* the renderer's cut-away, asked again for the eye of every frame drawn: orbiting round
     * the tank opens the side the camera is on */
    pfsph_cutaway cw;
    pfsph_cutaway_init(&cw, sc, A->cut_walls ? &f->walls : NULL);
    if (A->show_walls) n = add_sprites(A, 0, &f->walls, d2 ? 0.9 * r : r, -4 * r, 1, 0, 1, &cw);
    pfsph_vdraw_sprites(A->draw, 1, A->spr, n);
    /* meshes instead of particles where the run has them, as `pfsph render` does */
    if (f->mesh_new) upload_meshes(A);
    const bool liq = A->show_surface && !d2 && A->rf.liquid.ntris && !A->is_live;
    const bool bmesh = A->show_surface && !d2 && A->rf.bmesh.ntris && !A->is_live;
    n = liq ? 0 : add_sprites(A, 0, &f->fluid, d2 ? 1.3 * r : r, 0, 0, lo, hi, NULL);
    if (A->show_diffuse) n = add_sprites(A, n, &f->diffuse, 0.4 * r, 0, 2, 0, 1, NULL);
    if (A->show_bodies && !bmesh) n = add_sprites(A, n, &f->bodies, r, 0, 3, 0, 1, NULL);
    pfsph_vdraw_sprites(A->draw, 0, A->spr, n);
    if (liq) pfsph_vdraw_mesh(A->draw, A->gl_liquid, 1);
    if (bmesh && A->show_bodies) pfsph_vdraw_mesh(A->draw, A->gl_bodies, 0);
    pfsph_vdraw_composite(A->draw);
    if (!A->o.no_overlay) {
        overlay(A, lo, hi);
        pfsph_vdraw_overlay(A->draw);
    }
}

/* ---- input ---------------------------------------------------------------------------- */

static void next_pair(app *A)
{
    const pfsph_scene *s = A->scene;
    int np = s->nphases;
    for (int k = 0; k < np * np; k++) {
        A->pair_b++;
        if (A->pair_b >= np) {
            A->pair_a = (A->pair_a + 1) % np;
            A->pair_b = A->pair_a;
        }
        /* pairs that can act: not two solids */
        if (s->phases[A->pair_a].kind != PFSPH_PHASE_SOLID || s->phases[A->pair_b].kind != PFSPH_PHASE_SOLID) return;
    }
}

static void change_pair(app *A, int dir)
{
    pthread_mutex_lock(&A->L.mu);
    const pfsph_pairwise_params *pp = &pfsph_sim_scene(A->L.sim)->pairwise;
    int a = A->pair_a, b = A->pair_b;
    vcmd q = {CMD_COEF, a, b, {0, 0, 0}};
    if (!pp->enabled) {
        snprintf(A->L.msg, sizeof A->L.msg, "this scene has pair forces off (no \"pairwise\" block)");
        pthread_mutex_unlock(&A->L.mu);
        return;
    }
    if (pp->angle_set[a][b]) {
        q.kind = CMD_ANGLE;
        q.v[0] = fmin(180, fmax(0, pp->angle_deg[a][b] + 10 * dir));
    } else if (pp->sigma_set[a][b]) {
        q.kind = CMD_SIGMA;
        q.v[0] = pp->sigma[a][b] * (dir > 0 ? 1.25 : 0.8);
    } else {
        double c = pp->c[a][b];
        if (!(c > 0)) c = pp->c[a][a] > 0 ? 0.1 * pp->c[a][a] : 1e-3; /* something to grow from */
        q.v[0] = c * (dir > 0 ? 1.25 : 0.8);
    }
    pthread_mutex_unlock(&A->L.mu);
    live_post(&A->L, &q);
}

static void turn_gravity(app *A, double deg)
{
    pthread_mutex_lock(&A->L.mu);
    const double *g = pfsph_sim_scene(A->L.sim)->gravity;
    /* about the view axis: in the image plane, as tilting the container would */
    double ax[3] = {-A->cam.fwd[0], -A->cam.fwd[1], -A->cam.fwd[2]};
    if (A->scene->dim == 2) ax[0] = 0, ax[1] = 0, ax[2] = 1;
    double t = deg * 3.14159265358979323846 / 180, c = cos(t), s = sin(t);
    double d = ax[0] * g[0] + ax[1] * g[1] + ax[2] * g[2];
    double x[3] = {ax[1] * g[2] - ax[2] * g[1], ax[2] * g[0] - ax[0] * g[2], ax[0] * g[1] - ax[1] * g[0]};
    vcmd q = {CMD_GRAVITY, 0, 0, {0, 0, 0}};
    for (int k = 0; k < 3; k++) q.v[k] = g[k] * c + x[k] * s + ax[k] * d * (1 - c);
    pthread_mutex_unlock(&A->L.mu);
    live_post(&A->L, &q);
}

static void replay_goto(app *A, int k)
{
    if (k < 0) k = 0;
    if (k >= A->R.fluid.n) k = A->R.fluid.n - 1;
    if (k == A->R.cur) return;
    pfsph_error err = {0};
    if (replay_load(&A->R, k, &A->rf, &err)) fprintf(stderr, "pfsph: %s\n", err.msg);
    A->dirty = true;
}

static void on_key(GLFWwindow *w, int key, int sc, int action, int mods)
{
    (void)sc;
    (void)mods;
    app *A = glfwGetWindowUserPointer(w);
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    A->dirty = true;
    switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: glfwSetWindowShouldClose(w, 1); return;
    case GLFW_KEY_C: A->by = (A->by + 1) % BY_COUNT; return;
    case GLFW_KEY_W: A->show_walls = !A->show_walls; return;
    case GLFW_KEY_B: A->show_bodies = !A->show_bodies; return;
    case GLFW_KEY_D: A->show_diffuse = !A->show_diffuse; return;
    case GLFW_KEY_X: A->cut_walls = !A->cut_walls; return;
    case GLFW_KEY_M: A->show_surface = !A->show_surface; return;
    case GLFW_KEY_H: A->show_help = !A->show_help; return;
    case GLFW_KEY_F: A->cam = A->cam0; return;
    case GLFW_KEY_S: A->save_next = true; return;
    default: break;
    }
    if (!A->is_live) {
        switch (key) {
        case GLFW_KEY_SPACE:
            A->R.playing = !A->R.playing;
            A->R.next_t = glfwGetTime();
            break;
        case GLFW_KEY_N:
        case GLFW_KEY_RIGHT: replay_goto(A, A->R.cur + 1); break;
        case GLFW_KEY_P:
        case GLFW_KEY_LEFT: replay_goto(A, A->R.cur - 1); break;
        case GLFW_KEY_HOME:
        case GLFW_KEY_R: replay_goto(A, 0); break;
        case GLFW_KEY_END: replay_goto(A, A->R.fluid.n - 1); break;
        default: break;
        }
        return;
    }
    live *L = &A->L;
    switch (key) {
    case GLFW_KEY_SPACE:
        pthread_mutex_lock(&L->mu);
        L->paused = !L->paused;
        pthread_cond_broadcast(&L->cv);
        pthread_mutex_unlock(&L->mu);
        break;
    case GLFW_KEY_N:
    case GLFW_KEY_RIGHT:
        pthread_mutex_lock(&L->mu);
        L->paused = true;
        L->step_once = true;
        pthread_cond_broadcast(&L->cv);
        pthread_mutex_unlock(&L->mu);
        break;
    case GLFW_KEY_R:
        pthread_mutex_lock(&L->mu);
        L->reset = true;
        A->gravity_off = false;
        pthread_cond_broadcast(&L->cv);
        pthread_mutex_unlock(&L->mu);
        break;
    case GLFW_KEY_G: {
        vcmd q = {CMD_GRAVITY, 0, 0, {0, 0, 0}};
        pthread_mutex_lock(&L->mu);
        const double *g = pfsph_sim_scene(L->sim)->gravity;
        if (!A->gravity_off) memcpy(A->g_saved, g, sizeof A->g_saved);
        else memcpy(q.v, A->g_saved, sizeof q.v);
        A->gravity_off = !A->gravity_off;
        pthread_mutex_unlock(&L->mu);
        live_post(L, &q);
        break;
    }
    case GLFW_KEY_LEFT_BRACKET: turn_gravity(A, -15); break;
    case GLFW_KEY_RIGHT_BRACKET: turn_gravity(A, 15); break;
    case GLFW_KEY_TAB: next_pair(A); break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: change_pair(A, 1); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: change_pair(A, -1); break;
    default: break;
    }
}

static bool on_slider(const app *A, double x, double y)
{
    const float s = A->fb_h >= 500 ? 2.0f : 1.0f;
    (void)x;
    return !A->is_live && y > A->fb_h - 16 * s;
}

static void slider_set(app *A, double x)
{
    const float s = A->fb_h >= 500 ? 2.0f : 1.0f;
    double u = (x - 10 * s) / (A->fb_w - 20 * s);
    replay_goto(A, (int)lround(fmin(1, fmax(0, u)) * (A->R.fluid.n - 1)));
}

static void fb_pos(GLFWwindow *w, double *x, double *y)
{
    int ww, wh, fw, fh;
    glfwGetWindowSize(w, &ww, &wh);
    glfwGetFramebufferSize(w, &fw, &fh);
    if (ww > 0) *x *= (double)fw / ww;
    if (wh > 0) *y *= (double)fh / wh;
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    app *A = glfwGetWindowUserPointer(w);
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    fb_pos(w, &x, &y);
    A->mx = x;
    A->my = y;
    bool down = action == GLFW_PRESS;
    if (button == GLFW_MOUSE_BUTTON_LEFT && A->grab >= 0 && !down) {
        vcmd q = {CMD_RELEASE, A->grab, 0, {0, 0, 0}};
        live_post(&A->L, &q);
        A->grab = -1;
        return;
    }
    if (button == GLFW_MOUSE_BUTTON_LEFT && down && (mods & GLFW_MOD_CONTROL) && A->is_live) {
        /* the draggable body (dynamic, or kinematic without keyframes) whose centre is nearest
         * the cursor, within 80 pixels */
        const vframe *f = A->shown;
        double best = 80, bd = 0;
        int pick = -1;
        for (int i = 0; i < f->nb; i++) {
            double sx, sy, d;
            if (!f->draggable[i] || !pfsph_vcam_project(&A->cam, A->fb_w, A->fb_h, f->bx[i], &sx, &sy, &d)) continue;
            double r = hypot(sx - x, sy - y);
            if (r < best) best = r, pick = i, bd = d;
        }
        if (pick >= 0) {
            A->grab = pick;
            A->grab_depth = bd;
        } else {
            pthread_mutex_lock(&A->L.mu);
            snprintf(A->L.msg, sizeof A->L.msg,
                     "ctrl + drag: no body near the cursor (bodies moved by keyframes cannot be dragged)");
            pthread_mutex_unlock(&A->L.mu);
            A->dirty = true;
        }
        return;
    }
    if (button == GLFW_MOUSE_BUTTON_LEFT) {
        if (down && on_slider(A, x, y)) {
            A->slider_drag = true;
            slider_set(A, x);
            return;
        }
        A->slider_drag = false;
        A->drag_l = down && !(mods & GLFW_MOD_SHIFT);
        A->drag_r = down && (mods & GLFW_MOD_SHIFT);
    } else {
        A->drag_r = down;
    }
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    app *A = glfwGetWindowUserPointer(w);
    fb_pos(w, &x, &y);
    double dx = x - A->mx, dy = y - A->my;
    A->mx = x;
    A->my = y;
    if (A->grab >= 0) {
        vcmd q = {CMD_DRAG, A->grab, 0, {0, 0, 0}};
        pfsph_vcam_unproject(&A->cam, A->fb_w, A->fb_h, x, y, A->grab_depth, q.v);
        live_post(&A->L, &q);
    } else if (A->slider_drag) {
        slider_set(A, x);
    } else if (A->drag_l && !A->cam.ortho) {
        pfsph_vcam_orbit(&A->cam, dx * 0.008, dy * 0.008);
        A->dirty = true;
    } else if (A->drag_l || A->drag_r) {
        pfsph_vcam_pan(&A->cam, dx, dy, A->fb_h);
        A->dirty = true;
    }
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    app *A = glfwGetWindowUserPointer(w);
    pfsph_vcam_zoom(&A->cam, pow(1.12, dy));
    A->dirty = true;
}

static void on_glfw_error(int code, const char *desc)
{
    (void)code;
    fprintf(stderr, "pfsph: view: GLFW: %s\n", desc);
}

/* ---- the command ---------------------------------------------------------------------- */

static int usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "pfsph: view: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\nusage: see pfsph view --help\n");
    return 2;
}

static int parse_opts(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    o->frame = -1;
    o->frames = 1;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(pfsph_view_help, stdout);
            return 1;
        } else if (!strcmp(a, "--size")) {
            if (!v || sscanf(v, "%dx%d", &o->w, &o->h) != 2 || o->w < 16 || o->h < 16 || o->w > 8192 || o->h > 8192)
                return usage("--size: '%s' is not WxH (16..8192)", v ? v : "");
            i++;
        } else if (!strcmp(a, "--color-by")) {
            if (!v) return usage("%s needs a field", a);
            o->color_by = argv[++i];
        } else if (!strcmp(a, "--frame") || !strcmp(a, "--frames") || !strcmp(a, "--threads")) {
            char *end = NULL;
            long n = v ? strtol(v, &end, 10) : -1;
            if (!v || *end || n < 0 || n > 100000000 || (!strcmp(a, "--frames") && n < 1) ||
                (!strcmp(a, "--threads") && n > 1024))
                return usage(!strcmp(a, "--threads") ? "--threads: '%s' is not 0..1024"
                                                     : "'%s' is not a frame count or number",
                             v ? v : "");
            if (!strcmp(a, "--frame")) o->frame = (int)n;
            else if (!strcmp(a, "--frames")) o->frames = (int)n;
            else o->threads = (int)n;
            i++;
        } else if (!strcmp(a, "--screenshot") || !strcmp(a, "--dump")) {
            if (!v) return usage("%s needs a path", a);
            if (!strcmp(a, "--screenshot")) o->screenshot = v;
            else o->dump = v;
            i++;
        } else if (!strcmp(a, "--bench")) {
            char *end = NULL;
            o->bench = v ? strtod(v, &end) : -1;
            if (!v || *end || !(o->bench > 0 && o->bench <= 3600))
                return usage("--bench: '%s' is not 0..3600 seconds", v ? v : "");
            i++;
        } else if (!strcmp(a, "--hide")) {
            if (!v) return usage("%s needs a list: walls,bodies,diffuse", a);
            char buf[256];
            snprintf(buf, sizeof buf, "%s", v);
            for (char *t = strtok(buf, ","); t; t = strtok(NULL, ",")) {
                if (!strcmp(t, "walls")) o->hide_walls = true;
                else if (!strcmp(t, "bodies")) o->hide_bodies = true;
                else if (!strcmp(t, "diffuse")) o->hide_diffuse = true;
                else return usage("--hide: '%s' is not walls, bodies or diffuse", t);
            }
            i++;
        } else if (!strcmp(a, "--samples")) {
            if (!v || (strcmp(v, "1") && strcmp(v, "2"))) return usage("--samples: '%s' is not 1 or 2", v ? v : "");
            o->samples = atoi(v);
            i++;
        } else if (!strcmp(a, "--paused")) o->paused = true;
        else if (!strcmp(a, "--particles")) o->particles = true;
        else if (!strcmp(a, "--all-walls")) o->all_walls = true;
        else if (!strcmp(a, "--no-overlay")) o->no_overlay = true;
        else if (a[0] == '-') return usage("unknown option '%s'", a);
        else if (!o->input) o->input = a;
        else return usage("unexpected argument '%s'", a);
    }
    if (o->dump && !o->screenshot) return usage("%s", "--dump goes with --screenshot");
    if (o->screenshot && o->bench > 0) return usage("%s", "--screenshot and --bench: one at a time");
    return 0;
}

static int color_code(const char *s)
{
    if (!s || !*s) return BY_PHASE;
    for (int k = 0; k < BY_COUNT; k++)
        if (!strcmp(s, BY_NAME[k])) return k;
    return -1;
}

/* The frame just drawn as a PNG (the S key); prints where. */
static void save_png(app *A, const char *path)
{
    pfsph_error err = {0};
    uint8_t *rgb = malloc((size_t)A->fb_w * A->fb_h * 3);
    if (!rgb) return;
    pfsph_vdraw_read(A->draw, rgb);
    if (pfsph_write_png_rgb(path, rgb, A->fb_w, A->fb_h, &err)) fprintf(stderr, "pfsph: view: %s\n", err.msg);
    else printf("wrote %s\n", path);
    fflush(stdout);
    free(rgb);
}

static int write_outputs(app *A)
{
    pfsph_error err = {0};
    size_t bytes = (size_t)A->fb_w * A->fb_h * 3;
    uint8_t *rgb = malloc(bytes);
    if (!rgb) {
        fprintf(stderr, "pfsph: view: out of memory for the screenshot\n");
        return 1;
    }
    pfsph_vdraw_read(A->draw, rgb);
    int rc = pfsph_write_png_rgb(A->o.screenshot, rgb, A->fb_w, A->fb_h, &err);
    free(rgb);
    if (!rc && A->o.dump) {
        char p[PFSPH_PATH_LEN + 32];
        pfsph_io_opts io = {.dim = A->scene->dim, .write_id = true, .write_speed = true, .time = A->shown->time};
        if (!(rc = pfsph_mkdirs(A->o.dump, &err))) {
            snprintf(p, sizeof p, "%s/fluid.vtp", A->o.dump);
            rc = pfsph_write_vtp(p, &A->shown->fluid, &io, &err);
        }
        if (!rc) {
            snprintf(p, sizeof p, "%s/walls.vtp", A->o.dump);
            rc = pfsph_write_vtp(p, &A->shown->walls, &io, &err);
        }
    }
    if (rc) {
        fprintf(stderr, "pfsph: view: %s\n", err.msg);
        return 1;
    }
    printf("wrote %s (%dx%d, t = %.6g s, step %llu, %zu fluid particles)\n", A->o.screenshot, A->fb_w, A->fb_h,
           A->shown->time, (unsigned long long)A->shown->steps, A->shown->fluid.n);
    return 0;
}

/* Live mode with a screenshot: wait (up to 120 s) for a snapshot newer than the one drawn. */
static void wait_fresh(live *L)
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

static int run_window(app *A)
{
    const opts *o = &A->o;
    const bool headless = o->screenshot != NULL;
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        fprintf(stderr, "pfsph: view: cannot open a window (no display? set DISPLAY, or run under xvfb-run)\n");
        return 1;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, headless ? GLFW_FALSE : GLFW_TRUE);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_FALSE);
    char title[200];
    snprintf(title, sizeof title, "pfsph view: %s", A->scene->name[0] ? A->scene->name : A->scene->source);
    A->win = glfwCreateWindow(A->fb_w, A->fb_h, title, NULL, NULL);
    if (!A->win) {
        fprintf(stderr, "pfsph: view: cannot create an OpenGL 3.3 core window\n");
        glfwTerminate();
        return 1;
    }
    glfwMakeContextCurrent(A->win);
    glfwSwapInterval(o->bench > 0 || headless ? 0 : 1);
    char msg[1200] = "";
    A->draw = pfsph_vdraw_create(msg, sizeof msg);
    if (!A->draw) {
        fprintf(stderr, "pfsph: view: %s\n", msg);
        glfwDestroyWindow(A->win);
        glfwTerminate();
        return 1;
    }
    /* Screenshots take the renderer's 2 x 2 samples; a window on a software renderer 1, which
     * draws about 3x faster (docs/benchmarks.md) */
    int ss = o->samples ? o->samples : (!headless && pfsph_vdraw_software() ? 1 : 2);
    pfsph_vdraw_set_samples(A->draw, ss);
    glfwSetWindowUserPointer(A->win, A);
    glfwSetKeyCallback(A->win, on_key);
    glfwSetMouseButtonCallback(A->win, on_button);
    glfwSetCursorPosCallback(A->win, on_cursor);
    glfwSetScrollCallback(A->win, on_scroll);
    int status = 0, drawn = 0, fps_frames = 0;
    double fps_t0 = glfwGetTime(), bench_t0 = fps_t0;
    uint64_t bench_steps0 = A->shown->steps;
    const double fps_play = A->scene->fps > 0 ? A->scene->fps : 25;
    A->dirty = true;
    while (!glfwWindowShouldClose(A->win)) {
        if (!headless) {
            int fw, fh;
            glfwGetFramebufferSize(A->win, &fw, &fh);
            if (fw > 0 && fh > 0 && (fw != A->fb_w || fh != A->fb_h)) {
                A->fb_w = fw;
                A->fb_h = fh;
                A->dirty = true;
            }
        }
        if (A->is_live) {
            if (headless && drawn > 0) wait_fresh(&A->L);
            pthread_mutex_lock(&A->L.mu);
            if (A->L.fresh) {
                int t = A->L.idr;
                A->L.idr = A->L.ir;
                A->L.ir = t;
                A->L.fresh = false;
                A->dirty = true;
            }
            A->shown = &A->L.fr[A->L.idr];
            pthread_mutex_unlock(&A->L.mu);
        } else if (A->R.playing && glfwGetTime() >= A->R.next_t) {
            A->R.next_t += 1.0 / fps_play;
            if (A->R.next_t < glfwGetTime()) A->R.next_t = glfwGetTime() + 1.0 / fps_play; /* fell behind */
            if (A->R.cur + 1 < A->R.fluid.n) replay_goto(A, A->R.cur + 1);
            else A->R.playing = false;
        }
        if (A->dirty || headless || o->bench > 0) {
            A->dirty = false;
            draw_frame(A);
            if (!headless) {
                pfsph_vdraw_present(A->draw, A->fb_w, A->fb_h);
                glfwSwapBuffers(A->win);
            } else {
                glFinish();
            }
            drawn++;
            fps_frames++;
            double now = glfwGetTime();
            if (now - fps_t0 >= 0.5) {
                A->fps = fps_frames / (now - fps_t0);
                fps_frames = 0;
                fps_t0 = now;
            }
            if (A->save_next) {
                A->save_next = false;
                char name[64];
                snprintf(name, sizeof name, "pfsph_view_%03d.png", A->saved++);
                save_png(A, name);
            }
            if (headless && drawn >= o->frames) {
                status = write_outputs(A);
                break;
            }
            if (o->bench > 0 && now - bench_t0 >= o->bench) {
                uint64_t st = A->shown->steps;
                printf("bench: %zu fluid + %zu wall particles, %.1f frames/s drawn, %.2f simulation steps/s, "
                       "%dx%d, %d sample(s) per pixel, %s\n",
                       A->shown->fluid.n, A->shown->walls.n, drawn / (now - bench_t0),
                       (double)(st - bench_steps0) / (now - bench_t0), A->fb_w, A->fb_h, ss * ss,
                       (const char *)glGetString(GL_RENDERER));
                break;
            }
            glfwPollEvents();
        } else {
            /* nothing new: sleep until an event or the next replay frame, leaving the CPUs to
             * the simulation */
            glfwWaitEventsTimeout(A->is_live ? 0.005 : 0.01);
        }
    }
    pfsph_vmesh_destroy(A->gl_liquid);
    pfsph_vmesh_destroy(A->gl_bodies);
    A->gl_liquid = A->gl_bodies = NULL;
    pfsph_vdraw_destroy(A->draw);
    glfwDestroyWindow(A->win);
    glfwTerminate();
    return status;
}

static bool is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

int pfsph_view_main(int argc, char **argv)
{
    app *A = calloc(1, sizeof *A);
    if (!A) return 1;
    int rc = parse_opts(argc, argv, &A->o);
    if (rc) {
        free(A);
        return rc == 1 ? 0 : rc;
    }
    opts *o = &A->o;
    A->scene = malloc(sizeof *A->scene);
    pfsph_error err = {0};
    int status = 0;
    if (!A->scene) goto oom;
    A->is_live = !(o->input && is_dir(o->input));
    if (A->is_live && o->frame >= 0) {
        free(A->scene);
        free(A);
        return usage("%s", "--frame is for replay (a run directory)");
    }
    if (A->is_live) {
        rc = o->input ? pfsph_scene_load(A->scene, o->input, &err)
                      : pfsph_scene_parse(A->scene, pfsph_scene_default_json(), "<default scene>", &err);
    } else {
        char p[PFSPH_PATH_LEN + 32];
        if (strlen(o->input) >= PFSPH_PATH_LEN) {
            rc = pfsph_fail(&err, PFSPH_EINPUT, "%s: run directory path too long", o->input);
        } else {
            snprintf(p, sizeof p, "%s/scene.json", o->input);
            rc = pfsph_scene_load(A->scene, p, &err);
        }
    }
    /* a scene or run directory that cannot be read is bad input, as for `pfsph run` */
    if (rc == PFSPH_EIO) rc = PFSPH_EINPUT;
    if (rc) goto fail;
    A->by = color_code(o->color_by ? o->color_by : A->scene->camera.color_by);
    if (A->by < 0) {
        rc = pfsph_fail(&err, PFSPH_EINPUT, "--color-by '%s': expected phase, speed, density or pressure",
                        o->color_by ? o->color_by : A->scene->camera.color_by);
        goto fail;
    }
    A->fb_w = o->w > 0 ? o->w : (A->scene->camera.width > 0 ? A->scene->camera.width : 960);
    A->fb_h = o->h > 0 ? o->h : (A->scene->camera.height > 0 ? A->scene->camera.height : 540);
    A->grab = -1;
    A->show_walls = !o->hide_walls;
    A->show_bodies = !o->hide_bodies;
    A->show_diffuse = !o->hide_diffuse;
    A->show_surface = !o->particles;
    A->cut_walls = !o->all_walls;

    if (A->is_live) {
        live *L = &A->L;
        L->scene0 = A->scene;
        L->threads = o->threads;
        if (o->threads > 0) omp_set_num_threads(o->threads);
        if ((rc = pfsph_sim_create(&L->sim, A->scene, &err))) goto fail;
        L->iw = 0, L->ir = 1, L->idr = 2;
        L->paused = o->paused;
        /* the first snapshot, for the camera, before the worker starts */
        if (publish_into(L, &L->fr[L->idr])) goto oom;
        A->shown = &L->fr[L->idr];
        pthread_mutex_init(&L->mu, NULL);
        pthread_cond_init(&L->cv, NULL);
        const pfsph_scene *cur = pfsph_sim_scene(L->sim);
        if (cur->pairwise.enabled) {
            A->pair_a = 0;
            A->pair_b = -1;
            next_pair(A);
        }
    } else {
        replay *R = &A->R;
        snprintf(R->fdir, sizeof R->fdir, "%s/frames", o->input);
        R->loaded_bnd = -1;
        if (pfsph_frame_list_read(R->fdir, "fluid_", &R->fluid, &err) != PFSPH_OK) {
            rc = PFSPH_EINPUT;
            goto fail;
        }
        pfsph_error skip; /* the other sets are optional */
        pfsph_frame_list_read(R->fdir, "boundary_", &R->bnd, &skip);
        pfsph_frame_list_read(R->fdir, "diffuse_", &R->dif, &skip);
        pfsph_frame_list_read(R->fdir, "bodies_", &R->bod, &skip);
        if (R->fluid.n == 0) {
            rc = pfsph_fail(&err, PFSPH_EINPUT, "%s: no fluid_NNNNN.vtp or .ply frames", R->fdir);
            goto fail;
        }
        int k = 0;
        if (o->frame >= 0) {
            k = pfsph_frame_list_find(&R->fluid, o->frame);
            if (k < 0) {
                rc = pfsph_fail(&err, PFSPH_EINPUT, "--frame %d: %s has frames %d..%d and not this one", o->frame,
                                R->fdir, R->fluid.num[0], R->fluid.num[R->fluid.n - 1]);
                goto fail;
            }
        }
        /* the renderer frames the run by its first frame: load it for the camera first */
        if ((rc = replay_load(R, 0, &A->rf, &err))) goto fail;
        A->shown = &A->rf;
        R->playing = !o->paused && !o->screenshot && o->frame < 0;
        R->next_t = 0;
    }
    /* the renderer's camera for this frame size */
    pfsph_render_camera rc0;
    const vframe *f0 = A->shown;
    pfsph_render_camera_for(A->scene, &f0->fluid, f0->walls.n ? &f0->walls : NULL, A->fb_w, A->fb_h, &rc0);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    const pfsph_particles *sets[2] = {&f0->fluid, &f0->walls};
    for (int s = 0; s < 2; s++)
        for (size_t i = 0; i < sets[s]->n; i++) {
            const double p[3] = {sets[s]->x[i], sets[s]->y[i], sets[s]->z[i]};
            for (int k = 0; k < 3; k++)
                if (isfinite(p[k])) lo[k] = fmin(lo[k], p[k]), hi[k] = fmax(hi[k], p[k]);
        }
    double ctr[3] = {0, 0, 0};
    A->depth = 1;
    for (int k = 0; k < 3; k++)
        if (lo[k] <= hi[k]) {
            ctr[k] = 0.5 * (lo[k] + hi[k]);
            A->depth = fmax(A->depth, hi[k] - lo[k]);
        }
    for (int k = 0; k < 3; k++) A->depth = fmax(A->depth, A->scene->domain_max[k] - A->scene->domain_min[k]);
    pfsph_vcam_init(&A->cam, &rc0, ctr);
    A->cam0 = A->cam;
    A->vref = speed_scale(A->scene, &f0->fluid);
    if (!A->is_live && o->frame >= 0) {
        int k = pfsph_frame_list_find(&A->R.fluid, o->frame);
        if ((rc = replay_load(&A->R, k, &A->rf, &err))) goto fail;
    }

    if (A->is_live && pthread_create(&A->L.th, NULL, live_main, &A->L) != 0) {
        rc = pfsph_fail(&err, PFSPH_EIO, "cannot start the simulation thread");
        goto fail;
    }
    status = run_window(A);
    if (A->is_live) {
        pthread_mutex_lock(&A->L.mu);
        A->L.quit = true;
        pthread_cond_broadcast(&A->L.cv);
        pthread_mutex_unlock(&A->L.mu);
        pthread_join(A->L.th, NULL);
        if (A->L.failed && status == 0 && o->screenshot) {
            fprintf(stderr, "pfsph: view: %s\n", A->L.msg);
            status = 3;
        }
    }
    goto out;
oom:
    rc = pfsph_fail(&err, PFSPH_ENOMEM, "out of memory");
fail:
    fprintf(stderr, "pfsph: view: %s\n", err.msg);
    status = rc == PFSPH_EINPUT ? 2 : rc == PFSPH_EUNSTABLE ? 3 : 1;
out:
    if (A->is_live) {
        pfsph_sim_destroy(A->L.sim);
        for (int k = 0; k < 3; k++) vframe_free(&A->L.fr[k]);
    } else {
        vframe_free(&A->rf);
        pfsph_frame_list_free(&A->R.fluid);
        pfsph_frame_list_free(&A->R.bnd);
        pfsph_frame_list_free(&A->R.dif);
        pfsph_frame_list_free(&A->R.bod);
    }
    free(A->spr);
    free(A->mv);
    free(A->scene);
    free(A);
    return status;
}
