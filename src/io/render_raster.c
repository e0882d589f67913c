/* The renderer's rasteriser (render_internal.h): particles splatted as shaded spheres (screen
 * discs with per-pixel depth, Lambert + ambient + a little specular), meshes rasterised as
 * triangles (the liquid shaded as water, the bodies as flat-shaded solids), their colours, the
 * background (the caption and the key: render_key.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/colormap.h"
#include "io/render_internal.h"

typedef pfsph__rcam cam;
typedef pfsph__splat splat;
typedef pfsph__image image;

/* ---- splats ----------------------------------------------------------------------------- */

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static double field_value(const pfsph_particles *ps, size_t i, int by)
{
    switch (by) {
    case PFSPH__COLOR_SPEED: {
        double vx = ps->vx[i], vy = ps->vy[i], vz = ps->vz[i];
        return sqrt(vx * vx + vy * vy + vz * vz);
    }
    case PFSPH__COLOR_DENSITY: return ps->rho[i];
    default: return ps->p[i];
    }
}

/* Colour range of a field over one frame: 1st..99th percentile (speed from 0), so a few
 * outliers do not wash out the picture. */
static void field_range(const pfsph_particles *ps, int by, double *lo, double *hi)
{
    *lo = 0;
    *hi = 1;
    if (!ps->n) return;
    float *v = malloc(ps->n * sizeof *v);
    size_t m = 0;
    if (v) {
        for (size_t i = 0; i < ps->n; i++) {
            double x = field_value(ps, i, by);
            if (isfinite(x)) v[m++] = (float)x;
        }
    }
    if (m) {
        qsort(v, m, sizeof *v, cmp_float);
        *lo = by == PFSPH__COLOR_SPEED ? 0.0 : v[(size_t)(0.01 * (double)(m - 1))];
        *hi = v[(size_t)(0.99 * (double)(m - 1))];
    }
    free(v);
    if (!(*hi > *lo)) *hi = *lo + (fabs(*lo) > 0 ? 1e-3 * fabs(*lo) : 1.0);
}

int pfsph__splat_add_set(pfsph__splat_set *ss, const cam *c, const pfsph_particles *ps, double rad, int layer,
                         int kind /* 0 fluid, 1 boundary, 2 diffuse, 3 bodies */, const pfsph_scene *sc, int by,
                         double vref, int ssf, const pfsph_cutaway *cw, double range[2])
{
    if (ss->n + ps->n > ss->cap) {
        size_t cap = ss->n + ps->n;
        splat *q = realloc(ss->s, (cap ? cap : 1) * sizeof *q);
        if (!q) return PFSPH_ENOMEM;
        ss->s = q;
        ss->cap = cap;
    }
    double lo = 0, hi = 1;
    if (kind == 0 && by != PFSPH__COLOR_PHASE) field_range(ps, by, &lo, &hi);
    if (kind == 0 && by == PFSPH__COLOR_SPEED && vref > 0) hi = vref;
    if (range) range[0] = lo, range[1] = hi;
    for (size_t i = 0; i < ps->n; i++) {
        double p[3] = {ps->x[i], ps->y[i], sc->dim == 2 ? 0.0 : ps->z[i]};
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
        if (kind == 1 && pfsph_cutaway_hides(cw, c->eye, p)) continue;
        splat *s = &ss->s[ss->n];
        if (!pfsph__rcam_project(c, p, rad, s)) continue;
        s->layer = (uint8_t)layer;
        /* Shading a disc of one or two output pixels only adds noise (a dotted texture). */
        double rp = s->r / ssf;
        s->relief = (float)(rp <= 1.5 ? 0.0 : (rp >= 4.0 ? 1.0 : (rp - 1.5) / 2.5));
        if (kind == 1) {
            /* walls recede in light grey unless their phase asks for a colour (pfsph_wall_color) */
            pfsph_wall_color(sc, ps->phase[i], s->col);
        } else if (kind == 2) {
            int t = ps->phase[i] < 3 ? ps->phase[i] : 0;
            memcpy(s->col, PFSPH__DIFFUSE_COL[t], sizeof s->col);
        } else if (by == PFSPH__COLOR_PHASE || kind == 3) {
            int ph = ps->phase[i];
            if (ph < sc->nphases) memcpy(s->col, sc->phases[ph].color, sizeof s->col);
            else s->col[0] = 0.8f, s->col[1] = 0.2f, s->col[2] = 0.8f;
        } else {
            pfsph__viridis((field_value(ps, i, by) - lo) / (hi - lo), s->col);
        }
        ss->n++;
    }
    return PFSPH_OK;
}

