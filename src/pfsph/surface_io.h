/* Writers of body surfaces (triangle meshes in world coordinates) per frame. */
#ifndef PFSPH_SURFACE_IO_H
#define PFSPH_SURFACE_IO_H

#include "pfsph/mesh.h"

typedef struct pfsph_body_pose {
    const char *name;
    double x[3], q[4]; /* centre of mass, unit quaternion (w, x, y, z) */
} pfsph_body_pose;

/* n meshes (one per body) into one file, atomically; faces carry their body's index. */
int pfsph_write_surfaces_ply(const char *path, const pfsph_mesh *meshes, int n, const pfsph_body_pose *poses,
                             double time, pfsph_error *err);
int pfsph_write_surfaces_vtp(const char *path, const pfsph_mesh *meshes, int n, const pfsph_body_pose *poses,
                             double time, pfsph_error *err);

#endif
