/* The viewer's overlay (app.h): clock and counts, the selected phase pair, messages, the
 * legend, the replay slider and the help, as text on translucent panels. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "view/app.h"
#include "view/view.h"

static const char *const BY_UNIT[PFSPH_VBY_COUNT] = {"", "M/S", "KG/M3", "PA"};

static const float INK[4] = {0.08f, 0.09f, 0.12f, 1}, PANEL[4] = {1, 1, 1, 0.72f}, RED[4] = {0.75f, 0.1f, 0.1f, 1};

static void panel_text(pfsph_vapp *A, float x, float y, float sc, const char *s, const float col[4])
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
void pfsph_vhud_draw(pfsph_vapp *A, double lo, double hi)
{
    const pfsph_vframe *f = A->shown;
    const pfsph_scene *sc = A->scene;
    const float s = A->fb_h >= 500 ? 2.0f : 1.0f;
    const float lh = 8 * s;
    char line[1400];
    float y = 6 * s;
    if (A->is_live) {
        pthread_mutex_lock(&A->L.mu);
        double sps = A->L.sps, rtf = A->L.rtf;
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
        /* the real-time factor: simulated seconds per wall second (1 or more: real time) */
        snprintf(line, sizeof line, "LIVE  T=%.4f S  STEP %llu  %.1f STEPS/S  %.2fX REAL TIME%s%s", f->time,
                 (unsigned long long)f->steps, sps, rtf, fps,
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
    /* particles per set; bodies counted as bodies (their particles in brackets) */
    snprintf(line, sizeof line, "FLUID %zu  WALLS %zu  BODIES %d (%zu PARTICLES)  DIFFUSE %zu%s%s%s", f->fluid.n,
             f->walls.n, sc->nbodies, f->bodies.n, f->diffuse.n, A->show_walls ? "" : "  (WALLS HIDDEN)",
             A->show_bodies ? "" : "  (BODIES HIDDEN)", A->show_diffuse ? "" : "  (DIFFUSE HIDDEN)");
    panel_text(A, 6 * s, y, s, line, INK);
    const bool meshes = !A->is_live && sc->dim == 3 && (A->rf.liquid.ntris || A->rf.bmesh.ntris);
    if (meshes) {
        y += lh;
        snprintf(line, sizeof line, "MESHES: LIQUID %zu, BODIES %zu TRIANGLES  %s", A->rf.liquid.ntris,
                 A->rf.bmesh.ntris, A->show_surface ? "(M: PARTICLES)" : "HIDDEN (M: MESHES)");
        panel_text(A, 6 * s, y, s, line, INK);
    }
    if (A->is_live && A->S.started) {
        y += lh;
        pfsph_vsurf *S = &A->S;
        pthread_mutex_lock(&S->mu);
        bool gave_up = S->gave_up, failed = S->failed;
        double last = 1e3 * S->last_s, avg = 1e3 * S->avg_s, budget = 1e3 * S->budget, rate = S->rate;
        double retry = S->retry_at - omp_get_wtime(), cell = S->cell;
        char smsg[300];
        snprintf(smsg, sizeof smsg, "%s", S->msg);
        pthread_mutex_unlock(&S->mu);
        const float *col = INK;
        if (!A->show_surface) {
            snprintf(line, sizeof line, "PARTICLES (M: SURFACE)");
        } else if (failed) {
            snprintf(line, sizeof line, "%s: PARTICLES", smsg);
            col = RED;
        } else if (gave_up) {
            /* the automatic fallback: the surface could not keep up at the coarsest cell */
            snprintf(line, sizeof line,
                     "SURFACE TOO SLOW (%.0f MS > %.0f MS AT CELL %.3g D): PARTICLES, RETRY IN %.0f S", last, budget,
                     cell, retry > 0 ? retry : 0);
            col = RED;
        } else if (!A->live_mesh.nverts) {
            snprintf(line, sizeof line, "SURFACE: FIRST REBUILD...");
        } else {
            snprintf(line, sizeof line,
                     "SURFACE %zu TRIANGLES  CELL %.3g D  %.0f MS (MEAN %.0f)  %.0f/S  (M: PARTICLES)",
                     A->live_mesh.ntris, A->live_mesh_cell, last, avg, rate);
        }
        panel_text(A, 6 * s, y, s, line, col);
    }

    /* legend, bottom right (none for a liquid drawn as water: the field does not colour it) */
    float lw = 120 * s, bx = A->fb_w - lw - 10 * s, by = A->fb_h - (A->is_live ? 14 : 26) * s;
    if (((meshes && A->rf.liquid.ntris) || pfsph_vframe_live_surface(A)) && A->show_surface &&
        A->by != PFSPH_VBY_PHASE) {
        /* nothing */
    } else if (A->by == PFSPH_VBY_PHASE) {
        float yy = by;
        for (int p = sc->nphases - 1; p >= 0; p--) {
            float col[4] = {sc->phases[p].color[0], sc->phases[p].color[1], sc->phases[p].color[2], 1};
            /* solids: those drawn in a colour of their own (pfsph_wall_color), not the grey */
            if (sc->phases[p].kind == PFSPH_PHASE_SOLID && !pfsph_wall_color(sc, p, col)) continue;
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
        snprintf(line, sizeof line, "%s [%s]", pfsph_vby_name[A->by], BY_UNIT[A->by]);
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
