/* Binary little-endian PLY frames (Blender's importer reads x, y, z and skips the rest) and a
 * reader for exactly what the writer produces. */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "io/io_internal.h"
#include "pfsph/io.h"

#define REAL_PLY (sizeof(pfsph_real) == 4 ? "float" : "double")

int pfsph_write_ply(const char *path, const pfsph_particles *ps, const pfsph_io_opts *o, pfsph_error *err)
{
    pfsph_io_opts def = {.dim = 3};
    if (!o) o = &def;
    if (o->aux_name) {
        int r = pfsph__check_aux_name(path, o->aux_name, err);
        if (r != PFSPH_OK) return r;
    }
    const size_t n = ps->n, rs = sizeof(pfsph_real);
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    pfsph__enc_printf(&e, "ply\nformat binary_little_endian 1.0\ncomment pfsph %s\n", PFSPH_VERSION);
    /* %.17g round-trips every double exactly. */
    pfsph__enc_printf(&e, "comment time %.17g\n", o->time);
    pfsph__enc_printf(&e, "element vertex %zu\n", n);
    static const char *const names[] = {"x", "y", "z", "vx", "vy", "vz", "density", "pressure"};
    const int nreal = o->diffuse ? 6 : 8; /* diffuse sets: no density, pressure */
    for (int k = 0; k < nreal; k++) pfsph__enc_printf(&e, "property %s %s\n", REAL_PLY, names[k]);
    pfsph__enc_printf(&e, "property uchar %s\n", o->diffuse ? "type" : "phase");
    if (o->write_id) pfsph__enc_printf(&e, "property uint id\n");
    if (o->write_speed) pfsph__enc_printf(&e, "property %s speed\n", REAL_PLY);
    if (o->aux_name) pfsph__enc_printf(&e, "property %s %s\n", REAL_PLY, o->aux_name);
    if (o->surface_layer) pfsph__enc_printf(&e, "property uchar surface_layer\n");
    if (o->write_film) pfsph__enc_printf(&e, "property %s film\n", REAL_PLY);
    pfsph__enc_printf(&e, "end_header\n");
    const pfsph_real zero = 0;
    const bool d2 = o->dim == 2;
    for (size_t i = 0; i < n; i++) {
        pfsph__enc_put(&e, &ps->x[i], rs);
        pfsph__enc_put(&e, &ps->y[i], rs);
        pfsph__enc_put(&e, d2 ? &zero : &ps->z[i], rs);
        pfsph__enc_put(&e, &ps->vx[i], rs);
        pfsph__enc_put(&e, &ps->vy[i], rs);
        pfsph__enc_put(&e, d2 ? &zero : &ps->vz[i], rs);
        if (!o->diffuse) {
            pfsph__enc_put(&e, &ps->rho[i], rs);
            pfsph__enc_put(&e, &ps->p[i], rs);
        }
        pfsph__enc_put(&e, &ps->phase[i], 1);
        if (o->write_id) pfsph__enc_put(&e, &ps->id[i], 4);
        if (o->write_speed) {
            double vx = ps->vx[i], vy = ps->vy[i], vz = ps->vz[i];
            pfsph_real s = (pfsph_real)sqrt(vx * vx + vy * vy + vz * vz);
            pfsph__enc_put(&e, &s, rs);
        }
        if (o->aux_name) pfsph__enc_put(&e, &ps->aux[i], rs);
        if (o->surface_layer) pfsph__enc_put(&e, &o->surface_layer[i], 1);
        if (o->write_film) pfsph__enc_put(&e, &ps->film[i], rs);
    }
    rc = pfsph__enc_flush(&e);
    pfsph__enc_free(&e);
    if (rc != PFSPH_OK) {
        pfsph__afile_abort(&af);
        return rc;
    }
    return pfsph__afile_commit(&af, err);
}

/* ---- reader ---------------------------------------------------------------------------- */

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

#define MAX_PROPS 32
#define MAX_HEADER 65536

int pfsph__ply_header_line(const unsigned char *buf, size_t len, size_t *pos, char *line, size_t cap)
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

void pfsph__ply_comment_time(const char *line, double *time)
{
    double t;
    char tail;
    if (time && sscanf(line, "comment time %lf %c", &t, &tail) == 1) *time = t;
}

typedef struct ply_prop {
    int type;
    size_t offset; /* within a record */
    char name[80];
} ply_prop;

