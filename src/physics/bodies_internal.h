/* Shared by the rigid-body files (bodies.h): the bodies' state (bodies.c: poses, queries, state),
 * the builder (bodies_build.c: meshes, particles, volumes), the ODE world and its step
 * (bodies_world.c) and the fluid's forces on the bodies (bodies_coupling.c). */
#ifndef PFSPH_BODIES_INTERNAL_H
#define PFSPH_BODIES_INTERNAL_H

#include <ode/ode.h>

#include "pfsph/bodies.h"

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

/* Quaternion (w, x, y, z) of "degrees about x, then y, then z" (fixed axes): q = qz qy qx. */
void pfsph__bodies_euler_quat(const double deg[3], double q[4]);
/* the rotation matrix (row-major) of a unit quaternion */
void pfsph__bodies_quat_mat(const double q[4], double R[9]);
/* Pose of a keyframed body at time t. */
void pfsph__bodies_key_pose(const pfsph_body_def *d, double t, double x[3], double q[4]);

/* The ODE world of the scene (gravity, contact tuning) with its static solids as fixed
 * colliders; PFSPH_ENOMEM. */
int pfsph__bodies_world_create(pfsph_bodies *B, const pfsph_scene *s, double spacing);
/* bd's ODE body: mass, collision geometry, initial pose and velocities (keyframed: kinematic);
 * -1 (nothing given to ODE) for a mass or inertia ODE would abort on. */
int pfsph__bodies_world_add(pfsph_bodies *B, body *bd, int dim);
/* Move every body particle to its body's pose (one pass over the boundary set). */
void pfsph__bodies_place_all(pfsph_bodies *B, pfsph_particles *bs);
/* A body's quaternion as ODE stores it once renormalised (bit-exact resume). */
void pfsph__bodies_canonical_quat(dBodyID id);

#endif
