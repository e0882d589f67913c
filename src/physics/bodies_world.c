/* The bodies' dynamics and contacts by the Open Dynamics Engine (bodies.h): the world with the
 * static solids as fixed colliders, each body's mass and geometry, the step (keyframed and
 * dragged bodies, contacts) and the body particles that follow it. */
#include "pfsph/bodies.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "physics/bodies_internal.h"

_Static_assert(sizeof(dTriIndex) == sizeof(uint32_t), "ODE built with 32-bit trimesh indices");

#define MAX_CONTACTS 16

static void mat_ode(const double R[9], dMatrix3 M)
{
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) M[4 * r + c] = R[3 * r + c];
        M[4 * r + 3] = 0;
    }
}

/* Rotation taking the z axis (ODE's cylinder axis) to axis a. */
static void axis_from_z(int a, double R[9])
{
    static const double X[9] = {0, 0, 1, 0, 1, 0, -1, 0, 0}; /* z -> x */
    static const double Y[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0}; /* z -> y */
    static const double Z[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(R, a == 0 ? X : a == 1 ? Y : Z, sizeof(double) * 9);
}

/* ODE's "LCP internal error" message (number 3) comes from the redundant contacts of boxes
 * resting face on face; the step still resolves them (test_body_contacts: a stack of three
 * boxes rests to 5e-9 m/s). Other messages are printed. */
static void ode_message(int num, const char *msg, va_list ap)
{
    if (num == 3) return;
    fprintf(stderr, "pfsph: ODE message %d: ", num);
    vfprintf(stderr, msg, ap);
    fputc('\n', stderr);
}

static void ode_init_once(void)
{
    static int done = 0;
    if (!done) {
        dInitODE2(0);
        dSetMessageHandler(ode_message);
        done = 1;
    }
    dAllocateODEDataForThread(dAllocateMaskAll);
}

/* Static solids as fixed colliders: a container's walls are thick boxes outside its faces. */
static int add_statics(pfsph_bodies *B, const pfsph_scene *s)
{
    const double T = 1.0 + 0.1 * (s->domain_max[1] - s->domain_min[1]); /* wall thickness */
    const double zext = 100.0;                                          /* 2D: depth of walls */
    B->statics = calloc((size_t)s->nsolids * 6 + 1, sizeof(dGeomID));
    if (!B->statics) return PFSPH_ENOMEM;
    for (int i = 0; i < s->nsolids; i++) {
        const pfsph_solid *o = &s->solids[i];
        dGeomID g;
        switch (o->shape) {
        case PFSPH_SHAPE_CONTAINER:
            for (int a = 0; a < s->dim; a++)
                for (int side = 0; side < 2; side++) {
                    if (a == 1 && side == 1 && o->open_top) continue;
                    double ext[3], c[3];
                    for (int k = 0; k < 3; k++) {
                        ext[k] = k < s->dim ? (o->max[k] - o->min[k]) + 2 * T : zext;
                        c[k] = k < s->dim ? 0.5 * (o->min[k] + o->max[k]) : 0;
                    }
                    ext[a] = T;
                    c[a] = side ? o->max[a] + 0.5 * T : o->min[a] - 0.5 * T;
                    g = dCreateBox(B->space, ext[0], ext[1], ext[2]);
                    dGeomSetPosition(g, c[0], c[1], c[2]);
                    B->statics[B->nstatics++] = g;
                }
            continue;
        case PFSPH_SHAPE_BOX: {
            double ext[3], c[3];
            for (int k = 0; k < 3; k++) {
                ext[k] = k < s->dim ? o->max[k] - o->min[k] : zext;
                c[k] = k < s->dim ? 0.5 * (o->min[k] + o->max[k]) : 0;
            }
            g = dCreateBox(B->space, ext[0], ext[1], ext[2]);
            dGeomSetPosition(g, c[0], c[1], c[2]);
            break;
        }
        case PFSPH_SHAPE_SPHERE:
            g = dCreateSphere(B->space, o->radius);
            dGeomSetPosition(g, o->center[0], o->center[1], o->center[2]);
            break;
        case PFSPH_SHAPE_CYLINDER: {
            double R[9];
            dMatrix3 M;
            if (s->dim == 2) {
                g = dCreateCylinder(B->space, o->radius, zext);
                axis_from_z(2, R);
            } else {
                g = dCreateCylinder(B->space, o->radius, o->height);
                axis_from_z(o->axis, R);
            }
            mat_ode(R, M);
            dGeomSetRotation(g, M);
            dGeomSetPosition(g, o->center[0], o->center[1], s->dim == 2 ? 0 : o->center[2]);
            break;
        }
        case PFSPH_SHAPE_PLANE: {
            double d = o->normal[0] * o->center[0] + o->normal[1] * o->center[1] +
                (s->dim == 3 ? o->normal[2] * o->center[2] : 0);
            g = dCreatePlane(B->space, o->normal[0], o->normal[1], s->dim == 3 ? o->normal[2] : 0, d);
            break;
        }
        default: continue;
        }
        B->statics[B->nstatics++] = g;
    }
    return PFSPH_OK;
}

/* A mass ODE takes: dBodySetMass aborts the program (an assertion) on a mass <= 0 or an
 * inertia that is not positive definite, which underflow makes of tiny bodies. */
static int mass_ok(const dMass *m)
{
    const dReal *I = m->I; /* 3 x 4, row major */
    double a = I[0], b = I[1], c = I[2], e = I[5], f = I[6], i = I[10];
    double m2 = a * e - b * b, m3 = a * (e * i - f * f) - b * (b * i - f * c) + c * (b * f - e * c);
    return m->mass > 0 && isfinite(m->mass) && a > 0 && m2 > 0 && m3 > 0 && isfinite(m3) && dMassCheck(m);
}

static int set_mass(body *bd, int dim)
{
    const pfsph_body_def *d = &bd->def;
    dMass m;
    double vol;
    switch (d->shape) {
    case PFSPH_BODY_BOX:
        vol = 8 * d->half[0] * d->half[1] * d->half[2]; /* 2D: half[2] = 0.5, unit depth */
        bd->mass = d->mass > 0 ? d->mass : d->density * vol;
        dMassSetBoxTotal(&m, bd->mass, 2 * d->half[0], 2 * d->half[1], 2 * d->half[2]);
        break;
    case PFSPH_BODY_SPHERE:
    case PFSPH_BODY_CYLINDER:
        if (dim == 2) { /* a disc of unit depth */
            vol = PI * d->radius * d->radius;
            bd->mass = d->mass > 0 ? d->mass : d->density * vol;
            dMassSetCylinderTotal(&m, bd->mass, 3, d->radius, 1.0);
        } else if (d->shape == PFSPH_BODY_SPHERE) {
            vol = 4.0 / 3.0 * PI * d->radius * d->radius * d->radius;
            bd->mass = d->mass > 0 ? d->mass : d->density * vol;
            dMassSetSphereTotal(&m, bd->mass, d->radius);
        } else {
            vol = PI * d->radius * d->radius * d->height;
            bd->mass = d->mass > 0 ? d->mass : d->density * vol;
            dMassSetCylinderTotal(&m, bd->mass, d->axis + 1, d->radius, d->height);
        }
        break;
    default: {
        double com[3], I[9];
        pfsph_mesh_mass_properties(&bd->mesh, &vol, com, I);
        bd->mass = d->mass > 0 ? d->mass : d->density * vol;
        double rho = bd->mass / vol;
        dMassSetParameters(&m, bd->mass, 0, 0, 0, rho * I[0], rho * I[4], rho * I[8], rho * I[1], rho * I[2],
                           rho * I[5]);
        break;
    }
    }
    if (d->inertia[2] > 0) { /* given principal moments (2D: about z only) */
        double I[3] = {d->inertia[0], d->inertia[1], d->inertia[2]};
        if (dim == 2) I[0] = I[1] = I[2];
        dMassSetParameters(&m, bd->mass, 0, 0, 0, I[0], I[1], I[2], 0, 0, 0);
    }
    if (!mass_ok(&m)) return -1;
    dBodySetMass(bd->id, &m);
    return 0;
}

static void make_geom(pfsph_bodies *B, body *bd, int dim)
{
    const pfsph_body_def *d = &bd->def;
    double R[9];
    dMatrix3 M;
    switch (d->shape) {
    case PFSPH_BODY_BOX:
        bd->geom = dCreateBox(B->space, 2 * d->half[0], 2 * d->half[1], dim == 2 ? 100.0 : 2 * d->half[2]);
        dGeomSetBody(bd->geom, bd->id);
        break;
    case PFSPH_BODY_SPHERE:
        bd->geom = dCreateSphere(B->space, d->radius);
        dGeomSetBody(bd->geom, bd->id);
        break;
    case PFSPH_BODY_CYLINDER:
        if (dim == 2) { /* a disc: the sphere collides like it in the plane */
            bd->geom = dCreateSphere(B->space, d->radius);
            dGeomSetBody(bd->geom, bd->id);
        } else {
            bd->geom = dCreateCylinder(B->space, d->radius, d->height);
            dGeomSetBody(bd->geom, bd->id);
            axis_from_z(d->axis, R);
            mat_ode(R, M);
            dGeomSetOffsetRotation(bd->geom, M);
        }
        break;
    default:
        bd->tmdata = dGeomTriMeshDataCreate();
        dGeomTriMeshDataBuildDouble(bd->tmdata, bd->mesh.v, 3 * sizeof(double), (int)bd->mesh.nverts, bd->mesh.tri,
                                    (int)(3 * bd->mesh.ntris), 3 * sizeof(uint32_t));
        bd->geom = dCreateTriMesh(B->space, bd->tmdata, NULL, NULL, NULL);
        dGeomSetBody(bd->geom, bd->id);
        break;
    }
    dGeomSetData(bd->geom, bd);
}

int pfsph__bodies_world_create(pfsph_bodies *B, const pfsph_scene *s, double spacing)
{
    ode_init_once();
    B->world = dWorldCreate();
    B->space = dSimpleSpaceCreate(0);
    B->contacts = dJointGroupCreate(0);
    dWorldSetGravity(B->world, s->gravity[0], s->gravity[1], s->dim == 3 ? s->gravity[2] : 0);
    /* contact tuning in units of the particle spacing: bodies may sink d/20 into each other
     * before the contact pushes back, and are pushed apart at most 1 m/s */
    dWorldSetERP(B->world, 0.2);
    dWorldSetCFM(B->world, 1e-9);
    dWorldSetContactSurfaceLayer(B->world, 0.05 * spacing);
    dWorldSetContactMaxCorrectingVel(B->world, 1.0);
    return add_statics(B, s);
}

int pfsph__bodies_world_add(pfsph_bodies *B, body *bd, int dim)
{
    bd->id = dBodyCreate(B->world);
    if (set_mass(bd, dim)) return -1;
    make_geom(B, bd, dim);
    double q[4];
    pfsph__bodies_euler_quat(bd->def.rotation, q);
    dBodySetPosition(bd->id, bd->def.position[0], bd->def.position[1], bd->def.position[2]);
    dBodySetQuaternion(bd->id, q);
    dBodySetLinearVel(bd->id, bd->def.velocity[0], bd->def.velocity[1], bd->def.velocity[2]);
    dBodySetAngularVel(bd->id, bd->def.angular_velocity[0], bd->def.angular_velocity[1], bd->def.angular_velocity[2]);
    if (bd->def.kinematic) {
        double x[3];
        dBodySetKinematic(bd->id);
        pfsph__bodies_key_pose(&bd->def, 0.0, x, q);
        dBodySetPosition(bd->id, x[0], x[1], x[2]);
        dBodySetQuaternion(bd->id, q);
        dBodySetLinearVel(bd->id, 0, 0, 0);
        dBodySetAngularVel(bd->id, 0, 0, 0);
    } else if (dim == 2) {
        dJointID j = dJointCreatePlane2D(B->world, 0);
        dJointAttach(j, bd->id, 0);
    }
    dBodySetGyroscopicMode(bd->id, dim == 3);
    return 0;
}

void pfsph_bodies_destroy(pfsph_bodies *B)
{
    if (!B) return;
    for (int i = 0; i < B->nb; i++) {
        if (B->b[i].geom) dGeomDestroy(B->b[i].geom);
        if (B->b[i].tmdata) dGeomTriMeshDataDestroy(B->b[i].tmdata);
        pfsph_mesh_free(&B->b[i].mesh);
    }
    for (int i = 0; i < B->nstatics; i++) dGeomDestroy(B->statics[i]);
    if (B->contacts) dJointGroupDestroy(B->contacts);
    if (B->space) dSpaceDestroy(B->space);
    if (B->world) dWorldDestroy(B->world);
    free(B->statics);
    free(B->b);
    free(B->local);
    free(B->owner);
    free(B->fp);
    free(B);
}

static void near_cb(void *data, dGeomID g1, dGeomID g2)
{
    pfsph_bodies *B = data;
    dBodyID b1 = dGeomGetBody(g1), b2 = dGeomGetBody(g2);
    if (!b1 && !b2) return;
    if ((!b1 || dBodyIsKinematic(b1)) && (!b2 || dBodyIsKinematic(b2))) return;
    dContactGeom cg[MAX_CONTACTS];
    int n = dCollide(g1, g2, MAX_CONTACTS, cg, sizeof(dContactGeom));
    const body *p1 = b1 ? dGeomGetData(g1) : NULL, *p2 = b2 ? dGeomGetData(g2) : NULL;
    double mu = p1 && p2 ? sqrt(p1->def.friction * p2->def.friction) : (p1 ? p1->def.friction : p2->def.friction);
    double e = fmax(p1 ? p1->def.restitution : 0, p2 ? p2->def.restitution : 0);
    for (int i = 0; i < n; i++) {
        dContact c;
        memset(&c, 0, sizeof c);
        c.geom = cg[i];
        c.surface.mode = dContactApprox1 | (e > 0 ? dContactBounce : 0);
        c.surface.mu = mu;
        c.surface.bounce = e;
        c.surface.bounce_vel = 0.1;
        dJointID j = dJointCreateContact(B->world, B->contacts, &c);
        dJointAttach(j, b1, b2);
    }
}

/* Move every body particle to its body's pose (one pass over the boundary set, which is in
 * grid order). */
void pfsph__bodies_place_all(pfsph_bodies *B, pfsph_particles *bs)
{
    enum { NB = PFSPH_MAX_BODIES };
    double C[NB][3], R[NB][9], V[NB][3], W[NB][3], vmax2[NB];
    for (int i = 0; i < B->nb; i++) {
        const dReal *c = dBodyGetPosition(B->b[i].id), *Rm = dBodyGetRotation(B->b[i].id);
        const dReal *v = dBodyGetLinearVel(B->b[i].id), *w = dBodyGetAngularVel(B->b[i].id);
        for (int a = 0; a < 3; a++) {
            C[i][a] = c[a];
            V[i][a] = v[a];
            W[i][a] = w[a];
            for (int k = 0; k < 3; k++) R[i][3 * a + k] = Rm[4 * a + k];
        }
        vmax2[i] = 0;
    }
    for (size_t j = 0; j < bs->n; j++) {
        if (bs->id[j] < B->first_id) continue;
        const uint32_t l = bs->id[j] - B->first_id;
        const int i = B->owner[l];
        const double *lc = B->local + 3 * l, *Ri = R[i], *v = V[i], *w = W[i];
        double r[3];
        for (int a = 0; a < 3; a++) r[a] = Ri[3 * a] * lc[0] + Ri[3 * a + 1] * lc[1] + Ri[3 * a + 2] * lc[2];
        double u[3] = {v[0] + w[1] * r[2] - w[2] * r[1], v[1] + w[2] * r[0] - w[0] * r[2],
                       v[2] + w[0] * r[1] - w[1] * r[0]};
        if (B->dim == 2) r[2] = u[2] = 0;
        bs->x[j] = (pfsph_real)(C[i][0] + r[0]);
        bs->y[j] = (pfsph_real)(C[i][1] + r[1]);
        bs->z[j] = (pfsph_real)(B->dim == 2 ? 0 : C[i][2] + r[2]);
        bs->vx[j] = (pfsph_real)u[0];
        bs->vy[j] = (pfsph_real)u[1];
        bs->vz[j] = (pfsph_real)u[2];
        double s2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
        if (s2 > vmax2[i]) vmax2[i] = s2;
    }
    for (int i = 0; i < B->nb; i++) B->b[i].vmax = sqrt(vmax2[i]);
}

/* ODE renormalises a quaternion whenever it is set; storing the fixed point of that makes a
 * saved and restored pose identical to the running one (bit-exact resume). */
void pfsph__bodies_canonical_quat(dBodyID id)
{
    for (int it = 0; it < 4; it++) {
        dQuaternion q;
        memcpy(q, dBodyGetQuaternion(id), sizeof q);
        dBodySetQuaternion(id, q);
        if (memcmp(q, dBodyGetQuaternion(id), sizeof q) == 0) break;
    }
}

/* A dragged body moves from where it is straight towards drag_to, at most drag_vmax [m/s],
 * without turning. */
static void drag_pose(const body *bd, double dt, double x0[3], double q0[4], double x1[3], double q1[4])
{
    memcpy(x0, dBodyGetPosition(bd->id), 3 * sizeof(double));
    const dReal *q = dBodyGetQuaternion(bd->id);
    double d[3], len = 0;
    for (int k = 0; k < 3; k++) {
        q0[k] = q1[k] = q[k];
        d[k] = bd->drag_to[k] - x0[k];
        len += d[k] * d[k];
    }
    q0[3] = q1[3] = q[3];
    len = sqrt(len);
    double s = len > bd->drag_vmax * dt ? bd->drag_vmax * dt / len : 1;
    for (int k = 0; k < 3; k++) x1[k] = x0[k] + s * d[k];
}

/* The spring that pulls a dragged dynamic body's centre of mass towards drag_to: critically
 * damped at 5 Hz (omega = 31.4 1/s, the mouse joint's usual tuning in game physics: the body
 * follows a cursor within about 0.2 s and sags g / omega^2 = 1 cm under gravity while held).
 * Far from the target the pull is capped so that the speed it drives towards is drag_vmax:
 * omega^2 |dx| at most 2 omega vmax, where the damping -2 omega v balances it. Acts at the
 * centre of mass (no torque): the body turns only as the fluid and contacts turn it. */
#define DRAG_OMEGA (2 * PI * 5.0)
static void drag_spring(const body *bd)
{
    const dReal *x = dBodyGetPosition(bd->id), *v = dBodyGetLinearVel(bd->id);
    dMass ms;
    dBodyGetMass(bd->id, &ms);
    double d[3], len = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = bd->drag_to[k] - x[k];
        len += d[k] * d[k];
    }
    len = sqrt(len);
    const double w = DRAG_OMEGA, cap = 2 * bd->drag_vmax / w;
    const double s = len > cap ? cap / len : 1;
    double f[3];
    for (int k = 0; k < 3; k++) f[k] = ms.mass * (w * w * s * d[k] - 2 * w * v[k]);
    dBodyAddForce(bd->id, f[0], f[1], f[2]);
}

