/* PNG previews of a run directory: every particle is splatted as a shaded sphere (screen-space
 * disc with per-pixel depth, Lambert + ambient + a little specular), z-buffered, supersampled
 * 2x2, then written with libpng through the atomic writer; optionally an ffmpeg video. Where a
 * frame has meshes, the liquid's (liquid_NNNNN.ply) is rasterised and shaded as water and the
 * bodies' (surfaces_NNNNN.ply) as flat-shaded solids instead of their particles. */
#include "pfsph/render.h"
#include "pfsph/sim.h"
#include "pfsph/surface_mesh.h"

#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <png.h>
#include <spawn.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "io/io_internal.h"
#include "pfsph/io.h"
#include "pfsph/meshing.h"
#include "pfsph/scene.h"

extern char **environ;

#define BAND 16 /* rows per work item of the splatting loop */
#define PI 3.14159265358979323846

/* ---- frame files ------------------------------------------------------------------------ */

typedef pfsph_frame_list frame_list;

int pfsph_frame_list_read(const char *dir, const char *prefix, frame_list *fl, pfsph_error *err)
{
    memset(fl, 0, sizeof *fl);
    DIR *d = opendir(dir);
    if (!d) return pfsph_fail(err, PFSPH_EIO, "%s: cannot open: %s", dir, strerror(errno));
    size_t pl = strlen(prefix);
    struct dirent *de;
    int rc = PFSPH_OK;
    while ((de = readdir(d))) {
        const char *nm = de->d_name;
        if (strncmp(nm, prefix, pl) != 0) continue;
        const char *q = nm + pl;
        int digits = 0;
        long v = 0;
        while (q[digits] >= '0' && q[digits] <= '9' && digits < 9) v = v * 10 + (q[digits++] - '0');
        if (digits < 5) continue;
        bool vtp = strcmp(q + digits, ".vtp") == 0, ply = strcmp(q + digits, ".ply") == 0;
        if (!vtp && !ply) continue;
        int i;
        for (i = 0; i < fl->n; i++)
            if (fl->num[i] == (int)v) break;
        if (i < fl->n) {
            if (vtp) fl->ply[i] = 0;
            continue;
        }
        if (fl->n == fl->cap) {
            int cap = fl->cap ? 2 * fl->cap : 64;
            int *nn = realloc(fl->num, (size_t)cap * sizeof *nn);
            if (nn) fl->num = nn;
            char *np = realloc(fl->ply, (size_t)cap);
            if (np) fl->ply = np;
            if (!nn || !np) {
                rc = pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", dir);
                break;
            }
            fl->cap = cap;
        }
        fl->num[fl->n] = (int)v;
        fl->ply[fl->n] = ply;
        fl->n++;
    }
    closedir(d);
    /* Sort numbers and carry the ply flags along (small lists: insertion sort). */
    for (int i = 1; i < fl->n; i++)
        for (int j = i; j > 0 && fl->num[j - 1] > fl->num[j]; j--) {
            int t = fl->num[j];
            fl->num[j] = fl->num[j - 1];
            fl->num[j - 1] = t;
            char c = fl->ply[j];
            fl->ply[j] = fl->ply[j - 1];
            fl->ply[j - 1] = c;
        }
    return rc;
}

void pfsph_frame_list_free(frame_list *fl)
{
    free(fl->num);
    free(fl->ply);
    memset(fl, 0, sizeof *fl);
}

static int read_frame(const char *dir, const char *prefix, int num, bool ply, pfsph_particles *ps, double *time,
                      pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/%s%05d.%s", dir, prefix, num, ply ? "ply" : "vtp");
    return ply ? pfsph_read_ply(path, ps, time, err) : pfsph_read_vtp(path, ps, time, err);
}

/* ---- camera ----------------------------------------------------------------------------- */

typedef struct cam {
    bool ortho;
    double eye[3], right[3], up[3], fwd[3];
    double f;      /* perspective: focal length in pixels; ortho: pixels per metre */
    double cx, cy; /* ortho: world x, y at the image centre */
    int w, h;      /* supersampled image size */
} cam;

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void norm3(double a[3])
{
    double l = sqrt(dot3(a, a));
    if (l > 0)
        for (int k = 0; k < 3; k++) a[k] /= l;
}

static void look_at(cam *c, const double eye[3], const double target[3], const double up[3], double fov_deg)
{
    for (int k = 0; k < 3; k++) {
        c->eye[k] = eye[k];
        c->fwd[k] = target[k] - eye[k];
    }
    norm3(c->fwd);
    cross3(c->fwd, up, c->right);
    norm3(c->right);
    cross3(c->right, c->fwd, c->up);
    c->f = 0.5 * c->h / tan(0.5 * fov_deg * PI / 180.0);
}

typedef struct box3 {
    double lo[3], hi[3];
} box3;

static void box_empty(box3 *b)
{
    for (int k = 0; k < 3; k++) b->lo[k] = DBL_MAX, b->hi[k] = -DBL_MAX;
}

static void box_add(box3 *b, const pfsph_particles *ps)
{
    for (size_t i = 0; i < ps->n; i++) {
        double p[3] = {ps->x[i], ps->y[i], ps->z[i]};
        for (int k = 0; k < 3; k++)
            if (isfinite(p[k])) {
                if (p[k] < b->lo[k]) b->lo[k] = p[k];
                if (p[k] > b->hi[k]) b->hi[k] = p[k];
            }
    }
}

/* The box the default camera frames. 2D: the domain. 3D with a boundary: the fluid and
 * boundary particles of the first frame (the container is the scene; domains usually carry
 * head room). Either way the particles instead when the domain dwarfs them, so that a huge
 * safety domain does not shrink the scene to a dot. */
