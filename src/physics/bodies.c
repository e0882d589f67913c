/* Rigid bodies: surface particles in the boundary set, fluid forces gathered per body particle
 * (Akinci et al. 2012, Eqs. 10 and 13 in our number-density form), dynamics and contacts by
 * the Open Dynamics Engine (ODE). Why ODE: a maintained C library in Debian with quaternion
 * integration, joints and box/sphere/cylinder/trimesh contacts; the fluid coupling stays ours. */
#include "pfsph/bodies.h"
#include "pfsph/thermostat.h"

#include <math.h>
#include <ode/ode.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "physics/boundary.h"
#include "scene/shapes.h"

_Static_assert(sizeof(dTriIndex) == sizeof(uint32_t), "ODE built with 32-bit trimesh indices");

#define MAX_CONTACTS 16
static const double PI = 3.14159265358979323846;

typedef struct body {
    pfsph_body_def def;
    dBodyID id;
    dGeomID geom;
    dTriMeshDataID tmdata;
    pfsph_mesh mesh;     /* surface in body coordinates (about the centre of mass) */
    double lo[3], hi[3]; /* its bounding box */
    double mass;
    uint32_t first; /* first particle, as an index into the body-particle tables */
    uint32_t n;
    double f[3], tq[3]; /* fluid force and torque of the last step */
    double vmax;        /* largest particle speed */
    bool dragged;       /* follows drag_to (pfsph_bodies_drag): kinematic, no keyframes, on a
                        * straight line; dynamic, pulled by a damped spring */
    double drag_to[3], drag_vmax;
} body;

struct pfsph_bodies {
    int dim, nb;
    body *b;
    dWorldID world;
    dSpaceID space;
    dJointGroupID contacts;
    dGeomID *statics;
    int nstatics;
    uint32_t first_id; /* boundary ids >= first_id belong to bodies */
    uint32_t np;       /* body particles */
    double *local;     /* 3 * np body-frame positions */
    uint16_t *owner;   /* body of each particle */
    double *fp;        /* 3 * np fluid force per particle (this step) */
    double spacing;
};

static void place_all(pfsph_bodies *B, pfsph_particles *bs);
static void canonical_quat(dBodyID id);

/* ------------------------------------------------------------------------------------------ */
/* Rotations. */

/* Quaternion (w, x, y, z) of "degrees about x, then y, then z" (fixed axes): q = qz qy qx. */
static void euler_quat(const double deg[3], double q[4])
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

static void quat_mat(const double q[4], double R[9])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

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
static void key_pose(const pfsph_body_def *d, double t, double x[3], double q[4])
{
    if (d->nkeys == 0) {
        memcpy(x, d->position, sizeof(double) * 3);
        euler_quat(d->rotation, q);
        return;
    }
    int k = 0;
    while (k + 1 < d->nkeys && d->keys[k + 1].t <= t) k++;
    const pfsph_keyframe *a = &d->keys[k];
    if (k + 1 >= d->nkeys || t <= a->t) {
        memcpy(x, a->position, sizeof(double) * 3);
        euler_quat(a->rotation, q);
        return;
    }
    const pfsph_keyframe *b = &d->keys[k + 1];
    double s = (t - a->t) / (b->t - a->t), qa[4], qb[4];
    for (int i = 0; i < 3; i++) x[i] = (1 - s) * a->position[i] + s * b->position[i];
    euler_quat(a->rotation, qa);
    euler_quat(b->rotation, qb);
    slerp(qa, qb, s, q);
}

/* ------------------------------------------------------------------------------------------ */
/* Geometry of one body in its own frame. */

