/* The scene's output and camera blocks: formats, fields, intervals, surface meshes, checkpoints;
 * the preview camera (set, or framed on the domain). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/vdb.h"
#include "scene/scene_parser.h"

/* output.surface.vdb_grids: which grids a frame's .vdb holds */
static int parse_vdb_grids(parser *p, const cJSON *v, unsigned *grids)
{
    const char *P = "$.output.surface.vdb_grids";
    if (!v) return PFSPH_OK;
    if (!cJSON_IsArray(v) || !cJSON_GetArraySize(v))
        return pfsph__json_fail(&p->ctx, P,
                                "expected a non-empty array of strings (\"surface\", \"velocity\", \"density\")");
    *grids = 0;
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        char ep[64];
        path_index(ep, sizeof ep, P, i);
        const char *n = cJSON_IsString(e) ? e->valuestring : "";
        if (!strcmp(n, "surface")) *grids |= PFSPH_VDB_SURFACE;
        else if (!strcmp(n, "velocity")) *grids |= PFSPH_VDB_VELOCITY;
        else if (!strcmp(n, "density")) *grids |= PFSPH_VDB_DENSITY;
        else return pfsph__json_fail(&p->ctx, ep, "unknown grid (expected \"surface\", \"velocity\" or \"density\")");
    }
    return PFSPH_OK;
}

/* output.surface: true, false or {"formats", "smoothing", "isotropic", "cell", "droplet", "vdb_grids"} */
static int parse_surface(parser *p, const cJSON *v)
{
    pfsph_surface_output *o = &p->s->output.surface;
    if (!v) return PFSPH_OK;
    const char *P = "$.output.surface";
    if (cJSON_IsBool(v)) o->on = cJSON_IsTrue(v);
    else if (cJSON_IsObject(v)) {
        static const char *const keys[] = {"formats", "smoothing", "isotropic", "cell", "droplet", "vdb_grids", NULL};
        TRY(pfsph__json_check_keys(v, P, keys, &p->ctx));
        o->on = true;
        TRY(pfsph__json_int(v, P, "smoothing", 0, 100, &o->smoothing, &p->ctx));
        TRY(pfsph__json_bool(v, P, "isotropic", &o->isotropic, &p->ctx));
        TRY(pfsph__json_number(v, P, "cell", 0.2, 2.0, &o->cell, &p->ctx));
        TRY(pfsph__json_number(v, P, "droplet", -1, 2.0, &o->droplet, &p->ctx));
        if (o->droplet < 0 && o->droplet != -1)
            return pfsph__json_fail(&p->ctx, "$.output.surface.droplet",
                                    "expected -1 (no bound), 0 (default) or a radius in spacings up to 2");
        const cJSON *f = get(v, "formats");
        if (f) {
            if (!cJSON_IsArray(f) || !cJSON_GetArraySize(f))
                return pfsph__json_fail(&p->ctx, "$.output.surface.formats",
                                        "expected a non-empty array of strings (\"ply\", \"obj\", \"vtp\", \"vdb\")");
            o->ply = o->obj = o->vtp = o->vdb = false;
            int i = 0;
            for (const cJSON *e = f->child; e; e = e->next, i++) {
                char ep[64];
                path_index(ep, sizeof ep, "$.output.surface.formats", i);
                const char *n = cJSON_IsString(e) ? e->valuestring : "";
                if (!strcmp(n, "ply")) o->ply = true;
                else if (!strcmp(n, "obj")) o->obj = true;
                else if (!strcmp(n, "vtp")) o->vtp = true;
                else if (!strcmp(n, "vdb")) {
                    if (!pfsph_vdb_available())
                        return pfsph__json_fail(&p->ctx, ep,
                                                "\"vdb\": this build of pfsph has no OpenVDB (Debian: libopenvdb-dev, "
                                                "then rebuild; docs/artists.md#openvdb-level-sets-houdini-blender)");
                    o->vdb = true;
                } else
                    return pfsph__json_fail(&p->ctx, ep,
                                            "unknown format (expected \"ply\", \"obj\", \"vtp\" or \"vdb\")");
            }
        }
        TRY(parse_vdb_grids(p, get(v, "vdb_grids"), &o->vdb_grids));
    } else
        return pfsph__json_fail(&p->ctx, P,
                                "expected true, false or an object (formats, smoothing, isotropic, cell, droplet, "
                                "vdb_grids)");
    /* 2D: the outline as VTP polylines only (docs/surfaces.md#2d-contours) */
    if (o->on && p->s->dim == 2) {
        if (get(v, "formats") && (o->ply || o->obj || o->vdb))
            return pfsph__json_fail(&p->ctx, "$.output.surface.formats",
                                    "a 2D scene's outline is written as VTP polylines only (formats [\"vtp\"])");
        o->ply = o->obj = o->vdb = false;
        o->vtp = true;
    }
    return PFSPH_OK;
}

