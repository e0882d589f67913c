/* The renderer's camera (render_internal.h): the view that frames a run's first frame, the
 * projection of particles to the screen, and the cut-away of the walls that face the camera;
 * also lent to the live viewer (pfsph_render_camera_for, pfsph_cutaway_*). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "io/render_internal.h"

#define PI 3.14159265358979323846

typedef pfsph__rcam cam;

static void look_at(cam *c, const double eye[3], const double target[3], const double up[3], double fov_deg)
{
    for (int k = 0; k < 3; k++) {
        c->eye[k] = eye[k];
        c->fwd[k] = target[k] - eye[k];
    }
    c->dist = sqrt(pfsph__rdot3(c->fwd, c->fwd));
    pfsph__rnorm3(c->fwd);
    pfsph__rcross3(c->fwd, up, c->right);
    pfsph__rnorm3(c->right);
    pfsph__rcross3(c->right, c->fwd, c->up);
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
    if (!(pfsph__rdot3(up, up) > 0)) up[0] = 0, up[1] = 0, up[2] = 1;
    pfsph__rnorm3(up);
    int a = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(up[k]) > fabs(up[a])) a = k;
    double right[3] = {0, 0, 0}, back[3];
    right[a == 0 ? 1 : 0] = 1;       /* x, unless x is up: y up gives back = +z, z up back = -y */
    pfsph__rcross3(right, up, back); /* towards the viewer */
    double dir[3];
    for (int k = 0; k < 3; k++) dir[k] = 0.55 * right[k] + 0.6 * up[k] + 1.0 * back[k];
    pfsph__rnorm3(dir);
    const double fov = 40.0;
    double eye[3];
    for (int k = 0; k < 3; k++) eye[k] = ctr[k] + dir[k];
    look_at(c, eye, ctr, up, fov); /* orientation only; now move back until the box fits */
    /* Each corner at camera offsets (xr, yu, zf) from the target projects inside 90 % of the
     * half-width w/2 at distance D when |xr| f / (D + zf) <= 0.45 w, likewise for y. */
    double rad = 0.5 * sqrt(pfsph__rdot3(ext, ext)), dist = 1.2 * rad + 1e-9;
    for (int m = 0; m < 8; m++) {
        double q[3];
        for (int k = 0; k < 3; k++) q[k] = ((m >> k) & 1 ? bx->hi[k] : bx->lo[k]) - ctr[k];
        double xr = fabs(pfsph__rdot3(q, c->right)), yu = fabs(pfsph__rdot3(q, c->up)), zf = pfsph__rdot3(q, c->fwd);
        dist = fmax(dist, xr * c->f / (0.45 * c->w) - zf);
        dist = fmax(dist, yu * c->f / (0.45 * c->h) - zf);
    }
    for (int k = 0; k < 3; k++) eye[k] = ctr[k] + dist * dir[k];
    look_at(c, eye, ctr, up, fov);
}

bool pfsph__rcam_project(const cam *c, const double p[3], double rad, pfsph__splat *s)
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
    double zc = pfsph__rdot3(q, c->fwd);
    if (!(zc > rad)) return false; /* behind or too close to the eye */
    double xc = pfsph__rdot3(q, c->right), yc = pfsph__rdot3(q, c->up);
    s->sx = (float)(0.5 * c->w + xc * c->f / zc);
    s->sy = (float)(0.5 * c->h - yc * c->f / zc);
    s->r = (float)(rad * c->f / zc);
    s->depth = (float)zc;
    s->rw = (float)rad;
    return true;
}

/* The walls of a tank that face the camera (3D): particles within 5 particle radii of a face of
 * the walls' box on the camera's side, sideways or above (never the floor: "up" is the axis
 * gravity acts along), so that what stands inside the tank shows. Only where the walls rise
 * beside the fluid (some fluid lies lower than the walls' top less the cut): drops standing on
 * plates, or sauce on a tray, have nothing to look into, and the cut would take the plates away
 * whole (the interactive wetting scene's five plates). Shared with the live viewer, which asks
 * again for every eye position as it orbits. */
void pfsph_cutaway_init(pfsph_cutaway *cw, const pfsph_scene *s, const pfsph_particles *walls,
                        const pfsph_particles *fluid)
{
    memset(cw, 0, sizeof *cw);
    cw->up = 1;
    if (s->dim == 2 || !walls || !walls->n) return;
    const double r = s->particle_radius > 0 ? s->particle_radius : 0.01;
    box3 bb;
    box_empty(&bb);
    box_add(&bb, walls);
    if (!(bb.lo[0] <= bb.hi[0])) return;
    cw->m = 5 * r;
    memcpy(cw->lo, bb.lo, sizeof cw->lo);
    memcpy(cw->hi, bb.hi, sizeof cw->hi);
    for (int a = 0; a < 3; a++)
        if (fabs(s->gravity[a]) > fabs(s->gravity[cw->up])) cw->up = a;
    cw->on = true;
    if (fluid && fluid->n) {
        box3 fb;
        box_empty(&fb);
        box_add(&fb, fluid);
        cw->on = fb.lo[cw->up] < bb.hi[cw->up] - cw->m;
    }
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

void pfsph__rcam_frame(cam *c, const pfsph_scene *s, const pfsph_particles *fluid, const pfsph_particles *boundary)
{
    box3 pb;
    box_empty(&pb);
    box_add(&pb, fluid);
    if (boundary) box_add(&pb, boundary);
    if (s->dim == 2) pb.lo[2] = pb.hi[2] = 0;
    box3 fb = frame_box(s, &pb, boundary && boundary->n > 0);
    setup_camera(c, s, &fb);
}

/* ---- for other front ends (the live viewer) ------------------------------------------- */

void pfsph_render_camera_for(const pfsph_scene *s, const pfsph_particles *fluid, const pfsph_particles *boundary, int w,
                             int h, pfsph_render_camera *out)
{
    cam c;
    memset(&c, 0, sizeof c);
    c.w = w;
    c.h = h;
    pfsph__rcam_frame(&c, s, fluid, boundary);
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
