/* Closed triangle meshes (mesh.h): a defensive OBJ reader, closedness/orientation checks,
 * exact polyhedral mass properties, deterministic surface sampling and primitive shapes. */
#include "pfsph/mesh.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Limits that keep any input (including fuzzed bytes) within a bounded amount of memory. */
#define MESH_MAX_TRIS 10000000u
#define MESH_MAX_VERTS 10000000u
#define MESH_MAX_FILE ((size_t)1 << 30)
#define SAMPLE_MAX ((size_t)20000000u)
#define MESH_PI 3.14159265358979323846

/* Sampling parameters, in units of the spacing s (docs/meshes.md explains the choice):
 * samples on sharp edges are kept if no sample lies within R_EDGE, samples of the per-triangle
 * lattice (step STEP_STRUCT, scanned row by row) if none lies within R_STRUCT; the fill pass
 * then puts a sample at the centre of every hole wider than R_FILL, found on a candidate
 * lattice of step FILL_STEP, so that no surface point is farther than R_FILL + FILL_STEP
 * (0.74 s) from a sample and no two samples are closer than min(R_EDGE, R_STRUCT, R_FILL). */
#define R_EDGE 0.75
#define R_STRUCT 0.9
#define STEP_STRUCT 0.2
#define R_FILL 0.68
#define FILL_STEP 0.06
#define SHARP_DEG 30.0

void pfsph_mesh_free(pfsph_mesh *m)
{
    if (!m) return;
    free(m->v);
    free(m->tri);
    m->v = NULL;
    m->tri = NULL;
    m->nverts = m->ntris = 0;
}

/* ---------------------------------------------------------------------------------------- */
/* OBJ reader */

typedef struct {
    const char *src;
    size_t line;
    pfsph_error *err;
    double *v;
    size_t nv, capv;
    uint32_t *t;
    size_t nt, capt;
} obj_ctx;

static int is_blank(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

/* Copy a token into a printable, bounded form for messages (NUL and control bytes as '?'). */
static void printable(char *dst, size_t cap, const char *s, size_t n)
{
    size_t k = 0;
    for (size_t i = 0; i < n && k + 4 < cap; i++) {
        unsigned char c = (unsigned char)s[i];
        dst[k++] = (c >= 32 && c < 127) ? (char)c : '?';
    }
    if (n > k && k + 4 <= cap) {
        dst[k++] = '.';
        dst[k++] = '.';
        dst[k++] = '.';
    }
    dst[k] = 0;
}

static int obj_fail(obj_ctx *c, const char *reason)
{
    return pfsph_fail(c->err, PFSPH_EINPUT, "%s:%zu: %s", c->src, c->line, reason);
}

/* Grow an array to hold `need` elements of `size` bytes; the caps keep need * size small. */
static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap) return 0;
    size_t nc = *cap ? *cap : 64;
    while (nc < need) nc *= 2;
    void *np = realloc(*p, nc * size);
    if (!np) return -1;
    *p = np;
    *cap = nc;
    return 0;
}

/* Parse one number token [s, s+n) completely; strtod needs a NUL-terminated copy. */
static int parse_double(const char *s, size_t n, double *out)
{
    char buf[128];
    if (n == 0 || n >= sizeof buf) return -1;
    memcpy(buf, s, n);
    buf[n] = 0;
    if (memchr(buf, 0, n)) return -1; /* an embedded NUL byte */
    char *end;
    *out = strtod(buf, &end);
    return end == buf + n ? 0 : -1;
}

/* An optionally signed decimal integer filling [s, s+n); saturates instead of overflowing.
 * Returns 0 and the value, or -1 when the text is not an integer. */
