/* The "bodies" array of scene files: rigid bodies (dynamic or keyframed), validated key by key.
 * Keys, units and defaults: docs/bodies.md. Mesh files are only named here; they are read and
 * checked when the simulation is built (pfsph_bodies_create), so that parsing never touches
 * the file system. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/json_util.h"

#define COORD_MAX 1e6
/* A body's density, given or from its mass and volume (kg/m^3): lighter than the lightest
 * aerogels or heavier than ten times osmium is a typing error, and at the far ends the
 * masses and moments ODE is given underflow (it aborts on a zero inertia: issue 33). */
#define DENSITY_MIN 0.1
#define DENSITY_MAX 1e5

static const char *const shape_names[] = {"box", "sphere", "cylinder", "mesh", NULL};
static const char *const axis_names[] = {"x", "y", "z", NULL};

static int enum_key(const cJSON *e, const char *P, const char *key, const char *const *names, int *out, pfsph_jctx *ctx)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(e, key);
    if (!v) return PFSPH_OK;
    char kp[192];
    snprintf(kp, sizeof kp, "%s.%s", P, key);
    if (cJSON_IsString(v) && v->valuestring)
        for (int i = 0; names[i]; i++)
            if (strcmp(v->valuestring, names[i]) == 0) {
                *out = i;
                return PFSPH_OK;
            }
    char list[160] = "";
    size_t n = 0;
    for (int i = 0; names[i]; i++) {
        int w = snprintf(list + n, sizeof list - n, "%s\"%s\"", i ? ", " : "", names[i]);
        if (w > 0 && (size_t)w < sizeof list - n) n += (size_t)w;
    }
    return pfsph__json_fail(ctx, kp, "expected one of %s", list);
}

/* A vector of dim components (z = 0 in 2D), or of 3 when `full`. */
static int vec(const cJSON *e, const char *P, const char *key, int n, double lo, double hi, double *out,
               pfsph_jctx *ctx)
{
    if (!cJSON_GetObjectItemCaseSensitive(e, key)) return PFSPH_OK;
    int rc = pfsph__json_vec(e, P, key, n, lo, hi, out, ctx);
    if (rc) return rc;
    for (int k = n; k < 3; k++) out[k] = 0;
    return PFSPH_OK;
}

/* In 2D a rotation is one angle about z; in 3D three angles about x, y, z. */
static int rotation(const cJSON *e, const char *P, int dim, double *out, pfsph_jctx *ctx)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(e, "rotation");
    if (!v) return PFSPH_OK;
    if (dim == 2) {
        out[0] = out[1] = 0;
        return pfsph__json_number(e, P, "rotation", -1e6, 1e6, &out[2], ctx);
    }
    return pfsph__json_vec(e, P, "rotation", 3, -1e6, 1e6, out, ctx);
}

static int positive(const cJSON *e, const char *P, const char *key, double *out, pfsph_jctx *ctx)
{
    if (!cJSON_GetObjectItemCaseSensitive(e, key)) return PFSPH_OK;
    double v = 0;
    int rc = pfsph__json_number(e, P, key, 0, COORD_MAX, &v, ctx);
    if (rc) return rc;
    if (!(v > 0)) {
        char kp[192];
        snprintf(kp, sizeof kp, "%s.%s", P, key);
        return pfsph__json_fail(ctx, kp, "must be > 0, got %g", v);
    }
    *out = v;
    return PFSPH_OK;
}

static int require(const cJSON *e, const char *P, const char *key, pfsph_jctx *ctx)
{
    if (cJSON_GetObjectItemCaseSensitive(e, key)) return PFSPH_OK;
    char kp[192];
    snprintf(kp, sizeof kp, "%s.%s", P, key);
    return pfsph__json_fail(ctx, kp, "missing required key \"%s\"", key);
}