void pfsph_bodies_step(pfsph_bodies *B, pfsph_particles *bs, double t, double dt)
{
    if (!B->nb) return;
    for (int i = 0; i < B->nb; i++) {
        body *bd = &B->b[i];
        if (bd->def.kinematic) {
            /* velocities that carry the body from its pose at t to the one at t + dt */
            double x0[3], q0[4], x1[3], q1[4];
            pfsph__bodies_key_pose(&bd->def, t, x0, q0);
            pfsph__bodies_key_pose(&bd->def, t + dt, x1, q1);
            if (bd->dragged) drag_pose(bd, dt, x0, q0, x1, q1);
            dBodySetPosition(bd->id, x0[0], x0[1], x0[2]);
            dBodySetQuaternion(bd->id, q0);
            dBodySetLinearVel(bd->id, (x1[0] - x0[0]) / dt, (x1[1] - x0[1]) / dt, (x1[2] - x0[2]) / dt);
            /* omega = 2 (dq/dt) q^-1, vector part */
            double dq[4], w[3];
            double sg = q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3] < 0 ? -1 : 1;
            for (int k = 0; k < 4; k++) dq[k] = (sg * q1[k] - q0[k]) / dt;
            double c[4] = {q0[0], -q0[1], -q0[2], -q0[3]};
            w[0] = 2 * (dq[0] * c[1] + dq[1] * c[0] + dq[2] * c[3] - dq[3] * c[2]);
            w[1] = 2 * (dq[0] * c[2] - dq[1] * c[3] + dq[2] * c[0] + dq[3] * c[1]);
            w[2] = 2 * (dq[0] * c[3] + dq[1] * c[2] - dq[2] * c[1] + dq[3] * c[0]);
            dBodySetAngularVel(bd->id, w[0], w[1], w[2]);
        } else {
            dBodyAddForce(bd->id, bd->f[0], bd->f[1], bd->f[2]);
            dBodyAddTorque(bd->id, bd->tq[0], bd->tq[1], bd->tq[2]);
            if (bd->dragged) drag_spring(bd);
        }
    }
    dSpaceCollide(B->space, B, near_cb);
    /* The direct solver. The iterative one (QuickStep, 50 iterations) left an icosphere resting
     * on a box jittering at 7.5 cm/s; the direct one brings it to rest (1e-8 m/s). */
    dWorldStep(B->world, dt);
    dJointGroupEmpty(B->contacts);
    for (int i = 0; i < B->nb; i++) {
        body *bd = &B->b[i];
        if (bd->def.kinematic) {
            double x1[3], q1[4];
            pfsph__bodies_key_pose(&bd->def, t + dt, x1, q1);
            if (bd->dragged) {
                /* the step ended where the drag put it: from now on its resting pose */
                memcpy(x1, dBodyGetPosition(bd->id), sizeof x1);
                memcpy(bd->def.position, x1, sizeof x1);
            }
            dBodySetPosition(bd->id, x1[0], x1[1], x1[2]);
            dBodySetQuaternion(bd->id, q1);
        } else if (B->dim == 2) {
            /* keep the body in its plane exactly (the Plane2D joint holds it to round-off) */
            const dReal *p = dBodyGetPosition(bd->id);
            dBodySetPosition(bd->id, p[0], p[1], 0);
        }
        pfsph__bodies_canonical_quat(bd->id);
    }
    pfsph__bodies_place_all(B, bs);
}