static int body_mesh(const pfsph_scene *s, body *bd, pfsph_error *err)
{
    const pfsph_body_def *d = &bd->def;
    int rc = PFSPH_OK;
    switch (d->shape) {
    case PFSPH_BODY_BOX: rc = pfsph_mesh_box(&bd->mesh, d->half); break;
    case PFSPH_BODY_SPHERE:
        rc = s->dim == 2 ? pfsph_mesh_cylinder(&bd->mesh, d->radius, 1.0, 2, 48)
                         : pfsph_mesh_sphere(&bd->mesh, d->radius, 32);
        break;
    case PFSPH_BODY_CYLINDER:
        rc = s->dim == 2 ? pfsph_mesh_cylinder(&bd->mesh, d->radius, 1.0, 2, 48)
                         : pfsph_mesh_cylinder(&bd->mesh, d->radius, d->height, d->axis, 48);
        break;
    case PFSPH_BODY_MESH: {
        if ((rc = pfsph_mesh_load_obj(&bd->mesh, d->mesh, err)) ||
            (rc = pfsph_mesh_validate_closed(&bd->mesh, d->mesh, err))) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            int bi = 0; /* the body's index, for its JSON path */
            while (bi < s->nbodies - 1 && strcmp(s->bodies[bi].name, d->name) != 0) bi++;
            return pfsph_fail(err, PFSPH_EINPUT, "%s: $.bodies[%d].file (body \"%s\"): %s", s->source, bi, d->name,
                              msg);
        }
        double vol, com[3], I[9];
        pfsph_mesh_transform(&bd->mesh, d->scale, NULL, NULL);
        pfsph_mesh_mass_properties(&bd->mesh, &vol, com, I);
        double t[3] = {-com[0], -com[1], -com[2]};
        pfsph_mesh_transform(&bd->mesh, 1.0, NULL, t);
        break;
    }
    }
    if (rc) return pfsph_fail(err, rc, "out of memory building body \"%s\"", d->name);
    return PFSPH_OK;
}

/* Surface particles of a body in its own frame, d/2 inside the surface as for static solids
 * (their layer then continues the fluid's lattice, and the fluid's particle centres stop d/2
 * outside the surface: displaced volumes come out right). */
static int body_particles(const pfsph_scene *s, const body *bd, double d, pfsph_particles *ps, pfsph_error *err)
{
    const pfsph_body_def *bdef = &bd->def;
    if (bdef->shape != PFSPH_BODY_MESH) {
        pfsph_solid so;
        memset(&so, 0, sizeof so);
        so.layers = bdef->layers;
        so.phase = bdef->phase;
        so.axis = s->dim == 2 ? 2 : bdef->axis;
        so.radius = bdef->radius;
        so.height = bdef->height;
        so.shape = bdef->shape == PFSPH_BODY_BOX ? PFSPH_SHAPE_BOX
            : bdef->shape == PFSPH_BODY_SPHERE   ? PFSPH_SHAPE_SPHERE
                                                 : PFSPH_SHAPE_CYLINDER;
        for (int a = 0; a < 3; a++) {
            so.min[a] = -bdef->half[a];
            so.max[a] = bdef->half[a];
        }
        if (pfsph__sample_solid(s, &so, d, ps) < 0) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
        return PFSPH_OK;
    }
    double *pts = NULL;
    size_t n = 0;
    int rc = pfsph_mesh_sample_surface(&bd->mesh, d, &pts, &n, err);
    if (rc) return rc;
    /* move each sample d/2 inwards along the normal of its nearest triangle */
    const pfsph_mesh *m = &bd->mesh;
    for (size_t i = 0; i < n; i++) {
        double *p = pts + 3 * i, best = INFINITY, nb[3] = {0, 0, 0};
        for (size_t t = 0; t < m->ntris; t++) {
            const double *A = m->v + 3 * m->tri[3 * t], *B = m->v + 3 * m->tri[3 * t + 1],
                         *C = m->v + 3 * m->tri[3 * t + 2];
            double e1[3], e2[3], nn[3];
            for (int a = 0; a < 3; a++) e1[a] = B[a] - A[a], e2[a] = C[a] - A[a];
            nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
            nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
            nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
            double ln = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            if (!(ln > 0)) continue;
            for (int a = 0; a < 3; a++) nn[a] /= ln;
            /* distance to the plane, counted only if the projection falls in the triangle
             * (barycentric test); else the distance to the centroid stands in */
            double ap[3];
            for (int a = 0; a < 3; a++) ap[a] = p[a] - A[a];
            double dist = ap[0] * nn[0] + ap[1] * nn[1] + ap[2] * nn[2];
            double q[3] = {p[0] - dist * nn[0], p[1] - dist * nn[1], p[2] - dist * nn[2]};
            double d00 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
            double d01 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
            double d11 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
            double aq[3] = {q[0] - A[0], q[1] - A[1], q[2] - A[2]};
            double d20 = aq[0] * e1[0] + aq[1] * e1[1] + aq[2] * e1[2];
            double d21 = aq[0] * e2[0] + aq[1] * e2[1] + aq[2] * e2[2];
            double den = d00 * d11 - d01 * d01;
            double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
            double tol = 1e-6;
            double dd;
            if (v >= -tol && w >= -tol && v + w <= 1 + tol) dd = fabs(dist);
            else {
                double c[3] = {(A[0] + B[0] + C[0]) / 3 - p[0], (A[1] + B[1] + C[1]) / 3 - p[1],
                               (A[2] + B[2] + C[2]) / 3 - p[2]};
                dd = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            }
            if (dd < best) {
                best = dd;
                memcpy(nb, nn, sizeof nb);
            }
        }
        for (int l = 0; l < bdef->layers; l++) {
            const double o = (l + 0.5) * d;
            pfsph_real xr[3] = {(pfsph_real)(p[0] - o * nb[0]), (pfsph_real)(p[1] - o * nb[1]),
                                (pfsph_real)(p[2] - o * nb[2])};
            if (pfsph_particles_push(ps, xr, NULL, (uint8_t)bdef->phase) < 0) {
                free(pts);
                return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            }
        }
    }
    free(pts);
    return PFSPH_OK;
}

