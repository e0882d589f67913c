/* `pfsph view`: a window (GLFW, OpenGL 3.3 core) showing a scene simulated live or the frames
 * of a finished run (docs/viewer.md). This file: the command (options, setup of the scene, the
 * simulation or the run's frames, the camera; teardown); the rest is in app.h's files. */
#include "view/view.h"

#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "io/colormap.h"
#include "pfsph/render.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "view/app.h"

const char *const pfsph_view_help =
    "usage: pfsph view [SCENE | RUN_DIR] [--size WxH] [--color-by FIELD] [--frame N]\n"
    "                  [--threads N] [--paused] [--screenshot FILE.png --frames N]\n"
    "                  [--dump DIR] [--hide walls,bodies,diffuse] [--no-overlay]\n"
    "                  [--samples 1|2] [--bench SECONDS] [--particles] [--all-walls]\n"
    "                  [--surface-budget MS] [--press KEYS] [--max-fps N]\n"
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
    "  --particles        start with particles (replay: where the run has meshes; live:\n"
    "                     instead of the liquid's surface)\n"
    "  --surface-budget MS  live: the time one rebuild of the surface may take (default\n"
    "                     33.3, a 1/30 s frame; a screenshot: no limit, the finest cell)\n"
    "  --press KEYS       press these keys, one per frame drawn after the first (M, G, ...)\n"
    "  --max-fps N        draw at most N frames a second in the window (default 60; 0: no\n"
    "                     limit): on a software renderer every frame drawn is CPU taken\n"
    "                     from the simulation\n"
    "  --all-walls        3D: keep the walls that face the camera (default: cut away)\n"
    "\n"
    "Mouse: left drag orbits (2D: pans), right or middle drag (or shift + left) pans, wheel\n"
    "zooms, ctrl + left drag pulls a rigid body (live; a dynamic one on a spring, a kinematic\n"
    "one without keyframes along the cursor); replay:\n"
    "click or drag the slider. Keys: space pause/play, N single step (live) or\n"
    "next frame, P previous frame, Home/End first/last frame, R reset, C colour field,\n"
    "W walls, B bodies, D diffuse, X cut-away of the walls facing the camera (3D), M surface /\n"
    "particles, F reset the camera, S save pfsph_view_NNN.png, H help, Esc or Q quit.\n"
    "Live only:\n"
    "G gravity on/off, [ and ] turn gravity by 15 degrees, Tab next phase pair, + and - raise\n"
    "or lower its coefficient / surface tension (x1.25) or contact angle (10 degrees).\n";

const char *const pfsph_vby_name[PFSPH_VBY_COUNT] = {"phase", "speed", "density", "pressure"};

/* ---- the command ---------------------------------------------------------------------- */

static int usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "pfsph: view: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\nusage: see pfsph view --help\n");
    return 2;
}

static int parse_opts(int argc, char **argv, pfsph_vopts *o)
{
    memset(o, 0, sizeof *o);
    o->frame = -1;
    o->frames = 1;
    o->max_fps = 60;
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
        } else if (!strcmp(a, "--max-fps")) {
            char *end = NULL;
            o->max_fps = v ? strtod(v, &end) : -1;
            if (!v || *end || !(o->max_fps >= 0 && o->max_fps <= 1000))
                return usage("--max-fps: '%s' is not 0..1000 frames per second", v ? v : "");
            i++;
        } else if (!strcmp(a, "--surface-budget")) {
            char *end = NULL;
            o->surface_budget = v ? strtod(v, &end) : -1;
            if (!v || *end || !(o->surface_budget > 0 && o->surface_budget <= 60000))
                return usage("--surface-budget: '%s' is not 0..60000 ms", v ? v : "");
            i++;
        } else if (!strcmp(a, "--press")) {
            if (!v) return usage("%s needs keys", a);
            o->press = v;
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
    if (!s || !*s) return PFSPH_VBY_PHASE;
    for (int k = 0; k < PFSPH_VBY_COUNT; k++)
        if (!strcmp(s, pfsph_vby_name[k])) return k;
    return -1;
}

static bool is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

int pfsph_view_main(int argc, char **argv)
{
    pfsph_vapp *A = calloc(1, sizeof *A);
    if (!A) return 1;
    int rc = parse_opts(argc, argv, &A->o);
    if (rc) {
        free(A);
        return rc == 1 ? 0 : rc;
    }
    pfsph_vopts *o = &A->o;
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
        pfsph_vlive *L = &A->L;
        L->scene0 = A->scene;
        L->threads = o->threads;
        if (o->threads > 0) omp_set_num_threads(o->threads);
        if ((rc = pfsph_sim_create(&L->sim, A->scene, &err))) goto fail;
        L->iw = 0, L->ir = 1, L->idr = 2;
        L->paused = o->paused;
        /* the first snapshot, for the camera, before the worker starts */
        if (pfsph_vlive_publish_into(L, &L->fr[L->idr])) goto oom;
        A->shown = &L->fr[L->idr];
        pthread_mutex_init(&L->mu, NULL);
        pthread_cond_init(&L->cv, NULL);
        const pfsph_scene *cur = pfsph_sim_scene(L->sim);
        if (cur->pairwise.enabled) {
            A->pair_a = 0;
            A->pair_b = -1;
            pfsph_vinput_next_pair(A);
        }
    } else {
        pfsph_vreplay *R = &A->R;
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
        if ((rc = pfsph_vreplay_load(R, 0, &A->rf, &err))) goto fail;
        A->shown = &A->rf;
        R->playing = !o->paused && !o->screenshot && o->frame < 0;
        R->next_t = 0;
    }
    /* the renderer's camera for this frame size */
    pfsph_render_camera rc0;
    const pfsph_vframe *f0 = A->shown;
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
    A->vref = pfsph__speed_scale(A->scene, &f0->fluid);
    if (!A->is_live && o->frame >= 0) {
        int k = pfsph_frame_list_find(&A->R.fluid, o->frame);
        if ((rc = pfsph_vreplay_load(&A->R, k, &A->rf, &err))) goto fail;
    }

    if (A->is_live && pthread_create(&A->L.th, NULL, pfsph_vlive_main, &A->L) != 0) {
        rc = pfsph_fail(&err, PFSPH_EIO, "cannot start the simulation thread");
        goto fail;
    }
    /* live: the liquid's surface (2D: its outline) on a thread of its own (vsurf.c); without
     * it, particles */
    if (A->is_live) {
        if (pfsph_vsurf_start(&A->S, A->scene)) {
            fprintf(stderr, "pfsph: view: cannot start the surface thread; particles only\n");
        } else {
            /* a screenshot takes the finest cell unless told a budget: the same picture at any load */
            A->S.sync = o->screenshot != NULL;
            A->S.budget = o->surface_budget > 0 ? 1e-3 * o->surface_budget : o->screenshot ? INFINITY : 1.0 / 30;
        }
    }
    status = pfsph_vwindow_run(A);
    pfsph_vsurf_stop(&A->S);
    pfsph_surface_mesh_free(&A->live_mesh);
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
        for (int k = 0; k < 3; k++) pfsph_vframe_free(&A->L.fr[k]);
    } else {
        pfsph_vframe_free(&A->rf);
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
