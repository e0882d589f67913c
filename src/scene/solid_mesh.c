/* The static solids as triangle meshes (solid_mesh.h): primitives from mesh_shapes, a container
 * as its wall slabs, a plane as a slab clipped to the domain. */
#include "pfsph/solid_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh_internal.h"

#define SEGMENTS 48 /* around curved solids: under 0.3 % of the radius off the true surface */

/* dst += src (vertex indices shifted); src is freed */
static int append(pfsph_mesh *dst, pfsph_mesh *src)
{
    double *v = realloc(dst->v, 3 * (dst->nverts + src->nverts) * sizeof *v);
    if (v) dst->v = v;
    uint32_t *t = realloc(dst->tri, 3 * (dst->ntris + src->ntris) * sizeof *t);
    if (t) dst->tri = t;
    if (!v || !t) {
        pfsph_mesh_free(src);
        return PFSPH_ENOMEM;
    }
    memcpy(dst->v + 3 * dst->nverts, src->v, 3 * src->nverts * sizeof *v);
    for (size_t i = 0; i < 3 * src->ntris; i++) dst->tri[3 * dst->ntris + i] = src->tri[i] + (uint32_t)dst->nverts;
    dst->nverts += src->nverts;
    dst->ntris += src->ntris;
    pfsph_mesh_free(src);
    return PFSPH_OK;
}

/* the box lo..hi appended to m */
static int add_box(pfsph_mesh *m, const double lo[3], const double hi[3])
{
    double half[3], c[3];
    for (int a = 0; a < 3; a++) half[a] = 0.5 * (hi[a] - lo[a]), c[a] = 0.5 * (hi[a] + lo[a]);
    pfsph_mesh b;
    int rc = pfsph_mesh_box(&b, half);
    if (rc) return rc;
    pfsph_mesh_transform(&b, 1, NULL, c);
    return append(m, &b);
}

/* The walls as the particles stand for them: L cells of the container's own lattice
 * ((max - min) / n per axis, n the rounded count of spacings) outside every face, the top slab
 * left out when open. Slabs: the floor (and lid) across the whole outer extent, the x walls
 * between them over the full depth, the z walls between the x walls. */
static int container(const pfsph_solid *o, double d, pfsph_mesh *m)
{
    const int L = o->layers < 1 ? 1 : o->layers;
    double T[3], lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        double n = floor((o->max[a] - o->min[a]) / d + 0.5);
        if (n < 1) n = 1;
        T[a] = L * (o->max[a] - o->min[a]) / n;
    }
    int rc = PFSPH_OK;
    for (int s = 0; s < 2 && !rc; s++) { /* floor, lid */
        if (s == 1 && o->open_top) break;
        for (int a = 0; a < 3; a += 2) lo[a] = o->min[a] - T[a], hi[a] = o->max[a] + T[a];
        lo[1] = s ? o->max[1] : o->min[1] - T[1];
        hi[1] = s ? o->max[1] + T[1] : o->min[1];
        rc = add_box(m, lo, hi);
    }
    for (int s = 0; s < 2 && !rc; s++) { /* x walls */
        lo[0] = s ? o->max[0] : o->min[0] - T[0];
        hi[0] = s ? o->max[0] + T[0] : o->min[0];
        lo[1] = o->min[1], hi[1] = o->max[1];
        lo[2] = o->min[2] - T[2], hi[2] = o->max[2] + T[2];
        rc = add_box(m, lo, hi);
    }
    for (int s = 0; s < 2 && !rc; s++) { /* z walls */
        lo[0] = o->min[0], hi[0] = o->max[0];
        lo[1] = o->min[1], hi[1] = o->max[1];
        lo[2] = s ? o->max[2] : o->min[2] - T[2];
        hi[2] = s ? o->max[2] + T[2] : o->min[2];
        rc = add_box(m, lo, hi);
    }
    return rc;
}

#define MAXPOLY 64

/* Sutherland-Hodgman: keep the part of polygon p (n points) with sgn * (x[a] - c) <= 0 */
static int clip(double (*p)[3], int n, int a, double c, double sgn)
{
    double q[MAXPOLY][3];
    int k = 0;
    for (int i = 0; i < n && k < MAXPOLY - 1; i++) {
        const double *A = p[i], *B = p[(i + 1) % n];
        double fa = sgn * (A[a] - c), fb = sgn * (B[a] - c);
        if (fa <= 0) memcpy(q[k++], A, sizeof q[0]);
        if ((fa < 0 && fb > 0) || (fa > 0 && fb < 0)) {
            double t = fa / (fa - fb);
            for (int u = 0; u < 3; u++) q[k][u] = A[u] + t * (B[u] - A[u]);
            k++;
        }
    }
    memcpy(p, q, (size_t)k * sizeof q[0]);
    return k;
}

/* The slab behind a plane: the plane's polygon inside the domain grown by the thickness T (as the
 * particles are), and its copy T behind, joined by side quads. */
