/* Liquid surface files (PLY, OBJ, VTP with the phase per face; 2D outlines as VTP polylines),
 * meshing a run's frames, and the ParaView .pvd collections of a run directory. */
#include "pfsph/meshing.h"

#include <dirent.h>
#include <inttypes.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"
#include "io/ply_header.h"
#include "pfsph/io.h"
#include "pfsph/vdb.h"

int pfsph_write_surface_ply(const char *path, const pfsph_surface_mesh *m, double time, pfsph_error *err)
{
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    pfsph__enc_printf(&e, "ply\nformat binary_little_endian 1.0\ncomment pfsph %s liquid surface\n", PFSPH_VERSION);
    pfsph__enc_printf(&e, "comment time %.17g\n", time);
    pfsph__enc_printf(&e,
                      "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                      "property float nx\nproperty float ny\nproperty float nz\n",
                      m->nverts);
    if (m->vel) pfsph__enc_printf(&e, "property float vx\nproperty float vy\nproperty float vz\n");
    pfsph__enc_printf(&e,
                      "element face %zu\nproperty list uchar uint vertex_indices\nproperty uchar phase\n"
                      "end_header\n",
                      m->ntris);
    for (size_t i = 0; i < m->nverts; i++) {
        for (int k = 0; k < 3; k++) {
            float v = (float)m->v[3 * i + k];
            pfsph__enc_put(&e, &v, 4);
        }
        for (int k = 0; k < 3; k++) pfsph__enc_put(&e, &m->n[3 * i + k], 4);
        if (m->vel)
            for (int k = 0; k < 3; k++) pfsph__enc_put(&e, &m->vel[3 * i + k], 4);
    }
    const uint8_t three = 3;
    for (size_t t = 0; t < m->ntris; t++) {
        pfsph__enc_put(&e, &three, 1);
        for (int k = 0; k < 3; k++) pfsph__enc_put(&e, &m->tri[3 * t + k], 4);
        pfsph__enc_put(&e, &m->phase[t], 1);
    }
    return pfsph__enc_commit(&e, &af, err);
}

int pfsph_write_surface_obj(const char *path, const pfsph_surface_mesh *m, double time, pfsph_error *err)
{
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    pfsph__enc_printf(&e, "# pfsph %s liquid surface, time %.17g s\n", PFSPH_VERSION, time);
    for (size_t i = 0; i < m->nverts; i++)
        pfsph__enc_printf(&e, "v %.7g %.7g %.7g\n", m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2]);
    for (size_t i = 0; i < m->nverts; i++)
        pfsph__enc_printf(&e, "vn %.5f %.5f %.5f\n", m->n[3 * i], m->n[3 * i + 1], m->n[3 * i + 2]);
    for (size_t t = 0; t < m->ntris; t++) {
        if (t == 0 || m->phase[t] != m->phase[t - 1]) pfsph__enc_printf(&e, "g phase_%d\n", m->phase[t]);
        uint32_t a = m->tri[3 * t] + 1, b = m->tri[3 * t + 1] + 1, c = m->tri[3 * t + 2] + 1;
        pfsph__enc_printf(&e, "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
    }
    return pfsph__enc_commit(&e, &af, err);
}

/* VTP PolyData of a mesh or an outline: points, Normals and velocity (when vel is not NULL) as
 * point data, cells of `arity` indices under `cells` ("Polys" or "Lines"), phase (cell data),
 * TimeValue. Atomic. */
