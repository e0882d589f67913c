/* The byte layout of the particle frames (frame_layout.h): the PLY header and record, the VTP
 * header and its appended arrays, as literals and per-particle regions; the encoding of a range
 * of particles of one region; the serial writer that streams a layout into one atomic file. */
#include "io/frame_layout.h"

#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "io/io_internal.h"

#define REAL_PLY (sizeof(pfsph_real) == 4 ? "float" : "double")
#define REAL_VTK (sizeof(pfsph_real) == 4 ? "Float32" : "Float64")

/* region contents */
enum { R_PLY = 1, V_VEL, V_RHO, V_P, V_PHASE, V_ID, V_SPEED, V_AUX, V_LAYER, V_FILM, V_POINTS, V_CONN, V_OFFS };

static void lit_bytes(pfsph__frame_layout *L, const void *b, size_t len)
{
    if (L->failed) return;
    if (L->text_len + len > L->text_cap) {
        size_t cap = (L->text_len + len) * 2 + 256;
        char *q = realloc(L->text, cap);
        if (!q) {
            L->failed = 1;
            return;
        }
        L->text = q;
        L->text_cap = cap;
    }
    memcpy(L->text + L->text_len, b, len);
    pfsph__frame_seg *s = L->nseg ? &L->seg[L->nseg - 1] : NULL;
    if (!s || s->per) { /* a new literal */
        if (L->nseg == PFSPH__LAYOUT_MAX_SEGS) {
            L->failed = 1;
            return;
        }
        s = &L->seg[L->nseg++];
        *s = (pfsph__frame_seg){0, 0, 0, L->text_len, 0};
    }
    s->lit_len += len;
    L->text_len += len;
}

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void
lit_printf(pfsph__frame_layout *L, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    int len = vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (len < 0) return;
    if ((size_t)len >= sizeof line) len = (int)sizeof line - 1;
    lit_bytes(L, line, (size_t)len);
}

static void lit_le(pfsph__frame_layout *L, const void *v, size_t size)
{
    unsigned char b[8];
    pfsph__put_le(b, v, size);
    lit_bytes(L, b, size);
}

static void region(pfsph__frame_layout *L, int kind, size_t per)
{
    if (L->failed) return;
    if (L->nseg == PFSPH__LAYOUT_MAX_SEGS) {
        L->failed = 1;
        return;
    }
    L->seg[L->nseg++] = (pfsph__frame_seg){0, per, kind, 0, 0};
}

static void begin(pfsph__frame_layout *L, uint64_t n, const pfsph_io_opts *o)
{
    memset(L, 0, sizeof *L);
    L->n = n;
    if (o) L->o = *o;
    else L->o.dim = 3;
}

/* the offsets, once every segment is there */
static int finish(pfsph__frame_layout *L)
{
    if (L->failed) {
        pfsph__frame_layout_free(L);
        return PFSPH_ENOMEM;
    }
    uint64_t off = 0;
    for (int k = 0; k < L->nseg; k++) {
        L->seg[k].off = off;
        off += L->seg[k].per ? L->seg[k].per * L->n : L->seg[k].lit_len;
    }
    L->len = off;
    return PFSPH_OK;
}

void pfsph__frame_layout_free(pfsph__frame_layout *L)
{
    free(L->text);
    L->text = NULL;
    L->text_len = L->text_cap = 0;
    L->nseg = 0;
}