int pfsph__scene_parse_output(parser *p, const cJSON *root)
{
    pfsph_output *o = &p->s->output;
    const cJSON *v = get(root, "output");
    if (!v) return PFSPH_OK;
    static const char *const keys[] = {"directory",           "formats", "fields",        "boundary", "frame_interval",
                                       "checkpoint_interval", "surface", "surface_layer", "pieces",   NULL};
    const char *P = "$.output";
    TRY(pfsph__json_check_keys(v, P, keys, &p->ctx));
    TRY(parse_surface(p, get(v, "surface")));
    TRY(pfsph__json_string(v, P, "directory", o->dir, sizeof o->dir, &p->ctx));
    if (get(v, "directory") && !o->dir[0]) return pfsph__json_fail(&p->ctx, "$.output.directory", "must not be empty");
    TRY(pfsph__json_bool(v, P, "boundary", &o->write_boundary, &p->ctx));
    TRY(pfsph__json_bool(v, P, "surface_layer", &o->surface_layer, &p->ctx));
    TRY(pfsph__json_bool(v, P, "pieces", &o->pieces, &p->ctx));
    TRY(pfsph__json_int(v, P, "frame_interval", 1, 1000000, &o->frame_interval, &p->ctx));
    TRY(pfsph__json_int(v, P, "checkpoint_interval", 0, 1000000, &o->checkpoint_interval, &p->ctx));
    const cJSON *f = get(v, "formats");
    if (f) {
        static const char *const names[] = {"vtp", "ply", NULL};
        if (!cJSON_IsArray(f))
            return pfsph__json_fail(&p->ctx, "$.output.formats", "expected an array of strings (\"vtp\", \"ply\")");
        o->vtp = o->ply = false;
        int i = 0;
        for (const cJSON *e = f->child; e; e = e->next, i++) {
            char ep[64];
            path_index(ep, sizeof ep, "$.output.formats", i);
            int idx = -1;
            for (int k = 0; names[k] && cJSON_IsString(e); k++)
                if (strcmp(e->valuestring, names[k]) == 0) idx = k;
            if (idx < 0) return pfsph__json_fail(&p->ctx, ep, "unknown format (expected \"vtp\" or \"ply\")");
            if (idx == 0) o->vtp = true;
            else o->ply = true;
        }
    }
    const cJSON *fl = get(v, "fields");
    if (fl) {
        static const char *const names[] = {"id", "speed", NULL};
        static const unsigned bits[] = {PFSPH_OUT_ID, PFSPH_OUT_SPEED};
        if (!cJSON_IsArray(fl))
            return pfsph__json_fail(&p->ctx, "$.output.fields", "expected an array of strings (\"id\", \"speed\")");
        o->fields = 0;
        int i = 0;
        for (const cJSON *e = fl->child; e; e = e->next, i++) {
            char ep[64];
            path_index(ep, sizeof ep, "$.output.fields", i);
            int idx = -1;
            for (int k = 0; names[k] && cJSON_IsString(e); k++)
                if (strcmp(e->valuestring, names[k]) == 0) idx = k;
            if (idx < 0) return pfsph__json_fail(&p->ctx, ep, "unknown field (expected \"id\" or \"speed\")");
            o->fields |= bits[idx];
        }
    }
    if (o->pieces && !o->vtp)
        return pfsph__json_fail(&p->ctx, "$.output.pieces", "pieces are VTP files: needs \"vtp\" in $.output.formats");
    return PFSPH_OK;
}

