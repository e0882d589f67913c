/* Houdini JSON geometry and binary JSON (hgeo.h). The document is Houdini's: a flat array of
 * keys and values (fileversion, pointcount, vertexcount, primitivecount, topology, attributes,
 * primitives); the binary form encodes the same tokens as SideFX's UT_JSONDefines.h describes
 * (token bytes, encoded lengths, uniform arrays). */
#include "io/hgeo.h"

#include <stdio.h>
#include <string.h>

#include "io/io_internal.h"

enum {
    J_ARR = 0x5b,
    J_ARR_END = 0x5d,
    J_MAP = 0x7b,
    J_MAP_END = 0x7d,
    J_INT32 = 0x13,
    J_INT64 = 0x14,
    J_REAL32 = 0x19,
    J_STRING = 0x27,
    J_FALSE = 0x30,
    J_UNIFORM = 0x40,
    J_MAGIC = 0x7f
};

/* the emitter: text JSON with commas where they belong, or bJSON tokens */
typedef struct jw {
    pfsph__enc *e;
    int bin;
    int depth;
    int first[64]; /* no value yet at this depth */
} jw;

static void sep(jw *w)
{
    if (w->bin) return;
    if (!w->first[w->depth]) pfsph__enc_put(w->e, ",", 1);
    w->first[w->depth] = 0;
}

static void tok(jw *w, uint8_t t) { pfsph__enc_put(w->e, &t, 1); }

/* an encoded length: < 0xf1 in one byte, else 0xf2/0xf4/0xf8 and 2/4/8 bytes */
static void enc_len(jw *w, uint64_t n)
{
    if (n < 0xf1) tok(w, (uint8_t)n);
    else if (n <= 0xffff) {
        uint16_t v = (uint16_t)n;
        tok(w, 0xf2);
        pfsph__enc_put(w->e, &v, 2);
    } else if (n <= 0xffffffffu) {
        uint32_t v = (uint32_t)n;
        tok(w, 0xf4);
        pfsph__enc_put(w->e, &v, 4);
    } else {
        tok(w, 0xf8);
        pfsph__enc_put(w->e, &n, 8);
    }
}

static void open_(jw *w, int map)
{
    sep(w);
    if (w->bin) tok(w, map ? J_MAP : J_ARR);
    else pfsph__enc_put(w->e, map ? "{" : "[", 1);
    w->first[++w->depth] = 1;
}

static void close_(jw *w, int map)
{
    w->depth--;
    if (w->bin) tok(w, map ? J_MAP_END : J_ARR_END);
    else pfsph__enc_put(w->e, map ? "}" : "]", 1);
}

static void str(jw *w, const char *s)
{
    sep(w);
    size_t n = strlen(s);
    if (w->bin) {
        tok(w, J_STRING);
        enc_len(w, n);
        pfsph__enc_put(w->e, s, n);
        return;
    }
    pfsph__enc_put(w->e, "\"", 1);
    for (const char *c = s; *c; c++) { /* names here are plain; escape what JSON needs */
        if (*c == '"' || *c == '\\') pfsph__enc_put(w->e, "\\", 1);
        if ((unsigned char)*c < 0x20) pfsph__enc_printf(w->e, "\\u%04x", (unsigned char)*c);
        else pfsph__enc_put(w->e, c, 1);
    }
    pfsph__enc_put(w->e, "\"", 1);
}

/* a map key: in text a string and a colon, no comma after */
static void key(jw *w, const char *k)
{
    str(w, k);
    if (!w->bin) {
        pfsph__enc_put(w->e, ":", 1);
        w->first[w->depth] = 1;
    }
}

static void int_(jw *w, int64_t v)
{
    sep(w);
    if (!w->bin) {
        pfsph__enc_printf(w->e, "%lld", (long long)v);
        return;
    }
    if (v >= INT32_MIN && v <= INT32_MAX) {
        int32_t x = (int32_t)v;
        tok(w, J_INT32);
        pfsph__enc_put(w->e, &x, 4);
    } else {
        tok(w, J_INT64);
        pfsph__enc_put(w->e, &v, 8);
    }
}

static void false_(jw *w)
{
    sep(w);
    if (w->bin) tok(w, J_FALSE);
    else pfsph__enc_put(w->e, "false", 5);
}

/* a uniform array of n floats (stride between tuples' first values: step) / of n int32 */
static void floats(jw *w, const float *v, size_t n, size_t step)
{
    if (w->bin) {
        sep(w);
        tok(w, J_UNIFORM);
        tok(w, J_REAL32);
        enc_len(w, n);
        for (size_t k = 0; k < n; k++) pfsph__enc_put(w->e, v + k * step, 4);
        return;
    }
    open_(w, 0);
    for (size_t k = 0; k < n; k++) {
        sep(w);
        pfsph__enc_printf(w->e, "%.9g", (double)v[k * step]);
    }
    close_(w, 0);
}

static void ints(jw *w, const int32_t *v, size_t n)
{
    if (w->bin) {
        sep(w);
        tok(w, J_UNIFORM);
        tok(w, J_INT32);
        enc_len(w, n);
        pfsph__enc_put(w->e, v, 4 * n);
        return;
    }
    open_(w, 0);
    for (size_t k = 0; k < n; k++) int_(w, v[k]);
    close_(w, 0);
}

