/* `pfsph export RUN --houdini`: a run's frames as Houdini geometry (houdini.h): fluid and diffuse
 * particles as point clouds (ordered by id when the run wrote ids), pscale and their fields, liquid meshes with velocity,
 * body surfaces and the static solids as polygons; binary JSON (.bgeo) or JSON text (.geo). */
#include "pfsph/houdini.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/hgeo.h"
#include "io/io_internal.h"
#include "pfsph/io.h"
#include "pfsph/meshing.h"
#include "pfsph/scene.h"
#include "pfsph/solid_mesh.h"

/* whether the first 64 KiB of a frame file (its header) name an `id` array or property */
static int has_ids(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    static char buf[65537];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    for (size_t i = 0; i + 9 < n; i++)
        if (!memcmp(buf + i, "Name=\"id\"", 9) || !memcmp(buf + i, "uint id\n", 8)) return 1;
    return 0;
}

static int cmp_id(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : (x > y);
}

/* A particle frame as points: ordered by id when the frame has ids (so that point k is the same
 * particle in every frame), P v [id] pscale, then density pressure phase (fluid) or type
 * lifetime (diffuse). */
static int write_points(const char *in, const char *out, int binary, int diffuse, double pscale, int *no_ids,
                        pfsph_error *err)
{
    pfsph_particles ps;
    double t = 0;
    size_t len = strlen(in);
    int rc = !strcmp(in + len - 3, "vtp") ? pfsph_read_vtp(in, &ps, &t, err) : pfsph_read_ply(in, &ps, &t, err);
    if (rc) return rc;
    const int ids = has_ids(in);
    if (!ids) *no_ids = 1;
    const size_t n = ps.n;
    uint64_t *order = malloc((n ? n : 1) * sizeof *order);
    float *P = malloc(3 * (n ? n : 1) * sizeof *P), *V = malloc(3 * (n ? n : 1) * sizeof *V);
    float *sc = malloc((n ? n : 1) * sizeof *sc), *a1 = malloc((n ? n : 1) * sizeof *a1),
          *a2 = malloc((n ? n : 1) * sizeof *a2);
    int32_t *id = malloc((n ? n : 1) * sizeof *id), *ph = malloc((n ? n : 1) * sizeof *ph);
    if (!order || !P || !V || !sc || !a1 || !a2 || !id || !ph) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    for (size_t i = 0; !rc && i < n; i++) order[i] = ids ? ((uint64_t)ps.id[i] << 32 | i) : i;
    if (!rc && ids) qsort(order, n, sizeof *order, cmp_id);
    for (size_t k = 0; !rc && k < n; k++) {
        size_t i = (size_t)(order[k] & 0xffffffffu);
        P[3 * k] = (float)ps.x[i], P[3 * k + 1] = (float)ps.y[i], P[3 * k + 2] = (float)ps.z[i];
        V[3 * k] = (float)ps.vx[i], V[3 * k + 1] = (float)ps.vy[i], V[3 * k + 2] = (float)ps.vz[i];
        sc[k] = (float)pscale;
        id[k] = (int32_t)ps.id[i];
        ph[k] = ps.phase[i];
        a1[k] = diffuse ? (float)ps.aux[i] : (float)ps.rho[i];
        a2[k] = (float)ps.p[i];
    }
    if (!rc) {
        pfsph__hattr at[8] = {{.name = "P", .size = 3, .f = P, .typeinfo = "point"},
                              {.name = "v", .size = 3, .f = V, .typeinfo = "vector"},
                              {.name = "pscale", .size = 1, .f = sc}};
        int na = 3;
        if (ids) at[na++] = (pfsph__hattr){.name = "id", .size = 1, .i = id};
        if (diffuse) {
            at[na++] = (pfsph__hattr){.name = "type", .size = 1, .i = ph};
            at[na++] = (pfsph__hattr){.name = "lifetime", .size = 1, .f = a1};
        } else {
            at[na++] = (pfsph__hattr){.name = "density", .size = 1, .f = a1};
            at[na++] = (pfsph__hattr){.name = "pressure", .size = 1, .f = a2};
            at[na++] = (pfsph__hattr){.name = "phase", .size = 1, .i = ph};
        }
        pfsph__hgeo g = {.npoints = n, .npattr = na, .pattr = at};
        rc = pfsph__hgeo_write(out, binary, &g, err);
    }
    free(order), free(P), free(V), free(sc), free(a1), free(a2), free(id), free(ph);
    pfsph_particles_free(&ps);
    return rc;
}

/* A surface PLY (liquid or bodies) as polygons: P, N and v where the file has them, the face tag
 * as the primitive attribute `tag` ("phase" or "body"; bodies also get `name`). */
