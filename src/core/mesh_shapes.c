/* Primitive closed meshes (mesh.h): box, icosphere, cylinder. */
#include "pfsph/mesh.h"

#include <math.h>
#include <string.h>

#include "core/mesh_internal.h"
#include "core/vec.h"

static void set_tri(pfsph_mesh *m, size_t t, uint32_t a, uint32_t b, uint32_t c)
{
    m->tri[3 * t] = a;
    m->tri[3 * t + 1] = b;
    m->tri[3 * t + 2] = c;
}

int pfsph_mesh_box(pfsph_mesh *m, const double half[3])
{
    memset(m, 0, sizeof *m);
    for (int a = 0; a < 3; a++)
        if (!(half[a] > 0) || !isfinite(half[a])) return PFSPH_EINPUT;
    int rc = pfsph__mesh_alloc(m, 8, 12);
    if (rc) return rc;
    for (int i = 0; i < 8; i++) /* vertex i has bit a set when coordinate a is +half */
        for (int a = 0; a < 3; a++) m->v[3 * i + a] = (i >> a & 1) ? half[a] : -half[a];
    /* two triangles per face, counter-clockwise from outside */
    static const uint32_t q[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (int f = 0; f < 6; f++) {
        set_tri(m, 2 * (size_t)f, q[f][0], q[f][1], q[f][2]);
        set_tri(m, 2 * (size_t)f + 1, q[f][0], q[f][2], q[f][3]);
    }
    return PFSPH_OK;
}

/* Vertex index of grid point (i, j) = A + i/f (B - A) + j/f (C - A) of an icosphere face:
 * a corner, a point on one of the 30 shared edges (stored from the lower corner index up), or
 * a point inside the face (numbered row by row from `base`). */
static uint32_t ico_index(const uint8_t ed[30][2], size_t f, size_t base, int A, int B, int C, size_t i, size_t j)
{
    if (i == 0 && j == 0) return (uint32_t)A;
    if (j == 0 && i == f) return (uint32_t)B;
    if (i == 0 && j == f) return (uint32_t)C;
    int p, q;
    size_t k;
    if (j == 0) p = A, q = B, k = i;
    else if (i == 0) p = A, q = C, k = j;
    else if (i + j == f) p = B, q = C, k = j;
    else return (uint32_t)(base + (j - 1) * (f - 1) - (j - 1) * j / 2 + (i - 1));
    int lo = p < q ? p : q, hi = p < q ? q : p, e = 0;
    while (ed[e][0] != lo || ed[e][1] != hi) e++;
    return (uint32_t)(12 + (size_t)e * (f - 1) + (p < q ? k : f - k) - 1);
}

/* Icosphere: each icosahedron face split into f x f triangles (f = ceil(segments / 5.67), so
 * a great circle has about `segments` edges: an icosahedron edge spans 1.107 rad), then every
 * vertex pushed onto the sphere. Edge vertices are shared, so the mesh is closed by
 * construction and its triangles are all nearly equilateral (no pole slivers). */
int pfsph_mesh_sphere(pfsph_mesh *m, double radius, int segments)
{
    memset(m, 0, sizeof *m);
    if (!(radius > 0) || !isfinite(radius) || segments < 3 || segments > 4096) return PFSPH_EINPUT;
    const size_t f = (size_t)ceil(segments * 1.1071487177940904 / ((2 * MESH_PI)) - 1e-9);
    const double gr = 1.6180339887498949; /* golden ratio */
    /* (+-1, +-gr, 0) and cyclic permutations; the entry marked +-1 before a 0 (cyclically)
     * is the one scaled by gr */
    static const int8_t iv[12][3] = {{-1, 1, 0},  {1, 1, 0},  {-1, -1, 0}, {1, -1, 0}, {0, -1, 1},  {0, 1, 1},
                                     {0, -1, -1}, {0, 1, -1}, {1, 0, -1},  {1, 0, 1},  {-1, 0, -1}, {-1, 0, 1}};
    static const uint8_t ifc[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    uint8_t ed[30][2];
    int ne = 0;
    for (int fc = 0; fc < 20; fc++)
        for (int k = 0; k < 3; k++) {
            int a = ifc[fc][k], b = ifc[fc][(k + 1) % 3];
            if (a < b) {
                ed[ne][0] = (uint8_t)a;
                ed[ne][1] = (uint8_t)b;
                ne++;
            }
        }
    size_t nv = 12 + 30 * (f - 1) + 20 * ((f - 1) * (f >= 2 ? f - 2 : 0) / 2), nt = 20 * f * f;
    int rc = pfsph__mesh_alloc(m, nv, nt);
    if (rc) return rc;
    double cv[12][3];
    for (int i = 0; i < 12; i++) {
        double p[3];
        for (int a = 0; a < 3; a++) p[a] = iv[i][a] * ((iv[i][a] != 0 && iv[i][(a + 1) % 3] == 0) ? gr : 1.0);
        double l = vec3_norm(p);
        for (int a = 0; a < 3; a++) cv[i][a] = p[a] / l;
    }
    size_t vi = 0; /* corners, then f-1 points per edge, then each face's interior */
    for (int i = 0; i < 12; i++, vi++)
        for (int a = 0; a < 3; a++) m->v[3 * vi + a] = cv[i][a];
    for (int e = 0; e < 30; e++)
        for (size_t k = 1; k < f; k++, vi++)
            for (int a = 0; a < 3; a++)
                m->v[3 * vi + a] = cv[ed[e][0]][a] + (double)k / (double)f * (cv[ed[e][1]][a] - cv[ed[e][0]][a]);
    size_t ti = 0;
    for (int fc = 0; fc < 20; fc++) {
        int A = ifc[fc][0], B = ifc[fc][1], C = ifc[fc][2];
        size_t base = vi;
        for (size_t j = 1; j + 1 < f; j++)
            for (size_t i = 1; i + j < f; i++, vi++)
                for (int a = 0; a < 3; a++)
                    m->v[3 * vi + a] = cv[A][a] + (double)i / (double)f * (cv[B][a] - cv[A][a]) +
                        (double)j / (double)f * (cv[C][a] - cv[A][a]);
        /* "up" triangles (i,j),(i+1,j),(i,j+1) and "down" ones, same winding as A, B, C */
        for (size_t j = 0; j < f; j++)
            for (size_t i = 0; i + j < f; i++) {
                uint32_t g00 = ico_index(ed, f, base, A, B, C, i, j), g10 = ico_index(ed, f, base, A, B, C, i + 1, j),
                         g01 = ico_index(ed, f, base, A, B, C, i, j + 1);
                set_tri(m, ti++, g00, g10, g01);
                if (i + j + 2 <= f) set_tri(m, ti++, g10, ico_index(ed, f, base, A, B, C, i + 1, j + 1), g01);
            }
    }
    for (size_t i = 0; i < nv; i++) {
        double *p = m->v + 3 * i, l = vec3_norm(p);
        for (int a = 0; a < 3; a++) p[a] *= radius / l;
    }
    return PFSPH_OK;
}

int pfsph_mesh_cylinder(pfsph_mesh *m, double radius, double height, int axis, int segments)
{
    memset(m, 0, sizeof *m);
    if (!(radius > 0) || !isfinite(radius) || !(height > 0) || !isfinite(height) || axis < 0 || axis > 2 ||
        segments < 3 || segments > 1000000)
        return PFSPH_EINPUT;
    size_t n = (size_t)segments;
    /* rings: bottom 0..n-1, top n..2n-1, then the two cap centres (fans from the centre
     * keep cap triangles isosceles rather than slivers from a rim vertex) */
    int rc = pfsph__mesh_alloc(m, 2 * n + 2, 4 * n);
    if (rc) return rc;
    int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3; /* (a1, a2, axis) is right-handed */
    for (size_t i = 0; i < n; i++) {
        double th = (2 * MESH_PI) * (double)i / (double)n;
        for (int top = 0; top < 2; top++) {
            double *p = m->v + 3 * (i + (size_t)top * n);
            p[a1] = radius * cos(th);
            p[a2] = radius * sin(th);
            p[axis] = top ? 0.5 * height : -0.5 * height;
        }
    }
    for (int top = 0; top < 2; top++) {
        double *p = m->v + 3 * (2 * n + (size_t)top);
        p[a1] = p[a2] = 0;
        p[axis] = top ? 0.5 * height : -0.5 * height;
    }
    uint32_t cb = (uint32_t)(2 * n), ct = cb + 1;
    for (size_t i = 0; i < n; i++) {
        uint32_t b0 = (uint32_t)i, b1 = (uint32_t)((i + 1) % n), t0 = b0 + (uint32_t)n, t1 = b1 + (uint32_t)n;
        set_tri(m, 4 * i, b0, b1, t1);
        set_tri(m, 4 * i + 1, b0, t1, t0);
        set_tri(m, 4 * i + 2, ct, t0, t1);
        set_tri(m, 4 * i + 3, cb, b1, b0);
    }
    return PFSPH_OK;
}