/* [["scope","public","type",...,"name",N,"options",{...}], ["size",k,"storage",...,"values",...]] */
static void attribute(jw *w, const pfsph__hattr *a, size_t n)
{
    open_(w, 0);
    open_(w, 0);
    str(w, "scope");
    str(w, "public");
    str(w, "type");
    str(w, a->s ? "string" : "numeric");
    str(w, "name");
    str(w, a->name);
    str(w, "options");
    open_(w, 1);
    if (a->typeinfo) {
        key(w, "type");
        open_(w, 1);
        key(w, "type");
        str(w, "string");
        key(w, "value");
        str(w, a->typeinfo);
        close_(w, 1);
    }
    close_(w, 1);
    close_(w, 0);
    open_(w, 0);
    str(w, "size");
    int_(w, a->size);
    str(w, "storage");
    str(w, a->f ? "fpreal32" : "int32");
    if (a->s) { /* strings, then their indices per element */
        str(w, "strings");
        open_(w, 0);
        for (int k = 0; k < a->nstrings; k++) str(w, a->s[k]);
        close_(w, 0);
        str(w, "indices");
        open_(w, 0);
        str(w, "size");
        int_(w, 1);
        str(w, "storage");
        str(w, "int32");
        str(w, "arrays");
        open_(w, 0);
        ints(w, a->i, n);
        close_(w, 0);
        close_(w, 0);
    } else {
        str(w, "values");
        open_(w, 0);
        str(w, "size");
        int_(w, a->size);
        str(w, "storage");
        str(w, a->f ? "fpreal32" : "int32");
        if (a->size == 1) { /* one array of the values */
            str(w, "arrays");
            open_(w, 0);
            if (a->f) floats(w, a->f, n, 1);
            else ints(w, a->i, n);
            close_(w, 0);
        } else { /* one array per tuple */
            str(w, "tuples");
            open_(w, 0);
            for (size_t k = 0; k < n; k++) floats(w, a->f + (size_t)a->size * k, (size_t)a->size, 1);
            close_(w, 0);
        }
        close_(w, 0);
    }
    close_(w, 0);
    close_(w, 0);
}

int pfsph__hgeo_write(const char *path, int binary, const pfsph__hgeo *g, pfsph_error *err)
{
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    jw w = {.e = &e, .bin = binary, .depth = 0, .first = {1}};
    if (binary) {
        uint32_t magic = 0x624a534e; /* native order: a reader on the other endianness sees it swapped */
        tok(&w, J_MAGIC);
        pfsph__enc_put(&e, &magic, 4);
    }
    const size_t nv = 3 * g->ntris;
    open_(&w, 0);
    str(&w, "fileversion");
    str(&w, "19.0.0");
    str(&w, "hasindex");
    false_(&w);
    str(&w, "pointcount");
    int_(&w, (int64_t)g->npoints);
    str(&w, "vertexcount");
    int_(&w, (int64_t)nv);
    str(&w, "primitivecount");
    int_(&w, (int64_t)g->ntris);
    str(&w, "info");
    open_(&w, 1);
    key(&w, "software");
    str(&w, "pfsph " PFSPH_VERSION);
    close_(&w, 1);
    /* vertices -> points; Houdini's polygons wind clockwise seen from outside */
    str(&w, "topology");
    open_(&w, 0);
    str(&w, "pointref");
    open_(&w, 0);
    str(&w, "indices");
    if (binary) {
        sep(&w);
        tok(&w, J_UNIFORM);
        tok(&w, J_INT32);
        enc_len(&w, nv);
        for (size_t t = 0; t < g->ntris; t++)
            for (int k = 2; k >= 0; k--) {
                int32_t v = (int32_t)g->tri[3 * t + (size_t)k];
                pfsph__enc_put(&e, &v, 4);
            }
    } else {
        open_(&w, 0);
        for (size_t t = 0; t < g->ntris; t++)
            for (int k = 2; k >= 0; k--) int_(&w, g->tri[3 * t + (size_t)k]);
        close_(&w, 0);
    }
    close_(&w, 0);
    close_(&w, 0);
    str(&w, "attributes");
    open_(&w, 0);
    str(&w, "pointattributes");
    open_(&w, 0);
    for (int a = 0; a < g->npattr; a++) attribute(&w, &g->pattr[a], g->npoints);
    close_(&w, 0);
    if (g->nprattr && g->ntris) {
        str(&w, "primitiveattributes");
        open_(&w, 0);
        for (int a = 0; a < g->nprattr; a++) attribute(&w, &g->prattr[a], g->ntris);
        close_(&w, 0);
    }
    close_(&w, 0);
    str(&w, "primitives");
    open_(&w, 0);
    if (g->ntris) { /* one run of closed triangles */
        open_(&w, 0);
        open_(&w, 0);
        str(&w, "type");
        str(&w, "Polygon_run");
        close_(&w, 0);
        open_(&w, 0);
        str(&w, "startvertex");
        int_(&w, 0);
        str(&w, "nprimitives");
        int_(&w, (int64_t)g->ntris);
        str(&w, "nvertices_rle");
        open_(&w, 0);
        int_(&w, 3);
        int_(&w, (int64_t)g->ntris);
        close_(&w, 0);
        close_(&w, 0);
        close_(&w, 0);
    }
    close_(&w, 0);
    close_(&w, 0);
    if (!binary) pfsph__enc_put(&e, "\n", 1);
    return pfsph__enc_commit(&e, &af, err);
}
