/* Houdini's classic ASCII geometry (.geo, "PGEOMETRY V5" as SideFX documents it): points with v,
 * density, pressure, phase and id attributes, no primitives; a reader of the same subset. `pfsph
 * export --houdini --classic` (the JSON and binary geometry: houdini.c). */
#include "pfsph/houdini.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"
#include "pfsph/io.h"

int pfsph_write_houdini_geo(const char *path, const pfsph_particles *ps, double time, pfsph_error *err)
{
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    (void)time; /* the frame number gives it; no detail attribute, to stay in the documented core */
    pfsph__enc_printf(&e,
                      "PGEOMETRY V5\nNPoints %zu NPrims 0\nNPointGroups 0 NPrimGroups 0\n"
                      "NPointAttrib 5 NVertexAttrib 0 NPrimAttrib 0 NAttrib 0\n",
                      ps->n);
    pfsph__enc_printf(&e,
                      "PointAttrib\nv 3 vector 0 0 0\ndensity 1 float 0\npressure 1 float 0\n"
                      "phase 1 int 0\nid 1 int 0\n");
    for (size_t i = 0; i < ps->n; i++)
        pfsph__enc_printf(&e, "%.9g %.9g %.9g 1 (%.9g %.9g %.9g %.9g %.9g %d %u)\n", (double)ps->x[i], (double)ps->y[i],
                          (double)ps->z[i], (double)ps->vx[i], (double)ps->vy[i], (double)ps->vz[i], (double)ps->rho[i],
                          (double)ps->p[i], ps->phase[i], ps->id[i]);
    pfsph__enc_printf(&e, "beginExtra\nendExtra\n");
    return pfsph__enc_commit(&e, &af, err);
}

#define BAD(...)                                                           \
    do {                                                                   \
        char why_[256];                                                    \
        snprintf(why_, sizeof why_, __VA_ARGS__);                          \
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s:%d: %s", path, line, why_); \
        goto out;                                                          \
    } while (0)

/* the next line of text (NUL-terminated in place); NULL at the end */
static char *next_line(char **p)
{
    if (!**p) return NULL;
    char *s = *p, *nl = strchr(s, '\n');
    if (nl) {
        *nl = 0;
        *p = nl + 1;
    } else *p = s + strlen(s);
    return s;
}

int pfsph_read_houdini_geo(const char *path, pfsph_particles *ps, double *time, pfsph_error *err)
{
    unsigned char *data = NULL;
    size_t len;
    int rc = pfsph__read_file(path, &data, &len, err), line = 0;
    memset(ps, 0, sizeof *ps);
    if (rc) return rc;
    if (time) *time = 0;
    char *p = (char *)data, *l;
    size_t np = 0, nprims = 1;
    int nattr = -1, slot[16]; /* value offsets per known attribute: v, density, pressure, phase, id */
    int width = 0;
    for (int k = 0; k < 16; k++) slot[k] = -1;
    if (!(l = next_line(&p)) || (line++, strcmp(l, "PGEOMETRY V5"))) BAD("not a PGEOMETRY V5 file");
    if (!(l = next_line(&p)) || (line++, sscanf(l, "NPoints %zu NPrims %zu", &np, &nprims) != 2))
        BAD("expected NPoints # NPrims #");
    if (nprims != 0) BAD("primitives are not read (points only)");
    if (np > 100000000) BAD("too many points (%zu)", np);
    if (!(l = next_line(&p))) BAD("truncated");
    line++;
    if (!(l = next_line(&p)) || (line++, sscanf(l, "NPointAttrib %d", &nattr) != 1) || nattr < 0 || nattr > 64)
        BAD("expected NPointAttrib #");
    if (nattr > 0) {
        if (!(l = next_line(&p)) || (line++, strcmp(l, "PointAttrib"))) BAD("expected PointAttrib");
        for (int a = 0; a < nattr; a++) {
            char name[64], type[16];
            int size;
            if (!(l = next_line(&p)) || (line++, sscanf(l, "%63s %d %15s", name, &size, type) != 3) || size < 1 ||
                size > 16)
                BAD("bad attribute definition");
            static const char *const known[] = {"v", "density", "pressure", "phase", "id"};
            static const int ksize[] = {3, 1, 1, 1, 1};
            for (int k = 0; k < 5; k++)
                if (!strcmp(name, known[k])) {
                    if (size != ksize[k]) BAD("attribute %s must have %d values", name, ksize[k]);
                    slot[k] = width;
                }
            width += size;
        }
    }
    if ((rc = pfsph_particles_init(ps, np ? np : 1))) goto out;
    double vals[256];
    if (width > 256) BAD("attributes too wide");
    for (size_t i = 0; i < np; i++) {
        if (!(l = next_line(&p))) BAD("truncated: %zu of %zu points", i, np);
        line++;
        char *s = l, *end;
        double xyzw[4];
        for (int k = 0; k < 4; k++) {
            xyzw[k] = strtod(s, &end);
            if (end == s) BAD("expected x y z w");
            s = end;
        }
        while (*s == ' ') s++;
        if (width) {
            if (*s++ != '(') BAD("expected '(' before the attribute values");
            for (int k = 0; k < width; k++) {
                vals[k] = strtod(s, &end);
                if (end == s) BAD("expected %d attribute values", width);
                s = end;
            }
            while (*s == ' ') s++;
            if (*s != ')') BAD("expected ')'");
        }
        ps->x[i] = (pfsph_real)xyzw[0];
        ps->y[i] = (pfsph_real)xyzw[1];
        ps->z[i] = (pfsph_real)xyzw[2];
        if (slot[0] >= 0) {
            ps->vx[i] = (pfsph_real)vals[slot[0]];
            ps->vy[i] = (pfsph_real)vals[slot[0] + 1];
            ps->vz[i] = (pfsph_real)vals[slot[0] + 2];
        }
        if (slot[1] >= 0) ps->rho[i] = (pfsph_real)vals[slot[1]];
        if (slot[2] >= 0) ps->p[i] = (pfsph_real)vals[slot[2]];
        if (slot[3] >= 0) {
            if (!(vals[slot[3]] >= 0 && vals[slot[3]] <= 255)) BAD("phase out of range");
            ps->phase[i] = (uint8_t)vals[slot[3]];
        }
        if (slot[4] >= 0) {
            if (!(vals[slot[4]] >= 0 && vals[slot[4]] <= 4294967295.0)) BAD("id out of range");
            ps->id[i] = (uint32_t)vals[slot[4]];
        }
    }
    ps->n = np;
    if (!(l = next_line(&p)) || (line++, strcmp(l, "beginExtra"))) BAD("expected beginExtra");
    rc = PFSPH_OK;
out:
    free(data);
    if (rc) pfsph_particles_free(ps);
    return rc;
}