static int parse_int(const char *s, size_t n, long long *out)
{
    size_t i = 0;
    int neg = 0;
    if (i < n && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
    if (i == n) return -1;
    long long v = 0;
    for (; i < n; i++) {
        if (s[i] < '0' || s[i] > '9') return -1;
        if (v < 1000000000000LL) v = v * 10 + (s[i] - '0'); /* saturate far above any cap */
    }
    *out = neg ? -v : v;
    return 0;
}

/* Next blank-separated token of the line [*p, end). */
static int next_token(const char **p, const char *end, const char **tok, size_t *n)
{
    const char *q = *p;
    while (q < end && is_blank(*q)) q++;
    if (q == end) {
        *p = q;
        return 0;
    }
    const char *b = q;
    while (q < end && !is_blank(*q)) q++;
    *tok = b;
    *n = (size_t)(q - b);
    *p = q;
    return 1;
}

static int obj_vertex(obj_ctx *c, const char *p, const char *end)
{
    double x[7];
    int k = 0;
    const char *tok;
    size_t n;
    while (next_token(&p, end, &tok, &n)) {
        if (k == 7) return obj_fail(c, "expected 3 numbers after 'v'");
        if (parse_double(tok, n, &x[k])) {
            char buf[48], msg[96];
            printable(buf, sizeof buf, tok, n);
            snprintf(msg, sizeof msg, "bad number '%s' after 'v'", buf);
            return obj_fail(c, msg);
        }
        k++;
    }
    /* x y z, x y z w (w must be 1: no rational vertices) or x y z r g b (colours ignored) */
    if (k != 3 && k != 4 && k != 6) return obj_fail(c, "expected 3 numbers after 'v'");
    if (k == 4 && x[3] != 1.0) return obj_fail(c, "vertex weight w other than 1 is not supported");
    for (int a = 0; a < 3; a++)
        if (!isfinite(x[a])) return obj_fail(c, "vertex coordinate is not finite");
    if (c->nv >= MESH_MAX_VERTS) return obj_fail(c, "more than 10000000 vertices");
    if (grow((void **)&c->v, &c->capv, 3 * (c->nv + 1), sizeof(double)))
        return pfsph_fail(c->err, PFSPH_ENOMEM, "%s:%zu: out of memory", c->src, c->line);
    memcpy(c->v + 3 * c->nv, x, sizeof(double) * 3);
    c->nv++;
    return 0;
}

/* One face vertex: i, i/t, i//n or i/t/n (t and n are checked for syntax, then ignored). */
static int obj_face_ref(obj_ctx *c, const char *tok, size_t n, uint32_t *idx)
{
    const char *s1 = memchr(tok, '/', n);
    size_t ni = s1 ? (size_t)(s1 - tok) : n;
    char buf[48], msg[160];
    long long v;
    if (parse_int(tok, ni, &v)) {
        printable(buf, sizeof buf, tok, n);
        snprintf(msg, sizeof msg, "bad face vertex '%s'", buf);
        return obj_fail(c, msg);
    }
    if (s1) { /* the /t, //n or /t/n tail */
        const char *r = s1 + 1, *e = tok + n;
        const char *s2 = memchr(r, '/', (size_t)(e - r));
        long long dummy;
        int bad = 0;
        if (s2) {
            if (s2 > r && parse_int(r, (size_t)(s2 - r), &dummy)) bad = 1;
            if (parse_int(s2 + 1, (size_t)(e - s2 - 1), &dummy)) bad = 1;
        } else if (parse_int(r, (size_t)(e - r), &dummy)) {
            bad = 1;
        }
        if (bad) {
            printable(buf, sizeof buf, tok, n);
            snprintf(msg, sizeof msg, "bad face vertex '%s'", buf);
            return obj_fail(c, msg);
        }
    }
    long long nv = (long long)c->nv;
    long long r = v > 0 ? v - 1 : nv + v; /* negative: relative to the vertices so far */
    if (v == 0 || r < 0 || r >= nv) {
        printable(buf, sizeof buf, tok, ni);
        snprintf(msg, sizeof msg, "face index %s out of range (%zu vertices)", buf, c->nv);
        return obj_fail(c, msg);
    }
    *idx = (uint32_t)r;
    return 0;
}

static int obj_face(obj_ctx *c, const char *p, const char *end)
{
    const char *tok;
    size_t n;
    uint32_t first = 0, prev = 0;
    size_t k = 0;
    while (next_token(&p, end, &tok, &n)) {
        uint32_t idx = 0;
        int rc = obj_face_ref(c, tok, n, &idx);
        if (rc) return rc;
        if (k == 0) first = idx;
        if (k >= 2) { /* fan triangulation: (v0, v_{k-1}, v_k) */
            if (c->nt >= MESH_MAX_TRIS) return obj_fail(c, "more than 10000000 triangles");
            if (grow((void **)&c->t, &c->capt, 3 * (c->nt + 1), sizeof(uint32_t)))
                return pfsph_fail(c->err, PFSPH_ENOMEM, "%s:%zu: out of memory", c->src, c->line);
            uint32_t *t = c->t + 3 * c->nt++;
            t[0] = first;
            t[1] = prev;
            t[2] = idx;
        }
        prev = idx;
        k++;
    }
    if (k < 3) return obj_fail(c, "a face needs at least 3 vertices");
    return 0;
}

int pfsph_mesh_parse_obj(pfsph_mesh *m, const char *text, size_t len, const char *source, pfsph_error *err)
{
    memset(m, 0, sizeof *m);
    if (!source) source = "obj";
    obj_ctx c = {.src = source, .line = 0, .err = err};
    const char *p = text, *end = text ? text + len : text;
    int rc = 0;
    while (p < end && !rc) {
        /* a line ends at \n, \r\n or a lone \r */
        const char *e = p;
        while (e < end && *e != '\n' && *e != '\r') e++;
        c.line++;
        const char *q = p, *tok;
        size_t n;
        if (next_token(&q, e, &tok, &n) && tok[0] != '#') {
            if (n == 1 && tok[0] == 'v') rc = obj_vertex(&c, q, e);
            else if (n == 1 && tok[0] == 'f') rc = obj_face(&c, q, e);
            /* everything else (vt, vn, o, g, s, usemtl, mtllib, l, p, ...) is ignored */
        }
        if (e < end && *e == '\r' && e + 1 < end && e[1] == '\n') e++;
        p = e < end ? e + 1 : end;
    }
    if (!rc && c.nt == 0) rc = pfsph_fail(err, PFSPH_EINPUT, "%s:%zu: no faces (empty mesh)", source, c.line);
    if (rc) {
        free(c.v);
        free(c.t);
        return rc;
    }
    /* shrink to fit; failure to shrink is harmless */
    double *v = realloc(c.v, 3 * c.nv * sizeof(double));
    uint32_t *t = realloc(c.t, 3 * c.nt * sizeof(uint32_t));
    m->v = v ? v : c.v;
    m->tri = t ? t : c.t;
    m->nverts = c.nv;
    m->ntris = c.nt;
    return PFSPH_OK;
}

int pfsph_mesh_load_obj(pfsph_mesh *m, const char *path, pfsph_error *err)
{
    memset(m, 0, sizeof *m);
    FILE *f = fopen(path, "rb");
    if (!f) return pfsph_fail(err, PFSPH_EINPUT, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fileno(f), &sb) == 0 && !S_ISREG(sb.st_mode)) {
        fclose(f);
        return pfsph_fail(err, PFSPH_EINPUT, "%s: %s, not an OBJ file", path,
                          S_ISDIR(sb.st_mode) ? "is a directory" : "is not a regular file");
    }
    size_t cap = 1 << 16, n = 0, r;
    char *buf = malloc(cap);
    int rc = PFSPH_OK;
    while (buf && (r = fread(buf + n, 1, cap - n, f)) > 0) {
        n += r;
        if (n == cap) {
            if (cap >= MESH_MAX_FILE) {
                rc = pfsph_fail(err, PFSPH_EINPUT, "%s: file larger than 1 GiB", path);
                break;
            }
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
            cap *= 2;
        }
    }
    if (!buf) rc = pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory reading the file", path);
    else if (!rc && ferror(f)) rc = pfsph_fail(err, PFSPH_EINPUT, "%s: cannot read: %s", path, strerror(errno));
    fclose(f);
    if (!rc) rc = pfsph_mesh_parse_obj(m, buf, n, path, err);
    free(buf);
    return rc;
}