/* The mesh path relative to the scene file's directory (absolute paths are kept). */
static int resolve_mesh(const pfsph_scene *s, const char *P, const char *file, char *out, size_t cap, pfsph_jctx *ctx)
{
    char kp[192];
    snprintf(kp, sizeof kp, "%s.file", P);
    if (!file[0]) return pfsph__json_fail(ctx, kp, "must not be empty");
    const char *slash = strrchr(s->source, '/');
    /* built in a buffer of its own: out lies in the scene, like s->source, and gcc 12 cannot
     * tell that they do not overlap (-Wrestrict) */
    char buf[2 * PFSPH_PATH_LEN];
    int w;
    if (file[0] == '/' || !slash || s->source[0] == '<') w = snprintf(buf, sizeof buf, "%s", file);
    else w = snprintf(buf, sizeof buf, "%.*s/%s", (int)(slash - s->source), s->source, file);
    if (w < 0 || (size_t)w >= cap) return pfsph__json_fail(ctx, kp, "path too long");
    memcpy(out, buf, (size_t)w + 1);
    return PFSPH_OK;
}

/* Every extent of the body (box edges, diameters, a cylinder's height) at least the particle
 * spacing d = 2 particle_radius: a smaller body holds no particle of its own or one the fluid
 * cannot resolve (a radius of 1e-20 ran and never felt the water). A mesh body is checked when
 * its file is read (pfsph_bodies_create). */
static int check_extents(const pfsph_body_def *b, const char *P, const pfsph_scene *s, pfsph_jctx *ctx)
{
    const double d = 2 * s->particle_radius;
    const char *key = NULL;
    double ext = 0;
    if (b->shape == PFSPH_BODY_BOX) {
        for (int k = 0; k < s->dim; k++)
            if (!key || 2 * b->half[k] < ext) key = "half_extents", ext = 2 * b->half[k];
    } else if (b->shape != PFSPH_BODY_MESH) {
        key = "radius", ext = 2 * b->radius;
        if (b->shape == PFSPH_BODY_CYLINDER && s->dim == 3 && b->height < ext) key = "height", ext = b->height;
    }
    if (!key || ext >= d) return PFSPH_OK;
    char kp[192];
    snprintf(kp, sizeof kp, "%s.%s", P, key);
    return pfsph__json_fail(ctx, kp,
                            "the body is %g m across there, less than the particle spacing %g m (2 x "
                            "particle_radius): it would hold no particle the fluid can feel; make it at least %g m",
                            ext, d, d);
}

/* The body's volume (2D: per metre of depth); 0 for a mesh (known once its file is read). */
static double body_volume(const pfsph_body_def *b, int dim)
{
    const double pi = 3.14159265358979323846;
    switch (b->shape) {
    case PFSPH_BODY_BOX: return 8 * b->half[0] * b->half[1] * (dim == 2 ? 0.5 : b->half[2]);
    case PFSPH_BODY_SPHERE:
        return dim == 2 ? pi * b->radius * b->radius : 4.0 / 3.0 * pi * b->radius * b->radius * b->radius;
    case PFSPH_BODY_CYLINDER: return pi * b->radius * b->radius * (dim == 2 ? 1.0 : b->height);
    default: return 0;
    }
}

int pfsph__body_density_check(double density, double mass, double volume, char *msg, size_t cap)
{
    const double rho = mass > 0 ? mass / volume : density;
    if (rho >= DENSITY_MIN && rho <= DENSITY_MAX) return 0;
    if (mass > 0)
        snprintf(msg, cap,
                 "%g kg in the body's %g m^3 is a density of %g kg/m^3, outside the %g..%g a rigid body can "
                 "have",
                 mass, volume, rho, DENSITY_MIN, DENSITY_MAX);
    else snprintf(msg, cap, "%g kg/m^3 is outside the %g..%g a rigid body can have", rho, DENSITY_MIN, DENSITY_MAX);
    return 1;
}