static box3 frame_box(const pfsph_scene *s, const box3 *parts, bool have_boundary)
{
    box3 d;
    for (int k = 0; k < 3; k++) d.lo[k] = s->domain_min[k], d.hi[k] = s->domain_max[k];
    if (s->dim == 2) d.lo[2] = d.hi[2] = 0;
    bool have = parts->lo[0] <= parts->hi[0];
    if (!have) return d;
    if (s->dim == 3 && have_boundary) return *parts;
    double de = 0, pe = 0;
    for (int k = 0; k < s->dim; k++) {
        de = fmax(de, d.hi[k] - d.lo[k]);
        pe = fmax(pe, parts->hi[k] - parts->lo[k]);
    }
    if (de > 4 * pe + 8 * s->particle_radius) {
        box3 b = *parts;
        for (int k = 0; k < s->dim; k++) {
            b.lo[k] -= 2 * s->particle_radius;
            b.hi[k] += 2 * s->particle_radius;
        }
        return b;
    }
    return d;
}

static void setup_camera(cam *c, const pfsph_scene *s, const box3 *bx)
{
    double ctr[3], ext[3];
    for (int k = 0; k < 3; k++) {
        ctr[k] = 0.5 * (bx->lo[k] + bx->hi[k]);
        ext[k] = bx->hi[k] - bx->lo[k];
    }
    if (s->dim == 2) {
        /* Orthographic view of the x-y plane, the box filling 94 % of the tighter side. */
        c->ortho = true;
        double ex = fmax(ext[0], 1e-9), ey = fmax(ext[1], 1e-9);
        c->f = 0.94 * fmin(c->w / ex, c->h / ey);
        c->cx = ctr[0];
        c->cy = ctr[1];
        double right[3] = {1, 0, 0}, up[3] = {0, 1, 0}, fwd[3] = {0, 0, -1};
        memcpy(c->right, right, sizeof right);
        memcpy(c->up, up, sizeof up);
        memcpy(c->fwd, fwd, sizeof fwd);
        return;
    }
    c->ortho = false;
    if (s->camera.set) {
        double fov = s->camera.fov_deg > 0 ? s->camera.fov_deg : 40.0;
        look_at(c, s->camera.eye, s->camera.target, s->camera.up, fov);
        return;
    }
    /* Front-right-above: "up" opposes gravity; right and front are the next axes round. */
    double up[3] = {-s->gravity[0], -s->gravity[1], -s->gravity[2]};
    if (!(dot3(up, up) > 0)) up[0] = 0, up[1] = 0, up[2] = 1;
    norm3(up);
    int a = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(up[k]) > fabs(up[a])) a = k;
    double right[3] = {0, 0, 0}, back[3];
    right[a == 0 ? 1 : 0] = 1; /* x, unless x is up: y up gives back = +z, z up back = -y */
    cross3(right, up, back);   /* towards the viewer */
    double dir[3];
    for (int k = 0; k < 3; k++) dir[k] = 0.55 * right[k] + 0.6 * up[k] + 1.0 * back[k];
    norm3(dir);
    const double fov = 40.0;
    double eye[3];
    for (int k = 0; k < 3; k++) eye[k] = ctr[k] + dir[k];
    look_at(c, eye, ctr, up, fov); /* orientation only; now move back until the box fits */
    /* Each corner at camera offsets (xr, yu, zf) from the target projects inside 90 % of the
     * half-width w/2 at distance D when |xr| f / (D + zf) <= 0.45 w, likewise for y. */
    double rad = 0.5 * sqrt(dot3(ext, ext)), dist = 1.2 * rad + 1e-9;
    for (int m = 0; m < 8; m++) {
        double q[3];
        for (int k = 0; k < 3; k++) q[k] = ((m >> k) & 1 ? bx->hi[k] : bx->lo[k]) - ctr[k];
        double xr = fabs(dot3(q, c->right)), yu = fabs(dot3(q, c->up)), zf = dot3(q, c->fwd);
        dist = fmax(dist, xr * c->f / (0.45 * c->w) - zf);
        dist = fmax(dist, yu * c->f / (0.45 * c->h) - zf);
    }
    for (int k = 0; k < 3; k++) eye[k] = ctr[k] + dist * dir[k];
    look_at(c, eye, ctr, up, fov);
}

/* ---- splatting -------------------------------------------------------------------------- */

typedef struct splat {
    float sx, sy, r; /* screen centre and radius, supersampled pixels */
    float depth, rw; /* depth of the centre, sphere radius in depth units */
    float col[3];
    float relief;  /* 0..1: how much shading; discs of a pixel or two are drawn flat */
    uint8_t layer; /* 0 fluid/diffuse, 1 boundary */
} splat;

/* Supersampled layers (0 fluid and diffuse, 1 boundary): nearest depth and the splat that
 * owns the sample; shading is deferred to the composite pass, once per sample. */
typedef struct image {
    int w, h;
    float *z[2];
    uint32_t *id[2];
} image;

static bool project(const cam *c, const double p[3], double rad, splat *s)
{
    if (c->ortho) {
        s->sx = (float)(0.5 * c->w + (p[0] - c->cx) * c->f);
        s->sy = (float)(0.5 * c->h - (p[1] - c->cy) * c->f);
        s->r = (float)(rad * c->f);
        s->depth = (float)(-p[2]);
        s->rw = (float)rad;
        return true;
    }
    double q[3] = {p[0] - c->eye[0], p[1] - c->eye[1], p[2] - c->eye[2]};
    double zc = dot3(q, c->fwd);
    if (!(zc > rad)) return false; /* behind or too close to the eye */
    double xc = dot3(q, c->right), yc = dot3(q, c->up);
    s->sx = (float)(0.5 * c->w + xc * c->f / zc);
    s->sy = (float)(0.5 * c->h - yc * c->f / zc);
    s->r = (float)(rad * c->f / zc);
    s->depth = (float)zc;
    s->rw = (float)rad;
    return true;
}