/* ---------------------------------------------------------------------------------------- */
/* Geometry helpers */

static void sub3(const double *a, const double *b, double *o)
{
    o[0] = a[0] - b[0];
    o[1] = a[1] - b[1];
    o[2] = a[2] - b[2];
}
static void cross3(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

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

typedef struct {
    uint64_t key; /* (min vertex << 32) | max vertex */
    uint32_t tri;
    uint32_t fwd; /* 1 when the triangle runs min -> max */
} edge_rec;

static int cmp_edge(const void *a, const void *b)
{
    const edge_rec *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->tri > y->tri) - (x->tri < y->tri);
}

/* Signed volume (divergence theorem, relative to `ref` for precision). */
static double signed_volume(const pfsph_mesh *m, const double ref[3])
{
    double vol = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        double a[3], b[3], c[3], n[3];
        sub3(m->v + 3 * (size_t)m->tri[3 * t], ref, a);
        sub3(m->v + 3 * (size_t)m->tri[3 * t + 1], ref, b);
        sub3(m->v + 3 * (size_t)m->tri[3 * t + 2], ref, c);
        cross3(b, c, n);
        vol += dot3(a, n);
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
    double diag2 = dot3(d, d);
    /* the volume test below cubes the size: refuse sizes whose powers overflow */
    if (!(diag2 > 0) || !isfinite(diag2 * sqrt(diag2) * 1e3))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: mesh extent is zero or too large", source);

    /* degenerate triangles: area below 1e-12 diag^2 (also catches repeated vertices) */
    for (size_t t = 0; t < m->ntris; t++) {
        const uint32_t *ti = m->tri + 3 * t;
        double e1[3], e2[3], n[3];
        sub3(m->v + 3 * (size_t)ti[1], m->v + 3 * (size_t)ti[0], e1);
        sub3(m->v + 3 * (size_t)ti[2], m->v + 3 * (size_t)ti[0], e2);
        cross3(e1, e2, n);
        double area = 0.5 * sqrt(dot3(n, n));
        if (!(area >= 1e-12 * diag2))
            return pfsph_fail(err, PFSPH_EINPUT, "%s: triangle %zu (vertices %lu %lu %lu) is degenerate (area %.3g)",
                              source, t + 1, (unsigned long)ti[0] + 1, (unsigned long)ti[1] + 1,
                              (unsigned long)ti[2] + 1, area);
    }

    /* edges: sort the 3n directed edges by undirected key, O(n log n) */
    size_t ne = 3 * m->ntris;
    edge_rec *e = malloc(ne * sizeof *e);
    if (!e) return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory checking edges", source);
    for (size_t t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            edge_rec *r = e + 3 * t + k;
            r->key = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            r->tri = (uint32_t)t;
            r->fwd = a < b;
        }
    qsort(e, ne, sizeof *e, cmp_edge);
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
        sub3(m->v + 3 * (size_t)ti[0], ref, p0);
        sub3(m->v + 3 * (size_t)ti[1], ref, p1);
        sub3(m->v + 3 * (size_t)ti[2], ref, p2);
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
/* Surface sampling: samples live in a hash grid (cells of twice every query radius, so a
 * query looks at 8 cells); a candidate becomes a sample only if no sample is nearer than the
 * phase's radius, which bounds the minimum distance, and a final pass over a fine candidate
 * lattice fills every gap, which bounds the largest hole. Deterministic: no random numbers. */

typedef struct {
    int32_t c[3];
    uint32_t head; /* UINT32_MAX: empty slot */
} cell_slot;

typedef struct {
    double *p;
    uint32_t *next;
    size_t n, cap;
    cell_slot *tab;
    size_t tabsize, used; /* power of two; occupied slots */
    double lo[3], inv_cell;
    pfsph_error *err;
} sampler;

static size_t cell_hash(const int32_t c[3])
{
    uint64_t h = (uint64_t)(uint32_t)c[0] * 0x9E3779B97F4A7C15ULL;
    h ^= (uint64_t)(uint32_t)c[1] * 0xC2B2AE3D27D4EB4FULL;
    h ^= (uint64_t)(uint32_t)c[2] * 0x165667B19E3779F9ULL;
    h ^= h >> 29;
    return (size_t)h;
}

static void cell_of(const sampler *s, const double *p, int32_t c[3])
{
    for (int a = 0; a < 3; a++) c[a] = (int32_t)floor((p[a] - s->lo[a]) * s->inv_cell);
}

static cell_slot *find_slot(cell_slot *tab, size_t size, const int32_t c[3])
{
    size_t mask = size - 1, i = cell_hash(c) & mask;
    while (tab[i].head != UINT32_MAX && (tab[i].c[0] != c[0] || tab[i].c[1] != c[1] || tab[i].c[2] != c[2]))
        i = (i + 1) & mask;
    return tab + i;
}

static int rehash(sampler *s, size_t size)
{
    cell_slot *t = malloc(size * sizeof *t);
    if (!t) return -1;
    for (size_t i = 0; i < size; i++) t[i].head = UINT32_MAX;
    for (size_t i = 0; i < s->tabsize; i++)
        if (s->tab[i].head != UINT32_MAX) *find_slot(t, size, s->tab[i].c) = s->tab[i];
    free(s->tab);
    s->tab = t;
    s->tabsize = size;
    return 0;
}

/* The 2 x 2 x 2 cells that hold every point within half a cell of p: cells are twice the
 * largest query radius, so 8 lookups replace the 27 that cells of one radius would need. */
static void query_cells(const sampler *s, const double *p, int32_t c0[3])
{
    for (int a = 0; a < 3; a++) {
        double x = (p[a] - s->lo[a]) * s->inv_cell, f = floor(x);
        c0[a] = (int32_t)f - (x - f < 0.5);
    }
}

/* Is there a sample with squared distance below r2 from p? */
static int near_sample(const sampler *s, const double *p, double r2)
{
    int32_t c[3], q[3];
    query_cells(s, p, c);
    for (int k = 0; k < 8; k++) {
        q[0] = c[0] + (k & 1);
        q[1] = c[1] + (k >> 1 & 1);
        q[2] = c[2] + (k >> 2);
        const cell_slot *sl = find_slot(s->tab, s->tabsize, q);
        for (uint32_t j = sl->head; j != UINT32_MAX; j = s->next[j]) {
            const double *o = s->p + 3 * (size_t)j;
            double ex = o[0] - p[0], ey = o[1] - p[1], ez = o[2] - p[2];
            if (ex * ex + ey * ey + ez * ez < r2) return 1;
        }
    }
    return 0;
}

/* Add p unless a sample is nearer than sqrt(r2). Returns 0, or an error code. */
static int offer(sampler *s, const double *p, double r2)
{
    if (near_sample(s, p, r2)) return 0;
    if (s->n >= SAMPLE_MAX)
        return pfsph_fail(s->err, PFSPH_EINPUT, "spacing too small: more than %zu samples", SAMPLE_MAX);
    if (s->n == s->cap) {
        size_t nc = s->cap ? 2 * s->cap : 1024;
        double *np = realloc(s->p, 3 * nc * sizeof(double));
        if (!np) return pfsph_fail(s->err, PFSPH_ENOMEM, "out of memory sampling the surface");
        s->p = np;
        uint32_t *nn = realloc(s->next, nc * sizeof(uint32_t));
        if (!nn) return pfsph_fail(s->err, PFSPH_ENOMEM, "out of memory sampling the surface");
        s->next = nn;
        s->cap = nc;
    }
    if (2 * (s->used + 1) > s->tabsize && rehash(s, 2 * s->tabsize))
        return pfsph_fail(s->err, PFSPH_ENOMEM, "out of memory sampling the surface");
    int32_t c[3];
    cell_of(s, p, c);
    cell_slot *sl = find_slot(s->tab, s->tabsize, c);
    if (sl->head == UINT32_MAX) {
        sl->c[0] = c[0];
        sl->c[1] = c[1];
        sl->c[2] = c[2];
        s->used++;
    }
    memcpy(s->p + 3 * s->n, p, 3 * sizeof(double));
    s->next[s->n] = sl->head;
    sl->head = (uint32_t)s->n;
    s->n++;
    return 0;
}

/* Distance from p to the nearest sample, or `cap` (<= half a cell) if none is nearer. */
static double nearest_sample(const sampler *s, const double *p, double cap)
{
    int32_t c[3], q[3];
    double best = cap * cap;
    query_cells(s, p, c);
    for (int k = 0; k < 8; k++) {
        q[0] = c[0] + (k & 1);
        q[1] = c[1] + (k >> 1 & 1);
        q[2] = c[2] + (k >> 2);
        const cell_slot *sl = find_slot(s->tab, s->tabsize, q);
        for (uint32_t j = sl->head; j != UINT32_MAX; j = s->next[j]) {
            const double *o = s->p + 3 * (size_t)j;
            double ex = o[0] - p[0], ey = o[1] - p[1], ez = o[2] - p[2];
            double d2 = ex * ex + ey * ey + ez * ez;
            if (d2 < best) best = d2;
        }
    }
    return sqrt(best);
}

/* Max-heap of hole candidates keyed by distance to the nearest sample (ties: earlier first,
 * so the result does not depend on the heap's internal order). */
typedef struct {
    double d, p[3];
    size_t seq;
} hole;

typedef struct {
    hole *h;
    size_t n, cap;
} hole_heap;

static int hole_above(const hole *a, const hole *b) { return a->d > b->d || (a->d == b->d && a->seq < b->seq); }

static int heap_push(hole_heap *hp, const hole *x)
{
    if (hp->n == hp->cap) {
        size_t nc = hp->cap ? 2 * hp->cap : 1024;
        hole *nh = realloc(hp->h, nc * sizeof *nh);
        if (!nh) return -1;
        hp->h = nh;
        hp->cap = nc;
    }
    size_t i = hp->n++;
    while (i > 0 && hole_above(x, &hp->h[(i - 1) / 2])) {
        hp->h[i] = hp->h[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    hp->h[i] = *x;
    return 0;
}

static hole heap_pop(hole_heap *hp)
{
    hole top = hp->h[0], last = hp->h[--hp->n];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= hp->n) break;
        if (c + 1 < hp->n && hole_above(&hp->h[c + 1], &hp->h[c])) c++;
        if (!hole_above(&hp->h[c], &last)) break;
        hp->h[i] = hp->h[c];
        i = c;
    }
    if (hp->n) hp->h[i] = last;
    return top;
}

/* Fill-pass candidates of one segment or triangle go to the heap when they lie farther than
 * `thr` from every sample. */
typedef struct {
    sampler *s;
    hole_heap *hp;
    double thr, cap;
    size_t seq;
} hole_scan;

static int scan_point(hole_scan *hs, const double *p, double *dist)
{
    double d = nearest_sample(hs->s, p, hs->cap);
    *dist = d;
    if (d <= hs->thr) return 0;
    hole h = {.d = d, .p = {p[0], p[1], p[2]}, .seq = hs->seq++};
    return heap_push(hs->hp, &h) ? pfsph_fail(hs->s->err, PFSPH_ENOMEM, "out of memory sampling the surface") : 0;
}

/* Points along the segment a-b at steps of at most `step` (endpoints excluded). */
static int offer_edge(sampler *s, const double *a, const double *b, double step, double r2, hole_scan *hs)
{
    double d[3];
    sub3(b, a, d);
    double len = sqrt(dot3(d, d));
    size_t k = (size_t)ceil(len / step); /* bounded by the size check in the caller */
    for (size_t i = 1; i < k; i++) {
        double t = (double)i / (double)k, p[3];
        for (int a2 = 0; a2 < 3; a2++) p[a2] = a[a2] + t * d[a2];
        int rc;
        if (hs) {
            /* the next candidates within thr - dist of p are covered by p's nearest sample */
            double dist;
            rc = scan_point(hs, p, &dist);
            if (dist < hs->thr) i += (size_t)((hs->thr - dist) / (len / (double)k));
        } else {
            rc = offer(s, p, r2);
        }
        if (rc) return rc;
    }
    return 0;
}

/* A hex lattice of the given step over the triangle (rows parallel to its longest edge),
 * keeping points at least `margin` from every edge. */
static int offer_lattice(sampler *s, const double *P0, const double *P1, const double *P2, double step, double margin,
                         double r2, hole_scan *hs)
{
    const double *P[3] = {P0, P1, P2};
    double len2[3];
    for (int k = 0; k < 3; k++) {
        double d[3];
        sub3(P[(k + 1) % 3], P[k], d);
        len2[k] = dot3(d, d);
    }
    int b = 0; /* base edge: P[b] -> P[b+1], the longest */
    if (len2[1] > len2[b]) b = 1;
    if (len2[2] > len2[b]) b = 2;
    const double *A = P[b], *B = P[(b + 1) % 3], *C = P[(b + 2) % 3];
    double u[3], w[3], nrm[3], v[3];
    sub3(B, A, u);
    sub3(C, A, w);
    double L = sqrt(dot3(u, u));
    cross3(u, w, nrm);
    double nn = sqrt(dot3(nrm, nrm));
    if (!(L > 0) || !(nn > 0)) return 0;
    double H = nn / L; /* height over the base */
    if (H <= 2 * margin) return 0;
    for (int a = 0; a < 3; a++) u[a] /= L;
    cross3(nrm, u, v); /* in-plane, towards C */
    for (int a = 0; a < 3; a++) v[a] /= nn;
    double cx = dot3(w, u); /* C at (cx, H) in the (u, v) frame */
    /* distance of (x, y) to the left edge A-C and the right edge B-C */
    double lenl = sqrt(cx * cx + H * H), lenr = sqrt((L - cx) * (L - cx) + H * H);
    double rowh = step * 0.8660254037844386;
    size_t nrows = (size_t)ceil((H - margin) / rowh);
    for (size_t j = 1; j <= nrows; j++) {
        double y = (double)j * rowh;
        if (y > H - margin) break;
        /* x range from the two slanted edges, widened by their slope for the margin */
        double xl = cx * y / H + margin * lenl / H, xr = L + (cx - L) * y / H - margin * lenr / H;
        if (xr < xl) continue;
        double off = (j & 1) ? 0.5 * step : 0.0;
        double i0 = ceil((xl - off) / step), i1 = floor((xr - off) / step);
        if (!(i1 >= i0)) continue;
        size_t cnt = (size_t)(i1 - i0 + 1.0); /* <= L / step, bounded by the size guard */
        for (size_t i = 0; i < cnt; i++) {
            double x = off + (i0 + (double)i) * step, p[3];
            for (int a = 0; a < 3; a++) p[a] = A[a] + x * u[a] + y * v[a];
            int rc;
            if (hs) { /* skip what p's nearest sample provably covers (see offer_edge) */
                double dist;
                rc = scan_point(hs, p, &dist);
                if (dist < hs->thr) i += (size_t)((hs->thr - dist) / step);
            } else {
                rc = offer(s, p, r2);
            }
            if (rc) return rc;
        }
    }
    return 0;
}

/* Flag each triangle edge (3 t + k: from corner k to k+1) as sharp: a crease whose dihedral
 * angle exceeds SHARP_DEG, or an open or non-manifold edge. Sharp edges and their vertices get
 * samples of their own so corners and creases are represented exactly; smooth edges get none,
 * which keeps a curved surface from growing extra lines of samples along its edges. */
static int sharp_edges(const pfsph_mesh *m, unsigned char *sharp)
{
    size_t ne = 3 * m->ntris;
    edge_rec *e = malloc(ne * sizeof *e);
    double *nrm = malloc(3 * m->ntris * sizeof(double));
    if (!e || !nrm) {
        free(e);
        free(nrm);
        return -1;
    }
    for (size_t t = 0; t < m->ntris; t++) {
        double e1[3], e2[3], *n = nrm + 3 * t;
        sub3(m->v + 3 * (size_t)m->tri[3 * t + 1], m->v + 3 * (size_t)m->tri[3 * t], e1);
        sub3(m->v + 3 * (size_t)m->tri[3 * t + 2], m->v + 3 * (size_t)m->tri[3 * t], e2);
        cross3(e1, e2, n);
        double l = sqrt(dot3(n, n));
        for (int a = 0; a < 3; a++) n[a] = l > 0 ? n[a] / l : 0;
        for (int k = 0; k < 3; k++) {
            uint32_t va = m->tri[3 * t + k], vb = m->tri[3 * t + (k + 1) % 3];
            edge_rec *r = e + 3 * t + k;
            r->key = va < vb ? ((uint64_t)va << 32 | vb) : ((uint64_t)vb << 32 | va);
            r->tri = (uint32_t)t;
            r->fwd = (uint32_t)k; /* here: which edge of the triangle */
        }
    }
    qsort(e, ne, sizeof *e, cmp_edge);
    const double cos_sharp = cos(SHARP_DEG * MESH_PI / 180);
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].key == e[i].key) j++;
        int sh = 1;
        if (j - i == 2) sh = dot3(nrm + 3 * (size_t)e[i].tri, nrm + 3 * (size_t)e[i + 1].tri) < cos_sharp;
        for (size_t k = i; k < j; k++) sharp[3 * (size_t)e[k].tri + e[k].fwd] = (unsigned char)sh;
        i = j;
    }
    free(e);
    free(nrm);
    return 0;
}