static int parse_keys(const cJSON *arr, const char *P, const pfsph_scene *s, pfsph_body_def *b, pfsph_jctx *ctx)
{
    const int dim = s->dim;
    char kp[192];
    snprintf(kp, sizeof kp, "%s.keyframes", P);
    if (!cJSON_IsArray(arr)) return pfsph__json_fail(ctx, kp, "expected an array of keyframes");
    int n = cJSON_GetArraySize(arr);
    if (n < 1 || n > PFSPH_MAX_KEYFRAMES)
        return pfsph__json_fail(ctx, kp, "expected 1 to %d keyframes, got %d", PFSPH_MAX_KEYFRAMES, n);
    int i = 0;
    for (const cJSON *k = arr->child; k; k = k->next, i++) {
        char Q[224];
        snprintf(Q, sizeof Q, "%s[%d]", kp, i);
        if (!cJSON_IsObject(k)) return pfsph__json_fail(ctx, Q, "expected an object");
        static const char *const keys[] = {"t", "position", "rotation", "comment", NULL};
        int rc;
        if ((rc = pfsph__json_check_keys(k, Q, keys, ctx))) return rc;
        pfsph_keyframe *f = &b->keys[i];
        /* unspecified fields hold the previous keyframe's (or the body's) value */
        const pfsph_keyframe *prev = i ? &b->keys[i - 1] : NULL;
        memcpy(f->position, prev ? prev->position : b->position, sizeof f->position);
        memcpy(f->rotation, prev ? prev->rotation : b->rotation, sizeof f->rotation);
        if ((rc = require(k, Q, "t", ctx)) || (rc = pfsph__json_number(k, Q, "t", 0, 1e9, &f->t, ctx)) ||
            (rc = vec(k, Q, "position", dim, -COORD_MAX, COORD_MAX, f->position, ctx)) ||
            (rc = rotation(k, Q, dim, f->rotation, ctx)))
            return rc;
        for (int a = 0; a < dim; a++)
            if (f->position[a] < s->domain_min[a] || f->position[a] > s->domain_max[a]) {
                char T[240];
                snprintf(T, sizeof T, "%s.position", Q);
                return pfsph__json_fail(ctx, T,
                                        "lies outside the domain (a body outside the grid loses its particles)");
            }
        if (prev && !(f->t > prev->t)) {
            char T[240];
            snprintf(T, sizeof T, "%s.t", Q);
            return pfsph__json_fail(ctx, T, "keyframe times must increase: %g after %g", f->t, prev->t);
        }
    }
    b->nkeys = n;
    return PFSPH_OK;
}

