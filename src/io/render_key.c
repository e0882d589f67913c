/* The caption and the key of `pfsph render`'s previews (render_internal.h): the caption in a
 * 5x7 digits font of its own (unchanged since the first previews), the key in the font the viewer
 * shares (io/font.h): the colour bar with its field's name and unit, a legend of the colours that
 * stand for phases, bodies and diffuse particles, and a scale bar. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/colormap.h"
#include "io/font.h"
#include "io/render_internal.h"

/* ---- caption: a tiny built-in 5x7 font ------------------------------------------------ */

static const char GLYPH_CH[] = "0123456789framets=.- ";
static const uint8_t GLYPH[][7] = {
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},
    {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}, {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10},
    {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}, {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11},
    {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}, {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06},
    {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}, {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00},
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}, {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00},
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},
};

void pfsph__draw_text(uint8_t *rgb, int w, int h, int x0, int y0, int sc, const char *txt)
{
    for (const char *t = txt; *t; t++, x0 += 6 * sc) {
        const char *g = strchr(GLYPH_CH, *t);
        if (!g) continue;
        const uint8_t *rows = GLYPH[g - GLYPH_CH];
        for (int r = 0; r < 7; r++)
            for (int c = 0; c < 5; c++) {
                if (!(rows[r] & (0x10 >> c))) continue;
                for (int a = 0; a < sc; a++)
                    for (int b = 0; b < sc; b++) {
                        int x = x0 + c * sc + b, y = y0 + r * sc + a;
                        if (x < 0 || y < 0 || x >= w || y >= h) continue;
                        uint8_t *p = rgb + 3 * ((size_t)y * w + x);
                        p[0] = 55, p[1] = 58, p[2] = 66;
                    }
            }
    }
}

static void panel(uint8_t *rgb, int w, int h, int x0, int y0, int pw, int ph);

/* A colour bar at the right edge for the field the fluid is coloured by, its range at the ends
 * (the numbers in the caption's font: digits, '.', '-', 'e'), on a light panel. */
static void colour_bar(uint8_t *rgb, int w, int h, int sc, const double range[2])
{
    const int bw = 10 * sc, bh = h / 3, x0 = w - bw - 8 * sc - 40 * sc, y0 = h / 3;
    if (x0 < 0 || bh < 8) return;
    char out[2][32];
    int nw = 0;
    for (int e = 0; e < 2; e++) {
        char num[32];
        snprintf(num, sizeof num, "%.3g", range[1 - e]);
        size_t j = 0; /* "1.5e+03" -> "1.5e03": the font has no '+' */
        for (const char *t = num; *t && j + 1 < sizeof out[e]; t++)
            if (*t != '+') out[e][j++] = *t;
        out[e][j] = 0;
        if ((int)j * 6 * sc > nw) nw = (int)j * 6 * sc;
    }
    panel(rgb, w, h, x0 - 3 * sc, y0 - 3 * sc, bw + 3 * sc + nw + 5 * sc, bh + 6 * sc);
    for (int y = 0; y < bh; y++) {
        float c[3];
        pfsph__viridis(1.0 - (double)y / (bh - 1), c);
        for (int x = 0; x < bw; x++) {
            uint8_t *p = rgb + 3 * ((size_t)(y0 + y) * w + x0 + x);
            for (int k = 0; k < 3; k++) p[k] = (uint8_t)lrint(c[k] * 255.0f);
        }
    }
    for (int e = 0; e < 2; e++) pfsph__draw_text(rgb, w, h, x0 + bw + 3 * sc, e ? y0 + bh - 7 * sc : y0, sc, out[e]);
}

/* ---- the key ---------------------------------------------------------------------------- */

static const uint8_t INK[3] = {55, 58, 66};

/* Lighten a rectangle so that the key reads over the picture. */
static void panel(uint8_t *rgb, int w, int h, int x0, int y0, int pw, int ph)
{
    for (int y = y0 < 0 ? 0 : y0; y < y0 + ph && y < h; y++)
        for (int x = x0 < 0 ? 0 : x0; x < x0 + pw && x < w; x++) {
            uint8_t *p = rgb + 3 * ((size_t)y * w + x);
            for (int k = 0; k < 3; k++) p[k] = (uint8_t)(p[k] / 4 + 191);
        }
}

