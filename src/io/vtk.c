/* VTK XML PolyData (.vtp) frames for ParaView: raw binary appended data with UInt64 block
 * headers, one vertex cell per particle, and a reader for exactly what the writer produces. */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "io/frame_layout.h"
#include "io/io_internal.h"
#include "pfsph/io.h"

/* Checks an aux field name: it goes into an XML attribute (VTP) or a header word (PLY) and must
 * not collide with the fixed fields. */
int pfsph__check_aux_name(const char *path, const char *name, pfsph_error *err)
{
    static const char *const taken[] = {
        "x",       "y",        "z",         "vx",           "vy",     "vz",    "velocity",
        "density", "pressure", "phase",     "type",         "id",     "speed", "surface_layer",
        "film",    "Points",   "TimeValue", "connectivity", "offsets"};
    size_t len = strlen(name);
    if (len == 0 || len > 64)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: aux field name must have 1 to 64 characters", path);
    for (size_t i = 0; i < len; i++) {
        char c = name[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
              c == '.'))
            return pfsph_fail(err, PFSPH_EINPUT, "%s: aux field name '%s': only letters, digits, '_', '-', '.'", path,
                              name);
    }
    for (size_t i = 0; i < sizeof taken / sizeof taken[0]; i++)
        if (strcmp(name, taken[i]) == 0)
            return pfsph_fail(err, PFSPH_EINPUT, "%s: aux field name '%s' is reserved", path, name);
    return PFSPH_OK;
}

int pfsph_write_vtp(const char *path, const pfsph_particles *ps, const pfsph_io_opts *o, pfsph_error *err)
{
    if (o && o->aux_name) {
        int r = pfsph__check_aux_name(path, o->aux_name, err);
        if (r != PFSPH_OK) return r;
    }
    pfsph__frame_layout L; /* the header and the appended arrays: io/frame_layout.c */
    if (pfsph__vtp_layout(&L, ps->n, o)) return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    int rc = pfsph__frame_write(path, &L, ps, err);
    pfsph__frame_layout_free(&L);
    return rc;
}

/* ---- reader ---------------------------------------------------------------------------- */

typedef struct rd_array {
    char section[16];
    char name[80];
    int type;
    int ncomp;
    uint64_t ntuples; /* FieldData only */
    uint64_t offset;
} rd_array;

static int vtk_type(const char *s)
{
    static const struct {
        const char *n;
        int t;
    } map[] = {
        {"Int8", PFSPH__T_I8},     {"UInt8", PFSPH__T_U8},    {"Int16", PFSPH__T_I16}, {"UInt16", PFSPH__T_U16},
        {"Int32", PFSPH__T_I32},   {"UInt32", PFSPH__T_U32},  {"Int64", PFSPH__T_I64}, {"UInt64", PFSPH__T_U64},
        {"Float32", PFSPH__T_F32}, {"Float64", PFSPH__T_F64},
    };
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (strcmp(s, map[i].n) == 0) return map[i].t;
    return PFSPH__T_NONE;
}

/* Value of attribute key in the attribute text of one tag [a, end); 0 if absent. */
static int get_attr(const char *a, const char *end, const char *key, char *out, size_t cap)
{
    size_t kl = strlen(key);
    const char *p = a;
    while (p < end) {
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) p++;
        const char *nb = p;
        while (p < end && *p != '=' && *p != ' ' && *p != '>' && *p != '/') p++;
        size_t nl = (size_t)(p - nb);
        if (p >= end || *p != '=') {
            if (p < end) p++;
            continue;
        }
        p++;
        if (p >= end || (*p != '"' && *p != '\'')) return -1;
        char q = *p++;
        const char *vb = p;
        while (p < end && *p != q) p++;
        if (p >= end) return -1;
        size_t vl = (size_t)(p - vb);
        p++;
        if (nl == kl && memcmp(nb, key, kl) == 0) {
            if (vl >= cap) return -1;
            memcpy(out, vb, vl);
            out[vl] = 0;
            return 1;
        }
    }
    return 0;
}

