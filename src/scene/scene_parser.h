/* What the scene parser's files share: the parser, TRY, the JSON path helpers and the accepted
 * ranges (scene.c, scene_output.c). */
#ifndef PFSPH_SCENE_PARSER_H
#define PFSPH_SCENE_PARSER_H

#include <stdio.h>
#include <string.h>

#include "pfsph/scene.h"
#include "scene/json_util.h"

/* Limits of the accepted ranges (documented in docs/scene-format.md). */
#define COORD_MAX 1e6               /* m */
#define VEL_MAX 1e3                 /* m/s */
#define GRAVITY_MAX 1e3             /* m/s^2 */
#define SEED_MAX 9007199254740992.0 /* 2^53: integers a JSON double holds exactly */

static const float palette[][3] = {
    {0.20f, 0.40f, 0.90f}, {0.90f, 0.50f, 0.15f}, {0.20f, 0.75f, 0.35f}, {0.85f, 0.20f, 0.25f},
    {0.60f, 0.30f, 0.80f}, {0.95f, 0.85f, 0.20f}, {0.20f, 0.80f, 0.80f}, {0.80f, 0.50f, 0.60f},
};
static const float solid_grey[3] = {0.60f, 0.60f, 0.62f};

typedef struct parser {
    pfsph_scene *s;
    pfsph_jctx ctx;
} parser;

#define TRY(expr)            \
    do {                     \
        int rc_ = (expr);    \
        if (rc_) return rc_; \
    } while (0)

static inline void path_key(char *out, size_t cap, const char *path, const char *key)
{
    snprintf(out, cap, "%s.%s", path, key);
}

static inline void path_index(char *out, size_t cap, const char *path, int i) { snprintf(out, cap, "%s[%d]", path, i); }

static inline const cJSON *get(const cJSON *obj, const char *key) { return cJSON_GetObjectItemCaseSensitive(obj, key); }

static inline int require(parser *p, const cJSON *obj, const char *path, const char *key)
{
    if (get(obj, key)) return PFSPH_OK;
    char kp[512];
    path_key(kp, sizeof kp, path, key);
    return pfsph__json_fail(&p->ctx, kp, "missing required key \"%s\"", key);
}

/* A vector with as many components as the scene has dimensions; z = 0 in 2D. */
static inline int vecd(parser *p, const cJSON *obj, const char *path, const char *key, double lo, double hi,
                       double *out)
{
    if (!get(obj, key)) return PFSPH_OK;
    TRY(pfsph__json_vec(obj, path, key, p->s->dim, lo, hi, out, &p->ctx));
    if (p->s->dim == 2) out[2] = 0.0;
    return PFSPH_OK;
}

/* A string that must be one of names (NULL-terminated); *out becomes its index. */
static inline int json_enum(parser *p, const cJSON *obj, const char *path, const char *key, const char *const *names,
                            int *out)
{
    const cJSON *v = get(obj, key);
    if (!v) return PFSPH_OK;
    char kp[512];
    path_key(kp, sizeof kp, path, key);
    char list[256] = "";
    size_t n = 0;
    for (int i = 0; names[i]; i++) {
        int w = snprintf(list + n, sizeof list - n, "%s\"%s\"", i ? ", " : "", names[i]);
        if (w > 0 && (size_t)w < sizeof list - n) n += (size_t)w;
    }
    if (!cJSON_IsString(v) || !v->valuestring)
        return pfsph__json_fail(&p->ctx, kp, "expected a string, one of %s", list);
    for (int i = 0; names[i]; i++)
        if (strcmp(v->valuestring, names[i]) == 0) {
            *out = i;
            return PFSPH_OK;
        }
    return pfsph__json_fail(&p->ctx, kp, "unknown value \"%.60s\" (expected one of %s)", v->valuestring, list);
}

/* A number that must be strictly positive (the helpers check closed ranges only). */
static inline int positive(parser *p, const cJSON *obj, const char *path, const char *key, double hi, double *out)
{
    double v = *out;
    TRY(pfsph__json_number(obj, path, key, -HUGE_VAL, hi, &v, &p->ctx));
    if (!(v > 0.0)) {
        char kp[512];
        path_key(kp, sizeof kp, path, key);
        return pfsph__json_fail(&p->ctx, kp, "value %g is out of range: must be > 0 and <= %g", v, hi);
    }
    *out = v;
    return PFSPH_OK;
}

/* An array (possibly absent); error when it is not an array or has more than max entries. */
static inline int array_of(parser *p, const cJSON *root, const char *path, const char *key, int max, const cJSON **out)
{
    const cJSON *v = get(root, key);
    *out = NULL;
    if (!v) return PFSPH_OK;
    char kp[512];
    path_key(kp, sizeof kp, path, key);
    if (!cJSON_IsArray(v))
        return pfsph__json_fail(&p->ctx, kp, "expected an array, got %s",
                                cJSON_IsObject(v) ? "an object" : "a single value");
    int n = cJSON_GetArraySize(v);
    if (n > max) return pfsph__json_fail(&p->ctx, kp, "too many entries (%d, at most %d)", n, max);
    *out = v;
    return PFSPH_OK;
}

/* ---------------------------------------------------------------------------------------- */
/* Geometry used by the validation: bounding boxes and overlaps of blocks and solids. */

typedef struct pfsph__geo {
    int shape, dim, axis;
    double min[3], max[3], center[3], radius, height;
} pfsph__geo;
/* a block's or solid's shape for the overlap checks */
pfsph__geo pfsph__geo_of(int dim, int shape, const double *min, const double *max, const double *center, double radius,
                         double height, int axis);
/* "(x, y[, z])" of a point, for messages */
void pfsph__fmt_vec(char *out, size_t cap, int dim, const double *v);
/* blocks that overlap one another, a solid or leave the domain: a message with the JSON path */
int pfsph__scene_check_blocks(parser *p);
int pfsph__scene_parse_output(parser *p, const cJSON *root);
int pfsph__scene_parse_camera(parser *p, const cJSON *root);
/* frame the domain when the scene sets no camera */
void pfsph__scene_auto_camera(pfsph_scene *s);
/* the scene file's name without directory and extension ("scene" when none) */
void pfsph__scene_source_stem(const char *source, char *out, size_t cap);

#endif