static void colormap(double t, float out[3])
{
    /* Viridis, sampled at five stops. */
    static const float st[5][3] = {{0.267f, 0.005f, 0.329f},
                                   {0.229f, 0.322f, 0.546f},
                                   {0.128f, 0.567f, 0.551f},
                                   {0.369f, 0.789f, 0.383f},
                                   {0.993f, 0.906f, 0.144f}};
    if (!(t > 0)) t = 0;
    if (t > 1) t = 1;
    double u = t * 4;
    int i = (int)u;
    if (i > 3) i = 3;
    double f = u - i;
    for (int k = 0; k < 3; k++) out[k] = (float)((1 - f) * st[i][k] + f * st[i + 1][k]);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

enum { COLOR_PHASE, COLOR_SPEED, COLOR_DENSITY, COLOR_PRESSURE };

static double field_value(const pfsph_particles *ps, size_t i, int by)
{
    switch (by) {
    case COLOR_SPEED: {
        double vx = ps->vx[i], vy = ps->vy[i], vz = ps->vz[i];
        return sqrt(vx * vx + vy * vy + vz * vz);
    }
    case COLOR_DENSITY: return ps->rho[i];
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
        *lo = by == COLOR_SPEED ? 0.0 : v[(size_t)(0.01 * (double)(m - 1))];
        *hi = v[(size_t)(0.99 * (double)(m - 1))];
    }
    free(v);
    if (!(*hi > *lo)) *hi = *lo + (fabs(*lo) > 0 ? 1e-3 * fabs(*lo) : 1.0);
}

static const float DIFFUSE_COL[3][3] = {{0.98f, 0.98f, 0.98f},  /* spray */
                                        {0.80f, 0.82f, 0.85f},  /* foam */
                                        {0.55f, 0.78f, 0.98f}}; /* bubble */

typedef struct splat_set {
    splat *s;
    size_t n, cap;
} splat_set;

/* The walls of a tank that face the camera (3D): particles within 5 particle radii of a face of
 * the walls' box on the camera's side, sideways or above (never the floor: "up" is the axis
 * gravity acts along), so that what stands inside the tank shows. Shared with the live viewer,
 * which asks again for every eye position as it orbits. */
void pfsph_cutaway_init(pfsph_cutaway *cw, const pfsph_scene *s, const pfsph_particles *walls)
{
    memset(cw, 0, sizeof *cw);
    cw->up = 1;
    if (s->dim == 2 || !walls || !walls->n) return;
    const double r = s->particle_radius > 0 ? s->particle_radius : 0.01;
    box3 bb;
    box_empty(&bb);
    box_add(&bb, walls);
    if (!(bb.lo[0] <= bb.hi[0])) return;
    cw->on = true;
    cw->m = 5 * r;
    memcpy(cw->lo, bb.lo, sizeof cw->lo);
    memcpy(cw->hi, bb.hi, sizeof cw->hi);
    for (int a = 0; a < 3; a++)
        if (fabs(s->gravity[a]) > fabs(s->gravity[cw->up])) cw->up = a;
}

bool pfsph_cutaway_hides(const pfsph_cutaway *cw, const double eye[3], const double p[3])
{
    if (!cw || !cw->on) return false;
    for (int a = 0; a < 3; a++) {
        if (eye[a] > cw->hi[a] && p[a] > cw->hi[a] - cw->m) return true;
        if (a != cw->up && eye[a] < cw->lo[a] && p[a] < cw->lo[a] + cw->m) return true;
    }
    return false;
}

static int add_set(splat_set *ss, const cam *c, const pfsph_particles *ps, double rad, int layer,
                   int kind /* 0 fluid, 1 boundary, 2 diffuse, 3 bodies */, const pfsph_scene *sc, int by, double vref,
                   int ssf, const pfsph_cutaway *cw, double range[2])
{
    if (ss->n + ps->n > ss->cap) {
        size_t cap = ss->n + ps->n;
        splat *q = realloc(ss->s, (cap ? cap : 1) * sizeof *q);
        if (!q) return PFSPH_ENOMEM;
        ss->s = q;
        ss->cap = cap;
    }
    double lo = 0, hi = 1;
    if (kind == 0 && by != COLOR_PHASE) field_range(ps, by, &lo, &hi);
    if (kind == 0 && by == COLOR_SPEED && vref > 0) hi = vref;
    if (range) range[0] = lo, range[1] = hi;
    for (size_t i = 0; i < ps->n; i++) {
        double p[3] = {ps->x[i], ps->y[i], sc->dim == 2 ? 0.0 : ps->z[i]};
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
        if (kind == 1 && pfsph_cutaway_hides(cw, c->eye, p)) continue;
        splat *s = &ss->s[ss->n];
        if (!project(c, p, rad, s)) continue;
        s->layer = (uint8_t)layer;
        /* Shading a disc of one or two output pixels only adds noise (a dotted texture). */
        double rp = s->r / ssf;
        s->relief = (float)(rp <= 1.5 ? 0.0 : (rp >= 4.0 ? 1.0 : (rp - 1.5) / 2.5));
        if (kind == 1) {
            /* walls recede in light grey unless their phase asks for a colour */
            int ph = ps->phase[i];
            if (ph < sc->nphases && sc->phases[ph].color_set) memcpy(s->col, sc->phases[ph].color, sizeof s->col);
            else s->col[0] = 0.78f, s->col[1] = 0.78f, s->col[2] = 0.80f;
        } else if (kind == 2) {
            int t = ps->phase[i] < 3 ? ps->phase[i] : 0;
            memcpy(s->col, DIFFUSE_COL[t], sizeof s->col);
        } else if (by == COLOR_PHASE || kind == 3) {
            int ph = ps->phase[i];
            if (ph < sc->nphases) memcpy(s->col, sc->phases[ph].color, sizeof s->col);
            else s->col[0] = 0.8f, s->col[1] = 0.2f, s->col[2] = 0.8f;
        } else {
            colormap((field_value(ps, i, by) - lo) / (hi - lo), s->col);
        }
        ss->n++;
    }
    return PFSPH_OK;
}

/* Depth-test every splat overlapping rows [y0, y1) into its layer. */
static void splat_band(image *im, const splat *sp, const size_t *idx, size_t nidx, int y0, int y1)
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
static void shade(const splat *s, int px, int py, bool flat, float out[3])
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

static void background(int y, int h, double out[3])
{
    /* Light, slightly darker towards the bottom. */
    double t = h > 1 ? (double)y / (h - 1) : 0;
    const double top[3] = {0.945, 0.950, 0.965}, bot[3] = {0.840, 0.850, 0.875};
    for (int k = 0; k < 3; k++) out[k] = (1 - t) * top[k] + t * bot[k];
}

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

static void draw_text(uint8_t *rgb, int w, int h, int x0, int y0, int sc, const char *txt)
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

/* A colour bar at the right edge for the field the fluid is coloured by, its range at the ends
 * (the numbers in the built-in font: digits, '.', '-', 'e'). */
static void draw_legend(uint8_t *rgb, int w, int h, int sc, const double range[2])
{
    const int bw = 10 * sc, bh = h / 3, x0 = w - bw - 8 * sc - 40 * sc, y0 = h / 3;
    if (x0 < 0 || bh < 8) return;
    for (int y = 0; y < bh; y++) {
        float c[3];
        colormap(1.0 - (double)y / (bh - 1), c);
        for (int x = 0; x < bw; x++) {
            uint8_t *p = rgb + 3 * ((size_t)(y0 + y) * w + x0 + x);
            for (int k = 0; k < 3; k++) p[k] = (uint8_t)lrint(c[k] * 255.0f);
        }
    }
    for (int e = 0; e < 2; e++) {
        char num[32], out[32];
        snprintf(num, sizeof num, "%.3g", range[1 - e]);
        size_t j = 0; /* "1.5e+03" -> "1.5e03": the font has no '+' */
        for (const char *t = num; *t && j + 1 < sizeof out; t++)
            if (*t != '+') out[j++] = *t;
        out[j] = 0;
        draw_text(rgb, w, h, x0 + bw + 3 * sc, e ? y0 + bh - 7 * sc : y0, sc, out);
    }
}

/* ---- PNG ------------------------------------------------------------------------------- */

typedef struct membuf {
    unsigned char *d;
    size_t n, cap;
    int failed;
} membuf;

static void png_mem_write(png_structp png, png_bytep data, png_size_t len)
{
    membuf *m = png_get_io_ptr(png);
    if (m->failed) return;
    if (m->n + len > m->cap) {
        size_t cap = m->cap ? m->cap : 65536;
        while (cap < m->n + len) cap *= 2;
        unsigned char *q = realloc(m->d, cap);
        if (!q) {
            m->failed = 1;
            return;
        }
        m->d = q;
        m->cap = cap;
    }
    memcpy(m->d + m->n, data, len);
    m->n += len;
}

static void png_mem_flush(png_structp png) { (void)png; }

/* Encode 8-bit RGB into m (no longjmp crosses live locals: all state is in m and rows). */
static int png_encode(const uint8_t *rgb, int w, int h, membuf *m)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    if (!png) return -1;
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        return -1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return -1;
    }
    png_set_write_fn(png, m, png_mem_write, png_mem_flush);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 4);
    png_write_info(png, info);
    for (int y = 0; y < h; y++) png_write_row(png, (png_const_bytep)(rgb + (size_t)3 * w * y));
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return m->failed ? -1 : 0;
}