/* Akinci volumes over the body's own particles, so that a body's volumes do not depend on
 * what it touches at the start. */
static int body_volumes(const pfsph_particles *src, int dim, double h, pfsph_real *vol)
{
    pfsph_particles ps;
    pfsph_grid g;
    int rc = pfsph_particles_init(&ps, src->n ? src->n : 1);
    if (rc) return rc;
    pfsph_real lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < src->n; i++) {
        for (int k = 0; k < PFSPH_NFIELDS; k++) ps.f[k][i] = src->f[k][i];
        ps.aux[i] = -1;
        ps.id[i] = (uint32_t)i;
        const pfsph_real p[3] = {src->x[i], src->y[i], src->z[i]};
        for (int a = 0; a < dim; a++) {
            if (i == 0 || p[a] < lo[a]) lo[a] = p[a];
            if (i == 0 || p[a] > hi[a]) hi[a] = p[a];
        }
    }
    ps.n = src->n;
    for (int a = 0; a < dim; a++) {
        lo[a] -= (pfsph_real)(2 * h);
        hi[a] += (pfsph_real)(2 * h);
    }
    if ((rc = pfsph_grid_init(&g, dim, lo, hi, (pfsph_real)h))) {
        pfsph_particles_free(&ps);
        return rc;
    }
    pfsph_kernel k;
    pfsph_kernel_init(&k, dim, (pfsph_real)h);
    if (!(rc = pfsph_grid_sort(&g, &ps, NULL))) {
        pfsph__boundary_volumes(&ps, &g, &k);
        for (size_t i = 0; i < ps.n; i++) vol[ps.id[i]] = ps.aux[i];
    }
    pfsph_grid_free(&g);
    pfsph_particles_free(&ps);
    return rc;
}

/* ------------------------------------------------------------------------------------------ */
/* ODE setup. */

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

static void set_mass(body *bd, int dim)
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
    dBodySetMass(bd->id, &m);
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

/* ------------------------------------------------------------------------------------------ */

