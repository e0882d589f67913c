/* The frame the viewer draws (app.h): particle sets as sprites coloured as the renderer colours
 * them, a replayed frame's meshes in vertex buffers, layers composited, the overlay on top. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/colormap.h"
#include "view/app.h"

void pfsph_vframe_free(pfsph_vframe *f)
{
    pfsph_particles_free(&f->fluid);
    pfsph_particles_free(&f->walls);
    pfsph_particles_free(&f->bodies);
    pfsph_particles_free(&f->diffuse);
    pfsph_surface_mesh_free(&f->liquid);
    pfsph_surface_mesh_free(&f->bmesh);
}

static double field(const pfsph_particles *ps, size_t i, int by)
{
    switch (by) {
    case PFSPH_VBY_SPEED:
        return sqrt((double)ps->vx[i] * ps->vx[i] + (double)ps->vy[i] * ps->vy[i] + (double)ps->vz[i] * ps->vz[i]);
    case PFSPH_VBY_DENSITY: return ps->rho[i];
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
static void field_range(const pfsph_vapp *A, const pfsph_particles *ps, int by, double *lo, double *hi)
{
    *lo = 0;
    *hi = 1;
    if (by == PFSPH_VBY_SPEED && A->vref > 0) {
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
        *lo = by == PFSPH_VBY_SPEED ? 0.0 : v[(size_t)(0.01 * (double)(m - 1))];
        *hi = v[(size_t)(0.99 * (double)(m - 1))];
    }
    free(v);
    if (!(*hi > *lo)) *hi = *lo + (fabs(*lo) > 0 ? 1e-3 * fabs(*lo) : 1.0);
}

/* kind: 0 fluid, 1 walls, 2 diffuse, 3 bodies (as the renderer colours them) */
static size_t add_sprites(pfsph_vapp *A, size_t n0, const pfsph_particles *ps, double rad, double zoff, int kind,
                          double lo, double hi, const pfsph_cutaway *cw)
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
            pfsph_wall_color(sc, ph, col);
        } else if (kind == 2) {
            memcpy(col, PFSPH__DIFFUSE_COL[ph < 3 ? ph : 0], sizeof col);
        } else if (kind == 3 || A->by == PFSPH_VBY_PHASE) {
            if (ph < sc->nphases) memcpy(col, sc->phases[ph].color, sizeof col);
        } else {
            pfsph__viridis((field(ps, i, A->by) - lo) / (hi - lo), col);
        }
        s->cr = col[0], s->cg = col[1], s->cb = col[2];
        m++;
    }
    return m;
}