/* ---- one frame ------------------------------------------------------------------------ */

typedef struct ctx {
    const pfsph_scene *sc;
    cam c;
    int ss; /* supersampling factor */
    int out_w, out_h;
    bool all_walls, no_legend;
    int color_by;
    double vref; /* speed colour scale: sqrt(2 g H) of the first frame's fluid, 0 if none */
    image im;
    splat_set sp;
    size_t *bidx; /* band lists */
    size_t *bstart;
    size_t bcap;
    uint8_t *rgb;
    float *mn; /* camera-space normals of liquid-mesh pixels (layer 0, id MESH_ID) */
} ctx;

#define MESH_ID UINT32_MAX

/* Layer-0 ids at or above BODY_ID0 are pixels of a body's mesh (body = id - BODY_ID0); MESH_ID
 * the liquid's. Splats never come near: their count is checked against UINT32_MAX - 512. */
#define BODY_ID0 (UINT32_MAX - 257u)

/* A mesh file of frame f (frames/<prefix>NNNNN.ply) into m; -1 when absent or unreadable, so
 * that a missing or broken mesh falls back to the particles. */
static int read_mesh(const char *fdir, const char *prefix, int f, pfsph_surface_mesh *m)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/%s%05d.ply", fdir, prefix, f);
    memset(m, 0, sizeof *m);
    if (access(path, R_OK) != 0) return -1;
    pfsph_error e;
    return pfsph_read_surface_ply(path, m, NULL, &e) == PFSPH_OK ? 0 : -1;
}

/* Depth-test a mesh's triangles into layer 0 (serial: the same pixels for any thread count):
 * bodies (id BODY_ID0 + the face's body) with the face's own normal, so that boxes keep their
 * edges; the liquid (MESH_ID) with its smooth vertex normals. */
static void raster_mesh(ctx *x, const pfsph_surface_mesh *m, bool bodies)
{
    const cam *c = &x->c;
    image *im = &x->im;
    for (size_t t = 0; t < m->ntris; t++) {
        splat s[3];
        float n[3][3];
        int ok = 1;
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->tri[3 * t + k];
            double p[3] = {m->v[3 * v], m->v[3 * v + 1], m->v[3 * v + 2]};
            if (!project(c, p, 0, &s[k])) ok = 0;
            double nw[3];
            if (bodies || !m->n) {
                const double *a = m->v + 3 * m->tri[3 * t], *b = m->v + 3 * m->tri[3 * t + 1],
                             *q = m->v + 3 * m->tri[3 * t + 2];
                double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {q[0] - a[0], q[1] - a[1], q[2] - a[2]};
                cross3(e1, e2, nw);
                norm3(nw);
            } else {
                for (int j = 0; j < 3; j++) nw[j] = m->n[3 * v + j];
            }
            n[k][0] = (float)dot3(nw, c->right);
            n[k][1] = (float)dot3(nw, c->up);
            n[k][2] = (float)-dot3(nw, c->fwd);
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
                im->id[0][o] = bodies ? BODY_ID0 + (m->phase[t] < 255 ? m->phase[t] : 255) : MESH_ID;
                for (int k = 0; k < 3; k++) x->mn[3 * o + k] = w[0] * n[0][k] + w[1] * n[1][k] + w[2] * n[2][k];
            }
    }
}

