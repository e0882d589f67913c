/* Closed triangle meshes: the OBJ reader, mass properties and surface sampling that rigid
 * bodies are built from, and the primitive shapes (box, sphere, cylinder) as meshes so that
 * every body can be written out as a surface. */
#ifndef PFSPH_MESH_H
#define PFSPH_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "pfsph/types.h"

typedef struct pfsph_mesh {
    size_t nverts, ntris;
    double *v;     /* 3 * nverts coordinates */
    uint32_t *tri; /* 3 * ntris vertex indices, counter-clockwise seen from outside */
} pfsph_mesh;

/* Parse OBJ text: `v` and `f` statements (polygons fan-triangulated; v, v/vt, v//vn, v/vt/vn
 * and negative indices accepted); other statements ignored. `source` names the file in
 * messages, which read "<source>:<line>: <reason>". Returns PFSPH_EINPUT on bad input,
 * PFSPH_ENOMEM. On error *m is left empty. `text` need not be NUL-terminated (len bytes are
 * read). *m is overwritten, not freed first. Subset and limits: docs/meshes.md. */
int pfsph_mesh_parse_obj(pfsph_mesh *m, const char *text, size_t len, const char *source, pfsph_error *err);
/* Read a file and parse it (a missing or unreadable file is PFSPH_EINPUT naming the path). */
int pfsph_mesh_load_obj(pfsph_mesh *m, const char *path, pfsph_error *err);

/* Check that the mesh bounds a solid: no degenerate triangle (area below 1e-12 of the
 * bounding box diagonal squared), every edge shared by exactly two triangles with opposite
 * orientation, positive enclosed volume (a mesh whose volume comes out negative is flipped
 * in place, so inside-out files are accepted). PFSPH_EINPUT with the triangle or edge named
 * (numbered from 1, vertices as in the OBJ file). Sorts the edges: O(n log n). */
int pfsph_mesh_validate_closed(pfsph_mesh *m, const char *source, pfsph_error *err);

/* Volume, centre of mass and inertia tensor (row-major 3x3, about the centre of mass) of the
 * solid a closed mesh bounds, for unit density (multiply volume and tensor by the density).
 * Off-diagonal entries are minus the products of inertia. Exact for the polyhedron (Eberly /
 * Mirtich); any output pointer may be NULL. */
void pfsph_mesh_mass_properties(const pfsph_mesh *m, double *volume, double com[3], double inertia[9]);

/* Bounding box of the vertices used by triangles (unused vertices do not count). Returns 0, or
 * -1 when a coordinate is not finite or an index is out of range. */
int pfsph_mesh_bounds(const pfsph_mesh *m, double lo[3], double hi[3]);

/* Points on the surface at about `spacing` apart, with no hole wider than 1.5 spacings:
 * *pts gets 3 * *n coordinates (caller frees). Deterministic; no two points closer than 0.68
 * spacing; about area / (spacing^2 sqrt(3)/2) points; corners and sharp edges (dihedral
 * above 30 degrees) always get points. PFSPH_EINPUT for a spacing that is not positive and
 * finite or that would need more than about 2e7 points; on error *pts is NULL and *n 0. */
int pfsph_mesh_sample_surface(const pfsph_mesh *m, double spacing, double **pts, size_t *n, pfsph_error *err);

/* Primitive shapes as closed meshes centred at the origin (cylinder along axis 0/1/2;
 * `segments` around curved surfaces; the sphere is an icosphere with about `segments` edges
 * around a great circle). PFSPH_EINPUT for sizes that are not positive and finite, an axis
 * outside 0..2 or fewer than 3 segments (m left empty), PFSPH_ENOMEM. */
int pfsph_mesh_box(pfsph_mesh *m, const double half[3]);
int pfsph_mesh_sphere(pfsph_mesh *m, double radius, int segments);
int pfsph_mesh_cylinder(pfsph_mesh *m, double radius, double height, int axis, int segments);

/* Apply x' = s * R x + t to every vertex (R row-major 3x3; NULL for the identity; t may be
 * NULL). A mirroring map (s^3 det R < 0) also reverses every triangle so they still face out. */
void pfsph_mesh_transform(pfsph_mesh *m, double s, const double R[9], const double t[3]);
/* Deep copy; dst is overwritten (its old arrays are not freed). */
int pfsph_mesh_copy(pfsph_mesh *dst, const pfsph_mesh *src);
/* Frees the arrays and zeroes the mesh: safe on a zeroed mesh, twice, and on NULL. */
void pfsph_mesh_free(pfsph_mesh *m);

#endif