int pfsph_read_ply(const char *path, pfsph_particles *ps, double *time, pfsph_error *err)
{
    memset(ps, 0, sizeof *ps);
    if (time) *time = 0;
    unsigned char *buf;
    size_t len;
    int rc = pfsph__read_file(path, &buf, &len, err);
    if (rc != PFSPH_OK) return rc;
#define BAD(...)                                                                  \
    do {                                                                          \
        char m_[512];                                                             \
        snprintf(m_, sizeof m_, __VA_ARGS__);                                     \
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: invalid PLY file: %s", path, m_); \
        goto done;                                                                \
    } while (0)
    ply_prop props[MAX_PROPS];
    int np = 0;
    size_t rec = 0;
    uint64_t nvert = 0;
    bool have_vertex = false, have_format = false;
    size_t pos = 0, lineno = 0;
    char line[256];
    for (;;) {
        switch (pfsph__ply_header_line(buf, len, &pos, line, sizeof line)) {
        case 1: BAD("no end_header line");
        case 2: BAD("header line %zu too long", lineno + 1);
        default: break;
        }
        lineno++;
        char w1[80], w2[80], w3[80], extra[8];
        int nw = sscanf(line, "%79s %79s %79s %7s", w1, w2, w3, extra);
        if (lineno == 1) {
            if (nw != 1 || strcmp(w1, "ply") != 0) BAD("missing 'ply' magic");
            continue;
        }
        if (nw <= 0) continue;
        if (strcmp(w1, "end_header") == 0) break;
        if (strcmp(w1, "comment") == 0 || strcmp(w1, "obj_info") == 0) {
            pfsph__ply_comment_time(line, time);
            continue;
        }
        if (strcmp(w1, "format") == 0) {
            if (nw != 3 || strcmp(w2, "binary_little_endian") || strcmp(w3, "1.0"))
                BAD("format must be binary_little_endian 1.0");
            have_format = true;
        } else if (strcmp(w1, "element") == 0) {
            if (nw != 3 || strcmp(w2, "vertex") || have_vertex)
                BAD("line %zu: only one 'element vertex' is supported", lineno);
            if (pfsph__parse_u64(w3, &nvert) != 0) BAD("line %zu: bad vertex count", lineno);
            have_vertex = true;
        } else if (strcmp(w1, "property") == 0) {
            if (!have_vertex) BAD("line %zu: property before element", lineno);
            if (nw != 3) BAD("line %zu: bad property (lists are not supported)", lineno);
            if (np == MAX_PROPS) BAD("too many properties");
            int t = pfsph__ply_type(w2);
            if (t == PFSPH__T_NONE) BAD("line %zu: unknown type '%s'", lineno, w2);
            for (int k = 0; k < np; k++)
                if (strcmp(props[k].name, w3) == 0) BAD("duplicate property '%s'", w3);
            props[np].type = t;
            props[np].offset = rec;
            snprintf(props[np].name, sizeof props[np].name, "%s", w3);
            rec += pfsph__type_size(t);
            np++;
        } else {
            BAD("line %zu: unexpected '%s'", lineno, w1);
        }
    }
    if (!have_format) BAD("no format line");
    if (!have_vertex) BAD("no vertex element");
    if (rec == 0 && nvert > 0) BAD("vertex element without properties");
    size_t avail = len - pos;
    if (nvert > UINT32_MAX || (rec && nvert > avail / rec))
        BAD("%" PRIu64 " vertices of %zu bytes need more than the %zu bytes left", nvert, rec, avail);
    if (nvert * rec != avail) BAD("%zu trailing bytes after %" PRIu64 " vertices", avail - (size_t)nvert * rec, nvert);
    const size_t n = (size_t)nvert;
    rc = pfsph_particles_init(ps, n ? n : 1);
    if (rc != PFSPH_OK) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory for %zu particles", path, n);
        goto done;
    }
    ps->n = n;
    /* Map each property to a destination; unknown reals fill aux (first one only). */
    static const char *const rnames[] = {"x", "y", "z", "vx", "vy", "vz", "density", "pressure"};
    pfsph_real *rdst[MAX_PROPS] = {0};
    int kind[MAX_PROPS] = {0}; /* 0 skip, 1 real, 2 phase, 3 id */
    bool have_aux = false, have_xyz[3] = {false, false, false};
    for (int k = 0; k < np; k++) {
        const ply_prop *pr = &props[k];
        bool real = pr->type == PFSPH__T_F32 || pr->type == PFSPH__T_F64;
        int r = -1;
        for (int j = 0; j < 8; j++)
            if (strcmp(pr->name, rnames[j]) == 0) r = j;
        if (r >= 0) {
            if (!real) BAD("property '%s' must be float or double", pr->name);
            rdst[k] = ps->f[r]; /* x y z vx vy vz rho p are the first 8 fields, in this order */
            kind[k] = 1;
            if (r < 3) have_xyz[r] = true;
        } else if (strcmp(pr->name, "phase") == 0 || strcmp(pr->name, "type") == 0) {
            if (pr->type != PFSPH__T_U8) BAD("property '%s' must be uchar", pr->name);
            kind[k] = 2;
        } else if (strcmp(pr->name, "id") == 0) {
            if (pr->type != PFSPH__T_U32) BAD("property 'id' must be uint");
            kind[k] = 3;
        } else if (real && strcmp(pr->name, "speed") != 0 && !have_aux) {
            rdst[k] = ps->aux;
            kind[k] = 1;
            have_aux = true;
        }
    }
    if (!have_xyz[0] || !have_xyz[1] || !have_xyz[2]) BAD("missing x, y or z");
    const unsigned char *d = buf + pos;
    for (size_t i = 0; i < n; i++, d += rec)
        for (int k = 0; k < np; k++) {
            const unsigned char *s = d + props[k].offset;
            switch (kind[k]) {
            case 1: rdst[k][i] = (pfsph_real)pfsph__get_as_double(props[k].type, s); break;
            case 2: ps->phase[i] = s[0]; break;
            case 3: pfsph__get_le(&ps->id[i], s, 4); break;
            default: break;
            }
        }
    for (size_t i = 0; i < n; i++)
        if (ps->id[i] >= ps->next_id) ps->next_id = ps->id[i] + 1;
    rc = PFSPH_OK;
done:
#undef BAD
    if (rc != PFSPH_OK) pfsph_particles_free(ps);
    free(buf);
    return rc;
}