int pfsph_mesh_sample_surface(const pfsph_mesh *m, double spacing, double **pts, size_t *n, pfsph_error *err)
{
    *pts = NULL;
    *n = 0;
    if (!(spacing > 0) || !isfinite(spacing))
        return pfsph_fail(err, PFSPH_EINPUT, "sampling spacing %g must be positive and finite", spacing);
    if (!m || m->ntris == 0) return pfsph_fail(err, PFSPH_EINPUT, "mesh has no triangles");
    if (m->ntris > MESH_MAX_TRIS) return pfsph_fail(err, PFSPH_EINPUT, "mesh too large");
    double lo[3], hi[3];
    if (pfsph_mesh_bounds(m, lo, hi))
        return pfsph_fail(err, PFSPH_EINPUT, "mesh has a non-finite vertex or a bad index");
    /* size guard before anything is allocated: every loop below is bounded by these */
    double area = 0, elen = 0, ext = 0;
    for (int a = 0; a < 3; a++) ext = fmax(ext, hi[a] - lo[a]);
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p0 = m->v + 3 * (size_t)m->tri[3 * t], *p1 = m->v + 3 * (size_t)m->tri[3 * t + 1],
                     *p2 = m->v + 3 * (size_t)m->tri[3 * t + 2];
        double e1[3], e2[3], e3[3], c[3];
        sub3(p1, p0, e1);
        sub3(p2, p0, e2);
        sub3(p2, p1, e3);
        cross3(e1, e2, c);
        area += 0.5 * sqrt(dot3(c, c));
        elen += sqrt(dot3(e1, e1)) + sqrt(dot3(e2, e2)) + sqrt(dot3(e3, e3));
    }
    double est = area / (spacing * spacing) + elen / spacing + (double)m->nverts;
    if (!isfinite(est) || est > 2e7 || ext / spacing > 1e7)
        return pfsph_fail(err, PFSPH_EINPUT, "spacing %g too small for a mesh of area %g (about %.3g samples)", spacing,
                          area, est);
    unsigned char *sharp = malloc(3 * m->ntris);
    if (!sharp || sharp_edges(m, sharp)) {
        free(sharp);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling the surface");
    }

    const double re = R_EDGE * spacing, ra = R_STRUCT * spacing, rf = R_FILL * spacing;
    const double rmax = fmax(re, fmax(ra, rf));
    sampler s = {.err = err, .inv_cell = 0.5 / rmax};
    for (int a = 0; a < 3; a++) s.lo[a] = lo[a] - 4 * rmax;
    int rc = rehash(&s, 1024) ? pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling") : 0;
    /* 1. ends of sharp edges (corners), 2. points along sharp edges at most one spacing apart
     * (kept if no sample within R_EDGE) */
    for (size_t i = 0; i < 3 * m->ntris && !rc; i++)
        if (sharp[i] || sharp[i - i % 3 + (i + 2) % 3]) rc = offer(&s, m->v + 3 * (size_t)m->tri[i], re * re);
    for (size_t i = 0; i < 3 * m->ntris && !rc; i++)
        if (sharp[i])
            rc = offer_edge(&s, m->v + 3 * (size_t)m->tri[i], m->v + 3 * (size_t)m->tri[i - i % 3 + (i + 1) % 3],
                            spacing, re * re, NULL);
    /* 3. each triangle's fine lattice in raster order, kept if no sample within R_STRUCT:
     * greedy in scan order this settles into nearly hexagonal rows about R_STRUCT apart */
    for (size_t t = 0; t < m->ntris && !rc; t++)
        rc = offer_lattice(&s, m->v + 3 * (size_t)m->tri[3 * t], m->v + 3 * (size_t)m->tri[3 * t + 1],
                           m->v + 3 * (size_t)m->tri[3 * t + 2], STEP_STRUCT * spacing, 0.0, ra * ra, NULL);
    /* 4. gap filling, farthest point first: every candidate of a lattice of step FILL_STEP
     * (covering each triangle up to its edges, covering radius <= FILL_STEP) farther than
     * R_FILL from all samples goes into a max-heap; the farthest becomes a sample (its key is
     * re-checked first, as new samples only shrink distances), until none is left. A sample
     * placed at the centre of each hole rather than at its rim keeps the count low; at the end
     * no candidate is farther than R_FILL, so no surface point is farther than
     * R_FILL + FILL_STEP, and every fill sample is at least R_FILL from the others. */
    const double fs = FILL_STEP * spacing;
    hole_heap hp = {0};
    hole_scan hs = {.s = &s, .hp = &hp, .thr = rf, .cap = rmax};
    for (size_t t = 0; t < m->ntris && !rc; t++) {
        const double *p0 = m->v + 3 * (size_t)m->tri[3 * t], *p1 = m->v + 3 * (size_t)m->tri[3 * t + 1],
                     *p2 = m->v + 3 * (size_t)m->tri[3 * t + 2];
        rc = offer_edge(&s, p0, p1, fs, 0, &hs);
        if (!rc) rc = offer_edge(&s, p1, p2, fs, 0, &hs);
        if (!rc) rc = offer_edge(&s, p2, p0, fs, 0, &hs);
        double d0;
        if (!rc) rc = scan_point(&hs, p0, &d0);
        if (!rc) rc = offer_lattice(&s, p0, p1, p2, fs, 0.0, 0, &hs);
    }
    while (!rc && hp.n) {
        hole h = heap_pop(&hp);
        double d = nearest_sample(&s, h.p, rmax);
        if (d <= rf) continue;
        if (d < h.d && hp.n && hole_above(&hp.h[0], &(hole){d, {0, 0, 0}, h.seq})) {
            h.d = d; /* stale key: back in at its true distance */
            if (heap_push(&hp, &h)) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory sampling the surface");
            continue;
        }
        rc = offer(&s, h.p, 0.0);
    }
    free(hp.h);
    free(sharp);
    free(s.tab);
    free(s.next);
    if (rc) {
        free(s.p);
        return rc;
    }
    double *shrunk = realloc(s.p, 3 * s.n * sizeof(double));
    *pts = shrunk ? shrunk : s.p;
    *n = s.n;
    return PFSPH_OK;
}

/* ---------------------------------------------------------------------------------------- */
/* Primitives */

static int mesh_alloc(pfsph_mesh *m, size_t nv, size_t nt)
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
    int rc = mesh_alloc(m, 8, 12);
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
    int rc = mesh_alloc(m, nv, nt);
    if (rc) return rc;
    double cv[12][3];
    for (int i = 0; i < 12; i++) {
        double p[3];
        for (int a = 0; a < 3; a++) p[a] = iv[i][a] * ((iv[i][a] != 0 && iv[i][(a + 1) % 3] == 0) ? gr : 1.0);
        double l = sqrt(dot3(p, p));
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
        double *p = m->v + 3 * i, l = sqrt(dot3(p, p));
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
    int rc = mesh_alloc(m, 2 * n + 2, 4 * n);
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
    int rc = mesh_alloc(dst, src->nverts, src->ntris);
    if (rc) return rc;
    if (src->nverts) memcpy(dst->v, src->v, 3 * src->nverts * sizeof(double));
    if (src->ntris) memcpy(dst->tri, src->tri, 3 * src->ntris * sizeof(uint32_t));
    return PFSPH_OK;
}
