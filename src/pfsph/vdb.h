/* The liquid as an OpenVDB level set for volume tools (Houdini, Blender): a C interface to the
 * optional C++ exporter (src/vdb/vdb.cpp, built when OpenVDB is found: PFSPH_OPENVDB). Without
 * it every function here fails with PFSPH_EINPUT saying so. docs/artists.md#openvdb-level-sets-houdini-blender. */
#ifndef PFSPH_VDB_H
#define PFSPH_VDB_H

#include <stdbool.h>
#include <stddef.h>

#include "pfsph/surface_mesh.h"
#include "pfsph/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* the grids of a frame's .vdb (output.surface.vdb_grids) */
enum { PFSPH_VDB_SURFACE = 1u << 0, PFSPH_VDB_VELOCITY = 1u << 1, PFSPH_VDB_DENSITY = 1u << 2 };

/* Whether this build can write and read OpenVDB files. */
bool pfsph_vdb_available(void);

/* What a frame's .vdb holds: the liquid's closed mesh m (world coordinates, metres, y-up as
 * every other output) as a narrow-band signed distance field, and the particles for the
 * velocity grid. */
typedef struct pfsph_vdb_frame {
    const pfsph_surface_mesh *mesh;
    double voxel;      /* voxel edge [m]: the mesher's cell */
    double half_width; /* narrow band half width [voxels] (3 when <= 0) */
    unsigned grids;    /* PFSPH_VDB_* */
    const double *x;   /* 3 n particle positions [m] (velocity grid) */
    const float *v;    /* 3 n particle velocities [m/s] */
    size_t n;
    double radius; /* Shepard radius of the velocity average [m] */
    double time;   /* [s], file metadata "time" */
} pfsph_vdb_frame;

/* Write path (atomic, every write checked; PFSPH_FAULT_WRITE applies): a float grid "surface"
 * (GRID_LEVEL_SET, negative inside the liquid, background half_width * voxel), a vec3s grid
 * "velocity" on the surface's active voxels and a float fog volume "density" (0 outside, 1
 * deep inside), as f->grids asks. PFSPH_EINPUT without OpenVDB, PFSPH_EIO, PFSPH_ENOMEM. */
int pfsph_write_vdb(const char *path, const pfsph_vdb_frame *f, pfsph_error *err);

/* A grid of a .vdb file read back (for tests and checks). */
typedef struct pfsph_vdb_grid_info {
    char name[64];
    char value_type[32]; /* "float", "vec3s", ... */
    int level_set;       /* grid class GRID_LEVEL_SET */
    int fog;             /* grid class GRID_FOG_VOLUME */
    double voxel[3];     /* voxel size [m] */
    double background;
    size_t active; /* active voxels */
    double time;   /* the file's "time" metadata, NaN when absent */
} pfsph_vdb_grid_info;

/* Read grid `name` of the file at path (read with the frame cap) and, when p is not NULL, its
 * world-space trilinear values at the n points p (3 n, [m]) into out (n values; the first
 * component of a vector grid). PFSPH_EINPUT for a file that is not OpenVDB, or no such grid. For
 * pfsph's own files (tests, checks): OpenVDB's reader trusts a file past its header (a truncated
 * one makes libopenvdb 10.0 read lengths that were never read: valgrind). */
int pfsph_read_vdb(const char *path, const char *name, pfsph_vdb_grid_info *info, const double *p, size_t n,
                   double *out, pfsph_error *err);

#ifdef __cplusplus
}
#endif

#endif