/* Water: a blue body, Lambert light, a sharp highlight and Schlick's Fresnel towards the sky. */
static void shade_water(const float nin[3], float out[3])
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
static void shade_solid(const float nin[3], const float col[3], float out[3])
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
static void body_color(const pfsph_scene *sc, int b, float col[3])
{
    col[0] = 0.8f, col[1] = 0.2f, col[2] = 0.8f;
    if (b < sc->nbodies && sc->bodies[b].phase >= 0 && sc->bodies[b].phase < sc->nphases)
        memcpy(col, sc->phases[sc->bodies[b].phase].color, 3 * sizeof *col);
}

static int render_frame(ctx *x, const pfsph_particles *fluid, const pfsph_particles *bnd, const pfsph_particles *bod,
                        const pfsph_particles *dif, const pfsph_surface_mesh *liq, const pfsph_surface_mesh *bmesh,
                        int frame, double time, const char *png_path, pfsph_error *err)
{
    const pfsph_scene *sc = x->sc;
    const double r = sc->particle_radius > 0 ? sc->particle_radius : 0.01;
    x->sp.n = 0;
    int rc = PFSPH_OK;
    /* 2D: the boundary is drawn behind the fluid (depth bias) and slightly smaller. */
    const bool d2 = sc->dim == 2;
    /* 2D fluid discs are drawn a little larger than the particle so that a block of fluid
     * reads as a surface rather than a lattice with holes (spacing is 2r). */
    const int ssf = x->ss;
    pfsph_cutaway cw;
    pfsph_cutaway_init(&cw, sc, x->all_walls ? NULL : bnd);
    double range[2] = {0, 1};
    if (bnd && (rc = add_set(&x->sp, &x->c, bnd, d2 ? 0.9 * r : r, 1, 1, sc, COLOR_PHASE, 0, ssf, &cw, NULL))) goto oom;
    const bool mesh = liq && liq->ntris && !d2; /* the liquid's surface instead of its particles */
    if (!mesh &&
        (rc = add_set(&x->sp, &x->c, fluid, d2 ? 1.3 * r : r, 0, 0, sc, x->color_by, x->vref, ssf, NULL, range)))
        goto oom;
    if (dif && (rc = add_set(&x->sp, &x->c, dif, 0.4 * r, 0, 2, sc, COLOR_PHASE, 0, ssf, NULL, NULL))) goto oom;
    /* rigid bodies are drawn solid in their phase's colour, not as translucent walls */
    const bool bmeshes = bmesh && bmesh->ntris && !d2; /* the bodies' surfaces instead of their particles */
    if (bod && !bmeshes && (rc = add_set(&x->sp, &x->c, bod, r, 0, 3, sc, COLOR_PHASE, 0, ssf, NULL, NULL))) goto oom;

    if (x->sp.n > UINT32_MAX - 512) return pfsph_fail(err, PFSPH_EINPUT, "%s: too many particles", png_path);
    /* Bin splats into bands of rows: a splat goes to every band it overlaps. */
    const int W = x->c.w, H = x->c.h, nb = (H + BAND - 1) / BAND;
    size_t *cnt = calloc((size_t)nb + 1, sizeof *cnt);
    if (!cnt) goto oom;
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            size_t acc = 0;
            for (int b = 0; b <= nb; b++) {
                size_t t = cnt[b];
                cnt[b] = acc;
                acc += t;
            }
            total = acc;
            if (total > x->bcap) {
                size_t *q = realloc(x->bidx, (total ? total : 1) * sizeof *q);
                if (!q) {
                    free(cnt);
                    goto oom;
                }
                x->bidx = q;
                x->bcap = total;
            }
            memcpy(x->bstart, cnt, ((size_t)nb + 1) * sizeof *cnt);
        }
        for (size_t i = 0; i < x->sp.n; i++) {
            const splat *s = &x->sp.s[i];
            float rr = s->r < 0.6f ? 0.6f : s->r;
            if (s->sx + rr < 0 || s->sx - rr > W || s->sy + rr < 0 || s->sy - rr > H) continue;
            int b0 = (int)floorf((s->sy - rr) / BAND), b1 = (int)floorf((s->sy + rr) / BAND);
            if (b0 < 0) b0 = 0;
            if (b1 > nb - 1) b1 = nb - 1;
            for (int b = b0; b <= b1; b++) {
                if (pass == 0) cnt[b]++;
                else x->bidx[cnt[b]++] = i;
            }
        }
    }
    free(cnt);

    const size_t npix = (size_t)W * H;
    for (int l = 0; l < 2; l++) {
        for (size_t i = 0; i < npix; i++) x->im.z[l][i] = FLT_MAX;
    }
    if (d2) /* push the boundary layer behind every fluid particle */
        for (size_t i = 0; i < x->sp.n; i++)
            if (x->sp.s[i].layer == 1) x->sp.s[i].depth += (float)(4 * r);
#pragma omp parallel for schedule(dynamic, 1)
    for (int b = 0; b < nb; b++) {
        int y0 = b * BAND, y1 = y0 + BAND < H ? y0 + BAND : H;
        splat_band(&x->im, x->sp.s, x->bidx + x->bstart[b], x->bstart[b + 1] - x->bstart[b], y0, y1);
    }
    if (mesh || bmeshes) {
        if (!x->mn && !(x->mn = malloc(3 * npix * sizeof *x->mn))) goto oom;
        if (mesh) raster_mesh(x, liq, false);
        if (bmeshes) raster_mesh(x, bmesh, true);
    }

    /* Composite and downsample: boundary walls in front of fluid are translucent in 3D. */
    const int ss = x->ss, ow = x->out_w, oh = x->out_h;
    const double a_front = d2 ? 1.0 : 0.28, a_back = d2 ? 1.0 : 0.85;