/* Room for m floats in the staging array; false when out of memory. */
static bool mv_reserve(pfsph_vapp *A, size_t m)
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
static void upload_meshes(pfsph_vapp *A)
{
    pfsph_vframe *f = &A->rf;
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

/* Live mode: the reconstructed surface into its vertex buffers: the liquid phases' faces shaded as
 * water, the gases' (bubbles) in their phase's colour, both with the reconstruction's smooth
 * normals and one shared vertex array. */
static void upload_live_mesh(pfsph_vapp *A)
{
    A->live_mesh_new = false;
    if (!A->gl_liquid) A->gl_liquid = pfsph_vmesh_create();
    if (!A->gl_gas) A->gl_gas = pfsph_vmesh_create();
    if (!A->gl_liquid || !A->gl_gas) return;
    const pfsph_surface_mesh *m = &A->live_mesh;
    const pfsph_scene *sc = A->scene;
    uint32_t *idx = NULL;
    size_t nl = 0, ng = 0;
    if (m->ntris && m->n && mv_reserve(A, 9 * m->nverts) && (idx = malloc(3 * m->ntris * sizeof *idx))) {
        /* vertex colours from the faces (a vertex bounds one phase: phases are meshed apart) */
        for (size_t i = 0; i < m->nverts; i++) {
            float *v = A->mv + 9 * i;
            for (int k = 0; k < 3; k++) v[k] = (float)m->v[3 * i + k], v[3 + k] = m->n[3 * i + k], v[6 + k] = 0.7f;
        }
        for (size_t t = 0; t < m->ntris; t++) {
            int ph = m->phase[t];
            if (sc->dim == 2) { /* the outline: in the phase's colour, darker */
                ng++;
                for (int c = 0; c < 3; c++)
                    for (int k = 0; k < 3; k++)
                        A->mv[9 * m->tri[3 * t + c] + 6 + k] =
                            ph < sc->nphases ? 0.45f * sc->phases[ph].color[k] : 0.1f;
            } else if (ph < sc->nphases && sc->phases[ph].kind == PFSPH_PHASE_GAS) {
                ng++;
                for (int c = 0; c < 3; c++)
                    memcpy(A->mv + 9 * m->tri[3 * t + c] + 6, sc->phases[ph].color, 3 * sizeof(float));
            } else {
                nl++;
            }
        }
        /* liquid faces from the front of idx, gas faces from the back */
        size_t a = 0, b = m->ntris;
        for (size_t t = 0; t < m->ntris; t++) {
            int ph = m->phase[t];
            size_t o = sc->dim == 2 || (ph < sc->nphases && sc->phases[ph].kind == PFSPH_PHASE_GAS) ? --b : a++;
            memcpy(idx + 3 * o, m->tri + 3 * t, 3 * sizeof *idx);
        }
    }
    pfsph_vmesh_upload(A->gl_liquid, nl ? A->mv : NULL, nl ? m->nverts : 0, idx, 3 * nl);
    pfsph_vmesh_upload(A->gl_gas, ng ? A->mv : NULL, ng ? m->nverts : 0, idx ? idx + 3 * nl : NULL, 3 * ng);
    free(idx);
}

/* Whether live mode draws its reconstructed surface now (on, a mesh there, not given up). */
bool pfsph_vframe_live_surface(pfsph_vapp *A)
{
    if (!A->is_live || !A->show_surface || !A->S.started || !A->live_mesh.nverts) return false;
    pthread_mutex_lock(&A->S.mu);
    bool ok = !A->S.gave_up && !A->S.failed;
    pthread_mutex_unlock(&A->S.mu);
    return ok;
}

void pfsph_vframe_draw(pfsph_vapp *A)
{
    const pfsph_vframe *f = A->shown;
    const pfsph_scene *sc = A->scene;
    const bool d2 = sc->dim == 2;
    const double r = sc->particle_radius > 0 ? sc->particle_radius : 0.01;
    float view[16], proj[16];
    pfsph_vcam_matrices(&A->cam, A->fb_w, A->fb_h, A->depth, view, proj);
    pfsph_vdraw_begin(A->draw, A->fb_w, A->fb_h, view, proj, A->cam.ortho, pfsph_vcam_focal(&A->cam, A->fb_h), !d2);
    double lo = 0, hi = 1;
    if (A->by != PFSPH_VBY_PHASE) field_range(A, &f->fluid, A->by, &lo, &hi);
    /* radii as the renderer's: 2D fluid discs a little larger than the particle, walls smaller
     * and behind (4 r) */
    size_t n = 0;
    /* the renderer's cut-away, asked again for the eye of every frame drawn: orbiting round
     * the tank opens the side the camera is on */
    pfsph_cutaway cw;
    pfsph_cutaway_init(&cw, sc, A->cut_walls ? &f->walls : NULL, &f->fluid);
    if (A->show_walls) n = add_sprites(A, 0, &f->walls, d2 ? 0.9 * r : r, -4 * r, 1, 0, 1, &cw);
    pfsph_vdraw_sprites(A->draw, 1, A->spr, n);
    /* meshes instead of particles where the run has them, as `pfsph render` does */
    if (f->mesh_new) upload_meshes(A);
    const bool liq = A->show_surface && !d2 && A->rf.liquid.ntris && !A->is_live;
    const bool bmesh = A->show_surface && !d2 && A->rf.bmesh.ntris && !A->is_live;
    const bool lsurf = pfsph_vframe_live_surface(A);
    if (lsurf && A->live_mesh_new) upload_live_mesh(A);
    /* the surface covers every phase of the fluid set (liquids and gases: vsurf.c); in 2D the
     * outline is drawn over the particles */
    n = liq || (lsurf && !d2) ? 0 : add_sprites(A, 0, &f->fluid, d2 ? 1.3 * r : r, 0, 0, lo, hi, NULL);
    if (A->show_diffuse) n = add_sprites(A, n, &f->diffuse, 0.4 * r, 0, 2, 0, 1, NULL);
    if (A->show_bodies && !bmesh) n = add_sprites(A, n, &f->bodies, r, 0, 3, 0, 1, NULL);
    pfsph_vdraw_sprites(A->draw, 0, A->spr, n);
    if (liq || lsurf) pfsph_vdraw_mesh(A->draw, A->gl_liquid, 1);
    if (lsurf) pfsph_vdraw_mesh(A->draw, A->gl_gas, 0);
    if (bmesh && A->show_bodies) pfsph_vdraw_mesh(A->draw, A->gl_bodies, 0);
    pfsph_vdraw_composite(A->draw);
    if (!A->o.no_overlay) {
        pfsph_vhud_draw(A, lo, hi);
        pfsph_vdraw_overlay(A->draw);
    }
}