static int write_mesh(const char *in, const char *out, int binary, const char *tag, const pfsph_scene *s,
                      pfsph_error *err)
{
    pfsph_surface_mesh m;
    double t = 0;
    int rc = pfsph_read_surface_ply(in, &m, &t, err);
    if (rc) return rc;
    float *P = malloc(3 * (m.nverts ? m.nverts : 1) * sizeof *P);
    int32_t *tg = malloc((m.ntris ? m.ntris : 1) * sizeof *tg);
    const char *names[PFSPH_MAX_BODIES];
    int nn = s->nbodies < PFSPH_MAX_BODIES ? s->nbodies : PFSPH_MAX_BODIES;
    for (int b = 0; b < nn; b++) names[b] = s->bodies[b].name;
    if (!P || !tg) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    for (size_t i = 0; !rc && i < 3 * m.nverts; i++) P[i] = (float)m.v[i];
    for (size_t k = 0; !rc && k < m.ntris; k++) tg[k] = m.phase[k];
    if (!rc) {
        pfsph__hattr pa[3] = {{.name = "P", .size = 3, .f = P, .typeinfo = "point"}};
        int np = 1;
        if (m.n) pa[np++] = (pfsph__hattr){.name = "N", .size = 3, .f = m.n, .typeinfo = "normal"};
        if (m.vel) pa[np++] = (pfsph__hattr){.name = "v", .size = 3, .f = m.vel, .typeinfo = "vector"};
        pfsph__hattr pr[2] = {{.name = tag, .size = 1, .i = tg}};
        int npr = 1;
        int named = !strcmp(tag, "body") && nn > 0;
        for (size_t k = 0; named && k < m.ntris; k++)
            if (tg[k] >= nn) named = 0;
        if (named) pr[npr++] = (pfsph__hattr){.name = "name", .size = 1, .i = tg, .s = names, .nstrings = nn};
        pfsph__hgeo g = {.npoints = m.nverts,
                         .ntris = m.ntris,
                         .tri = m.tri,
                         .npattr = np,
                         .pattr = pa,
                         .nprattr = npr,
                         .prattr = pr};
        rc = pfsph__hgeo_write(out, binary, &g, err);
    }
    free(P);
    free(tg);
    pfsph_surface_mesh_free(&m);
    return rc;
}

/* RUN/solids.bgeo: every static solid's triangles, primitive attributes solid, phase and name */
static int write_solids(const pfsph_scene *s, const char *out, int binary, int *count, pfsph_error *err)
{
    *count = 0;
    if (s->dim != 3 || s->nsolids <= 0) return PFSPH_OK;
    pfsph_mesh all = {0};
    size_t cap = 0;
    int32_t *sid = NULL, *sph = NULL;
    int rc = PFSPH_OK;
    char namebuf[PFSPH_MAX_SOLIDS][PFSPH_NAME_LEN + 32];
    const char *names[PFSPH_MAX_SOLIDS];
    static const char *const shape[] = {"box", "sphere", "cylinder", "container", "plane"};
    for (int k = 0; k < s->nsolids && !rc; k++) {
        const pfsph_solid *o = &s->solids[k];
        snprintf(namebuf[k], sizeof namebuf[k], "solid_%d_%s", k,
                 o->shape >= 0 && o->shape < 5 ? shape[o->shape] : "solid");
        names[k] = namebuf[k];
        pfsph_mesh m;
        if (pfsph_solid_mesh(s, o, &m)) continue;
        size_t nt = all.ntris + m.ntris;
        if (nt > cap) {
            cap = 2 * nt;
            int32_t *a = realloc(sid, cap * sizeof *a), *b = realloc(sph, cap * sizeof *b);
            if (a) sid = a;
            if (b) sph = b;
            if (!a || !b) rc = PFSPH_ENOMEM;
        }
        double *v = rc ? NULL : realloc(all.v, 3 * (all.nverts + m.nverts) * sizeof *v);
        if (v) all.v = v;
        uint32_t *tr = rc || !v ? NULL : realloc(all.tri, 3 * nt * sizeof *tr);
        if (tr) all.tri = tr;
        if (!v || !tr) rc = PFSPH_ENOMEM;
        if (!rc) {
            memcpy(all.v + 3 * all.nverts, m.v, 3 * m.nverts * sizeof *v);
            for (size_t i = 0; i < m.ntris; i++) {
                for (int c = 0; c < 3; c++)
                    all.tri[3 * (all.ntris + i) + (size_t)c] = m.tri[3 * i + (size_t)c] + (uint32_t)all.nverts;
                sid[all.ntris + i] = k;
                sph[all.ntris + i] = o->phase;
            }
            all.nverts += m.nverts;
            all.ntris = nt;
            (*count)++;
        }
        pfsph_mesh_free(&m);
    }
    float *P = rc ? NULL : malloc(3 * (all.nverts ? all.nverts : 1) * sizeof *P);
    if (!rc && !P) rc = PFSPH_ENOMEM;
    if (rc) rc = pfsph_fail(err, rc, "out of memory");
    for (size_t i = 0; !rc && i < 3 * all.nverts; i++) P[i] = (float)all.v[i];
    if (!rc && *count) {
        pfsph__hattr pa[1] = {{.name = "P", .size = 3, .f = P, .typeinfo = "point"}};
        pfsph__hattr pr[3] = {{.name = "solid", .size = 1, .i = sid},
                              {.name = "phase", .size = 1, .i = sph},
                              {.name = "name", .size = 1, .i = sid, .s = names, .nstrings = s->nsolids}};
        pfsph__hgeo g = {.npoints = all.nverts,
                         .ntris = all.ntris,
                         .tri = all.tri,
                         .npattr = 1,
                         .pattr = pa,
                         .nprattr = 3,
                         .prattr = pr};
        rc = pfsph__hgeo_write(out, binary, &g, err);
    }
    free(P), free(sid), free(sph);
    pfsph_mesh_free(&all);
    return rc;
}

