/* Rigid bodies: surface particles in the boundary set, fluid forces gathered per body particle
 * (Akinci et al. 2012, Eqs. 10 and 13 in our number-density form), dynamics and contacts by
 * the Open Dynamics Engine (ODE). Why ODE: a maintained C library in Debian with quaternion
 * integration, joints and box/sphere/cylinder/trimesh contacts; the fluid coupling stays ours.
 *
 * This file: rotations and keyframed poses, the queries (distance, forces, counts) and the state
 * (get, set, drag); bodies_internal.h lists the other pieces. */
#include "pfsph/bodies.h"

#include <math.h>
#include <string.h>

#include "physics/bodies_internal.h"

/* ------------------------------------------------------------------------------------------ */
/* Rotations. */

/* Quaternion (w, x, y, z) of "degrees about x, then y, then z" (fixed axes): q = qz qy qx. */
void pfsph__bodies_euler_quat(const double deg[3], double q[4])
{
    double h[3], c[3], s[3];
    for (int a = 0; a < 3; a++) {
        h[a] = deg[a] * (PI / 360.0);
        c[a] = cos(h[a]);
        s[a] = sin(h[a]);
    }
    q[0] = c[2] * c[1] * c[0] + s[2] * s[1] * s[0];
    q[1] = c[2] * c[1] * s[0] - s[2] * s[1] * c[0];
    q[2] = c[2] * s[1] * c[0] + s[2] * c[1] * s[0];
    q[3] = s[2] * c[1] * c[0] - c[2] * s[1] * s[0];
}

void pfsph__bodies_quat_mat(const double q[4], double R[9])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

static void slerp(const double a[4], const double b0[4], double t, double q[4])
{
    double b[4], d = a[0] * b0[0] + a[1] * b0[1] + a[2] * b0[2] + a[3] * b0[3];
    double sg = d < 0 ? -1 : 1;
    for (int k = 0; k < 4; k++) b[k] = sg * b0[k];
    d = fabs(d);
    double wa, wb;
    if (d > 0.9995) {
        wa = 1 - t;
        wb = t;
    } else {
        double th = acos(d), s = sin(th);
        wa = sin((1 - t) * th) / s;
        wb = sin(t * th) / s;
    }
    double n = 0;
    for (int k = 0; k < 4; k++) {
        q[k] = wa * a[k] + wb * b[k];
        n += q[k] * q[k];
    }
    n = sqrt(n);
    for (int k = 0; k < 4; k++) q[k] /= n;
}

/* Pose of a keyframed body at time t. */
void pfsph__bodies_key_pose(const pfsph_body_def *d, double t, double x[3], double q[4])
{
    if (d->nkeys == 0) {
        memcpy(x, d->position, sizeof(double) * 3);
        pfsph__bodies_euler_quat(d->rotation, q);
        return;
    }
    int k = 0;
    while (k + 1 < d->nkeys && d->keys[k + 1].t <= t) k++;
    const pfsph_keyframe *a = &d->keys[k];
    if (k + 1 >= d->nkeys || t <= a->t) {
        memcpy(x, a->position, sizeof(double) * 3);
        pfsph__bodies_euler_quat(a->rotation, q);
        return;
    }
    const pfsph_keyframe *b = &d->keys[k + 1];
    double s = (t - a->t) / (b->t - a->t), qa[4], qb[4];
    for (int i = 0; i < 3; i++) x[i] = (1 - s) * a->position[i] + s * b->position[i];
    pfsph__bodies_euler_quat(a->rotation, qa);
    pfsph__bodies_euler_quat(b->rotation, qb);
    slerp(qa, qb, s, q);
}

/* ------------------------------------------------------------------------------------------ */
/* Queries and state. */

