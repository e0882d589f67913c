/* Binary little-endian PLY frames (Blender's importer reads x, y, z and skips the rest) and a
 * reader for exactly what the writer produces. */
#include <inttypes.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "io/frame_layout.h"
#include "io/io_internal.h"
#include "io/ply_header.h"
#include "pfsph/io.h"

int pfsph_write_ply(const char *path, const pfsph_particles *ps, const pfsph_io_opts *o, pfsph_error *err)
{
    if (o && o->aux_name) {
        int r = pfsph__check_aux_name(path, o->aux_name, err);
        if (r != PFSPH_OK) return r;
    }
    pfsph__frame_layout L; /* the header and the record: io/frame_layout.c */
    if (pfsph__ply_layout(&L, ps->n, o)) return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    int rc = pfsph__frame_write(path, &L, ps, err);
    pfsph__frame_layout_free(&L);
    return rc;
}

/* ---- reader ---------------------------------------------------------------------------- */

int pfsph_read_ply(const char *path, pfsph_particles *ps, double *time, pfsph_error *err)
{
    unsigned char *buf;
    size_t len;
    int rc = pfsph__reader_open(path, ps, sizeof *ps, &buf, &len, time, err);
    if (rc != PFSPH_OK) return rc;
    static const pfsph__ply_spec spec = {.what = "PLY file", .elems = {"vertex"}, .unique = true};
#define BAD(...) PFSPH__BAD(spec.what, __VA_ARGS__)
    pfsph__ply_header h;
    rc = pfsph__ply_header_read(buf, len, path, &spec, &h, time, err);
    if (rc != PFSPH_OK) goto done;
    if (h.nelems == 0) BAD("no vertex element");
    const pfsph__ply_prop *props = h.elem[0].prop;
    const int np = h.elem[0].nprops;
    const size_t rec = h.elem[0].rec, pos = h.data;
    const uint64_t nvert = h.elem[0].count;
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
    pfsph_real *rdst[PFSPH__PLY_MAX_PROPS] = {0};
    int kind[PFSPH__PLY_MAX_PROPS] = {0}; /* 0 skip, 1 real, 2 phase, 3 id */
    bool have_aux = false, have_xyz[3] = {false, false, false};
    for (int k = 0; k < np; k++) {
        const pfsph__ply_prop *pr = &props[k];
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