int pfsph__ply_layout(pfsph__frame_layout *L, uint64_t n, const pfsph_io_opts *o)
{
    begin(L, n, o);
    o = &L->o;
    const size_t rs = sizeof(pfsph_real);
    lit_printf(L, "ply\nformat binary_little_endian 1.0\ncomment pfsph %s\n", PFSPH_VERSION);
    /* %.17g round-trips every double exactly. */
    lit_printf(L, "comment time %.17g\n", o->time);
    lit_printf(L, "element vertex %" PRIu64 "\n", n);
    static const char *const names[] = {"x", "y", "z", "vx", "vy", "vz", "density", "pressure"};
    const int nreal = o->diffuse ? 6 : 8; /* diffuse sets: no density, pressure */
    size_t rec = (size_t)nreal * rs + 1;
    for (int k = 0; k < nreal; k++) lit_printf(L, "property %s %s\n", REAL_PLY, names[k]);
    lit_printf(L, "property uchar %s\n", o->diffuse ? "type" : "phase");
    if (o->write_id) lit_printf(L, "property uint id\n"), rec += 4;
    if (o->write_speed) lit_printf(L, "property %s speed\n", REAL_PLY), rec += rs;
    if (o->aux_name) lit_printf(L, "property %s %s\n", REAL_PLY, o->aux_name), rec += rs;
    if (o->surface_layer) lit_printf(L, "property uchar surface_layer\n"), rec += 1;
    if (o->write_film) lit_printf(L, "property %s film\n", REAL_PLY), rec += rs;
    lit_printf(L, "end_header\n");
    region(L, R_PLY, rec);
    return finish(L);
}

/* One appended array of the VTP: what the header says and its bytes per particle (0: TimeValue). */
typedef struct vtp_array {
    int kind;
    const char *name;
    const char *type;
    int ncomp;
    size_t per;
} vtp_array;

/* The arrays of a VTP frame of n particles, in the file's order; their count. */
static int vtp_arrays(const pfsph_io_opts *o, uint64_t n, vtp_array *arr)
{
    const size_t rs = sizeof(pfsph_real);
    const int idx64 = n > (uint64_t)INT32_MAX;
    const size_t is = idx64 ? 8 : 4;
    const char *itype = idx64 ? "Int64" : "Int32";
    int na = 0;
    arr[na++] = (vtp_array){0, "TimeValue", "Float64", 1, 0};
    arr[na++] = (vtp_array){V_VEL, "velocity", REAL_VTK, 3, 3 * rs};
    if (!o->diffuse) {
        arr[na++] = (vtp_array){V_RHO, "density", REAL_VTK, 1, rs};
        arr[na++] = (vtp_array){V_P, "pressure", REAL_VTK, 1, rs};
    }
    arr[na++] = (vtp_array){V_PHASE, o->diffuse ? "type" : "phase", "UInt8", 1, 1};
    if (o->write_id) arr[na++] = (vtp_array){V_ID, "id", "UInt32", 1, 4};
    if (o->write_speed) arr[na++] = (vtp_array){V_SPEED, "speed", REAL_VTK, 1, rs};
    if (o->aux_name) arr[na++] = (vtp_array){V_AUX, o->aux_name, REAL_VTK, 1, rs};
    if (o->surface_layer) arr[na++] = (vtp_array){V_LAYER, "surface_layer", "UInt8", 1, 1};
    if (o->write_film) arr[na++] = (vtp_array){V_FILM, "film", REAL_VTK, 1, rs};
    arr[na++] = (vtp_array){V_POINTS, "Points", REAL_VTK, 3, 3 * rs};
    arr[na++] = (vtp_array){V_CONN, "connectivity", itype, 1, is};
    arr[na++] = (vtp_array){V_OFFS, "offsets", itype, 1, is};
    return na;
}

