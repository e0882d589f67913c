/* Closed triangle meshes (mesh.h): closedness and orientation checks, exact polyhedral mass
 * properties, copies and rigid transforms. The OBJ reader, the surface sampler and the primitive
 * shapes are mesh_obj.c, mesh_sample.c and mesh_shapes.c. */
#include "pfsph/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh_internal.h"
#include "core/vec.h"

void pfsph_mesh_free(pfsph_mesh *m)
{
    if (!m) return;
    free(m->v);
    free(m->tri);
    m->v = NULL;
    m->tri = NULL;
    m->nverts = m->ntris = 0;
}

int pfsph__mesh_alloc(pfsph_mesh *m, size_t nv, size_t nt)
{
    memset(m, 0, sizeof *m);
    /* at least one element each: malloc(0) may return NULL, which is not a failure */
    m->v = malloc(3 * (nv ? nv : 1) * sizeof(double));
    m->tri = malloc(3 * (nt ? nt : 1) * sizeof(uint32_t));
    if (!m->v || !m->tri) {
        pfsph_mesh_free(m);
        return PFSPH_ENOMEM;
    }
    m->nverts = nv;
    m->ntris = nt;
    return PFSPH_OK;
}

int pfsph_mesh_bounds(const pfsph_mesh *m, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (size_t i = 0; i < 3 * m->ntris; i++) {
        if (m->tri[i] >= m->nverts) return -1;
        const double *p = m->v + 3 * (size_t)m->tri[i];
        for (int a = 0; a < 3; a++) {
            if (!isfinite(p[a])) return -1;
            if (p[a] < lo[a]) lo[a] = p[a];
            if (p[a] > hi[a]) hi[a] = p[a];
        }
    }
    return 0;
}

/* ---------------------------------------------------------------------------------------- */
/* Closedness and orientation */

int pfsph__mesh_edge_cmp(const void *a, const void *b)
{
    const pfsph__mesh_edge *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->tri > y->tri) - (x->tri < y->tri);
}

/* Signed volume (divergence theorem, relative to `ref` for precision). */
static double signed_volume(const pfsph_mesh *m, const double ref[3])
{
    double vol = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        double a[3], b[3], c[3], n[3];
        vec3_sub(m->v + 3 * (size_t)m->tri[3 * t], ref, a);
        vec3_sub(m->v + 3 * (size_t)m->tri[3 * t + 1], ref, b);
        vec3_sub(m->v + 3 * (size_t)m->tri[3 * t + 2], ref, c);
        vec3_cross(b, c, n);
        vol += vec3_dot(a, n);
    }
    return vol / 6.0;
}