#pragma omp parallel for schedule(static)
    for (int oy = 0; oy < oh; oy++) {
        for (int ox = 0; ox < ow; ox++) {
            double acc[3] = {0, 0, 0};
            for (int sy = 0; sy < ss; sy++) {
                int py = oy * ss + sy;
                double bg[3];
                background(py, H, bg);
                for (int sx = 0; sx < ss; sx++) {
                    const int px = ox * ss + sx;
                    const size_t o = (size_t)py * W + (size_t)px;
                    double c[3];
                    float sc3[3];
                    bool hf = x->im.z[0][o] < FLT_MAX, hb = x->im.z[1][o] < FLT_MAX;
                    if (hf && x->im.id[0][o] == MESH_ID) {
                        shade_water(x->mn + 3 * o, sc3);
                        for (int k = 0; k < 3; k++) c[k] = sc3[k];
                    } else if (hf && x->im.id[0][o] >= BODY_ID0) {
                        float bc[3];
                        body_color(sc, (int)(x->im.id[0][o] - BODY_ID0), bc);
                        shade_solid(x->mn + 3 * o, bc, sc3);
                        for (int k = 0; k < 3; k++) c[k] = sc3[k];
                    } else if (hf) {
                        shade(&x->sp.s[x->im.id[0][o]], px, py, false, sc3);
                        for (int k = 0; k < 3; k++) c[k] = sc3[k];
                    } else {
                        for (int k = 0; k < 3; k++) c[k] = bg[k];
                    }
                    if (hb) {
                        double a = !hf ? a_back : (x->im.z[1][o] < x->im.z[0][o] ? a_front : 0);
                        shade(&x->sp.s[x->im.id[1][o]], px, py, !d2, sc3);
                        for (int k = 0; k < 3; k++) c[k] = (1 - a) * c[k] + a * sc3[k];
                    }
                    for (int k = 0; k < 3; k++) acc[k] += c[k];
                }
            }
            for (int k = 0; k < 3; k++)
                x->rgb[3 * ((size_t)oy * ow + ox) + k] = (uint8_t)lrint(fmin(1.0, acc[k] / (ss * ss)) * 255.0);
        }
    }
    char cap[96];
    snprintf(cap, sizeof cap, "frame %d  t=%.3f s", frame, time);
    int tsc = oh >= 400 ? 2 : 1;
    draw_text(x->rgb, ow, oh, 6 * tsc, oh - 9 * tsc - 4, tsc, cap);
    if (x->color_by != COLOR_PHASE && !mesh && !x->no_legend) draw_legend(x->rgb, ow, oh, tsc, range);

    membuf m = {0};
    if (png_encode(x->rgb, ow, oh, &m) != 0) {
        free(m.d);
        return pfsph_fail(err, PFSPH_EIO, "%s: PNG encoding failed", png_path);
    }
    rc = pfsph_write_file_atomic(png_path, m.d, m.n, err);
    free(m.d);
    return rc;
oom:
    return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", png_path);
}

/* ---- video ---------------------------------------------------------------------------- */

static bool on_path(const char *prog)
{
    const char *path = getenv("PATH");
    if (!path) return false;
    char buf[4096];
    while (*path) {
        size_t l = strcspn(path, ":");
        if (l && l + strlen(prog) + 2 < sizeof buf) {
            memcpy(buf, path, l);
            buf[l] = '/';
            strcpy(buf + l + 1, prog);
            if (access(buf, X_OK) == 0) return true;
        }
        path += l;
        if (*path == ':') path++;
    }
    return false;
}

