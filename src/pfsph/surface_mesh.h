/* Liquid surface reconstruction: anisotropic kernels (Yu & Turk 2013), a colour field on a sparse
 * block grid that follows the surface, marching cubes (each cube split into six tetrahedra) and a
 * welded, closed triangle mesh with normals from the field's gradient; in 2D closed polylines from
 * marching triangles. docs/surfaces.md. */
#ifndef PFSPH_SURFACE_MESH_H
#define PFSPH_SURFACE_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "pfsph/types.h"

/* Lengths are multiples of the particle spacing d. A value <= 0 takes the default. */
typedef struct pfsph_surface_opts {
    double spacing;    /* particle spacing d [m]; required */
    double cell;       /* marching-cubes cell edge / d (0.5) */
    double support;    /* isotropic kernel support h / d (3) */
    double pca_radius; /* neighbourhood radius of the weighted PCA / d (3) */
    double lambda;     /* Laplacian smoothing of the kernel centres, 0..1 (0.9; < 0: none) */
    double kr;         /* largest / smallest kernel axis (4) */
    double kn;         /* kernel scale of particles with few neighbours (0.5) */
    int n_eps;         /* fewer neighbours than this: isotropic kn kernel (25) */
    double iso;        /* iso-level of the volume-fraction field; <= 0: calibrated so that a
                          * flat lattice surface lies half a spacing beyond its last layer */
    bool isotropic;    /* plain spherical kernels, no PCA (for comparison) */
    int smooth_iters;  /* Taubin mesh smoothing passes (0: none) */
    double droplet;    /* blob radius of an isolated particle (fewer than 5 particles within the
                          * PCA radius, itself included) / d: its kernel shrinks until a lone one
                          * meshes as a ball of this radius (0: (3 / 4 pi)^(1/3) = 0.62, the ball of
                          * the particle's own volume d^3; < 0: no bound, kn kernels as before) */
} pfsph_surface_opts;

/* A welded triangle mesh, counter-clockwise seen from outside (the liquid). */
typedef struct pfsph_surface_mesh {
    size_t nverts, ntris;
    double *v;      /* 3 * nverts */
    float *n;       /* 3 * nverts unit outward normals (minus the colour-field gradient) */
    uint32_t *tri;  /* 3 * ntris */
    uint8_t *phase; /* ntris: the fluid phase each face bounds */
    float *vel;     /* 3 * nverts: the liquid's velocity at each vertex [m/s], or NULL (filled by
                     * pfsph_surface_velocity, read back from a PLY's vx vy vz) */
    /* statistics of the last reconstruction (summed over phases) */
    size_t blocks;            /* sparse-grid blocks kept (those the surface crosses) */
    size_t blocks_peak;       /* blocks allocated at most at once */
    size_t grid_bytes;        /* peak bytes of the sparse grid's node values */
    size_t surface_particles; /* particles classified as near the surface */
    double seconds[4];        /* wall time: kernels (PCA), field (grid growth), marching, merge */
} pfsph_surface_mesh;

void pfsph_surface_opts_default(pfsph_surface_opts *o, double spacing);

/* Reconstruct the surface of n particles at x (3n coordinates, [m]); phase[i] groups them
 * (one closed surface set per phase present, faces tagged with it; phase may be NULL: all 0).
 * *m is overwritten (free with pfsph_surface_mesh_free). Deterministic: the same bytes for any
 * thread count. PFSPH_EINPUT for bad options or coordinates out of the grid's range (about
 * 2^18 cells from the origin), PFSPH_ENOMEM. */
int pfsph_surface_reconstruct(const double *x, const uint8_t *phase, size_t n, const pfsph_surface_opts *o,
                              pfsph_surface_mesh *m, pfsph_error *err);

/* The iso-level a calibrated reconstruction uses for these options (computed on a flat slab). */
double pfsph_surface_calibrate_iso(const pfsph_surface_opts *o);

void pfsph_surface_mesh_free(pfsph_surface_mesh *m);

/* m->vel (allocated here): at each vertex the particles' velocities v (3n, [m/s]) at x (3n, [m])
 * averaged with the weights (1 - r^2 / R^2)^3 over the particles within R (Shepard); 0 where none
 * is. Deterministic (each vertex sums its particles in one fixed order). PFSPH_ENOMEM. */
int pfsph_surface_velocity(pfsph_surface_mesh *m, const double *x, const float *v, size_t n, double R);

/* A 2D liquid's outline: closed polylines in the plane z = 0, as segments with the liquid on
 * their left (counter-clockwise around the liquid, clockwise around a hole). */
typedef struct pfsph_surface_contour {
    size_t nverts, nsegs;
    double *v;      /* 3 * nverts (z = 0) */
    float *n;       /* 3 * nverts unit outward normals (z = 0) */
    uint32_t *seg;  /* 2 * nsegs: from, to */
    uint8_t *phase; /* nsegs */
} pfsph_surface_contour;

/* The 2D counterpart of pfsph_surface_reconstruct: x holds 3 coordinates per particle (z
 * ignored); the same options (smooth_iters unused). Every vertex starts one segment and ends one.
 * Deterministic (serial). PFSPH_EINPUT as above, or when the grid over the particles would
 * exceed 2^26 nodes; PFSPH_ENOMEM. */
int pfsph_surface_contour2d(const double *x, const uint8_t *phase, size_t n, const pfsph_surface_opts *o,
                            pfsph_surface_contour *c, pfsph_error *err);

/* The iso-level of a calibrated 2D contour (a flat lattice slab, as in 3D). */
double pfsph_surface_calibrate_iso2d(const pfsph_surface_opts *o);

void pfsph_surface_contour_free(pfsph_surface_contour *c);

#endif