int pfsph_bodies_count(const pfsph_bodies *B) { return B ? B->nb : 0; }
const char *pfsph_bodies_name(const pfsph_bodies *B, int i) { return B->b[i].def.name; }
double pfsph_bodies_mass(const pfsph_bodies *B, int i) { return B->b[i].mass; }
uint32_t pfsph_bodies_first_id(const pfsph_bodies *B) { return B->first_id; }
uint32_t pfsph_bodies_particle_count(const pfsph_bodies *B) { return B ? B->np : 0; }

void pfsph_bodies_last_force(const pfsph_bodies *B, int i, double f[3], double tq[3])
{
    memcpy(f, B->b[i].f, sizeof B->b[i].f);
    memcpy(tq, B->b[i].tq, sizeof B->b[i].tq);
}

double pfsph_bodies_distance(const pfsph_bodies *B, int i, const double p[3])
{
    const body *bd = &B->b[i];
    const pfsph_body_def *d = &bd->def;
    double q[4], R[9], x[3] = {d->position[0], d->position[1], d->position[2]};
    if (d->kinematic) pfsph__bodies_key_pose(d, 0.0, x, q);
    else pfsph__bodies_euler_quat(d->rotation, q);
    pfsph__bodies_quat_mat(q, R);
    double r[3] = {p[0] - x[0], p[1] - x[1], p[2] - x[2]}, l[3];
    if (B->dim == 2) r[2] = 0;
    for (int a = 0; a < 3; a++) l[a] = R[a] * r[0] + R[3 + a] * r[1] + R[6 + a] * r[2]; /* R^T r */
    switch (d->shape) {
    case PFSPH_BODY_BOX: {
        double o = 0, in = -INFINITY;
        for (int a = 0; a < B->dim; a++) {
            double t = fabs(l[a]) - d->half[a];
            if (t > 0) o += t * t;
            if (t > in) in = t;
        }
        return o > 0 ? sqrt(o) : in;
    }
    case PFSPH_BODY_SPHERE: return sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]) - d->radius;
    case PFSPH_BODY_CYLINDER: {
        if (B->dim == 2) return sqrt(l[0] * l[0] + l[1] * l[1]) - d->radius;
        double rr = 0;
        for (int a = 0; a < 3; a++)
            if (a != d->axis) rr += l[a] * l[a];
        double dr = sqrt(rr) - d->radius, dz = fabs(l[d->axis]) - 0.5 * d->height;
        if (dr > 0 && dz > 0) return sqrt(dr * dr + dz * dz);
        return dr > dz ? dr : dz;
    }
    default: {
        /* inside by ray parity along +x; outside distance by the nearest sample vertex is
         * enough to keep fluid off the surface */
        const pfsph_mesh *m = &bd->mesh;
        /* outside the bounding box: its distance is a lower bound, enough for the callers
         * (which only ask "nearer than 0.4 d?") and it spares the O(triangles) walk */
        double o = 0;
        for (int a = 0; a < 3; a++) {
            double t = fmax(bd->lo[a] - l[a], l[a] - bd->hi[a]);
            if (t > 0) o += t * t;
        }
        if (o > 0) return sqrt(o);
        int cross = 0;
        double dmin = INFINITY;
        for (size_t t = 0; t < m->ntris; t++) {
            const double *A = m->v + 3 * m->tri[3 * t], *Bv = m->v + 3 * m->tri[3 * t + 1],
                         *C = m->v + 3 * m->tri[3 * t + 2];
            /* ray l + s e_x, s > 0, against triangle: solve in the yz plane */
            double y0 = A[1] - l[1], z0 = A[2] - l[2], y1 = Bv[1] - l[1], z1 = Bv[2] - l[2], y2 = C[1] - l[1],
                   z2 = C[2] - l[2];
            double w0 = y1 * z2 - z1 * y2, w1 = y2 * z0 - z2 * y0, w2 = y0 * z1 - z0 * y1;
            if ((w0 > 0 && w1 > 0 && w2 > 0) || (w0 < 0 && w1 < 0 && w2 < 0)) {
                double ws = w0 + w1 + w2;
                double xs = (w0 * A[0] + w1 * Bv[0] + w2 * C[0]) / ws;
                if (xs > l[0]) cross ^= 1;
            }
            for (int k = 0; k < 3; k++) {
                const double *P = m->v + 3 * m->tri[3 * t + k];
                double dd =
                    (P[0] - l[0]) * (P[0] - l[0]) + (P[1] - l[1]) * (P[1] - l[1]) + (P[2] - l[2]) * (P[2] - l[2]);
                if (dd < dmin) dmin = dd;
            }
        }
        return cross ? -1.0 : sqrt(dmin);
    }
    }
}

