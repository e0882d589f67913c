/* RUN/solids.ply and RUN/solids.obj: the scene's static solids as triangle meshes, written once
 * per run (solid_mesh.h; docs/artists.md#static-solids). */
#include <stdio.h>
#include <stdlib.h>

#include "io/io_internal.h"
#include "pfsph/solid_mesh.h"

static const char *shape_name(int shape)
{
    static const char *const names[] = {"box", "sphere", "cylinder", "container", "plane"};
    return shape >= 0 && shape < 5 ? names[shape] : "solid";
}

static int write_ply(const char *path, const pfsph_scene *s, const pfsph_mesh *m, const int *which, int n,
                     pfsph_error *err)
{
    size_t nv = 0, nt = 0;
    for (int k = 0; k < n; k++) nv += m[k].nverts, nt += m[k].ntris;
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    pfsph__enc_printf(&e, "ply\nformat binary_little_endian 1.0\ncomment pfsph %s\n", PFSPH_VERSION);
    for (int k = 0; k < n; k++) {
        const pfsph_solid *o = &s->solids[which[k]];
        pfsph__enc_printf(&e, "comment solid %d %s %s\n", which[k], shape_name(o->shape), s->phases[o->phase].name);
    }
    pfsph__enc_printf(&e, "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n", nv);
    pfsph__enc_printf(&e,
                      "element face %zu\nproperty list uchar uint vertex_indices\nproperty uchar solid\n"
                      "property uchar phase\nend_header\n",
                      nt);
    for (int k = 0; k < n; k++)
        for (size_t i = 0; i < 3 * m[k].nverts; i++) {
            float v = (float)m[k].v[i];
            pfsph__enc_put(&e, &v, 4);
        }
    uint32_t base = 0;
    for (int k = 0; k < n; k++) {
        const uint8_t three = 3, solid = (uint8_t)which[k], phase = (uint8_t)s->solids[which[k]].phase;
        for (size_t t = 0; t < m[k].ntris; t++) {
            pfsph__enc_put(&e, &three, 1);
            for (int c = 0; c < 3; c++) {
                uint32_t idx = base + m[k].tri[3 * t + c];
                pfsph__enc_put(&e, &idx, 4);
            }
            pfsph__enc_put(&e, &solid, 1);
            pfsph__enc_put(&e, &phase, 1);
        }
        base += (uint32_t)m[k].nverts;
    }
    return pfsph__enc_commit(&e, &af, err);
}

static int write_obj(const char *path, const pfsph_scene *s, const pfsph_mesh *m, const int *which, int n,
                     pfsph_error *err)
{
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    pfsph__enc_printf(&e, "# pfsph %s: static solids, metres, y up (docs/artists.md)\n", PFSPH_VERSION);
    size_t base = 1;
    for (int k = 0; k < n; k++) {
        const pfsph_solid *o = &s->solids[which[k]];
        pfsph__enc_printf(&e, "o solid_%d_%s\n", which[k], s->phases[o->phase].name);
        for (size_t i = 0; i < m[k].nverts; i++)
            pfsph__enc_printf(&e, "v %.9g %.9g %.9g\n", m[k].v[3 * i], m[k].v[3 * i + 1], m[k].v[3 * i + 2]);
        for (size_t t = 0; t < m[k].ntris; t++)
            pfsph__enc_printf(&e, "f %zu %zu %zu\n", base + m[k].tri[3 * t], base + m[k].tri[3 * t + 1],
                              base + m[k].tri[3 * t + 2]);
        base += m[k].nverts;
    }
    return pfsph__enc_commit(&e, &af, err);
}

int pfsph_write_solids(const pfsph_scene *s, const char *dir, int *count, pfsph_error *err)
{
    *count = 0;
    if (s->dim != 3 || s->nsolids <= 0) return PFSPH_OK;
    pfsph_mesh *m = calloc((size_t)s->nsolids, sizeof *m);
    int *which = calloc((size_t)s->nsolids, sizeof *which), n = 0, rc = PFSPH_OK;
    if (!m || !which) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    /* a solid without a surface (a plane outside the domain) is left out */
    for (int k = 0; k < s->nsolids && !rc; k++) {
        int r = pfsph_solid_mesh(s, &s->solids[k], &m[n]);
        if (r == PFSPH_ENOMEM) rc = pfsph_fail(err, r, "out of memory");
        else if (!r) which[n++] = k;
    }
    char path[PFSPH_PATH_LEN + 32];
    if (!rc && n) {
        snprintf(path, sizeof path, "%s/solids.ply", dir);
        rc = write_ply(path, s, m, which, n, err);
    }
    if (!rc && n) {
        snprintf(path, sizeof path, "%s/solids.obj", dir);
        rc = write_obj(path, s, m, which, n, err);
    }
    for (int k = 0; m && k < n; k++) pfsph_mesh_free(&m[k]);
    free(m);
    free(which);
    if (!rc) *count = n;
    return rc;
}