int pfsph__vtp_layout(pfsph__frame_layout *L, uint64_t n, const pfsph_io_opts *o)
{
    begin(L, n, o);
    o = &L->o;
    vtp_array arr[14];
    const int na = vtp_arrays(o, n, arr);
    /* XML header: every array's offset is the running sum of (8-byte header + data). */
    uint64_t off = 0;
    lit_printf(L, "<?xml version=\"1.0\"?>\n");
    lit_printf(L,
               "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
               "header_type=\"UInt64\">\n  <PolyData>\n");
    for (int k = 0; k < na; k++) {
        const vtp_array *a = &arr[k];
        switch (a->kind) {
        case 0: lit_printf(L, "    <FieldData>\n"); break;
        case V_VEL:
            lit_printf(L,
                       "    <Piece NumberOfPoints=\"%" PRIu64 "\" NumberOfVerts=\"%" PRIu64 "\" NumberOfLines=\"0\" "
                       "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
                       n, n);
            lit_printf(L, "      <PointData Scalars=\"%s\" Vectors=\"velocity\">\n", o->diffuse ? "type" : "density");
            break;
        case V_POINTS: lit_printf(L, "      </PointData>\n      <Points>\n"); break;
        case V_CONN: lit_printf(L, "      </Points>\n      <Verts>\n"); break;
        default: break;
        }
        if (a->kind == 0)
            lit_printf(L,
                       "      <DataArray type=\"%s\" Name=\"%s\" NumberOfTuples=\"1\" "
                       "format=\"appended\" offset=\"%" PRIu64 "\"/>\n    </FieldData>\n",
                       a->type, a->name, off);
        else
            lit_printf(L,
                       "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" "
                       "format=\"appended\" offset=\"%" PRIu64 "\"/>\n",
                       a->type, a->name, a->ncomp, off);
        off += 8 + (a->kind ? a->per * n : 8);
    }
    lit_printf(L, "      </Verts>\n    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _");
    /* Appended blocks, in the header's order: each its byte count, then its data. */
    for (int k = 0; k < na; k++) {
        const uint64_t nbytes = arr[k].kind ? arr[k].per * n : 8;
        lit_le(L, &nbytes, 8);
        if (arr[k].kind) region(L, arr[k].kind, arr[k].per);
        else lit_le(L, &o->time, 8);
    }
    lit_printf(L, "\n  </AppendedData>\n</VTKFile>\n");
    return finish(L);
}

static inline unsigned char *put(unsigned char *d, const void *v, size_t size)
{
    pfsph__put_le(d, v, size);
    return d + size;
}

void pfsph__frame_encode(const pfsph__frame_layout *L, int k, const pfsph_particles *ps, const uint8_t *layer,
                         size_t lo, size_t hi, uint64_t first, unsigned char *out)
{
    const pfsph_io_opts *o = &L->o;
    const size_t rs = sizeof(pfsph_real);
    const pfsph_real zero = 0;
    const int d2 = o->dim == 2;
    const int kind = L->seg[k].kind;
    unsigned char *d = out;
    for (size_t i = lo; i < hi; i++) {
        switch (kind) {
        case R_PLY:
            d = put(d, &ps->x[i], rs);
            d = put(d, &ps->y[i], rs);
            d = put(d, d2 ? &zero : &ps->z[i], rs);
            d = put(d, &ps->vx[i], rs);
            d = put(d, &ps->vy[i], rs);
            d = put(d, d2 ? &zero : &ps->vz[i], rs);
            if (!o->diffuse) {
                d = put(d, &ps->rho[i], rs);
                d = put(d, &ps->p[i], rs);
            }
            d = put(d, &ps->phase[i], 1);
            if (o->write_id) d = put(d, &ps->id[i], 4);
            if (o->write_speed) {
                double vx = ps->vx[i], vy = ps->vy[i], vz = ps->vz[i];
                pfsph_real s = (pfsph_real)sqrt(vx * vx + vy * vy + vz * vz);
                d = put(d, &s, rs);
            }
            if (o->aux_name) d = put(d, &ps->aux[i], rs);
            if (o->surface_layer) d = put(d, &layer[i], 1);
            if (o->write_film) d = put(d, &ps->film[i], rs);
            break;
        case V_VEL:
            d = put(d, &ps->vx[i], rs);
            d = put(d, &ps->vy[i], rs);
            d = put(d, d2 ? &zero : &ps->vz[i], rs);
            break;
        case V_RHO: d = put(d, &ps->rho[i], rs); break;
        case V_P: d = put(d, &ps->p[i], rs); break;
        case V_PHASE: d = put(d, &ps->phase[i], 1); break;
        case V_ID: d = put(d, &ps->id[i], 4); break;
        case V_SPEED: {
            double vx = ps->vx[i], vy = ps->vy[i], vz = ps->vz[i];
            pfsph_real s = (pfsph_real)sqrt(vx * vx + vy * vy + vz * vz);
            d = put(d, &s, rs);
            break;
        }
        case V_AUX: d = put(d, &ps->aux[i], rs); break;
        case V_LAYER: d = put(d, &layer[i], 1); break;
        case V_FILM: d = put(d, &ps->film[i], rs); break;
        case V_POINTS:
            d = put(d, &ps->x[i], rs);
            d = put(d, &ps->y[i], rs);
            d = put(d, d2 ? &zero : &ps->z[i], rs);
            break;
        case V_CONN:
        case V_OFFS: {
            const uint64_t v = first + (i - lo) + (kind == V_OFFS);
            if (L->seg[k].per == 8) {
                int64_t w = (int64_t)v;
                d = put(d, &w, 8);
            } else {
                int32_t w = (int32_t)v;
                d = put(d, &w, 4);
            }
            break;
        }
        default: break;
        }
    }
}

