/* The viewer's orbit / pan / zoom camera (camera.h). */
#include "view/camera.h"

#include <math.h>
#include <string.h>

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

/* Rotate v about the unit axis u by angle t (Rodrigues). */
static void rotate(double v[3], const double u[3], double t)
{
    double c = cos(t), s = sin(t), ux[3], d = dot3(u, v);
    cross3(u, v, ux);
    for (int k = 0; k < 3; k++) v[k] = v[k] * c + ux[k] * s + u[k] * d * (1 - c);
}

static void look(pfsph_vcam *c)
{
    for (int k = 0; k < 3; k++) c->fwd[k] = c->target[k] - c->eye[k];
    norm3(c->fwd);
    cross3(c->fwd, c->world_up, c->right);
    norm3(c->right);
    cross3(c->right, c->fwd, c->up);
}

void pfsph_vcam_init(pfsph_vcam *c, const pfsph_render_camera *rc, const double centre[3])
{
    memset(c, 0, sizeof *c);
    c->ortho = rc->ortho;
    memcpy(c->eye, rc->eye, sizeof c->eye);
    memcpy(c->right, rc->right, sizeof c->right);
    memcpy(c->up, rc->up, sizeof c->up);
    memcpy(c->fwd, rc->fwd, sizeof c->fwd);
    memcpy(c->world_up, rc->up, sizeof c->world_up);
    c->f_per_h = rc->f / rc->h;
    c->cx = rc->cx;
    c->cy = rc->cy;
    if (c->ortho) return;
    /* orbit about the point on the view axis nearest the scene's centre */
    double q[3] = {centre[0] - c->eye[0], centre[1] - c->eye[1], centre[2] - c->eye[2]};
    double d = dot3(q, c->fwd);
    if (!(d > 1e-6)) d = 1;
    for (int k = 0; k < 3; k++) c->target[k] = c->eye[k] + d * c->fwd[k];
}

void pfsph_vcam_orbit(pfsph_vcam *c, double yaw, double pitch)
{
    if (c->ortho) return;
    double off[3];
    for (int k = 0; k < 3; k++) off[k] = c->eye[k] - c->target[k];
    double r = sqrt(dot3(off, off));
    rotate(off, c->world_up, -yaw);
    double right[3];
    cross3(off, c->world_up, right);
    norm3(right);
    double trial[3] = {off[0], off[1], off[2]};
    rotate(trial, right, pitch);
    /* stay off the poles, where the orbit axis and the view direction line up */
    if (fabs(dot3(trial, c->world_up)) < 0.995 * r) memcpy(off, trial, sizeof off);
    for (int k = 0; k < 3; k++) c->eye[k] = c->target[k] + off[k];
    look(c);
}

void pfsph_vcam_pan(pfsph_vcam *c, double dx, double dy, int h)
{
    if (c->ortho) {
        double s = 1.0 / (c->f_per_h * h);
        c->cx -= dx * s;
        c->cy += dy * s;
        return;
    }
    double off[3];
    for (int k = 0; k < 3; k++) off[k] = c->eye[k] - c->target[k];
    double s = sqrt(dot3(off, off)) / (c->f_per_h * h);
    for (int k = 0; k < 3; k++) {
        double m = -dx * s * c->right[k] + dy * s * c->up[k];
        c->eye[k] += m;
        c->target[k] += m;
    }
}

void pfsph_vcam_zoom(pfsph_vcam *c, double s)
{
    if (!(s > 0)) return;
    if (c->ortho) {
        c->f_per_h *= s;
        return;
    }
    for (int k = 0; k < 3; k++) c->eye[k] = c->target[k] + (c->eye[k] - c->target[k]) / s;
}

double pfsph_vcam_focal(const pfsph_vcam *c, int h) { return c->f_per_h * h; }

void pfsph_vcam_matrices(const pfsph_vcam *c, int w, int h, double depth, float view[16], float proj[16])
{
    memset(view, 0, 16 * sizeof(float));
    memset(proj, 0, 16 * sizeof(float));
    double eye[3];
    if (c->ortho) eye[0] = c->cx, eye[1] = c->cy, eye[2] = depth + 1;
    else memcpy(eye, c->eye, sizeof eye);
    const double *R = c->right, *U = c->up, *F = c->fwd;
    /* rows right, up, -fwd; column-major storage: m[col * 4 + row] */
    for (int k = 0; k < 3; k++) {
        view[k * 4 + 0] = (float)R[k];
        view[k * 4 + 1] = (float)U[k];
        view[k * 4 + 2] = (float)-F[k];
    }
    view[12] = (float)-dot3(R, eye);
    view[13] = (float)-dot3(U, eye);
    view[14] = (float)dot3(F, eye);
    view[15] = 1;
    double f = c->f_per_h * h;
    if (c->ortho) {
        /* x_ndc = 2 f x / w; depth from near 0 to far 2 depth + 2 in front of the eye */
        double n = 0, fa = 2 * depth + 2;
        proj[0] = (float)(2 * f / w);
        proj[5] = (float)(2 * f / h);
        proj[10] = (float)(-2 / (fa - n));
        proj[14] = (float)(-(fa + n) / (fa - n));
        proj[15] = 1;
        return;
    }
    double dist = 0;
    for (int k = 0; k < 3; k++) dist += (c->eye[k] - c->target[k]) * (c->eye[k] - c->target[k]);
    dist = sqrt(dist);
    double n = fmax(1e-4, 0.01 * fmin(dist, depth)), fa = dist + 4 * depth + 1;
    proj[0] = (float)(2 * f / w);
    proj[5] = (float)(2 * f / h);
    proj[10] = (float)(-(fa + n) / (fa - n));
    proj[11] = -1;
    proj[14] = (float)(-2 * fa * n / (fa - n));
}

int pfsph_vcam_project(const pfsph_vcam *c, int w, int h, const double p[3], double *sx, double *sy, double *depth)
{
    double f = c->f_per_h * h;
    if (c->ortho) {
        *sx = 0.5 * w + (p[0] - c->cx) * f;
        *sy = 0.5 * h - (p[1] - c->cy) * f;
        *depth = 0;
        return 1;
    }
    double q[3] = {p[0] - c->eye[0], p[1] - c->eye[1], p[2] - c->eye[2]};
    double zc = dot3(q, c->fwd);
    if (!(zc > 0)) return 0;
    *sx = 0.5 * w + dot3(q, c->right) * f / zc;
    *sy = 0.5 * h - dot3(q, c->up) * f / zc;
    *depth = zc;
    return 1;
}

void pfsph_vcam_unproject(const pfsph_vcam *c, int w, int h, double sx, double sy, double depth, double p[3])
{
    double f = c->f_per_h * h;
    if (c->ortho) {
        p[0] = c->cx + (sx - 0.5 * w) / f;
        p[1] = c->cy - (sy - 0.5 * h) / f;
        p[2] = 0;
        return;
    }
    double a = (sx - 0.5 * w) / f, b = -(sy - 0.5 * h) / f;
    for (int k = 0; k < 3; k++) p[k] = c->eye[k] + depth * (c->fwd[k] + a * c->right[k] + b * c->up[k]);
}
