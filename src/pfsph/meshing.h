/* Liquid surface files and run-directory collections: the fluid's surface mesh per frame as
 * binary PLY, OBJ and VTK PolyData (phase per face), `pfsph mesh RUN_DIR`, and the ParaView .pvd
 * collections that make a run one time series. docs/surfaces.md. */
#ifndef PFSPH_MESHING_H
#define PFSPH_MESHING_H

#include "pfsph/particles.h"
#include "pfsph/scene.h"
#include "pfsph/surface_mesh.h"

/* Atomic writers. PLY: binary little-endian, vertex x y z nx ny nz (float), face
 * vertex_indices (uchar count, uint indices) and uchar phase. OBJ: v, vn and f v//vn lines, one
 * group "phase_<k>" per phase. VTP: points, Normals (point data), phase (cell data), TimeValue. */
int pfsph_write_surface_ply(const char *path, const pfsph_surface_mesh *m, double time, pfsph_error *err);
int pfsph_write_surface_obj(const char *path, const pfsph_surface_mesh *m, double time, pfsph_error *err);
int pfsph_write_surface_vtp(const char *path, const pfsph_surface_mesh *m, double time, pfsph_error *err);

/* Read a triangle mesh PLY as pfsph writes them (binary little-endian, vertices then faces):
 * the liquid's frames/liquid_NNNNN.ply (x y z nx ny nz, faces tagged `phase`) and the bodies'
 * frames/surfaces_NNNNN.ply (x y z, faces tagged `body`). *m is overwritten (free with
 * pfsph_surface_mesh_free): v, tri, phase (the face's uchar `phase` or `body`, else 0), n NULL
 * when the file has no nx ny nz; the statistics are 0. *time (may be NULL) from "comment time".
 * PFSPH_EINPUT naming the path for a malformed file or a face that is not a triangle. */
int pfsph_read_surface_ply(const char *path, pfsph_surface_mesh *m, double *time, pfsph_error *err);

/* VTP PolyData of a 2D outline: points (z = 0), Normals (point data), Lines (one per segment),
 * phase (cell data), TimeValue. Atomic. */
int pfsph_write_contour_vtp(const char *path, const pfsph_surface_contour *c, double time, pfsph_error *err);

/* Reconstruct the surface of a frame's fluid particles with the scene's output.surface settings
 * and write RUN/frames/liquid_NNNNN.{ply,obj,vtp} (the formats it names); in 2D the outline as
 * liquid_NNNNN.vtp polylines (VTP only). st (may be NULL) receives the statistics (arrays freed;
 * zero in 2D). */
int pfsph_mesh_frame(const pfsph_scene *s, const char *dir, int frame, const pfsph_particles *fluid, double time,
                     pfsph_surface_mesh *st, pfsph_error *err);

/* Mesh every fluid frame of a finished run (RUN/scene.json, RUN/frames/fluid_NNNNN.vtp or .ply),
 * then rewrite the .pvd collections. `over` (may be NULL) replaces the scene's output.surface.
 * A 2D run gets VTP outlines; asking it for PLY or OBJ is PFSPH_EINPUT. *frames gets the number
 * meshed. */
int pfsph_mesh_run(const char *dir, const pfsph_surface_output *over, int *frames, pfsph_error *err);

/* Rewrite RUN/<set>.pvd for every frame set with .vtp files in RUN/frames (fluid, boundary,
 * diffuse, bodies, surfaces, liquid), frame k at time k * frame_dt; atomic, so a collection is
 * valid whenever a run stops. */
int pfsph_write_pvd_collections(const char *dir, double frame_dt, pfsph_error *err);

#endif