static void fill(uint8_t *rgb, int w, int h, int x0, int y0, int fw, int fh, const uint8_t c[3])
{
    for (int y = y0 < 0 ? 0 : y0; y < y0 + fh && y < h; y++)
        for (int x = x0 < 0 ? 0 : x0; x < x0 + fw && x < w; x++) memcpy(rgb + 3 * ((size_t)y * w + x), c, 3);
}

/* Text in the shared 3x5 font at scale sc (lower case drawn as upper case). */
static void label(uint8_t *rgb, int w, int h, int x0, int y0, int sc, const char *txt)
{
    for (const char *t = txt; *t; t++, x0 += PFSPH_FONT_ADVANCE * sc) {
        const char *g = pfsph_font_glyph(*t);
        if (!g) continue;
        for (int r = 0; r < PFSPH_FONT_H; r++)
            for (int c = 0; c < PFSPH_FONT_W; c++)
                if (g[PFSPH_FONT_W * r + c] == '#') fill(rgb, w, h, x0 + c * sc, y0 + r * sc, sc, sc, INK);
    }
}

static int label_w(const char *txt, int sc) { return (int)strlen(txt) * PFSPH_FONT_ADVANCE * sc - sc; }

typedef struct entry {
    char name[28];
    uint8_t col[3];
} entry;

#define MAX_ENTRIES 40

static void add(entry *e, int *n, const char *name, const float col[3])
{
    if (*n >= MAX_ENTRIES) return;
    for (int i = 0; i < *n; i++) /* a solid phase both walls and bodies are made of: once */
        if (!strncmp(e[i].name, name, sizeof e[i].name - 1) && e[i].col[0] == (uint8_t)lrintf(col[0] * 255.0f) &&
            e[i].col[1] == (uint8_t)lrintf(col[1] * 255.0f) && e[i].col[2] == (uint8_t)lrintf(col[2] * 255.0f))
            return;
    snprintf(e[*n].name, sizeof e[*n].name, "%s", name);
    for (int k = 0; k < 3; k++) e[*n].col[k] = (uint8_t)lrintf(fminf(fmaxf(col[k], 0.0f), 1.0f) * 255.0f);
    (*n)++;
}

/* Which phase numbers (0..255) a particle set holds. */
static void present(const pfsph_particles *ps, bool seen[256])
{
    memset(seen, 0, 256 * sizeof *seen);
    if (ps)
        for (size_t i = 0; i < ps->n; i++) seen[ps->phase[i]] = true;
}

/* The legend, top left: a swatch and a name for each colour that stands for something. */
static void legend(uint8_t *rgb, int w, int h, const pfsph__key *k, int ls)
{
    const pfsph_scene *sc = k->sc;
    entry e[MAX_ENTRIES];
    int n = 0;
    bool seen[256];
    if (k->fluid_phases)
        for (int p = 0; p < sc->nphases; p++)
            if (sc->phases[p].kind != PFSPH_PHASE_SOLID) add(e, &n, sc->phases[p].name, sc->phases[p].color);
    if (k->liquid_mesh) {
        const float up[3] = {0, 0, 1};
        float c[3];
        pfsph__shade_water(up, c);
        add(e, &n, "liquid surface", c);
    }
    present(k->walls, seen);
    for (int p = 0; p < sc->nphases; p++)
        if (seen[p] && sc->phases[p].kind == PFSPH_PHASE_SOLID) {
            float c[3];
            pfsph_wall_color(sc, p, c);
            add(e, &n, sc->phases[p].name, c);
        }
    if (k->bodies)
        for (int b = 0; b < sc->nbodies; b++) {
            float c[3];
            pfsph__body_color(sc, b, c);
            int ph = sc->bodies[b].phase;
            add(e, &n, ph >= 0 && ph < sc->nphases ? sc->phases[ph].name : "body", c);
        }
    present(k->diffuse, seen);
    static const char *const DIFFUSE[3] = {"spray", "foam", "bubbles"};
    for (int t = 0; t < 3; t++)
        if (seen[t] && k->diffuse) add(e, &n, DIFFUSE[t], PFSPH__DIFFUSE_COL[t]);
    if (!n) return;
    const int m = 6 * k->tsc, pad = 2 * ls, sw = PFSPH_FONT_H * ls, lh = 7 * ls;
    int tw = 0;
    for (int i = 0; i < n; i++)
        if (label_w(e[i].name, ls) > tw) tw = label_w(e[i].name, ls);
    int rows = n;
    while (rows > 0 && m + 2 * pad + rows * lh - 2 * ls > h / 2 + lh) rows--; /* at most half the height */
    panel(rgb, w, h, m, m, 2 * pad + sw + 2 * ls + tw, 2 * pad + rows * lh - 2 * ls);
    for (int i = 0; i < rows; i++) {
        int x = m + pad, y = m + pad + i * lh;
        fill(rgb, w, h, x - 1, y - 1, sw + 2, sw + 2, INK); /* outlined: white spray on a light panel */
        fill(rgb, w, h, x, y, sw, sw, e[i].col);
        label(rgb, w, h, x + sw + 2 * ls, y, ls, e[i].name);
    }
}