int pfsph_wall_color(const pfsph_scene *s, int phase, float out[3])
{
    static const float grey[3] = {0.78f, 0.78f, 0.80f};
    /* muted, distinct from the fluids' palette and from the grey */
    static const float plates[6][3] = {{0.80f, 0.55f, 0.35f}, {0.45f, 0.65f, 0.45f}, {0.55f, 0.50f, 0.75f},
                                       {0.75f, 0.70f, 0.40f}, {0.40f, 0.65f, 0.70f}, {0.75f, 0.45f, 0.55f}};
    /* the walls' grey when a fluid or gas phase is drawn in a grey like it (the bubble scenes'
     * near-white gas): a darker slate, so that the gas does not read as wall */
    static const float slate[3] = {0.46f, 0.48f, 0.53f};
    memcpy(out, grey, sizeof grey);
    if (phase < 0 || phase >= s->nphases) return 0;
    int dark = 0;
    for (int p = 0; p < s->nphases; p++) {
        if (s->phases[p].kind == PFSPH_PHASE_SOLID) continue;
        float d = 0;
        for (int k = 0; k < 3; k++) d = fmaxf(d, fabsf(s->phases[p].color[k] - grey[k]));
        if (d < 0.2f) dark = 1;
    }
    if (dark) memcpy(out, slate, sizeof slate);
    if (s->phases[phase].color_set) {
        memcpy(out, s->phases[phase].color, sizeof grey);
        return 1;
    }
    int uncoloured = 0, rank = -1;
    for (int p = 0; p < s->nphases; p++)
        if (s->phases[p].kind == PFSPH_PHASE_SOLID && !s->phases[p].color_set) {
            if (p == phase) rank = uncoloured;
            uncoloured++;
        }
    if (uncoloured < 2 || rank <= 0) return dark;
    memcpy(out, plates[(rank - 1) % 6], sizeof grey);
    return 1;
}

/* Depth-test every splat overlapping rows [y0, y1) into its layer. */
void pfsph__splat_band(image *im, const splat *sp, const size_t *idx, size_t nidx, int y0, int y1)
{
    for (size_t t = 0; t < nidx; t++) {
        const splat *s = &sp[idx[t]];
        float r = s->r < 0.6f ? 0.6f : s->r;
        int ya = (int)floorf(s->sy - r), yb = (int)ceilf(s->sy + r);
        int xa = (int)floorf(s->sx - r), xb = (int)ceilf(s->sx + r);
        if (ya < y0) ya = y0;
        if (yb > y1 - 1) yb = y1 - 1;
        if (xa < 0) xa = 0;
        if (xb > im->w - 1) xb = im->w - 1;
        float *zb = im->z[s->layer];
        uint32_t *ib = im->id[s->layer];
        const float inv = 1.0f / r;
        for (int py = ya; py <= yb; py++) {
            float dy = ((float)py + 0.5f - s->sy) * inv;
            for (int px = xa; px <= xb; px++) {
                float dx = ((float)px + 0.5f - s->sx) * inv;
                float d2 = dx * dx + dy * dy;
                if (d2 > 1.0f) continue;
                float z = s->depth - s->rw * sqrtf(1.0f - d2);
                size_t o = (size_t)py * (size_t)im->w + (size_t)px;
                if (!(z < zb[o])) continue;
                zb[o] = z;
                ib[o] = (uint32_t)idx[t];
            }
        }
    }
}

/* Colour of splat s at supersampled pixel (px, py): Lambert + ambient + a small specular
 * highlight from a fixed light at the upper left, in camera coordinates (x right, y up, z
 * towards the viewer). */
