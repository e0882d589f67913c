/* The fluid blocks' and solids' geometry as the parser checks it: overlaps of blocks with one
 * another, with solids and with the domain, before any particle exists. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/scene_parser.h"
#include "scene/shapes.h"

typedef pfsph__geo geo;

static const char *const axis_names[] = {"x", "y", "z"};

geo pfsph__geo_of(int dim, int shape, const double *min, const double *max, const double *center, double radius,
                  double height, int axis)
{
    geo g;
    memset(&g, 0, sizeof g);
    g.shape = shape;
    g.dim = dim;
    g.axis = axis;
    g.radius = radius;
    g.height = height;
    for (int k = 0; k < 3; k++) {
        g.center[k] = center[k];
        g.min[k] = min[k];
        g.max[k] = max[k];
    }
    /* A 2D cylinder is a disc: the same thing as a 2D sphere. */
    if (dim == 2 && shape == PFSPH_SHAPE_CYLINDER) g.shape = PFSPH_SHAPE_SPHERE;
    if (g.shape == PFSPH_SHAPE_SPHERE) {
        for (int k = 0; k < dim; k++) {
            g.min[k] = center[k] - radius;
            g.max[k] = center[k] + radius;
        }
    } else if (g.shape == PFSPH_SHAPE_CYLINDER) {
        for (int k = 0; k < 3; k++) {
            double e = k == axis ? 0.5 * height : radius;
            g.min[k] = center[k] - e;
            g.max[k] = center[k] + e;
        }
    }
    if (dim == 2) g.min[2] = g.max[2] = 0.0;
    return g;
}

/* Is point x inside g shrunk by d on every side? */
static bool geo_inside(const geo *g, const double *x, double d)
{
    if (g->shape == PFSPH_SHAPE_SPHERE) {
        double r2 = 0;
        for (int k = 0; k < g->dim; k++) r2 += (x[k] - g->center[k]) * (x[k] - g->center[k]);
        return g->radius > d && r2 < (g->radius - d) * (g->radius - d);
    }
    if (g->shape == PFSPH_SHAPE_CYLINDER) {
        double r2 = 0;
        for (int k = 0; k < 3; k++) {
            double e = x[k] - g->center[k];
            if (k == g->axis) {
                if (fabs(e) >= 0.5 * g->height - d) return false;
            } else {
                r2 += e * e;
            }
        }
        return g->radius > d && r2 < (g->radius - d) * (g->radius - d);
    }
    for (int k = 0; k < g->dim; k++)
        if (x[k] <= g->min[k] + d || x[k] >= g->max[k] - d) return false;
    return true;
}

/* Distance from point c to the box [lo, hi] (0 inside). */
static double point_box_distance(int dim, const double *c, const double *lo, const double *hi)
{
    double d2 = 0;
    for (int k = 0; k < dim; k++) {
        double e = c[k] < lo[k] ? lo[k] - c[k] : (c[k] > hi[k] ? c[k] - hi[k] : 0.0);
        d2 += e * e;
    }
    return sqrt(d2);
}

/* Do a and b overlap by more than half a particle spacing? Both shapes are shrunk by a quarter
 * spacing and tested for intersection: for two boxes this is "overlap > s/2 along every axis",
 * for two spheres "r1 + r2 - distance > s/2". Cylinders (3D) are sampled on a fine lattice over
 * the common bounding box, which is exact to a small fraction of the spacing. */
static bool geo_overlap(const geo *a, const geo *b, double spacing)
{
    const int dim = a->dim;
    const double d = 0.25 * spacing;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int k = 0; k < dim; k++) {
        lo[k] = fmax(a->min[k], b->min[k]) + d;
        hi[k] = fmin(a->max[k], b->max[k]) - d;
        if (!(lo[k] < hi[k])) return false;
    }
    if (a->shape == PFSPH_SHAPE_BOX && b->shape == PFSPH_SHAPE_BOX) return true;
    if (a->shape == PFSPH_SHAPE_SPHERE && b->shape == PFSPH_SHAPE_SPHERE) {
        double r2 = 0;
        for (int k = 0; k < dim; k++) r2 += (a->center[k] - b->center[k]) * (a->center[k] - b->center[k]);
        return sqrt(r2) < a->radius + b->radius - 2.0 * d;
    }
    if ((a->shape == PFSPH_SHAPE_BOX && b->shape == PFSPH_SHAPE_SPHERE) ||
        (a->shape == PFSPH_SHAPE_SPHERE && b->shape == PFSPH_SHAPE_BOX)) {
        const geo *bx = a->shape == PFSPH_SHAPE_BOX ? a : b;
        const geo *sp = a->shape == PFSPH_SHAPE_BOX ? b : a;
        double blo[3], bhi[3];
        for (int k = 0; k < dim; k++) {
            blo[k] = bx->min[k] + d;
            bhi[k] = bx->max[k] - d;
        }
        return point_box_distance(dim, sp->center, blo, bhi) < sp->radius - d;
    }
    /* Sampled test; at most 64 samples per axis of the common box, never coarser than an
     * eighth of a spacing in practice for blocks that touch. */
    int n[3] = {1, 1, 1};
    for (int k = 0; k < dim; k++) {
        double cells = (hi[k] - lo[k]) / (0.125 * spacing);
        n[k] = cells < 1 ? 1 : (cells > 64 ? 64 : (int)ceil(cells));
    }
    double x[3] = {0, 0, 0};
    for (int i = 0; i <= n[0]; i++)
        for (int j = 0; j <= n[1]; j++)
            for (int l = 0; l <= (dim == 3 ? n[2] : 0); l++) {
                int idx[3] = {i, j, l};
                for (int k = 0; k < dim; k++) x[k] = lo[k] + (hi[k] - lo[k]) * (double)idx[k] / (double)n[k];
                if (geo_inside(a, x, d) && geo_inside(b, x, d)) return true;
            }
    return false;
}

