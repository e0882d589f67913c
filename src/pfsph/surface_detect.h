/* Free-surface particle detection, layer by layer (PF Section 4.2.2 and Fig. 9, after
 * Barecasco, Terissa & Naa 2013, "Simple free-surface detection in two and three-dimensional
 * SPH solver"; NOTES item 10). Every particle is a sphere of radius r_c = radius / 2; the
 * spheres of the neighbours within `radius` overlap it. The sum of the unit vectors from the
 * neighbours to the particle points to where its sphere is least covered; the particle is on
 * the surface when the point of its sphere in that direction, x_i + r_c s / |s|, lies inside
 * no neighbour's sphere. The next layer in is the surface of what is left once the outer
 * layer is taken away. Core data only (ctx, grid): any stage, the output or a tool may call it.
 * Choices and measurements: docs/film.md. */
#ifndef PFSPH_SURFACE_DETECT_H
#define PFSPH_SURFACE_DETECT_H

#include <stdbool.h>
#include <stdint.h>

#include "pfsph/ctx.h"

#define PFSPH_SURFACE_MAX_LAYERS 8

typedef struct pfsph_surface_opts {
    double radius;        /* neighbour radius [m] (= 2 r_c); 0: min(2 d, h). Must be covered
                           * by the grid's query (reach cells) */
    int layers;           /* how many layers to peel, 1..PFSPH_SURFACE_MAX_LAYERS */
    const uint8_t *group; /* NULL: every fluid particle covers every other; else only particles
                           * of the same group cover each other (a bubble's own particles,
                           * fluid->bubble) */
    bool boundary;        /* boundary particles cover fluid ones (a fluid against a wall has no
                           * free surface there) */
    int reach;            /* grid cells walked each way; 0: ctx->grid->reach. One more than the
                           * grid's reach after particles moved since the sort (at most 3) */
} pfsph_surface_opts;

/* Writes layer[i] for every fluid particle of ctx (in grid order, ctx->grid sorted for them):
 * 0 interior, 1 outermost layer, 2 the next one in, ... up to o->layers. A particle without
 * neighbours is layer 1. work: scratch of ctx->fluid->n bytes (unused when layers == 1).
 * Deterministic for any thread count; allocates nothing. */
void pfsph_surface_detect(const pfsph_ctx *ctx, const pfsph_surface_opts *o, uint8_t *layer, uint8_t *work);

/* The frames' surface layers of the fluid as it is now (up to `layers`), boundary particles
 * covering, each bubble on its own when `bubbles`; allocates its work. PFSPH_OK or PFSPH_ENOMEM. */
int pfsph__surface_layers(const pfsph_ctx *ctx, bool bubbles, int layers, uint8_t *out);

#endif
