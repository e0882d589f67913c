/* The viewer's input (app.h): keys (display toggles, replay stepping, live control of
 * gravity and phase pairs) and the mouse (orbit, pan, zoom, the slider, dragging a body). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "view/app.h"

void pfsph_vinput_next_pair(pfsph_vapp *A)
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

static void change_pair(pfsph_vapp *A, int dir)
{
    pthread_mutex_lock(&A->L.mu);
    const pfsph_pairwise_params *pp = &pfsph_sim_scene(A->L.sim)->pairwise;
    int a = A->pair_a, b = A->pair_b;
    pfsph_vcmd q = {PFSPH_VCMD_COEF, a, b, {0, 0, 0}};
    if (!pp->enabled) {
        snprintf(A->L.msg, sizeof A->L.msg, "this scene has pair forces off (no \"pairwise\" block)");
        pthread_mutex_unlock(&A->L.mu);
        return;
    }
    if (pp->angle_set[a][b]) {
        q.kind = PFSPH_VCMD_ANGLE;
        q.v[0] = fmin(180, fmax(0, pp->angle_deg[a][b] + 10 * dir));
    } else if (pp->sigma_set[a][b]) {
        q.kind = PFSPH_VCMD_SIGMA;
        q.v[0] = pp->sigma[a][b] * (dir > 0 ? 1.25 : 0.8);
    } else {
        double c = pp->c[a][b];
        if (!(c > 0)) c = pp->c[a][a] > 0 ? 0.1 * pp->c[a][a] : 1e-3; /* something to grow from */
        q.v[0] = c * (dir > 0 ? 1.25 : 0.8);
    }
    pthread_mutex_unlock(&A->L.mu);
    pfsph_vlive_post(&A->L, &q);
}

static void turn_gravity(pfsph_vapp *A, double deg)
{
    pthread_mutex_lock(&A->L.mu);
    const double *g = pfsph_sim_scene(A->L.sim)->gravity;
    /* about the view axis: in the image plane, as tilting the container would */
    double ax[3] = {-A->cam.fwd[0], -A->cam.fwd[1], -A->cam.fwd[2]};
    if (A->scene->dim == 2) ax[0] = 0, ax[1] = 0, ax[2] = 1;
    double t = deg * 3.14159265358979323846 / 180, c = cos(t), s = sin(t);
    double d = ax[0] * g[0] + ax[1] * g[1] + ax[2] * g[2];
    double x[3] = {ax[1] * g[2] - ax[2] * g[1], ax[2] * g[0] - ax[0] * g[2], ax[0] * g[1] - ax[1] * g[0]};
    pfsph_vcmd q = {PFSPH_VCMD_GRAVITY, 0, 0, {0, 0, 0}};
    for (int k = 0; k < 3; k++) q.v[k] = g[k] * c + x[k] * s + ax[k] * d * (1 - c);
    pthread_mutex_unlock(&A->L.mu);
    pfsph_vlive_post(&A->L, &q);
}
static void on_key(GLFWwindow *w, int key, int sc, int action, int mods)
{
    (void)sc;
    (void)mods;
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    pfsph_vinput_key(glfwGetWindowUserPointer(w), key);
}

void pfsph_vinput_key(pfsph_vapp *A, int key)
{
    A->dirty = true;
    switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: glfwSetWindowShouldClose(A->win, 1); return;
    case GLFW_KEY_C: A->by = (A->by + 1) % PFSPH_VBY_COUNT; return;
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
        case GLFW_KEY_RIGHT: pfsph_vreplay_goto(A, A->R.cur + 1); break;
        case GLFW_KEY_P:
        case GLFW_KEY_LEFT: pfsph_vreplay_goto(A, A->R.cur - 1); break;
        case GLFW_KEY_HOME:
        case GLFW_KEY_R: pfsph_vreplay_goto(A, 0); break;
        case GLFW_KEY_END: pfsph_vreplay_goto(A, A->R.fluid.n - 1); break;
        default: break;
        }
        return;
    }
    pfsph_vlive *L = &A->L;
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
        pfsph_vcmd q = {PFSPH_VCMD_GRAVITY, 0, 0, {0, 0, 0}};
        pthread_mutex_lock(&L->mu);
        const double *g = pfsph_sim_scene(L->sim)->gravity;
        if (!A->gravity_off) memcpy(A->g_saved, g, sizeof A->g_saved);
        else memcpy(q.v, A->g_saved, sizeof q.v);
        A->gravity_off = !A->gravity_off;
        pthread_mutex_unlock(&L->mu);
        pfsph_vlive_post(L, &q);
        break;
    }
    case GLFW_KEY_LEFT_BRACKET: turn_gravity(A, -15); break;
    case GLFW_KEY_RIGHT_BRACKET: turn_gravity(A, 15); break;
    case GLFW_KEY_TAB: pfsph_vinput_next_pair(A); break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: change_pair(A, 1); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: change_pair(A, -1); break;
    default: break;
    }
}

static bool on_slider(const pfsph_vapp *A, double x, double y)
{
    const float s = A->fb_h >= 500 ? 2.0f : 1.0f;
    (void)x;
    return !A->is_live && y > A->fb_h - 16 * s;
}

static void slider_set(pfsph_vapp *A, double x)
{
    const float s = A->fb_h >= 500 ? 2.0f : 1.0f;
    double u = (x - 10 * s) / (A->fb_w - 20 * s);
    pfsph_vreplay_goto(A, (int)lround(fmin(1, fmax(0, u)) * (A->R.fluid.n - 1)));
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
    pfsph_vapp *A = glfwGetWindowUserPointer(w);
    double x, y;
    glfwGetCursorPos(w, &x, &y);
    fb_pos(w, &x, &y);
    A->mx = x;
    A->my = y;
    bool down = action == GLFW_PRESS;
    if (button == GLFW_MOUSE_BUTTON_LEFT && A->grab >= 0 && !down) {
        pfsph_vcmd q = {PFSPH_VCMD_RELEASE, A->grab, 0, {0, 0, 0}};
        pfsph_vlive_post(&A->L, &q);
        A->grab = -1;
        return;
    }
    if (button == GLFW_MOUSE_BUTTON_LEFT && down && (mods & GLFW_MOD_CONTROL) && A->is_live) {
        /* the draggable body (dynamic, or kinematic without keyframes) whose centre is nearest
         * the cursor, within 80 pixels */
        const pfsph_vframe *f = A->shown;
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
    pfsph_vapp *A = glfwGetWindowUserPointer(w);
    fb_pos(w, &x, &y);
    double dx = x - A->mx, dy = y - A->my;
    A->mx = x;
    A->my = y;
    if (A->grab >= 0) {
        pfsph_vcmd q = {PFSPH_VCMD_DRAG, A->grab, 0, {0, 0, 0}};
        pfsph_vcam_unproject(&A->cam, A->fb_w, A->fb_h, x, y, A->grab_depth, q.v);
        pfsph_vlive_post(&A->L, &q);
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
    pfsph_vapp *A = glfwGetWindowUserPointer(w);
    pfsph_vcam_zoom(&A->cam, pow(1.12, dy));
    A->dirty = true;
}

void pfsph_vinput_attach(GLFWwindow *w)
{
    glfwSetKeyCallback(w, on_key);
    glfwSetMouseButtonCallback(w, on_button);
    glfwSetCursorPosCallback(w, on_cursor);
    glfwSetScrollCallback(w, on_scroll);
}
