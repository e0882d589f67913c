/* The PLY header reader (ply_header.h): one parser of the header lines for the particle and the
 * surface readers, which then judge the elements and properties it returns. */
#include "io/ply_header.h"

#include <stdio.h>
#include <string.h>

#include "io/io_internal.h"

#define MAX_HEADER 65536

int pfsph__ply_type(const char *s)
{
    static const struct {
        const char *n;
        int t;
    } map[] = {
        {"char", PFSPH__T_I8},   {"int8", PFSPH__T_I8},     {"uchar", PFSPH__T_U8},   {"uint8", PFSPH__T_U8},
        {"short", PFSPH__T_I16}, {"int16", PFSPH__T_I16},   {"ushort", PFSPH__T_U16}, {"uint16", PFSPH__T_U16},
        {"int", PFSPH__T_I32},   {"int32", PFSPH__T_I32},   {"uint", PFSPH__T_U32},   {"uint32", PFSPH__T_U32},
        {"float", PFSPH__T_F32}, {"float32", PFSPH__T_F32}, {"double", PFSPH__T_F64}, {"float64", PFSPH__T_F64},
    };
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (strcmp(s, map[i].n) == 0) return map[i].t;
    return PFSPH__T_NONE;
}

/* The next header line at *pos (CR-LF tolerated), copied into line[cap]: 0, or 1 when no
 * end_header comes within MAX_HEADER bytes, 2 when the line does not fit. */
static int header_line(const unsigned char *buf, size_t len, size_t *pos, char *line, size_t cap)
{
    const unsigned char *nl = memchr(buf + *pos, '\n', len - *pos);
    if (!nl || (size_t)(nl - buf) > MAX_HEADER) return 1;
    size_t ll = (size_t)(nl - (buf + *pos));
    if (ll >= cap) return 2;
    memcpy(line, buf + *pos, ll);
    line[ll] = 0;
    if (ll && line[ll - 1] == '\r') line[--ll] = 0;
    *pos = (size_t)(nl - buf) + 1;
    return 0;
}

/* "comment time T" sets *time (when time is not NULL); other comments are ignored. */
static void comment_time(const char *line, double *time)
{
    double t;
    char tail;
    if (time && sscanf(line, "comment time %lf %c", &t, &tail) == 1) *time = t;
}

int pfsph__ply_header_read(const unsigned char *buf, size_t len, const char *path, const pfsph__ply_spec *spec,
                           pfsph__ply_header *h, double *time, pfsph_error *err)
{
#define BAD(...) PFSPH__BAD(spec->what, __VA_ARGS__)
    int rc = PFSPH_OK;
    memset(h, 0, sizeof *h);
    const char *const *names = spec->elems;
    int nnames = 0;
    while (nnames < PFSPH__PLY_MAX_ELEMS && names[nnames]) nnames++;
    bool have_format = false;
    size_t pos = 0, lineno = 0;
    char line[256];
    for (;;) {
        switch (header_line(buf, len, &pos, line, sizeof line)) {
        case 1: BAD("no end_header line");
        case 2: BAD("header line %zu too long", lineno + 1);
        default: break;
        }
        lineno++;
        char w[5][80];
        int nw = sscanf(line, "%79s %79s %79s %79s %79s", w[0], w[1], w[2], w[3], w[4]);
        if (lineno == 1) {
            if (nw != 1 || strcmp(w[0], "ply") != 0) BAD("missing 'ply' magic");
            continue;
        }
        if (nw <= 0) continue;
        if (strcmp(w[0], "end_header") == 0) break;
        if (strcmp(w[0], "comment") == 0 || strcmp(w[0], "obj_info") == 0) {
            comment_time(line, time);
            continue;
        }
        if (strcmp(w[0], "format") == 0) {
            if (nw != 3 || strcmp(w[1], "binary_little_endian") || strcmp(w[2], "1.0"))
                BAD("format must be binary_little_endian 1.0");
            have_format = true;
        } else if (strcmp(w[0], "element") == 0) {
            if (nw != 3 || h->nelems == nnames || strcmp(w[1], names[h->nelems]) != 0) {
                if (nnames == 1) BAD("line %zu: only one 'element %s' is supported", lineno, names[0]);
                BAD("line %zu: expected 'element %s N' then 'element %s N'", lineno, names[0], names[1]);
            }
            pfsph__ply_element *e = &h->elem[h->nelems++];
            if (pfsph__parse_u64(w[2], &e->count) != 0) BAD("line %zu: bad %s count", lineno, w[1]);
            e->line = lineno;
        } else if (strcmp(w[0], "property") == 0) {
            if (h->nelems == 0) BAD("line %zu: property before element", lineno);
            pfsph__ply_element *e = &h->elem[h->nelems - 1];
            const bool list = spec->lists && nw == 5 && strcmp(w[1], "list") == 0;
            if (!list && nw != 3)
                BAD(spec->lists ? "line %zu: bad property" : "line %zu: bad property (lists are not supported)",
                    lineno);
            if (e->nprops == PFSPH__PLY_MAX_PROPS) BAD("too many properties");
            pfsph__ply_prop *p = &e->prop[e->nprops++];
            p->list = list;
            p->line = lineno;
            if (list) {
                /* the reader judges the types of the lists it reads */
                p->count_type = pfsph__ply_type(w[2]);
                p->type = pfsph__ply_type(w[3]);
                snprintf(p->name, sizeof p->name, "%s", w[4]);
                continue;
            }
            p->type = pfsph__ply_type(w[1]);
            if (p->type == PFSPH__T_NONE) BAD("line %zu: unknown type '%s'", lineno, w[1]);
            if (spec->unique)
                for (int k = 0; k < e->nprops - 1; k++)
                    if (strcmp(e->prop[k].name, w[2]) == 0) BAD("duplicate property '%s'", w[2]);
            p->count_type = PFSPH__T_NONE;
            p->offset = e->rec;
            snprintf(p->name, sizeof p->name, "%s", w[2]);
            e->rec += pfsph__type_size(p->type);
        } else {
            BAD("line %zu: unexpected '%s'", lineno, w[0]);
        }
    }
    if (!have_format) BAD("no format line");
    h->data = pos;
done:
#undef BAD
    return rc;
}