static int run_wait(char *const argv[])
{
    pid_t pid;
    if (posix_spawnp(&pid, argv[0], NULL, NULL, argv, environ) != 0) return -1;
    int st;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int make_video(const char *run_dir, int first, double fps, const pfsph_render_opts *o, pfsph_error *err)
{
    char pattern[PFSPH_PATH_LEN + 64], out[PFSPH_PATH_LEN + 64], tmp[PFSPH_PATH_LEN + 96];
    snprintf(pattern, sizeof pattern, "%s/png/frame_%%05d.png", run_dir);
    snprintf(out, sizeof out, "%s/frames.mp4", run_dir);
    /* ffmpeg picks the container from the extension, so the temporary name ends in .mp4. */
    snprintf(tmp, sizeof tmp, "%s/frames.tmp.%ld.mp4", run_dir, (long)getpid());
    if (!on_path("ffmpeg"))
        return pfsph_fail(err, PFSPH_EIO, "%s: ffmpeg not found on PATH; the PNG frames are in %s/png", out, run_dir);
    char rate[32], start[32];
    snprintf(rate, sizeof rate, "%g", fps > 0 ? fps : 25.0);
    snprintf(start, sizeof start, "%d", first);
    const char *codecs[2][4] = {{"-c:v", "libx264", "-crf", "20"}, {"-c:v", "mpeg4", "-q:v", "3"}};
    int st = -1;
    for (int c = 0; c < 2 && st != 0; c++) {
        char *argv[] = {"ffmpeg",
                        "-y",
                        "-loglevel",
                        "error",
                        "-framerate",
                        rate,
                        "-start_number",
                        start,
                        "-i",
                        pattern,
                        "-vf",
                        "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                        "-pix_fmt",
                        "yuv420p",
                        (char *)codecs[c][0],
                        (char *)codecs[c][1],
                        (char *)codecs[c][2],
                        (char *)codecs[c][3],
                        tmp,
                        NULL};
        st = run_wait(argv);
    }
    if (st != 0) {
        unlink(tmp);
        return pfsph_fail(err, PFSPH_EIO, "%s: ffmpeg failed (exit status %d)", out, st);
    }
    if (rename(tmp, out) != 0) {
        int e = errno;
        unlink(tmp);
        return pfsph_fail(err, PFSPH_EIO, "%s: rename failed: %s", out, strerror(e));
    }
    if (o->message) {
        char msg[PFSPH_PATH_LEN + 96];
        snprintf(msg, sizeof msg, "wrote %s", out);
        o->message(msg, o->user);
    }
    return PFSPH_OK;
}

/* ---- driver --------------------------------------------------------------------------- */

/* A fixed colour scale for speed over the whole run (per-frame ranges flicker): the free-fall
 * speed sqrt(2 g H) over the fluid's height H in the first frame, the largest speed a
 * gravity-driven flow such as a dam break reaches, or what emitted fluid reaches when more.
 * 0 (per-frame range) without gravity or fluid. */
static double speed_scale(const pfsph_scene *sc, const pfsph_particles *fluid)
{
    double g2 = 0, ve = pfsph_scene_emitter_speed(sc);
    for (int k = 0; k < 3; k++) g2 += sc->gravity[k] * sc->gravity[k];
    if (!(g2 > 0) || fluid->n == 0) return ve;
    double g = sqrt(g2), lo = DBL_MAX, hi = -DBL_MAX;
    for (size_t i = 0; i < fluid->n; i++) {
        double h = -(fluid->x[i] * sc->gravity[0] + fluid->y[i] * sc->gravity[1] +
                     (sc->dim == 3 ? fluid->z[i] * sc->gravity[2] : 0.0)) /
            g;
        if (!isfinite(h)) continue;
        if (h < lo) lo = h;
        if (h > hi) hi = h;
    }
    return fmax(ve, hi > lo ? sqrt(2 * g * (hi - lo)) : 0);
}

static int color_code(const char *s)
{
    if (!s || !*s || strcmp(s, "phase") == 0) return COLOR_PHASE;
    if (strcmp(s, "speed") == 0) return COLOR_SPEED;
    if (strcmp(s, "density") == 0) return COLOR_DENSITY;
    if (strcmp(s, "pressure") == 0) return COLOR_PRESSURE;
    return -1;
}

/* Index of the newest entry with number <= f, or -1. */
static int newest_le(const frame_list *fl, int f)
{
    int best = -1;
    for (int i = 0; i < fl->n; i++)
        if (fl->num[i] <= f) best = i;
    return best;
}

int pfsph_frame_list_find(const frame_list *fl, int f)
{
    for (int i = 0; i < fl->n; i++)
        if (fl->num[i] == f) return i;
    return -1;
}

int pfsph_render_run(const char *run_dir, const pfsph_render_opts *o, int *count, pfsph_error *err)
{
    pfsph_render_opts def = {.last = -1};
    if (!o) o = &def;
    if (count) *count = 0;
    char path[PFSPH_PATH_LEN + 64], fdir[PFSPH_PATH_LEN + 16], pdir[PFSPH_PATH_LEN + 16];
    if (strlen(run_dir) >= PFSPH_PATH_LEN)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: run directory path too long", run_dir);
    snprintf(path, sizeof path, "%s/scene.json", run_dir);
    snprintf(fdir, sizeof fdir, "%s/frames", run_dir);
    snprintf(pdir, sizeof pdir, "%s/png", run_dir);

    pfsph_scene *sc = malloc(sizeof *sc);
    if (!sc) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    int rc = pfsph_scene_load(sc, path, err);
    if (rc != PFSPH_OK) {
        free(sc);
        return rc;
    }
    ctx x;
    memset(&x, 0, sizeof x);
    x.sc = sc;
    frame_list fl = {0}, bl = {0}, dl = {0}, rl = {0};
    pfsph_particles fluid = {0}, bnd = {0}, dif = {0}, both = {0};
    int bnd_loaded = -1, rendered = 0;

    const char *cby = o->color_by ? o->color_by : sc->camera.color_by;
    x.color_by = color_code(cby);
    x.all_walls = o->all_walls;
    x.no_legend = o->no_legend;
    if (x.color_by < 0) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "color_by '%s': expected phase, speed, density or pressure", cby);
        goto out;
    }
    x.out_w = o->width > 0 ? o->width : (sc->camera.width > 0 ? sc->camera.width : 960);
    x.out_h = o->height > 0 ? o->height : (sc->camera.height > 0 ? sc->camera.height : 540);
    if (x.out_w < 8 || x.out_h < 8 || x.out_w > 16384 || x.out_h > 16384) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "image size %dx%d: expected 8..16384 per side", x.out_w, x.out_h);
        goto out;
    }
    x.ss = (double)x.out_w * x.out_h <= 4096.0 * 2160.0 ? 2 : 1;
    x.c.w = x.out_w * x.ss;
    x.c.h = x.out_h * x.ss;

    if ((rc = pfsph_frame_list_read(fdir, "fluid_", &fl, err))) goto out;
    if ((rc = pfsph_frame_list_read(fdir, "boundary_", &bl, err))) goto out;
    if ((rc = pfsph_frame_list_read(fdir, "diffuse_", &dl, err))) goto out;
    if ((rc = pfsph_frame_list_read(fdir, "bodies_", &rl, err))) goto out;
    if (fl.n == 0) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: no fluid_NNNNN.vtp or .ply frames", fdir);
        goto out;
    }
    if (mkdir(pdir, 0755) != 0 && errno != EEXIST) {
        rc = pfsph_fail(err, PFSPH_EIO, "%s: cannot create: %s", pdir, strerror(errno));
        goto out;
    }

    const size_t npix = (size_t)x.c.w * x.c.h;
    for (int l = 0; l < 2; l++) {
        x.im.z[l] = malloc(npix * sizeof(float));
        x.im.id[l] = malloc(npix * sizeof(uint32_t));
    }
    x.im.w = x.c.w;
    x.im.h = x.c.h;
    x.rgb = malloc((size_t)x.out_w * x.out_h * 3);
    x.bstart = malloc(((size_t)(x.c.h + BAND - 1) / BAND + 1) * sizeof(size_t));
    if (!x.im.z[0] || !x.im.z[1] || !x.im.id[0] || !x.im.id[1] || !x.rgb || !x.bstart) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory for a %dx%d image", x.c.w, x.c.h);
        goto out;
    }

    /* The camera is fixed for the whole run, from the first frame rendered. */
    int i0 = -1;
    for (int i = 0; i < fl.n; i++)
        if (fl.num[i] >= o->first && (o->last < 0 || fl.num[i] <= o->last)) {
            i0 = i;
            break;
        }
    if (i0 < 0) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: no frames in the range %d..%d", fdir, o->first, o->last);
        goto out;
    }
    int first_num = fl.num[i0];
    int total = 0;
    for (int i = i0; i < fl.n && (o->last < 0 || fl.num[i] <= o->last); i++) total++;
    for (int i = i0; i < fl.n; i++) {
        int f = fl.num[i];
        if (o->last >= 0 && f > o->last) break;
        double t = 0;
        pfsph_particles_free(&fluid);
        if ((rc = read_frame(fdir, "fluid_", f, fl.ply[i], &fluid, &t, err))) goto out;
        int bi = newest_le(&bl, f);
        if (bi >= 0 && bl.num[bi] != bnd_loaded) {
            pfsph_particles_free(&bnd);
            if ((rc = read_frame(fdir, "boundary_", bl.num[bi], bl.ply[bi], &bnd, NULL, err))) goto out;
            bnd_loaded = bl.num[bi];
        }
        /* rigid bodies move: their particles of this frame */
        int ri = pfsph_frame_list_find(&rl, f);
        pfsph_particles_free(&both);
        if (ri >= 0 && (rc = read_frame(fdir, "bodies_", f, rl.ply[ri], &both, NULL, err))) goto out;
        int di = pfsph_frame_list_find(&dl, f);
        pfsph_particles_free(&dif);
        if (di >= 0 && (rc = read_frame(fdir, "diffuse_", f, dl.ply[di], &dif, NULL, err))) goto out;
        if (i == i0) {
            box3 pb;
            box_empty(&pb);
            box_add(&pb, &fluid);
            if (bi >= 0) box_add(&pb, &bnd);
            if (sc->dim == 2) pb.lo[2] = pb.hi[2] = 0;
            box3 fb = frame_box(sc, &pb, bi >= 0 && bnd.n > 0);
            setup_camera(&x.c, sc, &fb);
            x.vref = speed_scale(sc, &fluid);
        }
        pfsph_surface_mesh liq, bm;
        /* the liquid needs its normals (smooth shading); a file without them counts as absent */
        int have_liq = o->particles ? -1 : read_mesh(fdir, "liquid_", f, &liq);
        if (have_liq == 0 && !liq.n) {
            pfsph_surface_mesh_free(&liq);
            have_liq = -1;
        }
        int have_bm = o->particles ? -1 : read_mesh(fdir, "surfaces_", f, &bm);
        snprintf(path, sizeof path, "%s/frame_%05d.png", pdir, f);
        rc = render_frame(&x, &fluid, bi >= 0 ? &bnd : NULL, ri >= 0 ? &both : NULL, di >= 0 ? &dif : NULL,
                          have_liq == 0 ? &liq : NULL, have_bm == 0 ? &bm : NULL, f, t, path, err);
        if (have_liq == 0) pfsph_surface_mesh_free(&liq);
        if (have_bm == 0) pfsph_surface_mesh_free(&bm);
        if (rc != PFSPH_OK) goto out;
        rendered++;
        if (o->progress) o->progress(rendered, total, path, o->user);
    }
    if (o->video) rc = make_video(run_dir, first_num, sc->fps, o, err);