void pfsph__shade_splat(const splat *s, int px, int py, bool flat, float out[3])
{
    static const float L[3] = {-0.45f, 0.62f, 0.64f};
    static const float Hv[3] = {-0.2116f, 0.2915f, 0.9328f}; /* normalize(L + (0,0,1)) */
    float r = s->r < 0.6f ? 0.6f : s->r;
    float dx = ((float)px + 0.5f - s->sx) / r, dy = ((float)py + 0.5f - s->sy) / r;
    float d2 = dx * dx + dy * dy;
    float nz = d2 < 1.0f ? sqrtf(1.0f - d2) : 0.0f;
    float n[3] = {dx, -dy, nz};
    float diff = n[0] * L[0] + n[1] * L[1] + n[2] * L[2];
    if (diff < 0) diff = 0;
    float sp = n[0] * Hv[0] + n[1] * Hv[1] + n[2] * Hv[2];
    if (sp < 0) sp = 0;
    float s4 = sp * sp * sp * sp, s8 = s4 * s4, s16 = s8 * s8;
    float spec = s16 * s8 * s4; /* ^28 */
    float sh = 0.32f + 0.68f * diff;
    if (flat) sh = 0.75f + 0.25f * diff, spec = 0;
    sh = s->relief * sh + (1 - s->relief) * 0.85f;
    spec *= s->relief;
    for (int k = 0; k < 3; k++) {
        float v = s->col[k] * sh + 0.22f * spec;
        out[k] = v < 0 ? 0 : (v > 1 ? 1 : v);
    }
}

void pfsph__background(int y, int h, double out[3])
{
    /* Light, slightly darker towards the bottom. */
    double t = h > 1 ? (double)y / (h - 1) : 0;
    const double top[3] = {0.945, 0.950, 0.965}, bot[3] = {0.840, 0.850, 0.875};
    for (int k = 0; k < 3; k++) out[k] = (1 - t) * top[k] + t * bot[k];
}

/* ---- meshes ---------------------------------------------------------------------------- */

/* Depth-test a mesh's triangles into layer 0 (serial: the same pixels for any thread count):
 * bodies (id PFSPH__BODY_ID0 + the face's body) with the face's own normal, so that boxes keep their
 * edges; the liquid (PFSPH__MESH_ID) with its smooth vertex normals. */
void pfsph__raster_mesh(const cam *c, image *im, float *mn, const pfsph_surface_mesh *m, bool bodies)
{
    for (size_t t = 0; t < m->ntris; t++) {
        splat s[3];
        float n[3][3];
        int ok = 1;
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->tri[3 * t + k];
            double p[3] = {m->v[3 * v], m->v[3 * v + 1], m->v[3 * v + 2]};
            if (!pfsph__rcam_project(c, p, 0, &s[k])) ok = 0;
            double nw[3];
            if (bodies || !m->n) {
                const double *a = m->v + 3 * m->tri[3 * t], *b = m->v + 3 * m->tri[3 * t + 1],
                             *q = m->v + 3 * m->tri[3 * t + 2];
                double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {q[0] - a[0], q[1] - a[1], q[2] - a[2]};
                pfsph__rcross3(e1, e2, nw);
                pfsph__rnorm3(nw);
            } else {
                for (int j = 0; j < 3; j++) nw[j] = m->n[3 * v + j];
            }
            n[k][0] = (float)pfsph__rdot3(nw, c->right);
            n[k][1] = (float)pfsph__rdot3(nw, c->up);
            n[k][2] = (float)-pfsph__rdot3(nw, c->fwd);
        }
        if (!ok) continue;
        float area = (s[1].sx - s[0].sx) * (s[2].sy - s[0].sy) - (s[2].sx - s[0].sx) * (s[1].sy - s[0].sy);
        if (!(fabsf(area) > 1e-12f)) continue;
        float xa = fminf(s[0].sx, fminf(s[1].sx, s[2].sx)), xb = fmaxf(s[0].sx, fmaxf(s[1].sx, s[2].sx));
        float ya = fminf(s[0].sy, fminf(s[1].sy, s[2].sy)), yb = fmaxf(s[0].sy, fmaxf(s[1].sy, s[2].sy));
        int x0 = (int)floorf(xa), x1 = (int)ceilf(xb), y0 = (int)floorf(ya), y1 = (int)ceilf(yb);
        if (x0 < 0) x0 = 0;
        if (y0 < 0) y0 = 0;
        if (x1 > im->w - 1) x1 = im->w - 1;
        if (y1 > im->h - 1) y1 = im->h - 1;
        for (int py = y0; py <= y1; py++)
            for (int px = x0; px <= x1; px++) {
                float fx = (float)px + 0.5f, fy = (float)py + 0.5f, w[3];
                for (int k = 0; k < 3; k++) {
                    const splat *a = &s[(k + 1) % 3], *b = &s[(k + 2) % 3];
                    w[k] = ((b->sx - a->sx) * (fy - a->sy) - (fx - a->sx) * (b->sy - a->sy)) / area;
                }
                if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
                float z = w[0] * s[0].depth + w[1] * s[1].depth + w[2] * s[2].depth;
                size_t o = (size_t)py * (size_t)im->w + (size_t)px;
                if (!(z < im->z[0][o])) continue;
                im->z[0][o] = z;
                im->id[0][o] = bodies ? PFSPH__BODY_ID0 + (m->phase[t] < 255 ? m->phase[t] : 255) : PFSPH__MESH_ID;
                for (int k = 0; k < 3; k++) mn[3 * o + k] = w[0] * n[0][k] + w[1] * n[1][k] + w[2] * n[2][k];
            }
    }
}

