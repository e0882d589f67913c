/* Shared by the closed-mesh files (mesh.c: checks and mass properties; mesh_obj.c: the OBJ
 * reader; mesh_sample.c: surface sampling; mesh_shapes.c: primitives): limits, the edge record. */
#ifndef PFSPH_MESH_INTERNAL_H
#define PFSPH_MESH_INTERNAL_H

#include "pfsph/mesh.h"

/* Limits that keep any input (including fuzzed bytes) within a bounded amount of memory. */
#define MESH_MAX_TRIS 10000000u
#define MESH_MAX_VERTS 10000000u
#define MESH_PI 3.14159265358979323846

/* A directed edge of a triangle, sorted by its undirected key to find each edge's triangles. */
typedef struct {
    uint64_t key; /* (min vertex << 32) | max vertex */
    uint32_t tri;
    uint32_t fwd; /* 1 when the triangle runs min -> max */
} pfsph__mesh_edge;

/* qsort order: by key, then triangle (a total order: the same result for any sort) */
int pfsph__mesh_edge_cmp(const void *a, const void *b);

/* An empty mesh with room for nv vertices and nt triangles (counts set); PFSPH_ENOMEM. */
int pfsph__mesh_alloc(pfsph_mesh *m, size_t nv, size_t nt);

#endif