static int plane(const pfsph_scene *s, const pfsph_solid *o, double d, pfsph_mesh *m)
{
    const int L = o->layers < 1 ? 1 : o->layers;
    const double T = L * d;
    double n[3] = {o->normal[0], o->normal[1], o->normal[2]};
    double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(ln > 0)) return PFSPH_EINPUT;
    for (int a = 0; a < 3; a++) n[a] /= ln;
    double t1[3], t2[3], e[3] = {1, 0, 0}, diag = 0;
    if (fabs(n[0]) > 0.9) e[0] = 0, e[1] = 1;
    t1[0] = e[1] * n[2] - e[2] * n[1], t1[1] = e[2] * n[0] - e[0] * n[2], t1[2] = e[0] * n[1] - e[1] * n[0];
    double l1 = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int a = 0; a < 3; a++) t1[a] /= l1;
    t2[0] = n[1] * t1[2] - n[2] * t1[1], t2[1] = n[2] * t1[0] - n[0] * t1[2], t2[2] = n[0] * t1[1] - n[1] * t1[0];
    for (int a = 0; a < 3; a++) {
        double w = s->domain_max[a] - s->domain_min[a] + 2 * T;
        diag += w * w;
    }
    diag = 2 * sqrt(diag);
    double p[MAXPOLY][3];
    static const double corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}; /* counter-clockwise about n */
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++) p[k][a] = o->center[a] + diag * (corner[k][0] * t1[a] + corner[k][1] * t2[a]);
    /* the front polygon inside both the box and the box moved by T n, so that the back one (the
     * front moved by -T n) stays inside the box too: a prism, at the cost of a sliver T wide at
     * the box's faces */
    int np = 4;
    for (int a = 0; a < 3 && np >= 3; a++) {
        double hi = s->domain_max[a] + T, lo = s->domain_min[a] - T;
        np = clip(p, np, a, n[a] < 0 ? hi + T * n[a] : hi, 1);
        if (np >= 3) np = clip(p, np, a, n[a] > 0 ? lo + T * n[a] : lo, -1);
    }
    if (np < 3) return PFSPH_EINPUT;
    pfsph_mesh sl = {0};
    int rc = pfsph__mesh_alloc(&sl, 2 * (size_t)np, 2 * (size_t)(np - 2) + 2 * (size_t)np);
    if (rc) return rc;
    for (int k = 0; k < np; k++)
        for (int a = 0; a < 3; a++) {
            sl.v[3 * k + a] = p[k][a];                   /* front: the plane */
            sl.v[3 * (np + k) + a] = p[k][a] - T * n[a]; /* back */
        }
    size_t t = 0;
    for (int k = 1; k + 1 < np; k++) { /* front faces +n: counter-clockwise as the polygon */
        uint32_t f[6] = {0, (uint32_t)k, (uint32_t)k + 1, (uint32_t)np, (uint32_t)(np + k + 1), (uint32_t)(np + k)};
        memcpy(sl.tri + 3 * t++, f, 3 * sizeof *f);
        memcpy(sl.tri + 3 * t++, f + 3, 3 * sizeof *f);
    }
    for (int k = 0; k < np; k++) { /* sides: outward, front edge k -> k+1 reversed */
        uint32_t a = (uint32_t)k, b = (uint32_t)((k + 1) % np), A = a + (uint32_t)np, B = b + (uint32_t)np;
        uint32_t f[6] = {a, A, B, a, B, b};
        memcpy(sl.tri + 3 * t++, f, 3 * sizeof *f);
        memcpy(sl.tri + 3 * t++, f + 3, 3 * sizeof *f);
    }
    return append(m, &sl);
}

int pfsph_solid_mesh(const pfsph_scene *s, const pfsph_solid *o, pfsph_mesh *m)
{
    memset(m, 0, sizeof *m);
    if (s->dim != 3) return PFSPH_EINPUT;
    const double d = 2 * s->particle_radius;
    pfsph_mesh p = {0};
    int rc;
    switch (o->shape) {
    case PFSPH_SHAPE_BOX: return add_box(m, o->min, o->max);
    case PFSPH_SHAPE_SPHERE: rc = pfsph_mesh_sphere(&p, o->radius, SEGMENTS); break;
    case PFSPH_SHAPE_CYLINDER: rc = pfsph_mesh_cylinder(&p, o->radius, o->height, o->axis, SEGMENTS); break;
    case PFSPH_SHAPE_CONTAINER: rc = container(o, d, m); return rc ? (pfsph_mesh_free(m), rc) : rc;
    case PFSPH_SHAPE_PLANE: rc = plane(s, o, d, m); return rc ? (pfsph_mesh_free(m), rc) : rc;
    default: return PFSPH_EINPUT;
    }
    if (rc) return rc;
    pfsph_mesh_transform(&p, 1, NULL, o->center);
    *m = p;
    return PFSPH_OK;
}