int pfsph__parse_u64(const char *s, uint64_t *v)
{
    if (!*s) return -1;
    uint64_t r = 0;
    for (; *s; s++) {
        if (*s < '0' || *s > '9') return -1;
        unsigned d = (unsigned)(*s - '0');
        if (r > (UINT64_MAX - d) / 10) return -1;
        r = r * 10 + d;
    }
    *v = r;
    return 0;
}

static const unsigned char *find_bytes(const unsigned char *h, size_t hl, const char *needle)
{
    size_t nl = strlen(needle);
    if (nl > hl) return NULL;
    for (size_t i = 0; i + nl <= hl; i++)
        if (h[i] == (unsigned char)needle[0] && memcmp(h + i, needle, nl) == 0) return h + i;
    return NULL;
}

#define MAX_ARRAYS 64

int pfsph_read_vtp(const char *path, pfsph_particles *ps, double *time, pfsph_error *err)
{
    unsigned char *buf;
    size_t len;
    int rc = pfsph__reader_open(path, ps, sizeof *ps, &buf, &len, time, err);
    if (rc != PFSPH_OK) return rc;
#define BAD(...) PFSPH__BAD("VTP file", __VA_ARGS__)

    rd_array *ar = calloc(MAX_ARRAYS, sizeof *ar);
    if (!ar) {
        free(buf);
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    }
    int na = 0;
    uint64_t npoints = 0;
    bool have_vtkfile = false, have_piece = false;
    size_t hsize = 4;
    const unsigned char *data = NULL;
    size_t dlen = 0;

    /* Walk the tags of the XML header up to the AppendedData element. */
    const unsigned char *app = find_bytes(buf, len, "<AppendedData");
    if (!app) BAD("no <AppendedData> section");
    const char *p = (const char *)buf, *hend = (const char *)app;
    char section[16] = "";
    char val[128];
    while (p < hend) {
        const char *lt = memchr(p, '<', (size_t)(hend - p));
        if (!lt) break;
        const char *gt = memchr(lt, '>', (size_t)(hend - lt));
        if (!gt) BAD("unterminated tag");
        p = gt + 1;
        const char *nb = lt + 1;
        if (*nb == '?' || *nb == '!') continue;
        bool closing = *nb == '/';
        if (closing) nb++;
        const char *ne = nb;
        while (ne < gt && *ne != ' ' && *ne != '\t' && *ne != '\n' && *ne != '\r' && *ne != '/') ne++;
        size_t nl = (size_t)(ne - nb);
#define IS(s) (nl == strlen(s) && memcmp(nb, s, nl) == 0)
        if (IS("VTKFile") && !closing) {
            have_vtkfile = true;
            if (get_attr(ne, gt, "type", val, sizeof val) != 1 || strcmp(val, "PolyData"))
                BAD("VTKFile type is not PolyData");
            if (get_attr(ne, gt, "byte_order", val, sizeof val) != 1 || strcmp(val, "LittleEndian"))
                BAD("byte_order is not LittleEndian");
            if (get_attr(ne, gt, "compressor", val, sizeof val) != 0) BAD("compressed data is not supported");
            int h = get_attr(ne, gt, "header_type", val, sizeof val);
            if (h < 0 || (h == 1 && strcmp(val, "UInt64") && strcmp(val, "UInt32"))) BAD("unsupported header_type");
            hsize = (h == 1 && strcmp(val, "UInt64") == 0) ? 8 : 4;
        } else if (IS("Piece") && !closing) {
            if (have_piece) BAD("more than one Piece");
            have_piece = true;
            if (get_attr(ne, gt, "NumberOfPoints", val, sizeof val) != 1 || pfsph__parse_u64(val, &npoints) != 0)
                BAD("bad NumberOfPoints");
        } else if (IS("FieldData") || IS("PointData") || IS("Points") || IS("Verts") || IS("CellData") || IS("Lines") ||
                   IS("Strips") || IS("Polys")) {
            if (closing || gt[-1] == '/') section[0] = 0;
            else {
                memcpy(section, nb, nl);
                section[nl] = 0;
            }
        } else if (IS("DataArray") && !closing) {
            if (na == MAX_ARRAYS) BAD("too many arrays");
            rd_array *a = &ar[na++];
            snprintf(a->section, sizeof a->section, "%s", section);
            if (get_attr(ne, gt, "Name", a->name, sizeof a->name) < 0) BAD("bad array name");
            if (get_attr(ne, gt, "type", val, sizeof val) != 1 || (a->type = vtk_type(val)) == PFSPH__T_NONE)
                BAD("array '%s': bad type", a->name);
            if (get_attr(ne, gt, "format", val, sizeof val) != 1 || strcmp(val, "appended"))
                BAD("array '%s': format is not appended", a->name);
            uint64_t v = 1;
            int h = get_attr(ne, gt, "NumberOfComponents", val, sizeof val);
            if (h < 0 || (h == 1 && (pfsph__parse_u64(val, &v) || v < 1 || v > 9)))
                BAD("array '%s': bad NumberOfComponents", a->name);
            a->ncomp = (int)v;
            v = 0;
            h = get_attr(ne, gt, "NumberOfTuples", val, sizeof val);
            if (h < 0 || (h == 1 && pfsph__parse_u64(val, &v))) BAD("array '%s': bad NumberOfTuples", a->name);
            a->ntuples = v;
            if (get_attr(ne, gt, "offset", val, sizeof val) != 1 || pfsph__parse_u64(val, &a->offset))
                BAD("array '%s': bad offset", a->name);
        }
#undef IS
    }
    if (!have_vtkfile) BAD("no VTKFile element");
    if (!have_piece) BAD("no Piece element");
    {
        const char *gt = memchr(hend, '>', len - (size_t)(hend - (const char *)buf));
        if (!gt) BAD("unterminated AppendedData tag");
        char enc[32];
        if (get_attr(hend + 13, gt, "encoding", enc, sizeof enc) != 1 || strcmp(enc, "raw"))
            BAD("AppendedData encoding is not raw");
        const char *u = gt + 1, *end = (const char *)buf + len;
        while (u < end && (*u == ' ' || *u == '\n' || *u == '\r' || *u == '\t')) u++;
        if (u >= end || *u != '_') BAD("AppendedData does not start with '_'");
        data = (const unsigned char *)u + 1;
        dlen = (size_t)(end - (u + 1));
    }
    /* Every particle needs at least 3 coordinates of 4 bytes: bounds npoints by the size. */
    if (npoints > dlen / 12 + 1 || npoints > UINT32_MAX) BAD("NumberOfPoints %" PRIu64 " exceeds the data", npoints);
    const size_t n = (size_t)npoints;
    rc = pfsph_particles_init(ps, n ? n : 1);
    if (rc != PFSPH_OK) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory for %zu particles", path, n);
        goto done;
    }
    ps->n = n;

    bool have_points = false, have_aux = false;
    uint64_t data_end = 0;
    for (int k = 0; k < na; k++) {
        rd_array *a = &ar[k];
        const size_t ts = pfsph__type_size(a->type);
        if (a->offset > dlen || dlen - a->offset < hsize)
            BAD("array '%s': offset %" PRIu64 " outside the data", a->name, a->offset);
        uint64_t nbytes = 0;
        const unsigned char *blk = data + a->offset;
        if (hsize == 8) pfsph__get_le(&nbytes, blk, 8);
        else {
            uint32_t s32;
            pfsph__get_le(&s32, blk, 4);
            nbytes = s32;
        }
        if (nbytes > dlen - a->offset - hsize)
            BAD("array '%s': %" PRIu64 " bytes run past the end of the file", a->name, nbytes);
        blk += hsize;
        if (a->offset + hsize + nbytes > data_end) data_end = a->offset + hsize + nbytes;
        uint64_t count = strcmp(a->section, "FieldData") == 0 ? a->ntuples : npoints;
        uint64_t want = count * (uint64_t)a->ncomp * ts;
        if (nbytes != want) BAD("array '%s': %" PRIu64 " bytes, expected %" PRIu64, a->name, nbytes, want);

        pfsph_real *dst[3] = {NULL, NULL, NULL};
        uint8_t *dst8 = NULL;
        uint32_t *dst32 = NULL;
        bool is_real = a->type == PFSPH__T_F32 || a->type == PFSPH__T_F64;
        if (strcmp(a->section, "FieldData") == 0) {
            if (strcmp(a->name, "TimeValue") == 0) {
                if (count != 1 || a->ncomp != 1 || !is_real) BAD("bad TimeValue");
                if (time) *time = pfsph__get_as_double(a->type, blk);
            }
            continue;
        } else if (strcmp(a->section, "Points") == 0) {
            if (a->ncomp != 3 || !is_real) BAD("Points must be 3 real components");
            dst[0] = ps->x, dst[1] = ps->y, dst[2] = ps->z;
            have_points = true;
        } else if (strcmp(a->section, "Verts") == 0) {
            if (a->ncomp != 1) BAD("bad Verts array");
            continue; /* one vertex per point by construction; sizes checked above */
        } else if (strcmp(a->section, "PointData") == 0) {
            if (strcmp(a->name, "velocity") == 0) {
                if (a->ncomp != 3 || !is_real) BAD("velocity must be 3 real components");
                dst[0] = ps->vx, dst[1] = ps->vy, dst[2] = ps->vz;
            } else if (strcmp(a->name, "phase") == 0 || strcmp(a->name, "type") == 0) {
                if (a->ncomp != 1 || a->type != PFSPH__T_U8) BAD("phase/type must be UInt8");
                dst8 = ps->phase;
            } else if (strcmp(a->name, "id") == 0) {
                if (a->ncomp != 1 || a->type != PFSPH__T_U32) BAD("id must be UInt32");
                dst32 = ps->id;
            } else if (a->ncomp == 1 && is_real) {
                if (strcmp(a->name, "density") == 0) dst[0] = ps->rho;
                else if (strcmp(a->name, "pressure") == 0) dst[0] = ps->p;
                else if (strcmp(a->name, "speed") == 0) continue; /* derived from velocity */
                else if (!have_aux) dst[0] = ps->aux, have_aux = true;
                else continue;
            } else {
                continue;
            }
        } else {
            continue;
        }
        const size_t nc = (size_t)a->ncomp;
        for (size_t i = 0; i < n; i++)
            for (size_t c = 0; c < nc; c++) {
                const unsigned char *s = blk + (i * nc + c) * ts;
                if (dst8) dst8[i] = s[0];
                else if (dst32) pfsph__get_le(&dst32[i], s, 4);
                else dst[c][i] = (pfsph_real)pfsph__get_as_double(a->type, s);
            }
    }
    if (!have_points) BAD("no Points array");
    /* The document must be complete: a file cut inside its closing tags is truncated too. */
    if (!find_bytes(data + data_end, dlen - (size_t)data_end, "</AppendedData>") ||
        !find_bytes(data + data_end, dlen - (size_t)data_end, "</VTKFile>"))
        BAD("missing closing tags (truncated file?)");
    for (size_t i = 0; i < n; i++)
        if (ps->id[i] >= ps->next_id) ps->next_id = ps->id[i] + 1;
    rc = PFSPH_OK;
done:
#undef BAD
    if (rc != PFSPH_OK) pfsph_particles_free(ps);
    free(ar);
    free(buf);
    return rc;
}
