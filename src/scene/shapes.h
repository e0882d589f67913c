/* Internal: sampling scene shapes with particles, and signed distances to solids. */
#ifndef PFSPH_SHAPES_H
#define PFSPH_SHAPES_H

#include "pfsph/particles.h"
#include "pfsph/scene.h"

/* Append the fluid particles of block b alone on the scene lattice of spacing d (sites at
 * (k + 1/2) d along every axis; shapes.c). ps may be NULL to only count. Returns the count or
 * -1 (out of memory). */
long pfsph__sample_block(const pfsph_scene *s, const pfsph_block *b, double d, pfsph_particles *ps);
/* The same for s->blocks[i] as the scene makes it: less the sites that later blocks contain
 * (a later block replaces what earlier ones put where they overlap). */
long pfsph__sample_scene_block(const pfsph_scene *s, int i, double d, pfsph_particles *ps);
/* 1 when later blocks take every site of s->blocks[i] (it adds nothing). Checked up to 1e7
 * sites in its bounding box (bounded work for the loader); larger blocks return 0. */
int pfsph__scene_block_covered(const pfsph_scene *s, int i, double d);
/* Append the boundary particles of a solid (its `layers` layers at spacing d, the first layer
 * centred d/2 inside the solid surface). ps may be NULL to only count. */
long pfsph__sample_solid(const pfsph_scene *s, const pfsph_solid *o, double d, pfsph_particles *ps);
/* Signed distance from p to the solid's surface, positive on the fluid side (d: the particle
 * spacing, which sets the thickness of container walls). */
double pfsph__solid_distance(const pfsph_solid *o, int dim, double d, const double p[3]);

#endif