int pfsph_mesh_validate_closed(pfsph_mesh *m, const char *source, pfsph_error *err)
{
    if (!source) source = "mesh";
    if (!m || m->ntris == 0) return pfsph_fail(err, PFSPH_EINPUT, "%s: mesh has no triangles", source);
    if (m->ntris > MESH_MAX_TRIS || m->nverts > MESH_MAX_VERTS)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: mesh too large", source);
    for (size_t i = 0; i < 3 * m->ntris; i++)
        if (m->tri[i] >= m->nverts)
            return pfsph_fail(err, PFSPH_EINPUT, "%s: triangle %zu uses vertex %lu, out of range (%zu vertices)",
                              source, i / 3 + 1, (unsigned long)m->tri[i] + 1, m->nverts);
    double lo[3], hi[3], ref[3], d[3];
    if (pfsph_mesh_bounds(m, lo, hi))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: a vertex coordinate is not finite", source);
    for (int a = 0; a < 3; a++) {
        ref[a] = 0.5 * (lo[a] + hi[a]);
        d[a] = hi[a] - lo[a];
    }
    double diag2 = vec3_dot(d, d);
    /* the volume test below cubes the size: refuse sizes whose powers overflow */
    if (!(diag2 > 0) || !isfinite(diag2 * sqrt(diag2) * 1e3))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: mesh extent is zero or too large", source);

    /* degenerate triangles: area below 1e-12 diag^2 (also catches repeated vertices) */
    for (size_t t = 0; t < m->ntris; t++) {
        const uint32_t *ti = m->tri + 3 * t;
        double e1[3], e2[3], n[3];
        vec3_sub(m->v + 3 * (size_t)ti[1], m->v + 3 * (size_t)ti[0], e1);
        vec3_sub(m->v + 3 * (size_t)ti[2], m->v + 3 * (size_t)ti[0], e2);
        vec3_cross(e1, e2, n);
        double area = 0.5 * vec3_norm(n);
        if (!(area >= 1e-12 * diag2))
            return pfsph_fail(err, PFSPH_EINPUT, "%s: triangle %zu (vertices %lu %lu %lu) is degenerate (area %.3g)",
                              source, t + 1, (unsigned long)ti[0] + 1, (unsigned long)ti[1] + 1,
                              (unsigned long)ti[2] + 1, area);
    }

    /* edges: sort the 3n directed edges by undirected key, O(n log n) */
    size_t ne = 3 * m->ntris;
    pfsph__mesh_edge *e = malloc(ne * sizeof *e);
    if (!e) return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory checking edges", source);
    for (size_t t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            pfsph__mesh_edge *r = e + 3 * t + k;
            r->key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            r->tri = (uint32_t)t;
            r->fwd = a < b;
        }
    qsort(e, ne, sizeof *e, pfsph__mesh_edge_cmp);
    int rc = PFSPH_OK;
    for (size_t i = 0; i < ne && !rc;) {
        size_t j = i + 1;
        while (j < ne && e[j].key == e[i].key) j++;
        unsigned long va = (unsigned long)(e[i].key >> 32) + 1, vb = (unsigned long)(e[i].key & 0xffffffffu) + 1;
        if (j - i == 1)
            rc = pfsph_fail(err, PFSPH_EINPUT, "%s: edge %lu-%lu is open (used by triangle %lu only)", source, va, vb,
                            (unsigned long)e[i].tri + 1);
        else if (j - i > 2)
            rc = pfsph_fail(err, PFSPH_EINPUT, "%s: edge %lu-%lu is non-manifold (shared by %zu triangles)", source, va,
                            vb, j - i);
        else if (e[i].fwd == e[i + 1].fwd)
            rc = pfsph_fail(err, PFSPH_EINPUT,
                            "%s: triangles %lu and %lu have inconsistent orientation across "
                            "edge %lu-%lu",
                            source, (unsigned long)e[i].tri + 1, (unsigned long)e[i + 1].tri + 1, va, vb);
        i = j;
    }
    free(e);
    if (rc) return rc;

    double vol = signed_volume(m, ref);
    if (!isfinite(vol) || fabs(vol) <= 1e-12 * diag2 * sqrt(diag2))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: mesh encloses zero volume (%.3g)", source, vol);
    if (vol < 0) /* inside out: flip every triangle */
        for (size_t t = 0; t < m->ntris; t++) {
            uint32_t tmp = m->tri[3 * t + 1];
            m->tri[3 * t + 1] = m->tri[3 * t + 2];
            m->tri[3 * t + 2] = tmp;
        }
    return PFSPH_OK;
}

/* ---------------------------------------------------------------------------------------- */
/* Mass properties: D. Eberly, "Polyhedral Mass Properties (Revisited)", Geometric Tools 2002
 * (the triangle-mesh form of Mirtich 1996): volume integrals of 1, x, y, z, x^2, y^2, z^2,
 * xy, yz, zx turned into surface integrals by the divergence theorem, exact for polyhedra. */

static void eberly_sub(double w0, double w1, double w2, double *f1, double *f2, double *f3, double *g0, double *g1,
                       double *g2)
{
    double t0 = w0 + w1, t1 = w0 * w0, t2 = t1 + w1 * t0;
    *f1 = t0 + w2;
    *f2 = t2 + w2 * *f1;
    *f3 = w0 * t1 + w1 * t2 + w2 * *f2;
    *g0 = *f2 + w0 * (*f1 + w0);
    *g1 = *f2 + w1 * (*f1 + w1);
    *g2 = *f2 + w2 * (*f1 + w2);
}