/* The scale bar, bottom right: a round length in metres, as long as it is drawn in the image
 * plane of the target (2D: everywhere). */
static void scale_bar(uint8_t *rgb, int w, int h, const pfsph__key *k, int ls)
{
    const pfsph__rcam *c = k->cam;
    double ppm = c->f / k->ss; /* output pixels per metre */
    if (!c->ortho) ppm = c->dist > 0 ? ppm / c->dist : 0;
    if (!(ppm > 0) || !isfinite(ppm)) return;
    double want = 0.15 * w / ppm, l0 = pow(10.0, floor(log10(want))), r = want / l0;
    double len = r >= 5 ? 5 * l0 : (r >= 2 ? 2 * l0 : l0);
    int px = (int)lrint(len * ppm);
    if (px < 8) return;
    char txt[32];
    if (len >= 1) snprintf(txt, sizeof txt, "%.3g m", len);
    else if (len >= 0.01) snprintf(txt, sizeof txt, "%.3g cm", len * 100);
    else if (len >= 0.001) snprintf(txt, sizeof txt, "%.3g mm", len * 1000);
    else snprintf(txt, sizeof txt, "%.2g m", len);
    const int m = 6 * k->tsc, t = 2 * k->tsc, tick = 3 * ls, pad = 2 * ls;
    int tw = label_w(txt, ls), bw = px > tw ? px : tw;
    int x1 = w - m, x0 = x1 - px, yb = h - m; /* the bar's bottom */
    int ytop = yb - tick - ls - PFSPH_FONT_H * ls;
    panel(rgb, w, h, x1 - bw - pad, ytop - pad, bw + 2 * pad, yb - ytop + 2 * pad);
    fill(rgb, w, h, x0, yb - t, px, t, INK);
    fill(rgb, w, h, x0, yb - tick, t, tick, INK);
    fill(rgb, w, h, x1 - t, yb - tick, t, tick, INK);
    label(rgb, w, h, x0 + (px - tw) / 2, ytop, ls, txt);
}

void pfsph__draw_key(uint8_t *rgb, int w, int h, const pfsph__key *k)
{
    /* the key's letters as tall as the caption's digits (5x7 at tsc) */
    const int ls = k->tsc == 1 ? 2 : (3 * k->tsc) / 2;
    if (k->color_by != PFSPH__COLOR_PHASE && !k->liquid_mesh) {
        static const char *const NAME[] = {"", "speed [m/s]", "density [kg/m3]", "pressure [Pa]"};
        colour_bar(rgb, w, h, k->tsc, k->range);
        const char *txt = NAME[k->color_by];
        int x0 = w - 10 * k->tsc - 8 * k->tsc - 40 * k->tsc, y0 = h / 3 - 9 * ls;
        int tw = label_w(txt, ls), m = 6 * k->tsc;
        if (x0 + tw > w - m) x0 = w - m - tw;
        if (x0 >= 0 && h / 3 >= 8) {
            panel(rgb, w, h, x0 - ls, y0 - ls, tw + 2 * ls, (PFSPH_FONT_H + 2) * ls);
            label(rgb, w, h, x0, y0, ls, txt);
        }
    }
    legend(rgb, w, h, k, ls);
    scale_bar(rgb, w, h, k, ls);
}