/* Water: a blue body, Lambert light, a sharp highlight and Schlick's Fresnel towards the sky. */
void pfsph__shade_water(const float nin[3], float out[3])
{
    static const float L[3] = {-0.45f, 0.62f, 0.64f}, Hv[3] = {-0.2116f, 0.2915f, 0.9328f};
    static const float base[3] = {0.13f, 0.38f, 0.72f}, sky[3] = {0.86f, 0.91f, 0.96f};
    float len = sqrtf(nin[0] * nin[0] + nin[1] * nin[1] + nin[2] * nin[2]);
    float n[3] = {0, 0, 1};
    if (len > 0)
        for (int k = 0; k < 3; k++) n[k] = nin[k] / len;
    if (n[2] < 0) n[2] = -n[2];
    float diff = fmaxf(0.0f, n[0] * L[0] + n[1] * L[1] + n[2] * L[2]);
    float sp = fmaxf(0.0f, n[0] * Hv[0] + n[1] * Hv[1] + n[2] * Hv[2]);
    float spec = powf(sp, 60.0f);
    float fr = 0.04f + 0.96f * powf(1.0f - n[2], 5.0f);
    for (int k = 0; k < 3; k++) {
        float v = base[k] * (0.35f + 0.65f * diff) * (1 - fr) + sky[k] * fr + 0.7f * spec;
        out[k] = v < 0 ? 0 : (v > 1 ? 1 : v);
    }
}

/* A body's mesh: the particles' look (shade()) with the surface's own normal. */
void pfsph__shade_solid(const float nin[3], const float col[3], float out[3])
{
    static const float L[3] = {-0.45f, 0.62f, 0.64f}, Hv[3] = {-0.2116f, 0.2915f, 0.9328f};
    float len = sqrtf(nin[0] * nin[0] + nin[1] * nin[1] + nin[2] * nin[2]);
    float n[3] = {0, 0, 1};
    if (len > 0)
        for (int k = 0; k < 3; k++) n[k] = nin[k] / len;
    if (n[2] < 0)
        for (int k = 0; k < 3; k++) n[k] = -n[k];
    float diff = fmaxf(0.0f, n[0] * L[0] + n[1] * L[1] + n[2] * L[2]);
    float spec = powf(fmaxf(0.0f, n[0] * Hv[0] + n[1] * Hv[1] + n[2] * Hv[2]), 28.0f);
    for (int k = 0; k < 3; k++) {
        float v = col[k] * (0.32f + 0.68f * diff) + 0.22f * spec;
        out[k] = v < 0 ? 0 : (v > 1 ? 1 : v);
    }
}

/* The colour of body b of the bodies' surface file: its phase's, as its particles are drawn. */
void pfsph__body_color(const pfsph_scene *sc, int b, float col[3])
{
    col[0] = 0.8f, col[1] = 0.2f, col[2] = 0.8f;
    if (b < sc->nbodies && sc->bodies[b].phase >= 0 && sc->bodies[b].phase < sc->nphases)
        memcpy(col, sc->phases[sc->bodies[b].phase].color, 3 * sizeof *col);
}
