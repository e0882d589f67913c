/* The OBJ reader of closed meshes (mesh.h): defensive, for any bytes (tests/fuzz/fuzz_obj.c), with
 * bounded memory and messages that name the file and line. */
#include "pfsph/mesh.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/mesh_internal.h"

#define MESH_MAX_FILE ((size_t)1 << 30)

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