double pfsph_bodies_vmax(const pfsph_bodies *B)
{
    double v = 0;
    for (int i = 0; B && i < B->nb; i++) v = fmax(v, B->b[i].vmax);
    return v;
}

void pfsph_bodies_get_state(const pfsph_bodies *B, int i, pfsph_body_state *st)
{
    const body *bd = &B->b[i];
    const dReal *p = dBodyGetPosition(bd->id), *q = dBodyGetQuaternion(bd->id), *v = dBodyGetLinearVel(bd->id),
                *w = dBodyGetAngularVel(bd->id);
    for (int a = 0; a < 3; a++) {
        st->x[a] = p[a];
        st->v[a] = v[a];
        st->w[a] = w[a];
    }
    for (int a = 0; a < 4; a++) st->q[a] = q[a];
}

void pfsph_bodies_set_state(pfsph_bodies *B, int i, const pfsph_body_state *st, pfsph_particles *boundary)
{
    body *bd = &B->b[i];
    dBodySetPosition(bd->id, st->x[0], st->x[1], st->x[2]);
    dBodySetQuaternion(bd->id, st->q);
    pfsph__bodies_canonical_quat(bd->id);
    dBodySetLinearVel(bd->id, st->v[0], st->v[1], st->v[2]);
    dBodySetAngularVel(bd->id, st->w[0], st->w[1], st->w[2]);
    pfsph__bodies_place_all(B, boundary);
}

int pfsph_bodies_world_mesh(const pfsph_bodies *B, int i, pfsph_mesh *m)
{
    const body *bd = &B->b[i];
    int rc = pfsph_mesh_copy(m, &bd->mesh);
    if (rc) return rc;
    const dReal *c = dBodyGetPosition(bd->id), *Rm = dBodyGetRotation(bd->id);
    double R[9], t[3] = {c[0], c[1], c[2]};
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) R[3 * r + k] = Rm[4 * r + k];
    pfsph_mesh_transform(m, 1.0, R, t);
    return PFSPH_OK;
}

void pfsph_bodies_set_gravity(pfsph_bodies *b, int dim, const double g[3])
{
    if (b) dWorldSetGravity(b->world, g[0], g[1], dim == 3 ? g[2] : 0);
}

int pfsph_bodies_drag(pfsph_bodies *b, int i, const double target[3], double vmax)
{
    if (!b || i < 0 || i >= b->nb) return PFSPH_EINPUT;
    body *bd = &b->b[i];
    if (bd->def.kinematic && bd->def.nkeys > 0) return PFSPH_EINPUT;
    if (!target) {
        bd->dragged = false;
        return PFSPH_OK;
    }
    for (int k = 0; k < 3; k++)
        if (!isfinite(target[k])) return PFSPH_EINPUT;
    if (!(vmax > 0) || !isfinite(vmax)) return PFSPH_EINPUT;
    memcpy(bd->drag_to, target, sizeof bd->drag_to);
    if (b->dim == 2) bd->drag_to[2] = 0;
    bd->drag_vmax = vmax;
    bd->dragged = true;
    return PFSPH_OK;
}

bool pfsph_bodies_draggable(const pfsph_bodies *b, int i)
{
    return b && i >= 0 && i < b->nb && !(b->b[i].def.kinematic && b->b[i].def.nkeys > 0);
}