out:
    if (count) *count = rendered;
    pfsph_particles_free(&fluid);
    pfsph_particles_free(&bnd);
    pfsph_particles_free(&dif);
    pfsph_particles_free(&both);
    pfsph_frame_list_free(&fl);
    pfsph_frame_list_free(&bl);
    pfsph_frame_list_free(&dl);
    pfsph_frame_list_free(&rl);
    for (int l = 0; l < 2; l++) {
        free(x.im.z[l]);
        free(x.im.id[l]);
    }
    free(x.sp.s);
    free(x.bidx);
    free(x.bstart);
    free(x.rgb);
    free(x.mn);
    free(sc);
    return rc;
}

/* ---- for other front ends (the live viewer) ------------------------------------------- */

void pfsph_render_camera_for(const pfsph_scene *s, const pfsph_particles *fluid, const pfsph_particles *boundary, int w,
                             int h, pfsph_render_camera *out)
{
    box3 pb;
    box_empty(&pb);
    box_add(&pb, fluid);
    if (boundary) box_add(&pb, boundary);
    if (s->dim == 2) pb.lo[2] = pb.hi[2] = 0;
    box3 fb = frame_box(s, &pb, boundary && boundary->n > 0);
    cam c;
    memset(&c, 0, sizeof c);
    c.w = w;
    c.h = h;
    setup_camera(&c, s, &fb);
    memset(out, 0, sizeof *out);
    out->ortho = c.ortho;
    memcpy(out->eye, c.eye, sizeof c.eye);
    memcpy(out->right, c.right, sizeof c.right);
    memcpy(out->up, c.up, sizeof c.up);
    memcpy(out->fwd, c.fwd, sizeof c.fwd);
    out->f = c.f;
    out->cx = c.cx;
    out->cy = c.cy;
    out->w = w;
    out->h = h;
}

int pfsph_write_png_rgb(const char *path, const uint8_t *rgb, int w, int h, pfsph_error *err)
{
    membuf m = {0};
    if (png_encode(rgb, w, h, &m) != 0) {
        free(m.d);
        return pfsph_fail(err, PFSPH_EIO, "%s: PNG encoding failed", path);
    }
    int rc = pfsph_write_file_atomic(path, m.d, m.n, err);
    free(m.d);
    return rc;
}