/* frames/<set>_NNNNN.<ext> for the first extension that exists; 0 when none */
static int find_frame(char *path, size_t cap, const char *dir, const char *set, long k, const char *const *exts)
{
    for (int e = 0; exts[e]; e++) {
        snprintf(path, cap, "%s/frames/%s_%05ld.%s", dir, set, k, exts[e]);
        FILE *f = fopen(path, "rb");
        if (f) {
            fclose(f);
            return 1;
        }
    }
    return 0;
}

int pfsph_export_houdini(const char *dir, int format, pfsph_houdini_report *rep, pfsph_error *err)
{
    memset(rep, 0, sizeof *rep);
    char path[PFSPH_PATH_LEN + 64], out[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/scene.json", dir);
    pfsph_scene *s = calloc(1, sizeof *s);
    if (!s) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    int rc = pfsph_scene_load(s, path, err);
    if (rc) {
        free(s);
        return rc;
    }
    const int binary = format == PFSPH_HOUDINI_BGEO;
    const char *ext = binary ? "bgeo" : "geo";
    static const char *const particles[] = {"vtp", "ply", NULL}, *const meshes[] = {"ply", NULL};
    int misses = 0;
    for (long k = 0; k < 1000000 && !rc && misses < 1000; k++) {
        if (!find_frame(path, sizeof path, dir, "fluid", k, particles)) {
            misses++; /* gaps from a frame interval or a resume */
            continue;
        }
        misses = 0;
        snprintf(out, sizeof out, "%s/frames/fluid_%05ld.%s", dir, k, ext);
        if (format == PFSPH_HOUDINI_CLASSIC) {
            pfsph_particles ps;
            double t = 0;
            rc = path[strlen(path) - 1] == 'p' && path[strlen(path) - 2] == 't' ? pfsph_read_vtp(path, &ps, &t, err)
                                                                                : pfsph_read_ply(path, &ps, &t, err);
            if (!rc) rc = pfsph_write_houdini_geo(out, &ps, t, err);
            if (!rc) pfsph_particles_free(&ps);
            if (!rc) rep->frames++;
            continue;
        }
        rc = write_points(path, out, binary, 0, s->particle_radius, &rep->no_ids, err);
        if (!rc) rep->frames++;
        if (!rc && find_frame(path, sizeof path, dir, "diffuse", k, particles)) {
            snprintf(out, sizeof out, "%s/frames/diffuse_%05ld.%s", dir, k, ext);
            rc = write_points(path, out, binary, 1, 0.5 * s->particle_radius, &rep->no_ids, err);
            if (!rc) rep->diffuse++;
        }
        if (!rc && find_frame(path, sizeof path, dir, "liquid", k, meshes)) {
            snprintf(out, sizeof out, "%s/frames/liquid_%05ld.%s", dir, k, ext);
            rc = write_mesh(path, out, binary, "phase", s, err);
            if (!rc) rep->liquid++;
        }
        if (!rc && find_frame(path, sizeof path, dir, "surfaces", k, meshes)) {
            snprintf(out, sizeof out, "%s/frames/bodies_%05ld.%s", dir, k, ext);
            rc = write_mesh(path, out, binary, "body", s, err);
            if (!rc) rep->bodies++;
        }
    }
    if (!rc && !rep->frames)
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: no fluid frames (frames/fluid_NNNNN.vtp or .ply)", dir);
    if (!rc && format != PFSPH_HOUDINI_CLASSIC) {
        snprintf(out, sizeof out, "%s/solids.%s", dir, ext);
        rc = write_solids(s, out, binary, &rep->solids, err);
    }
    free(s);
    return rc;
}