int pfsph__scene_parse_camera(parser *p, const cJSON *root)
{
    pfsph_camera *c = &p->s->camera;
    const cJSON *v = get(root, "camera");
    if (!v) return PFSPH_OK;
    static const char *const keys[] = {"eye", "target", "up", "fov", "width", "height", "color_by", NULL};
    const char *P = "$.camera";
    TRY(pfsph__json_check_keys(v, P, keys, &p->ctx));
    c->set = true;
    /* The camera always lives in 3D: a 2D scene lies in the plane z = 0. */
    TRY(pfsph__json_vec(v, P, "eye", 3, -COORD_MAX, COORD_MAX, c->eye, &p->ctx));
    TRY(pfsph__json_vec(v, P, "target", 3, -COORD_MAX, COORD_MAX, c->target, &p->ctx));
    TRY(pfsph__json_vec(v, P, "up", 3, -1e3, 1e3, c->up, &p->ctx));
    TRY(pfsph__json_number(v, P, "fov", 1.0, 179.0, &c->fov_deg, &p->ctx));
    TRY(pfsph__json_int(v, P, "width", 16, 16384, &c->width, &p->ctx));
    TRY(pfsph__json_int(v, P, "height", 16, 16384, &c->height, &p->ctx));
    int cb = 0;
    static const char *const colors[] = {"phase", "speed", "density", "pressure", NULL};
    TRY(json_enum(p, v, P, "color_by", colors, &cb));
    snprintf(c->color_by, sizeof c->color_by, "%s", colors[cb]);
    double d[3], u2 = 0, d2 = 0, cr2 = 0;
    for (int k = 0; k < 3; k++) {
        d[k] = c->target[k] - c->eye[k];
        d2 += d[k] * d[k];
        u2 += c->up[k] * c->up[k];
    }
    if (!(d2 > 0)) return pfsph__json_fail(&p->ctx, "$.camera.target", "target equals eye");
    double cr[3] = {d[1] * c->up[2] - d[2] * c->up[1], d[2] * c->up[0] - d[0] * c->up[2],
                    d[0] * c->up[1] - d[1] * c->up[0]};
    for (int k = 0; k < 3; k++) cr2 += cr[k] * cr[k];
    if (!(u2 > 0) || !(cr2 > 1e-12 * d2 * u2))
        return pfsph__json_fail(&p->ctx, "$.camera.up", "up must be non-zero and not parallel to the view direction");
    return PFSPH_OK;
}

/* A camera framing the domain, used when the scene names none (and as defaults for the keys a
 * "camera" object leaves out). */
void pfsph__scene_auto_camera(pfsph_scene *s)
{
    pfsph_camera *c = &s->camera;
    double ext = 0;
    for (int k = 0; k < s->dim; k++) {
        c->target[k] = 0.5 * (s->domain_min[k] + s->domain_max[k]);
        ext = fmax(ext, s->domain_max[k] - s->domain_min[k]);
    }
    if (s->dim == 2) {
        c->target[2] = 0;
        c->eye[0] = c->target[0];
        c->eye[1] = c->target[1];
        c->eye[2] = 1.6 * ext;
    } else {
        c->eye[0] = c->target[0] + 0.35 * ext;
        c->eye[1] = c->target[1] + 0.45 * ext;
        c->eye[2] = c->target[2] + 1.4 * ext;
    }
}

/* File name without directory and ".json": default scene name and output directory. */
void pfsph__scene_source_stem(const char *source, char *out, size_t cap)
{
    const char *b = source ? strrchr(source, '/') : NULL;
    b = b ? b + 1 : (source ? source : "");
    size_t n = strlen(b);
    if (n > 5 && strcmp(b + n - 5, ".json") == 0) n -= 5;
    size_t m = 0;
    for (size_t i = 0; i < n && m + 1 < cap; i++) {
        char ch = b[i];
        bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
            ch == '-' || ch == '.';
        if (ok) out[m++] = ch;
    }
    out[m] = 0;
    if (!m) snprintf(out, cap, "scene");
}
