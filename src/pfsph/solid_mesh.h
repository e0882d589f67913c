/* The static solids of a scene as closed triangle meshes (their geometry, not their particles),
 * written once per run as RUN/solids.ply and RUN/solids.obj for Blender, Houdini and ParaView
 * (docs/artists.md#static-solids). */
#ifndef PFSPH_SOLID_MESH_H
#define PFSPH_SOLID_MESH_H

#include "pfsph/mesh.h"
#include "pfsph/scene.h"

/* The surface of solid o of a 3D scene in world coordinates: a box or a sphere or a cylinder as
 * itself; a container as its walls (layers x spacing thick outside min..max, the top left open
 * when open_top); a plane as the slab layers x spacing thick behind it, clipped to the domain
 * (grown by that thickness, as the particles are). Closed, counter-clockwise from outside (a
 * container's wall slabs are closed boxes that touch). *m is overwritten. PFSPH_EINPUT for a 2D
 * scene or a degenerate solid, PFSPH_ENOMEM. */
int pfsph_solid_mesh(const pfsph_scene *s, const pfsph_solid *o, pfsph_mesh *m);

/* RUN/solids.ply (binary: vertex x y z float; face vertex_indices, uchar solid, uchar phase; a
 * comment per solid: "solid K SHAPE PHASE") and RUN/solids.obj (an object "solid_K_PHASE" per
 * solid), atomically, for a 3D scene with solids; nothing otherwise. *count gets the solids
 * written (0 when none). */
int pfsph_write_solids(const pfsph_scene *s, const char *dir, int *count, pfsph_error *err);

#endif