int pfsph__scene_parse_bodies(const cJSON *arr, const char *path, pfsph_scene *s, pfsph_jctx *ctx)
{
    if (!cJSON_IsArray(arr)) return pfsph__json_fail(ctx, path, "expected an array of bodies");
    int n = cJSON_GetArraySize(arr);
    if (n > PFSPH_MAX_BODIES)
        return pfsph__json_fail(ctx, path, "too many bodies (%d, at most %d)", n, PFSPH_MAX_BODIES);
    int def = -1; /* default phase: the first solid phase */
    for (int i = 0; i < s->nphases; i++)
        if (s->phases[i].kind == PFSPH_PHASE_SOLID) {
            def = i;
            break;
        }
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        char P[96];
        snprintf(P, sizeof P, "%s[%d]", path, i);
        if (!cJSON_IsObject(e)) return pfsph__json_fail(ctx, P, "expected an object");
        static const char *const keys[] = {
            "name",     "shape",       "phase",    "half_extents", "radius",           "height",  "axis", "file",
            "scale",    "position",    "rotation", "velocity",     "angular_velocity", "density", "mass", "inertia",
            "friction", "restitution", "layers",   "kinematic",    "keyframes",        "comment", NULL};
        int rc;
        if ((rc = pfsph__json_check_keys(e, P, keys, ctx))) return rc;
        pfsph_body_def *b = &s->bodies[i];
        memset(b, 0, sizeof *b);
        snprintf(b->name, sizeof b->name, "body%d", i);
        b->scale = 1;
        b->friction = 0.5;
        b->layers = 2;
        b->axis = s->dim == 2 ? 2 : 1;
        if ((rc = require(e, P, "shape", ctx)) || (rc = enum_key(e, P, "shape", shape_names, &b->shape, ctx)) ||
            (rc = pfsph__json_string(e, P, "name", b->name, sizeof b->name, ctx)) ||
            (rc = require(e, P, "position", ctx)) ||
            (rc = vec(e, P, "position", s->dim, -COORD_MAX, COORD_MAX, b->position, ctx)) ||
            (rc = rotation(e, P, s->dim, b->rotation, ctx)) ||
            (rc = vec(e, P, "velocity", s->dim, -1e3, 1e3, b->velocity, ctx)) ||
            (rc = pfsph__json_number(e, P, "friction", 0, 100, &b->friction, ctx)) ||
            (rc = pfsph__json_number(e, P, "restitution", 0, 1, &b->restitution, ctx)) ||
            (rc = pfsph__json_int(e, P, "layers", 1, 4, &b->layers, ctx)) ||
            (rc = pfsph__json_bool(e, P, "kinematic", &b->kinematic, ctx)))
            return rc;
        for (const char *q = b->name; *q; q++)
            if (!((*q >= 'a' && *q <= 'z') || (*q >= 'A' && *q <= 'Z') || (*q >= '0' && *q <= '9') || *q == '_' ||
                  *q == '-' || *q == '.')) {
                char kp[128];
                snprintf(kp, sizeof kp, "%s.name", P);
                return pfsph__json_fail(ctx, kp,
                                        "\"%s\": use letters, digits, '_', '-' and '.' only "
                                        "(the name is a column of bodies.csv)",
                                        b->name);
            }
        for (int j = 0; j < i; j++)
            if (strcmp(s->bodies[j].name, b->name) == 0) {
                char kp[128];
                snprintf(kp, sizeof kp, "%s.name", P);
                return pfsph__json_fail(ctx, kp, "name \"%s\" is used by %s[%d] already", b->name, path, j);
            }
        if (s->dim == 2) {
            b->angular_velocity[0] = b->angular_velocity[1] = 0;
            rc = pfsph__json_number(e, P, "angular_velocity", -1e4, 1e4, &b->angular_velocity[2], ctx);
        } else rc = vec(e, P, "angular_velocity", 3, -1e4, 1e4, b->angular_velocity, ctx);
        if (rc) return rc;
        char kp[192];
        switch (b->shape) {
        case PFSPH_BODY_BOX:
            if ((rc = require(e, P, "half_extents", ctx)) ||
                (rc = vec(e, P, "half_extents", s->dim, 0, COORD_MAX, b->half, ctx)))
                return rc;
            for (int k = 0; k < s->dim; k++)
                if (!(b->half[k] > 0)) {
                    snprintf(kp, sizeof kp, "%s.half_extents", P);
                    return pfsph__json_fail(ctx, kp, "every half extent must be > 0");
                }
            if (s->dim == 2) b->half[2] = 0.5; /* unit depth: 2D masses are per metre */
            break;
        case PFSPH_BODY_SPHERE:
            if ((rc = require(e, P, "radius", ctx)) || (rc = positive(e, P, "radius", &b->radius, ctx))) return rc;
            break;
        case PFSPH_BODY_CYLINDER:
            if ((rc = require(e, P, "radius", ctx)) || (rc = positive(e, P, "radius", &b->radius, ctx))) return rc;
            if (s->dim == 3) {
                if ((rc = require(e, P, "height", ctx)) || (rc = positive(e, P, "height", &b->height, ctx)) ||
                    (rc = enum_key(e, P, "axis", axis_names, &b->axis, ctx)))
                    return rc;
            } else if (cJSON_GetObjectItemCaseSensitive(e, "height")) {
                snprintf(kp, sizeof kp, "%s.height", P);
                return pfsph__json_fail(ctx, kp, "not used in 2D (a 2D cylinder is a disc)");
            }
            break;
        case PFSPH_BODY_MESH: {
            if (s->dim != 3) {
                snprintf(kp, sizeof kp, "%s.shape", P);
                return pfsph__json_fail(ctx, kp, "mesh bodies need a 3D scene");
            }
            char file[PFSPH_PATH_LEN] = "";
            if ((rc = require(e, P, "file", ctx)) || (rc = pfsph__json_string(e, P, "file", file, sizeof file, ctx)) ||
                (rc = resolve_mesh(s, P, file, b->mesh, sizeof b->mesh, ctx)) ||
                (rc = positive(e, P, "scale", &b->scale, ctx)))
                return rc;
            break;
        }
        }
        if ((rc = positive(e, P, "density", &b->density, ctx)) || (rc = positive(e, P, "mass", &b->mass, ctx)))
            return rc;
        if (cJSON_GetObjectItemCaseSensitive(e, "inertia")) {
            if (s->dim == 2) {
                rc = positive(e, P, "inertia", &b->inertia[2], ctx);
            } else {
                rc = pfsph__json_vec(e, P, "inertia", 3, 0, 1e12, b->inertia, ctx);
                if (!rc &&
                    !(b->inertia[0] > 0 && b->inertia[1] > 0 && b->inertia[2] > 0 &&
                      b->inertia[0] + b->inertia[1] >= b->inertia[2] &&
                      b->inertia[1] + b->inertia[2] >= b->inertia[0] &&
                      b->inertia[0] + b->inertia[2] >= b->inertia[1])) {
                    snprintf(kp, sizeof kp, "%s.inertia", P);
                    return pfsph__json_fail(ctx, kp,
                                            "principal moments must be > 0 and each at most the sum of "
                                            "the other two (a rigid body's)");
                }
            }
            if (rc) return rc;
        }
        if (b->density > 0 && b->mass > 0) {
            snprintf(kp, sizeof kp, "%s.mass", P);
            return pfsph__json_fail(ctx, kp, "give either \"density\" or \"mass\", not both");
        }
        /* phase */
        const cJSON *ph = cJSON_GetObjectItemCaseSensitive(e, "phase");
        snprintf(kp, sizeof kp, "%s.phase", P);
        if (ph) {
            int idx = cJSON_IsString(ph) && ph->valuestring ? pfsph_scene_phase_index(s, ph->valuestring) : -1;
            if (idx < 0) return pfsph__json_fail(ctx, kp, "expected the name of a phase of the scene");
            if (s->phases[idx].kind != PFSPH_PHASE_SOLID)
                return pfsph__json_fail(ctx, kp,
                                        "phase \"%s\" is not a solid phase; bodies need a phase of kind \"solid\"",
                                        s->phases[idx].name);
            b->phase = idx;
        } else if (def >= 0) b->phase = def;
        else return pfsph__json_fail(ctx, kp, "the scene has no solid phase: add one to \"phases\" and name it here");
        if (!(b->density > 0) && !(b->mass > 0)) b->density = s->phases[b->phase].rest_density;
        if (!(b->density > 0) && !(b->mass > 0))
            return pfsph__json_fail(ctx, P, "give \"density\" or \"mass\" (phase \"%s\" has no rest_density)",
                                    s->phases[b->phase].name);
        if ((rc = check_extents(b, P, s, ctx))) return rc;
        char why[256];
        const double volume = body_volume(b, s->dim);
        if ((b->mass > 0 ? volume > 0 : 1) && pfsph__body_density_check(b->density, b->mass, volume, why, sizeof why)) {
            const char *key = b->mass > 0                        ? "mass"
                : cJSON_GetObjectItemCaseSensitive(e, "density") ? "density"
                                                                 : "phase";
            snprintf(kp, sizeof kp, "%s.%s", P, key);
            return pfsph__json_fail(ctx, kp, "%s%s", why,
                                    key[0] == 'p' ? " (the phase's rest_density; give the body a \"density\")" : "");
        }
        const cJSON *kf = cJSON_GetObjectItemCaseSensitive(e, "keyframes");
        if (kf) {
            if (!b->kinematic) {
                snprintf(kp, sizeof kp, "%s.keyframes", P);
                return pfsph__json_fail(ctx, kp, "keyframes move kinematic bodies only: add \"kinematic\": true");
            }
            if ((rc = parse_keys(kf, P, s, b, ctx))) return rc;
        }
        for (int k = 0; k < s->dim; k++)
            if (b->position[k] < s->domain_min[k] || b->position[k] > s->domain_max[k]) {
                snprintf(kp, sizeof kp, "%s.position", P);
                return pfsph__json_fail(ctx, kp, "lies outside the domain");
            }
    }
    s->nbodies = i;
    return PFSPH_OK;
}