int pfsph_bodies_create(pfsph_bodies **out, const pfsph_scene *s, double spacing, pfsph_particles *boundary,
                        pfsph_error *err)
{
    *out = NULL;
    pfsph_bodies *B = calloc(1, sizeof *B);
    if (!B) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    B->dim = s->dim;
    B->spacing = spacing;
    B->nb = s->nbodies;
    B->first_id = boundary->next_id;
    int rc = PFSPH_OK;
    B->b = calloc((size_t)(B->nb ? B->nb : 1), sizeof(body));
    if (!B->b) {
        free(B);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    }
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
    if ((rc = add_statics(B, s))) {
        pfsph_bodies_destroy(B);
        return pfsph_fail(err, rc, "out of memory");
    }

    const double h = s->support_factor * spacing;
    pfsph_particles tmp;
    if ((rc = pfsph_particles_init(&tmp, 1024))) {
        pfsph_bodies_destroy(B);
        return pfsph_fail(err, rc, "out of memory");
    }
    for (int i = 0; i < B->nb; i++) {
        body *bd = &B->b[i];
        bd->def = s->bodies[i];
        if ((rc = body_mesh(s, bd, err))) goto fail;
        pfsph_mesh_bounds(&bd->mesh, bd->lo, bd->hi); /* body_mesh validated it */
        tmp.n = 0;
        if ((rc = body_particles(s, bd, spacing, &tmp, err))) goto fail;
        if (tmp.n == 0) {
            rc = pfsph_fail(err, PFSPH_EINPUT, "%s: body \"%s\" is too small for the particle spacing %g m", s->source,
                            bd->def.name, spacing);
            goto fail;
        }
        pfsph_real *vol = malloc(tmp.n * sizeof *vol);
        double *loc = realloc(B->local, 3 * (B->np + tmp.n) * sizeof(double));
        uint16_t *own = realloc(B->owner, (B->np + tmp.n) * sizeof(uint16_t));
        if (loc) B->local = loc;
        if (own) B->owner = own;
        /* Volumes as for static walls (docs/solids): two or more layers continue the fluid's
         * lattice (V0); one layer stands for a half-space (Akinci), over the body alone. With
         * one layer a floating box rode 0.22 d too high (submerged fraction 0.454 for 0.5). */
        if (vol && bd->def.layers > 1)
            for (size_t j = 0; j < tmp.n; j++)
                vol[j] = (pfsph_real)(s->dim == 2 ? spacing * spacing : spacing * spacing * spacing);
        if (!vol || !loc || !own || (bd->def.layers == 1 && (rc = body_volumes(&tmp, s->dim, h, vol)))) {
            free(vol);
            rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            goto fail;
        }
        bd->first = B->np;
        bd->n = (uint32_t)tmp.n;
        for (size_t j = 0; j < tmp.n; j++) {
            B->local[3 * (B->np + j)] = tmp.x[j];
            B->local[3 * (B->np + j) + 1] = tmp.y[j];
            B->local[3 * (B->np + j) + 2] = tmp.z[j];
            B->owner[B->np + j] = (uint16_t)i;
            pfsph_real z[3] = {0, 0, 0};
            long k = pfsph_particles_push(boundary, z, NULL, (uint8_t)bd->def.phase);
            if (k < 0) {
                free(vol);
                rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
                goto fail;
            }
            boundary->aux[k] = vol[j];
            boundary->rho[k] = (pfsph_real)s->phases[bd->def.phase].rest_density;
        }
        free(vol);
        B->np += (uint32_t)tmp.n;

        bd->id = dBodyCreate(B->world);
        set_mass(bd, s->dim);
        make_geom(B, bd, s->dim);
        double q[4];
        euler_quat(bd->def.rotation, q);
        dBodySetPosition(bd->id, bd->def.position[0], bd->def.position[1], bd->def.position[2]);
        dBodySetQuaternion(bd->id, q);
        dBodySetLinearVel(bd->id, bd->def.velocity[0], bd->def.velocity[1], bd->def.velocity[2]);
        dBodySetAngularVel(bd->id, bd->def.angular_velocity[0], bd->def.angular_velocity[1],
                           bd->def.angular_velocity[2]);
        if (bd->def.kinematic) {
            double x[3];
            dBodySetKinematic(bd->id);
            key_pose(&bd->def, 0.0, x, q);
            dBodySetPosition(bd->id, x[0], x[1], x[2]);
            dBodySetQuaternion(bd->id, q);
            dBodySetLinearVel(bd->id, 0, 0, 0);
            dBodySetAngularVel(bd->id, 0, 0, 0);
        } else if (s->dim == 2) {
            dJointID j = dJointCreatePlane2D(B->world, 0);
            dJointAttach(j, bd->id, 0);
        }
        dBodySetGyroscopicMode(bd->id, s->dim == 3);
    }
    pfsph_particles_free(&tmp);
    B->fp = calloc(3 * (size_t)(B->np ? B->np : 1), sizeof(double));
    if (!B->fp) {
        pfsph_bodies_destroy(B);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    }
    for (int i = 0; i < B->nb; i++) canonical_quat(B->b[i].id);
    place_all(B, boundary);
    /* Bodies that overlap at the start were pushed apart by their contacts at 0.5 m/s each:
     * refuse them, naming both (issue 15 item 15). Body particles sit d/2 inside their own
     * surface, so bodies that only touch are not caught. */
    for (size_t j = 0; j < boundary->n; j++) {
        if (boundary->id[j] < B->first_id) continue;
        const int i = B->owner[boundary->id[j] - B->first_id];
        const double p[3] = {boundary->x[j], boundary->y[j], boundary->z[j]};
        for (int k = 0; k < B->nb; k++) {
            /* keyframed bodies are not moved by contacts: two of them may overlap (the egg's
             * halves of scenes/bodies_cracked_egg.json meet along the crack) */
            bool skip = k == i || (B->b[i].def.kinematic && B->b[k].def.kinematic);
            double dist = skip ? 1 : pfsph_bodies_distance(B, k, p);
            if (dist < 0) {
                int lo = i < k ? i : k, hi = i < k ? k : i;
                rc = pfsph_fail(err, PFSPH_EINPUT,
                                "%s: $.bodies[%d] (\"%s\") and $.bodies[%d] (\"%s\") overlap at the start (a "
                                "surface particle of \"%s\" at %.4g %.4g %.4g lies inside \"%s\"); move them "
                                "apart: overlapping bodies are pushed apart by their contacts",
                                s->source, lo, B->b[lo].def.name, hi, B->b[hi].def.name, B->b[i].def.name, p[0], p[1],
                                p[2], B->b[k].def.name);
                pfsph_bodies_destroy(B);
                return rc;
            }
        }
    }
    *out = B;
    return PFSPH_OK;
fail:
    pfsph_particles_free(&tmp);
    pfsph_bodies_destroy(B);
    return rc;
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
    if (d->kinematic) key_pose(d, 0.0, x, q);
    else euler_quat(d->rotation, q);
    quat_mat(q, R);
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

/* ------------------------------------------------------------------------------------------ */
/* Coupling. */

void pfsph_bodies_fluid_forces(pfsph_bodies *B, const pfsph_ctx *ctx, const pfsph_real *p)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h, eps = (pfsph_real)0.01 * h2;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const pfsph_real visc_c = (pfsph_real)(2 * (ctx->dim + 2));
    const uint32_t first = B->first_id;
    const size_t nb = b->n;
    const pfsph_pairwise_params *pp = ctx->pairwise;
    const bool pw_on = pp->enabled;
    const double Rk = pw_on ? pp->k * (double)ctx->h : 0, U_R = pw_on ? 1.5 * PI / Rk : 0;
    const pfsph_real R2 = (pfsph_real)(Rk * Rk);
    double cm[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES]; /* c m_a m_b, once per call */
    for (int a = 0; pw_on && a < ctx->nphases; a++)
        for (int q = 0; q < ctx->nphases; q++) cm[a][q] = pp->c[a][q] * (double)ctx->mass[a] * (double)ctx->mass[q];
    /* particles dropped from the boundary set (a body that left the grid) must not keep their
     * last force: only the present ones are written below */
    memset(B->fp, 0, 3 * (size_t)B->np * sizeof(double));
    const double amp = pfsph__thermo_amp(ctx);
    const uint64_t wkey = pfsph_thermo_step_key(ctx->seed, ctx->step, PFSPH_THERMO_SALT_WALL);
#pragma omp parallel for schedule(static)
    for (size_t j = 0; j < nb; j++) {
        if (b->id[j] < first) continue;
        const uint32_t l = b->id[j] - first;
        const pfsph_real xj = b->x[j], yj = b->y[j], zj = b->z[j], vol = b->aux[j];
        double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
        pfsph_ranges r;
        pfsph_grid_ranges(ctx->grid, xj, yj, zj, &r);
        for (int q = 0; q < r.n; q++)
            for (uint32_t i = r.b[q]; i < r.e[q]; i++) {
                /* the same expressions, in the same order, as the fluid side, with x_ib */
                pfsph_real dx = f->x[i] - xj, dy = f->y[i] - yj, dz = f->z[i] - zj;
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2) continue;
                pfsph_real dw = pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                pfsph_real s = 0;
                const pfsph_real pi = p[i] / (ctx->nd[i] * ctx->nd[i]);
                if (pi > 0) s += pi * inv_v0 * vol * dw; /* pressure: -F_i of Akinci Eq. 10 */
                const pfsph_real nui = ctx->nu[f->phase[i]];
                if (nui > 0) {
                    pfsph_real vdx =
                        (f->vx[i] - b->vx[j]) * dx + (f->vy[i] - b->vy[j]) * dy + (f->vz[i] - b->vz[j]) * dz;
                    /* friction: the fluid gains m_i nu visc_c V_b (v_ib . x_ib)/(r^2+eps) grad W */
                    s -= ctx->mass[f->phase[i]] * visc_c * nui * vol * vdx / (r2 + eps) * dw;
                    if (amp > 0 && r2 > 0) {
                        /* the thermostat's random force on the fluid, reversed (thermostat.c:
                         * the same expression, same draw) */
                        double rr = sqrt((double)r2);
                        /* x_ib points from the body particle to the fluid: -e_ib on the body */
                        double sr = -pfsph__thermo_wall(amp * pfsph_thermostat_scale(ctx, f->phase[i]), (double)nui,
                                                        (double)ctx->mass[f->phase[i]], (double)vol, (double)r2,
                                                        (double)pfsph_kernel_dw_r(k, (pfsph_real)rr), (double)eps, rr,
                                                        pfsph_thermo_theta(wkey, f->id[i], b->id[j]));
                        tx += sr * (double)dx;
                        ty += sr * (double)dy;
                        tz += sr * (double)dz;
                    }
                }
                fx += (double)(s * dx);
                fy += (double)(s * dy);
                fz += (double)(s * dz);
            }
        fx += tx;
        fy += ty;
        fz += tz;
        if (pw_on) {
            /* the pair forces' reaction (PF Eq. 3): -c m_i m_b f(r) x_ib / r, over k h. The
             * fluid applies its filter T_i (Eq. 12) to its own sum, so with eta > 0 action and
             * reaction differ by that filter; with eta = 0 they cancel exactly. */
            const int pb = b->phase[j];
            pfsph_grid_ranges_far(ctx->grid, xj, yj, zj, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t i = r.b[q]; i < r.e[q]; i++) {
                    const double cf = cm[f->phase[i]][pb];
                    if (cf == 0.0) continue;
                    pfsph_real dx = f->x[i] - xj, dy = f->y[i] - yj, dz = f->z[i] - zj;
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= R2 || r2 <= 0) continue;
                    double rr = sqrt((double)r2);
                    double sp = -cf * (double)cosf((float)(U_R * rr)) / rr;
                    fx += sp * dx;
                    fy += sp * dy;
                    fz += sp * dz;
                }
        }
        B->fp[3 * l] = fx;
        B->fp[3 * l + 1] = fy;
        B->fp[3 * l + 2] = fz;
    }
    /* sums in id order: the same bits for any thread count and particle order */
    for (int i = 0; i < B->nb; i++) {
        body *bd = &B->b[i];
        const dReal *Rm = dBodyGetRotation(bd->id);
        double F[3] = {0, 0, 0}, T[3] = {0, 0, 0};
        for (uint32_t l = bd->first; l < bd->first + bd->n; l++) {
            const double *fl = B->fp + 3 * l, *lc = B->local + 3 * l;
            double rr[3];
            for (int a = 0; a < 3; a++) rr[a] = Rm[4 * a] * lc[0] + Rm[4 * a + 1] * lc[1] + Rm[4 * a + 2] * lc[2];
            for (int a = 0; a < 3; a++) F[a] += fl[a];
            T[0] += rr[1] * fl[2] - rr[2] * fl[1];
            T[1] += rr[2] * fl[0] - rr[0] * fl[2];
            T[2] += rr[0] * fl[1] - rr[1] * fl[0];
        }
        if (B->dim == 2) F[2] = T[0] = T[1] = 0;
        memcpy(bd->f, F, sizeof F);
        memcpy(bd->tq, T, sizeof T);
    }
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
static void place_all(pfsph_bodies *B, pfsph_particles *bs)
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
static void canonical_quat(dBodyID id)
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
            key_pose(&bd->def, t, x0, q0);
            key_pose(&bd->def, t + dt, x1, q1);
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
            key_pose(&bd->def, t + dt, x1, q1);
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
        canonical_quat(bd->id);
    }
    place_all(B, bs);
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
    canonical_quat(bd->id);
    dBodySetLinearVel(bd->id, st->v[0], st->v[1], st->v[2]);
    dBodySetAngularVel(bd->id, st->w[0], st->w[1], st->w[2]);
    place_all(B, boundary);
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