void pfsph__fmt_vec(char *out, size_t cap, int dim, const double *v)
{
    if (dim == 2) snprintf(out, cap, "[%g, %g]", v[0], v[1]);
    else snprintf(out, cap, "[%g, %g, %g]", v[0], v[1], v[2]);
}

int pfsph__scene_check_blocks(parser *p)
{
    pfsph_scene *s = p->s;
    const double sp = 2.0 * s->particle_radius;
    const double tiny = 1e-9 * sp;
    for (int i = 0; i < s->nblocks; i++) {
        const pfsph_block *b = &s->blocks[i];
        char P[128], kp[160];
        path_index(P, sizeof P, "$.fluid", i);
        const geo gb = pfsph__geo_of(s->dim, b->shape, b->min, b->max, b->center, b->radius, b->height, b->axis);
        /* Empty: fewer than one particle along some axis. */
        if (b->shape == PFSPH_SHAPE_BOX) {
            for (int k = 0; k < s->dim; k++)
                if (b->max[k] - b->min[k] < sp - tiny) {
                    path_key(kp, sizeof kp, P, "max");
                    return pfsph__json_fail(&p->ctx, kp,
                                            "block is %g m wide along %s, less than one particle "
                                            "spacing (%g m = 2 x particle_radius): it would hold no "
                                            "particle",
                                            b->max[k] - b->min[k], axis_names[k], sp);
                }
        } else {
            if (b->radius < sp - tiny) {
                path_key(kp, sizeof kp, P, "radius");
                return pfsph__json_fail(&p->ctx, kp,
                                        "radius %g m is less than one particle spacing (%g m = 2 x "
                                        "particle_radius): too small to sample",
                                        b->radius, sp);
            }
            if (b->shape == PFSPH_SHAPE_CYLINDER && s->dim == 3 && b->height < sp - tiny) {
                path_key(kp, sizeof kp, P, "height");
                return pfsph__json_fail(&p->ctx, kp, "height %g m is less than one particle spacing (%g m)", b->height,
                                        sp);
            }
        }
        /* Inside the domain. */
        for (int k = 0; k < s->dim; k++) {
            double scale = fmax(1.0, fabs(s->domain_max[k] - s->domain_min[k]));
            if (gb.min[k] < s->domain_min[k] - 1e-9 * scale || gb.max[k] > s->domain_max[k] + 1e-9 * scale) {
                char a[96], c[96], lo[96], hi[96];
                pfsph__fmt_vec(a, sizeof a, s->dim, s->domain_min);
                pfsph__fmt_vec(c, sizeof c, s->dim, s->domain_max);
                pfsph__fmt_vec(lo, sizeof lo, s->dim, gb.min);
                pfsph__fmt_vec(hi, sizeof hi, s->dim, gb.max);
                const char *key =
                    b->shape != PFSPH_SHAPE_BOX ? "center" : (gb.min[k] < s->domain_min[k] ? "min" : "max");
                path_key(kp, sizeof kp, P, key);
                return pfsph__json_fail(&p->ctx, kp, "block %s .. %s extends outside the domain %s .. %s along %s", lo,
                                        hi, a, c, axis_names[k]);
            }
        }
        /* Solids: obstacles must not start inside fluid; container walls must not cut blocks. */
        for (int j = 0; j < s->nsolids; j++) {
            const pfsph_solid *so = &s->solids[j];
            if (so->shape == PFSPH_SHAPE_PLANE) continue;
            if (so->shape == PFSPH_SHAPE_CONTAINER) {
                /* Partly inside the container's inner box but not wholly: crosses a wall. */
                bool touches = true, inside = true;
                for (int k = 0; k < s->dim; k++) {
                    double lo = fmax(gb.min[k], so->min[k]), hi = fmin(gb.max[k], so->max[k]);
                    if (hi - lo <= 0.5 * sp) touches = false;
                    if (gb.min[k] < so->min[k] - 0.5 * sp) inside = false;
                    bool top = so->open_top && k == 1;
                    if (!top && gb.max[k] > so->max[k] + 0.5 * sp) inside = false;
                }
                if (touches && !inside)
                    return pfsph__json_fail(&p->ctx, P, "block crosses the walls of the container $.solids[%d]", j);
                continue;
            }
            geo g = pfsph__geo_of(s->dim, so->shape, so->min, so->max, so->center, so->radius, so->height, so->axis);
            if (geo_overlap(&g, &gb, sp))
                return pfsph__json_fail(&p->ctx, P,
                                        "overlaps the solid $.solids[%d]; fluid particles would start "
                                        "inside it",
                                        j);
        }
        /* Overlaps with later blocks are what carving is for (shapes.c); a block they cover
         * wholly adds nothing, which is an ordering mistake (a tank listed after its bubble). */
        if (pfsph__scene_block_covered(s, i, sp)) {
            return pfsph__json_fail(&p->ctx, P,
                                    "every particle of this block lies inside later blocks, which replace "
                                    "earlier ones where they overlap: it would add nothing (list it after "
                                    "the blocks it should replace)");
        }
    }
    return PFSPH_OK;
}