/* particles per encoded run: at most 4096 x 96 bytes, under the encoder's 1 MiB buffer */
#define RUN 4096

int pfsph__frame_write(const char *path, const pfsph__frame_layout *L, const pfsph_particles *ps, pfsph_error *err)
{
    size_t maxper = 1;
    for (int k = 0; k < L->nseg; k++)
        if (L->seg[k].per > maxper) maxper = L->seg[k].per;
    unsigned char *buf = malloc(RUN * maxper);
    if (!buf) return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) {
        free(buf);
        return rc;
    }
    const size_t n = (size_t)L->n;
    for (int k = 0; k < L->nseg; k++) {
        const pfsph__frame_seg *s = &L->seg[k];
        if (!s->per) {
            for (size_t o = 0; o < s->lit_len; o += 65536) /* put_text: below the buffer's size */
                pfsph__enc_put_text(&e, L->text + s->lit + o, s->lit_len - o < 65536 ? s->lit_len - o : 65536);
            continue;
        }
        for (size_t lo = 0; lo < n; lo += RUN) {
            const size_t hi = n - lo < RUN ? n : lo + RUN;
            pfsph__frame_encode(L, k, ps, L->o.surface_layer, lo, hi, lo, buf);
            pfsph__enc_put_text(&e, (const char *)buf, (hi - lo) * s->per);
        }
    }
    free(buf);
    return pfsph__enc_commit(&e, &af, err);
}

int pfsph__write_pvtp(const char *path, const pfsph_io_opts *o, const char *base, int npieces, pfsph_error *err)
{
    pfsph__frame_layout L; /* a text builder here */
    begin(&L, 0, o);
    vtp_array arr[14];
    const int na = vtp_arrays(&L.o, 0, arr); /* the pieces' arrays (each piece below 2^31 points) */
    lit_printf(&L, "<?xml version=\"1.0\"?>\n");
    lit_printf(&L,
               "<VTKFile type=\"PPolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
               "header_type=\"UInt64\">\n  <PPolyData GhostLevel=\"0\">\n");
    lit_printf(&L, "    <PPointData Scalars=\"%s\" Vectors=\"velocity\">\n", L.o.diffuse ? "type" : "density");
    for (int k = 0; k < na; k++) {
        const vtp_array *a = &arr[k];
        if (a->kind == V_POINTS) lit_printf(&L, "    </PPointData>\n    <PPoints>\n");
        if (a->kind == V_CONN) break; /* the cells are each piece's own */
        if (a->kind)
            lit_printf(&L, "      <PDataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\"/>\n", a->type, a->name,
                       a->ncomp);
    }
    lit_printf(&L, "    </PPoints>\n");
    for (int q = 0; q < npieces; q++) lit_printf(&L, "    <Piece Source=\"%s_%04d.vtp\"/>\n", base, q);
    lit_printf(&L, "  </PPolyData>\n</VTKFile>\n");
    if (L.failed) {
        pfsph__frame_layout_free(&L);
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    }
    int rc = pfsph_write_file_atomic(path, L.text, L.text_len, err);
    pfsph__frame_layout_free(&L);
    return rc;
}