static int write_polydata_vtp(const char *path, const double *v, const float *nrm, const float *vel, size_t nverts,
                              const uint32_t *idx, const uint8_t *phase, size_t ncells, int arity, const char *cells,
                              double time, pfsph_error *err)
{
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    pfsph__enc_printf(&e,
                      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" "
                      "byte_order=\"LittleEndian\">\n<PolyData>\n");
    pfsph__enc_printf(&e,
                      "<FieldData>\n<DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
                      "format=\"ascii\">%.17g</DataArray>\n</FieldData>\n",
                      time);
    pfsph__enc_printf(&e,
                      "<Piece NumberOfPoints=\"%zu\" NumberOf%s=\"%zu\">\n<Points>\n<DataArray type=\"Float32\" "
                      "NumberOfComponents=\"3\" format=\"ascii\">\n",
                      nverts, cells, ncells);
    for (size_t i = 0; i < nverts; i++) pfsph__enc_printf(&e, "%.7g %.7g %.7g\n", v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    pfsph__enc_printf(&e,
                      "</DataArray>\n</Points>\n<PointData Normals=\"Normals\">\n<DataArray type=\"Float32\" "
                      "Name=\"Normals\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (size_t i = 0; i < nverts; i++)
        pfsph__enc_printf(&e, "%.5f %.5f %.5f\n", nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
    if (vel) {
        pfsph__enc_printf(&e,
                          "</DataArray>\n<DataArray type=\"Float32\" Name=\"velocity\" NumberOfComponents=\"3\" "
                          "format=\"ascii\">\n");
        for (size_t i = 0; i < nverts; i++)
            pfsph__enc_printf(&e, "%.7g %.7g %.7g\n", vel[3 * i], vel[3 * i + 1], vel[3 * i + 2]);
    }
    pfsph__enc_printf(
        &e, "</DataArray>\n</PointData>\n<%s>\n<DataArray type=\"UInt32\" Name=\"connectivity\" format=\"ascii\">\n",
        cells);
    for (size_t t = 0; t < ncells; t++) {
        const uint32_t *c = idx + (size_t)arity * t;
        if (arity == 3) pfsph__enc_printf(&e, "%u %u %u\n", c[0], c[1], c[2]);
        else pfsph__enc_printf(&e, "%u %u\n", c[0], c[1]);
    }
    pfsph__enc_printf(&e, "</DataArray>\n<DataArray type=\"UInt32\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t t = 1; t <= ncells; t++) pfsph__enc_printf(&e, "%zu\n", (size_t)arity * t);
    pfsph__enc_printf(&e,
                      "</DataArray>\n</%s>\n<CellData Scalars=\"phase\">\n<DataArray type=\"UInt8\" Name=\"phase\" "
                      "format=\"ascii\">\n",
                      cells);
    for (size_t t = 0; t < ncells; t++) pfsph__enc_printf(&e, "%d\n", phase[t]);
    pfsph__enc_printf(&e, "</DataArray>\n</CellData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    return pfsph__enc_commit(&e, &af, err);
}

int pfsph_write_surface_vtp(const char *path, const pfsph_surface_mesh *m, double time, pfsph_error *err)
{
    return write_polydata_vtp(path, m->v, m->n, m->vel, m->nverts, m->tri, m->phase, m->ntris, 3, "Polys", time, err);
}

/* ---- reader ---------------------------------------------------------------------------- */

int pfsph_read_surface_ply(const char *path, pfsph_surface_mesh *m, double *time, pfsph_error *err)
{
    unsigned char *buf;
    size_t len;
    int rc = pfsph__reader_open(path, m, sizeof *m, &buf, &len, time, err);
    if (rc != PFSPH_OK) return rc;
    static const pfsph__ply_spec spec = {.what = "surface PLY", .elems = {"vertex", "face"}, .lists = true};
#define BAD(...) PFSPH__BAD(spec.what, __VA_ARGS__)
    pfsph__ply_header h;
    rc = pfsph__ply_header_read(buf, len, path, &spec, &h, time, err);
    if (rc != PFSPH_OK) goto done;
    /* one list: the face's first property, its vertex indices */
    for (int e = 0; e < h.nelems; e++)
        for (int k = 0; k < h.elem[e].nprops; k++) {
            const pfsph__ply_prop *p = &h.elem[e].prop[k];
            if (e == 1 && k == 0) {
                if (!p->list) BAD("line %zu: vertex_indices must come first", p->line);
                if (strcmp(p->name, "vertex_indices") && strcmp(p->name, "vertex_index"))
                    BAD("line %zu: the only list must be the face's first property, vertex_indices", p->line);
                if (p->count_type != PFSPH__T_U8 || (p->type != PFSPH__T_U32 && p->type != PFSPH__T_I32))
                    BAD("line %zu: vertex_indices must be 'list uchar uint' (or int)", p->line);
            } else if (p->list) {
                BAD("line %zu: the only list must be the face's first property, vertex_indices", p->line);
            }
        }
    if (h.nelems < 2 || h.elem[1].nprops == 0) BAD("no face element with vertex_indices");
    const pfsph__ply_prop *vp = h.elem[0].prop, *fp = h.elem[1].prop;
    const int nvp = h.elem[0].nprops, nfp = h.elem[1].nprops;
    const size_t vrec = h.elem[0].rec, frec = h.elem[1].rec, pos = h.data; /* frec: the face's scalars */
    const uint64_t nv = h.elem[0].count, nt = h.elem[1].count;
    const int idx_type = fp[0].type;
    if (nv >= (1u << 31) || nt >= (1u << 31)) BAD("too many vertices or faces");
    int ix[3] = {-1, -1, -1}, in[3] = {-1, -1, -1}, iv[3] = {-1, -1, -1}, itag = -1;
    static const char *const pn[9] = {"x", "y", "z", "nx", "ny", "nz", "vx", "vy", "vz"};
    for (int k = 0; k < nvp; k++)
        for (int j = 0; j < 9; j++)
            if (!strcmp(vp[k].name, pn[j])) {
                if (vp[k].type != PFSPH__T_F32 && vp[k].type != PFSPH__T_F64)
                    BAD("property '%s' must be float or double", pn[j]);
                if (j < 3) ix[j] = k;
                else if (j < 6) in[j - 3] = k;
                else iv[j - 6] = k;
            }
    if (ix[0] < 0 || ix[1] < 0 || ix[2] < 0) BAD("missing x, y or z");
    const bool normals = in[0] >= 0 && in[1] >= 0 && in[2] >= 0, vels = iv[0] >= 0 && iv[1] >= 0 && iv[2] >= 0;
    /* the face's tag: the liquid's phase, or the body of a body surface */
    for (int k = 1; k < nfp; k++)
        if ((!strcmp(fp[k].name, "phase") || !strcmp(fp[k].name, "body")) && fp[k].type == PFSPH__T_U8) itag = k;
    const size_t isz = 4, frecord = 1 + 3 * isz + frec;
    size_t avail = len - pos;
    if ((vrec && nv > avail / vrec) || nv * vrec + nt * frecord != avail)
        BAD("%zu bytes of data, expected %" PRIu64 " vertices of %zu bytes and %" PRIu64 " triangles of %zu bytes",
            avail, nv, vrec, nt, frecord);
    m->v = malloc(3 * (nv ? nv : 1) * sizeof *m->v);
    m->n = normals ? malloc(3 * (nv ? nv : 1) * sizeof *m->n) : NULL;
    m->tri = malloc(3 * (nt ? nt : 1) * sizeof *m->tri);
    m->phase = calloc(nt ? nt : 1, 1);
    m->vel = vels ? malloc(3 * (nv ? nv : 1) * sizeof *m->vel) : NULL;
    if (!m->v || (normals && !m->n) || !m->tri || !m->phase || (vels && !m->vel)) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    const unsigned char *d = buf + pos;
    for (size_t i = 0; i < nv; i++, d += vrec) {
        for (int k = 0; k < 3; k++) m->v[3 * i + k] = pfsph__get_as_double(vp[ix[k]].type, d + vp[ix[k]].offset);
        if (normals)
            for (int k = 0; k < 3; k++)
                m->n[3 * i + k] = (float)pfsph__get_as_double(vp[in[k]].type, d + vp[in[k]].offset);
        if (vels)
            for (int k = 0; k < 3; k++)
                m->vel[3 * i + k] = (float)pfsph__get_as_double(vp[iv[k]].type, d + vp[iv[k]].offset);
    }
    for (size_t t = 0; t < nt; t++, d += frecord) {
        if (d[0] != 3) BAD("face %zu has %d vertices (triangles only)", t, d[0]);
        for (int k = 0; k < 3; k++) {
            double v = pfsph__get_as_double(idx_type, d + 1 + isz * k);
            if (!(v >= 0 && v < (double)nv)) BAD("face %zu: vertex index %.0f out of range", t, v);
            m->tri[3 * t + k] = (uint32_t)v;
        }
        if (itag >= 0) m->phase[t] = d[1 + 3 * isz + fp[itag].offset];
    }
    m->nverts = (size_t)nv;
    m->ntris = (size_t)nt;
    rc = PFSPH_OK;
done:
#undef BAD
    if (rc != PFSPH_OK) pfsph_surface_mesh_free(m);
    free(buf);
    return rc;
}

int pfsph_write_contour_vtp(const char *path, const pfsph_surface_contour *c, double time, pfsph_error *err)
{
    return write_polydata_vtp(path, c->v, c->n, NULL, c->nverts, c->seg, c->phase, c->nsegs, 2, "Lines", time, err);
}

static int mesh_particles(const pfsph_surface_output *so, int dim, double spacing, const char *dir, int frame,
                          const pfsph_particles *ps, double time, pfsph_surface_mesh *st, pfsph_error *err)
{
    double *x = malloc(3 * (ps->n ? ps->n : 1) * sizeof *x);
    if (!x) return pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    for (size_t i = 0; i < ps->n; i++) {
        x[3 * i] = ps->x[i];
        x[3 * i + 1] = ps->y[i];
        x[3 * i + 2] = ps->z[i];
    }
    pfsph_surface_opts o;
    pfsph_surface_opts_default(&o, spacing);
    o.isotropic = so->isotropic;
    o.smooth_iters = so->smoothing;
    o.cell = so->cell;
    o.droplet = so->droplet;
    char path[PFSPH_PATH_LEN + 64];
    if (dim == 2) { /* the outline as polylines, VTP only (docs/surfaces.md#2d-contours) */
        pfsph_surface_contour c;
        int rc = pfsph_surface_contour2d(x, ps->phase, ps->n, &o, &c, err);
        free(x);
        if (rc) return rc;
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.vtp", dir, frame);
        rc = pfsph_write_contour_vtp(path, &c, time, err);
        pfsph_surface_contour_free(&c);
        if (st) memset(st, 0, sizeof *st);
        return rc;
    }
    pfsph_surface_mesh m;
    int rc = pfsph_surface_reconstruct(x, ps->phase, ps->n, &o, &m, err);
    /* the liquid's velocity at the vertices (motion blur: docs/artists.md), from the particles
     * within 2 spacings (a vertex lies about half a spacing beyond the outer layer) */
    float *vel = rc ? NULL : malloc(3 * (ps->n ? ps->n : 1) * sizeof *vel);
    if (!rc && !vel) rc = pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    for (size_t i = 0; !rc && i < ps->n; i++) {
        vel[3 * i] = (float)ps->vx[i];
        vel[3 * i + 1] = (float)ps->vy[i];
        vel[3 * i + 2] = (float)ps->vz[i];
    }
    if (!rc && pfsph_surface_velocity(&m, x, vel, ps->n, 2 * spacing))
        rc = pfsph_fail(err, PFSPH_ENOMEM, "surface: out of memory");
    /* the level set for volume tools: voxels of the mesher's cell (docs/artists.md#openvdb-level-sets-houdini-blender) */
    if (!rc && so->vdb) {
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.vdb", dir, frame);
        pfsph_vdb_frame vf = {.mesh = &m,
                              .voxel = (so->cell > 0 ? so->cell : 0.5) * spacing,
                              .grids = so->vdb_grids ? so->vdb_grids : PFSPH_VDB_SURFACE | PFSPH_VDB_VELOCITY,
                              .x = x,
                              .v = vel,
                              .n = ps->n,
                              .radius = 2 * spacing,
                              .time = time};
        rc = pfsph_write_vdb(path, &vf, err);
    }
    free(vel);
    free(x);
    if (rc) {
        pfsph_surface_mesh_free(&m);
        return rc;
    }
    if (so->ply) {
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.ply", dir, frame);
        rc = pfsph_write_surface_ply(path, &m, time, err);
    }
    if (!rc && so->obj) {
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.obj", dir, frame);
        rc = pfsph_write_surface_obj(path, &m, time, err);
    }
    if (!rc && so->vtp) {
        snprintf(path, sizeof path, "%s/frames/liquid_%05d.vtp", dir, frame);
        rc = pfsph_write_surface_vtp(path, &m, time, err);
    }
    free(m.v);
    free(m.n);
    free(m.tri);
    free(m.phase);
    free(m.vel);
    m.vel = NULL;
    m.v = NULL;
    m.n = NULL;
    m.tri = NULL;
    m.phase = NULL;
    if (st) *st = m;
    return rc;
}

int pfsph_mesh_frame(const pfsph_scene *s, const char *dir, int frame, const pfsph_particles *fluid, double time,
                     pfsph_surface_mesh *st, pfsph_error *err)
{
    return mesh_particles(&s->output.surface, s->dim, 2 * s->particle_radius, dir, frame, fluid, time, st, err);
}

/* frame files "<set>_NNNNN.<ext>" in RUN/frames: the largest number, -1 when none */
static long last_frame(const char *frames, const char *set, const char *ext)
{
    DIR *d = opendir(frames);
    if (!d) return -1;
    long last = -1;
    size_t ls = strlen(set), le = strlen(ext);
    for (struct dirent *de; (de = readdir(d));) {
        const char *n = de->d_name;
        size_t len = strlen(n);
        if (len != ls + 1 + 5 + 1 + le || strncmp(n, set, ls) || n[ls] != '_' || n[ls + 6] != '.' ||
            strcmp(n + ls + 7, ext))
            continue;
        long k = 0;
        int ok = 1;
        for (int i = 0; i < 5; i++) {
            if (n[ls + 1 + i] < '0' || n[ls + 1 + i] > '9') ok = 0;
            k = 10 * k + (n[ls + 1 + i] - '0');
        }
        if (ok && k > last) last = k;
    }
    closedir(d);
    return last;
}

int pfsph_mesh_run(const char *dir, const pfsph_surface_output *over, int *frames, pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64], frames_dir[PFSPH_PATH_LEN + 16];
    *frames = 0;
    snprintf(path, sizeof path, "%s/scene.json", dir);
    FILE *probe = fopen(path, "rb");
    if (!probe) return pfsph_fail(err, PFSPH_EINPUT, "%s: not a run directory (no readable scene.json)", dir);
    fclose(probe);
    pfsph_scene *s = malloc(sizeof *s);
    if (!s) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    int rc = pfsph_scene_load(s, path, err);
    if (rc) {
        free(s);
        return rc;
    }
    pfsph_surface_output so = over ? *over : s->output.surface;
    if (!so.vdb_grids) so.vdb_grids = s->output.surface.vdb_grids;
    if (s->dim == 2) {
        /* only formats asked for here are refused: a 2D scene without output.surface keeps the
         * default ply, vtp, and `pfsph mesh` of such a run refused to do anything (issue 33's
         * attack, repeated) */
        if (over && (so.ply || so.obj || so.vdb)) {
            rc = pfsph_fail(err, PFSPH_EINPUT,
                            "%s: a 2D run: its outline is written as VTP polylines only "
                            "(--formats vtp); nothing written",
                            dir);
            free(s);
            return rc;
        }
        so.ply = so.obj = so.vdb = false;
        so.vtp = true;
    }
    if (!so.ply && !so.obj && !so.vtp && !so.vdb) so.ply = so.vtp = true;
    snprintf(frames_dir, sizeof frames_dir, "%s/frames", dir);
    const char *ext = "vtp";
    long last = last_frame(frames_dir, "fluid", ext);
    if (last < 0) {
        ext = "ply";
        last = last_frame(frames_dir, "fluid", ext);
    }
    if (last < 0) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: no fluid frames (frames/fluid_NNNNN.vtp or .ply)", dir);
        free(s);
        return rc;
    }
    const double frame_dt = s->output.frame_interval / s->fps;
    for (long k = 0; k <= last && !rc; k++) {
        snprintf(path, sizeof path, "%s/fluid_%05ld.%s", frames_dir, k, ext);
        FILE *f = fopen(path, "rb");
        if (!f) continue; /* a gap (frame_interval, a resume) */
        fclose(f);
        pfsph_particles ps;
        double t = k * frame_dt;
        rc = ext[0] == 'v' ? pfsph_read_vtp(path, &ps, &t, err) : pfsph_read_ply(path, &ps, &t, err);
        if (rc) break;
        rc = mesh_particles(&so, s->dim, 2 * s->particle_radius, dir, (int)k, &ps, t, NULL, err);
        pfsph_particles_free(&ps);
        if (!rc) (*frames)++;
    }
    if (!rc && so.vtp) rc = pfsph_write_pvd_collections(dir, frame_dt, err);
    free(s);
    return rc;
}

static int long_cmp(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return x < y ? -1 : (x > y);
}

int pfsph_write_pvd_collections(const char *dir, double frame_dt, pfsph_error *err)
{
    enum { NSETS = 6 };
    static const char *const sets[NSETS] = {"fluid", "boundary", "diffuse", "bodies", "surfaces", "liquid"};
    char frames_dir[PFSPH_PATH_LEN + 16], path[PFSPH_PATH_LEN + 64];
    snprintf(frames_dir, sizeof frames_dir, "%s/frames", dir);
    long *num[NSETS] = {NULL};
    size_t n[NSETS] = {0}, cap[NSETS] = {0};
    int rc = PFSPH_OK;
    /* one pass over the directory: the frame numbers of "<set>_NNNNN.vtp", or of "<set>_NNNNN.pvtp"
     * (a frame in pieces: output.pieces, docs/cluster.md), as 2 N + (1 for a .pvtp) */
    DIR *d = opendir(frames_dir);
    if (!d) return PFSPH_OK;
    for (struct dirent *de; (de = readdir(d)) && !rc;) {
        const char *nm = de->d_name;
        size_t len = strlen(nm);
        const int pv = len >= 12 && !strcmp(nm + len - 5, ".pvtp");
        if (len < 11 || (!pv && strcmp(nm + len - 4, ".vtp"))) continue;
        for (int k = 0; k < NSETS; k++) {
            size_t ls = strlen(sets[k]);
            if (len != ls + 10 + (size_t)pv || strncmp(nm, sets[k], ls) || nm[ls] != '_') continue;
            long v = 0;
            int ok = 1;
            for (int i = 0; i < 5; i++) {
                char c = nm[ls + 1 + i];
                if (c < '0' || c > '9') ok = 0;
                v = 10 * v + (c - '0');
            }
            if (!ok) continue;
            if (n[k] == cap[k]) {
                size_t nc = cap[k] ? 2 * cap[k] : 64;
                long *t = realloc(num[k], nc * sizeof *t);
                if (!t) {
                    rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
                    break;
                }
                num[k] = t;
                cap[k] = nc;
            }
            num[k][n[k]++] = 2 * v + pv;
        }
    }
    closedir(d);
    for (int k = 0; k < NSETS && !rc; k++) {
        if (!n[k]) continue;
        qsort(num[k], n[k], sizeof *num[k], long_cmp);
        const size_t line = 160; /* one DataSet line is at most about 100 characters */
        size_t bcap = 256 + n[k] * line, len = 0;
        char *buf = malloc(bcap);
        if (!buf) {
            rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            break;
        }
        len += (size_t)snprintf(buf + len, bcap - len,
                                "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" "
                                "version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n");
        for (size_t i = 0; i < n[k]; i++)
            len += (size_t)snprintf(
                buf + len, line, "<DataSet timestep=\"%.9g\" group=\"\" part=\"0\" file=\"frames/%s_%05ld.%s\"/>\n",
                (double)(num[k][i] / 2) * frame_dt, sets[k], num[k][i] / 2, num[k][i] % 2 ? "pvtp" : "vtp");
        len += (size_t)snprintf(buf + len, bcap - len, "</Collection>\n</VTKFile>\n");
        snprintf(path, sizeof path, "%s/%s.pvd", dir, sets[k]);
        rc = pfsph_write_file_atomic(path, buf, len, err);
        free(buf);
    }
    for (int k = 0; k < NSETS; k++) free(num[k]);
    return rc;
}