void pfsph_mesh_mass_properties(const pfsph_mesh *m, double *volume, double com[3], double inertia[9])
{
    double ref[3] = {0, 0, 0}, lo[3], hi[3];
    /* integrate about the bounding-box centre: far-off meshes keep their precision */
    if (m && m->ntris && pfsph_mesh_bounds(m, lo, hi) == 0)
        for (int a = 0; a < 3; a++) ref[a] = 0.5 * (lo[a] + hi[a]);
    double in[10] = {0};
    for (size_t t = 0; m && t < m->ntris; t++) {
        const uint32_t *ti = m->tri + 3 * t;
        if (ti[0] >= m->nverts || ti[1] >= m->nverts || ti[2] >= m->nverts) continue;
        double p0[3], p1[3], p2[3];
        vec3_sub(m->v + 3 * (size_t)ti[0], ref, p0);
        vec3_sub(m->v + 3 * (size_t)ti[1], ref, p1);
        vec3_sub(m->v + 3 * (size_t)ti[2], ref, p2);
        double a1 = p1[0] - p0[0], b1 = p1[1] - p0[1], c1 = p1[2] - p0[2];
        double a2 = p2[0] - p0[0], b2 = p2[1] - p0[1], c2 = p2[2] - p0[2];
        double d0 = b1 * c2 - b2 * c1, d1 = a2 * c1 - a1 * c2, d2 = a1 * b2 - a2 * b1;
        double f1x, f2x, f3x, g0x, g1x, g2x, f1y, f2y, f3y, g0y, g1y, g2y, f1z, f2z, f3z, g0z, g1z, g2z;
        eberly_sub(p0[0], p1[0], p2[0], &f1x, &f2x, &f3x, &g0x, &g1x, &g2x);
        eberly_sub(p0[1], p1[1], p2[1], &f1y, &f2y, &f3y, &g0y, &g1y, &g2y);
        eberly_sub(p0[2], p1[2], p2[2], &f1z, &f2z, &f3z, &g0z, &g1z, &g2z);
        in[0] += d0 * f1x;
        in[1] += d0 * f2x;
        in[2] += d1 * f2y;
        in[3] += d2 * f2z;
        in[4] += d0 * f3x;
        in[5] += d1 * f3y;
        in[6] += d2 * f3z;
        in[7] += d0 * (p0[1] * g0x + p1[1] * g1x + p2[1] * g2x);
        in[8] += d1 * (p0[2] * g0y + p1[2] * g1y + p2[2] * g2y);
        in[9] += d2 * (p0[0] * g0z + p1[0] * g1z + p2[0] * g2z);
    }
    static const double mult[10] = {1.0 / 6,  1.0 / 24, 1.0 / 24,  1.0 / 24,  1.0 / 60,
                                    1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
    for (int i = 0; i < 10; i++) in[i] *= mult[i];
    double vol = in[0], c[3] = {0, 0, 0};
    if (vol != 0)
        for (int a = 0; a < 3; a++) c[a] = in[1 + a] / vol;
    if (volume) *volume = vol;
    if (com)
        for (int a = 0; a < 3; a++) com[a] = ref[a] + c[a];
    if (inertia) {
        /* second moments about the reference point, shifted to the centre of mass
         * (parallel-axis theorem); the tensor does not depend on where we integrated */
        double xx = in[4] - vol * c[0] * c[0], yy = in[5] - vol * c[1] * c[1], zz = in[6] - vol * c[2] * c[2];
        double xy = in[7] - vol * c[0] * c[1], yz = in[8] - vol * c[1] * c[2], zx = in[9] - vol * c[2] * c[0];
        inertia[0] = yy + zz;
        inertia[4] = zz + xx;
        inertia[8] = xx + yy;
        inertia[1] = inertia[3] = -xy;
        inertia[5] = inertia[7] = -yz;
        inertia[2] = inertia[6] = -zx;
    }
}

/* ---------------------------------------------------------------------------------------- */
/* Copies and rigid transforms */

void pfsph_mesh_transform(pfsph_mesh *m, double s, const double R[9], const double t[3])
{
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (!R) R = I;
    for (size_t i = 0; i < m->nverts; i++) {
        double *p = m->v + 3 * i, q[3];
        for (int a = 0; a < 3; a++)
            q[a] = s * (R[3 * a] * p[0] + R[3 * a + 1] * p[1] + R[3 * a + 2] * p[2]) + (t ? t[a] : 0.0);
        memcpy(p, q, sizeof q);
    }
    /* a mirroring transform (s^3 det R < 0) would turn the surface inside out: re-orient */
    double det =
        R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) + R[2] * (R[3] * R[7] - R[4] * R[6]);
    if (s * s * s * det < 0)
        for (size_t k = 0; k < m->ntris; k++) {
            uint32_t tmp = m->tri[3 * k + 1];
            m->tri[3 * k + 1] = m->tri[3 * k + 2];
            m->tri[3 * k + 2] = tmp;
        }
}

int pfsph_mesh_copy(pfsph_mesh *dst, const pfsph_mesh *src)
{
    int rc = pfsph__mesh_alloc(dst, src->nverts, src->ntris);
    if (rc) return rc;
    if (src->nverts) memcpy(dst->v, src->v, 3 * src->nverts * sizeof(double));
    if (src->ntris) memcpy(dst->tri, src->tri, 3 * src->ntris * sizeof(uint32_t));
    return PFSPH_OK;
}
