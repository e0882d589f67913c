/* The viewer's window (app.h): GLFW and the OpenGL context, the loop that takes new frames
 * (live snapshots, replay playback) and draws them, screenshots and the benchmark. */
#include <epoxy/gl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/io.h"
#include "view/app.h"

static void on_glfw_error(int code, const char *desc)
{
    (void)code;
    fprintf(stderr, "pfsph: view: GLFW: %s\n", desc);
}

/* The frame just drawn as a PNG (the S key); prints where. */
static void save_png(pfsph_vapp *A, const char *path)
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

/* Live: the changes made with keys or the mouse, and how soon they acted. */
static void print_changes(pfsph_vapp *A)
{
    if (!A->is_live) return;
    pthread_mutex_lock(&A->L.mu);
    if (A->L.applied)
        printf("changes: %llu applied, the last from step %llu, %.1f ms after it was made (at most %.1f ms)\n",
               (unsigned long long)A->L.applied, (unsigned long long)A->L.applied_step, 1e3 * A->L.lat_last,
               1e3 * A->L.lat_max);
    pthread_mutex_unlock(&A->L.mu);
}

/* Live: what the surface (2D: the outline) drew and what it cost (screenshots and --bench). */
static void print_surface(pfsph_vapp *A)
{
    pfsph_vsurf *S = &A->S;
    if (!S->started) return;
    const bool drawn = pfsph_vframe_live_surface(A);
    pthread_mutex_lock(&S->mu);
    if (drawn)
        printf("surface: %zu triangles at t = %.6g s, cell %.3g d, %llu rebuilds, last %.1f ms, mean %.1f ms\n",
               A->live_mesh.ntris, A->live_mesh_time, A->live_mesh_cell, (unsigned long long)S->nbuilt, 1e3 * S->last_s,
               1e3 * S->avg_s);
    else
        printf("surface: particles drawn (%s; %llu rebuilds, last %.1f ms, budget %.1f ms)\n",
               !A->show_surface ? "off"
                   : S->gave_up ? "too slow"
                   : S->failed  ? S->msg
                                : "no mesh yet",
               (unsigned long long)S->nbuilt, 1e3 * S->last_s, 1e3 * S->budget);
    pthread_mutex_unlock(&S->mu);
}

static int write_outputs(pfsph_vapp *A)
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
    print_surface(A);
    print_changes(A);
    return 0;
}

int pfsph_vwindow_run(pfsph_vapp *A)
{
    const pfsph_vopts *o = &A->o;
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
    pfsph_vinput_attach(A->win);
    int status = 0, drawn = 0, fps_frames = 0;
    double fps_t0 = glfwGetTime(), bench_t0 = fps_t0, last_draw = -1e30;
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
            if (headless && drawn > 0) pfsph_vlive_wait_fresh(&A->L);
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
            /* the liquid's surface: the drawn snapshot to the surface thread when it is idle,
             * its newest mesh back; a screenshot waits for the mesh of the frame it draws */
            if (A->S.started && A->show_surface) {
                bool posted = pfsph_vsurf_post(&A->S, A->scene, A->shown);
                if (headless && posted) pfsph_vsurf_wait(&A->S);
                if (pfsph_vsurf_take(&A->S, &A->live_mesh, &A->live_mesh_time, &A->live_mesh_cell))
                    A->live_mesh_new = A->dirty = true;
            } else if (A->live_mesh.nverts) {
                /* off: drop the old mesh, so that turning it on does not show a stale one */
                pfsph_surface_mesh_free(&A->live_mesh);
                memset(&A->live_mesh, 0, sizeof A->live_mesh);
                pthread_mutex_lock(&A->S.mu);
                A->S.posted_time = -1; /* turned on again (paused, say): rebuild the frame shown */
                pthread_mutex_unlock(&A->S.mu);
            }
        } else if (A->R.playing && glfwGetTime() >= A->R.next_t) {
            A->R.next_t += 1.0 / fps_play;
            if (A->R.next_t < glfwGetTime()) A->R.next_t = glfwGetTime() + 1.0 / fps_play; /* fell behind */
            if (A->R.cur + 1 < A->R.fluid.n) pfsph_vreplay_goto(A, A->R.cur + 1);
            else A->R.playing = false;
        }
        /* at most max_fps frames a second in a window: with a software renderer each frame
         * drawn is CPU the simulation's threads do not get, and live mode has a new snapshot
         * after every step (1-9 a frame) */
        const bool want = A->dirty || headless || o->bench > 0;
        const double wait = headless || !(o->max_fps > 0) ? 0 : last_draw + 1.0 / o->max_fps - glfwGetTime();
        if (want && wait > 0) {
            glfwWaitEventsTimeout(wait);
            continue;
        }
        if (want) {
            last_draw = glfwGetTime();
            A->dirty = false;
            pfsph_vframe_draw(A);
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
            /* --press: one key per drawn frame after the first, through the key handler */
            if (o->press && drawn >= 1 && o->press[drawn - 1]) {
                int c = o->press[drawn - 1];
                pfsph_vinput_key(A, c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
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
                print_surface(A);
                print_changes(A);
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
    pfsph_vmesh_destroy(A->gl_gas);
    A->gl_liquid = A->gl_bodies = A->gl_gas = NULL;
    pfsph_vdraw_destroy(A->draw);
    glfwDestroyWindow(A->win);
    glfwTerminate();
    return status;
}
