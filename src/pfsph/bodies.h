/* Rigid bodies two-way coupled with the fluid (Akinci et al. 2012, "Versatile rigid-fluid
 * coupling for incompressible SPH"). A body's surface is sampled with boundary particles that
 * live in the simulation's boundary set, so the fluid sees them like any wall; the forces the
 * fluid exerts on them are summed into a force and torque. Body dynamics and contacts (body to
 * body, body to static solid) are the Open Dynamics Engine's. docs/bodies.md. */
#ifndef PFSPH_BODIES_H
#define PFSPH_BODIES_H

#include "pfsph/mesh.h"
#include "pfsph/ctx.h"
#include "pfsph/scene.h"

typedef struct pfsph_bodies pfsph_bodies;

/* Pose and velocity of one body: centre of mass, unit quaternion (w, x, y, z), linear and
 * angular velocity (world frame). */
typedef struct pfsph_body_state {
    double x[3], q[4], v[3], w[3];
} pfsph_body_state;

/* Build the scene's bodies: read and check mesh files (PFSPH_EINPUT naming the body and the
 * file), sample each surface with particles appended to `boundary` (ids after those already
 * there; aux = Akinci volume over the body's own particles), and set up the dynamics with
 * the scene's static solids as fixed colliders. */
int pfsph_bodies_create(pfsph_bodies **out, const pfsph_scene *s, double spacing, pfsph_particles *boundary,
                        pfsph_error *err);
void pfsph_bodies_destroy(pfsph_bodies *b); /* NULL is a no-op */
int pfsph_bodies_count(const pfsph_bodies *b);

/* Signed distance from p to the surface of body i at its initial pose (< 0 inside): fluid
 * particles are not created inside bodies. */
double pfsph_bodies_distance(const pfsph_bodies *b, int i, const double p[3]);

/* The forces the fluid exerts on every body particle this step (pressure p of the fluid,
 * whose wall term it felt this step (the solver's wall pressure), and number density nd at the current positions, viscous friction with ctx->nu), summed into
 * each body's force and torque: exactly the opposite of what the fluid receives from the body
 * particles in pfsph__pressure_accel and pfsph__nonpressure. */
void pfsph_bodies_fluid_forces(pfsph_bodies *b, const pfsph_ctx *ctx, const pfsph_real *p);

/* Advance the bodies from t to t + dt with the fluid forces, gravity and contacts; move their
 * particles (positions and velocities) in `boundary`. */
void pfsph_bodies_step(pfsph_bodies *b, pfsph_particles *boundary, double t, double dt);

/* Largest speed of any body particle [m/s] (for the CFL condition). */
double pfsph_bodies_vmax(const pfsph_bodies *b);

const char *pfsph_bodies_name(const pfsph_bodies *b, int i);
void pfsph_bodies_get_state(const pfsph_bodies *b, int i, pfsph_body_state *st);
/* Put a saved state back (checkpoints); particles in `boundary` follow. */
void pfsph_bodies_set_state(pfsph_bodies *b, int i, const pfsph_body_state *st, pfsph_particles *boundary);
/* Fluid force and torque on body i in the last step (about its centre of mass). */
void pfsph_bodies_last_force(const pfsph_bodies *b, int i, double f[3], double tq[3]);
double pfsph_bodies_mass(const pfsph_bodies *b, int i);
/* Body i's surface in world coordinates at its current pose (caller frees m). */
int pfsph_bodies_world_mesh(const pfsph_bodies *b, int i, pfsph_mesh *m);
/* Particles sampled on all bodies (ids first_id .. first_id + count - 1). */
uint32_t pfsph_bodies_particle_count(const pfsph_bodies *b);
/* First boundary-particle id that belongs to a body (ids below are static solids). */
uint32_t pfsph_bodies_first_id(const pfsph_bodies *b);

/* Drag body i towards target [m] from the next step on (pfsph_bodies_draggable: any body but a
 * keyframed one). Kinematic: in a straight line at most vmax [m/s], without turning; it stays
 * where the drag leaves it. Dynamic: a critically damped spring (5 Hz) on its centre of mass
 * pulls it, its pull capped so that it drives towards at most vmax; the fluid, gravity and
 * contacts act as before; let go, it moves on freely. target NULL lets go. PFSPH_EINPUT for a
 * keyframed body or a non-finite target. */
int pfsph_bodies_drag(pfsph_bodies *b, int i, const double target[3], double vmax);
bool pfsph_bodies_draggable(const pfsph_bodies *b, int i);
/* Gravity of the body dynamics [m/s^2] (the live viewer changes it; 2D ignores g[2]). */
void pfsph_bodies_set_gravity(pfsph_bodies *b, int dim, const double g[3]);

#endif
