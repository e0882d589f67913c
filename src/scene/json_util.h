/* Internal: validated reads from cJSON objects with errors that name the file and JSON path.
 * Paths are written JSONPath style: "$.phases[1].rest_density". Every getter leaves *out
 * unchanged when the key is absent (so defaults survive) and returns PFSPH_OK, or fills ctx->err
 * and returns PFSPH_EINPUT. */
#ifndef PFSPH_JSON_UTIL_H
#define PFSPH_JSON_UTIL_H

#include <cjson/cJSON.h>
#include <stdbool.h>

#include "pfsph/scene.h"

typedef struct pfsph_jctx {
    const char *source; /* file name for messages */
    pfsph_error *err;
} pfsph_jctx;

/* Error unless obj is an object whose keys are all in `allowed` (NULL-terminated). */
int pfsph__json_check_keys(const cJSON *obj, const char *path, const char *const *allowed, pfsph_jctx *ctx);
int pfsph__json_number(const cJSON *obj, const char *path, const char *key, double lo, double hi, double *out,
                       pfsph_jctx *ctx);
int pfsph__json_int(const cJSON *obj, const char *path, const char *key, long lo, long hi, int *out, pfsph_jctx *ctx);
int pfsph__json_bool(const cJSON *obj, const char *path, const char *key, bool *out, pfsph_jctx *ctx);
/* true, false or "auto": *out = 1, -1 or 0. */
int pfsph__json_tristate(const cJSON *obj, const char *path, const char *key, int *out, pfsph_jctx *ctx);
int pfsph__json_string(const cJSON *obj, const char *path, const char *key, char *out, size_t cap, pfsph_jctx *ctx);
/* An array of exactly n numbers, each in [lo, hi]. */
int pfsph__json_vec(const cJSON *obj, const char *path, const char *key, int n, double lo, double hi, double *out,
                    pfsph_jctx *ctx);
/* The text of a scene before its keys are read (issue 33): no "\u0000" escape in a string
 * (cJSON would cut the string there), and then every key and string value of the tree valid
 * UTF-8 (no overlong forms, surrogates or code points past U+10FFFF) and at most
 * PFSPH_JSON_MAX_STRING bytes; the error names the JSON path (the line and column for \u0000). */
#define PFSPH_JSON_MAX_STRING 65536
int pfsph__json_check_nul_escapes(const char *json, pfsph_jctx *ctx);
int pfsph__json_check_strings(const cJSON *root, pfsph_jctx *ctx);
/* Error "<source>: <path>: <reason>" (printf-style reason); returns PFSPH_EINPUT. */
int pfsph__json_fail(pfsph_jctx *ctx, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Sub-parsers owned by their modules (src/scene/scene_pairwise.c, scene_diffuse.c). Called
 * after phases are parsed, with the object under "pairwise" / "diffuse" and its path. */
int pfsph__scene_parse_pairwise(const cJSON *node, const char *path, pfsph_scene *s, pfsph_jctx *ctx);
int pfsph__scene_parse_diffuse(const cJSON *node, const char *path, pfsph_scene *s, pfsph_jctx *ctx);
/* The "bodies" array (src/scene/scene_bodies.c), after solids and fluid. */
int pfsph__scene_parse_bodies(const cJSON *arr, const char *path, pfsph_scene *s, pfsph_jctx *ctx);
/* The "emitters" array (src/scene/scene_emitters.c), after the fluid blocks and solids. */
int pfsph__scene_parse_emitters(const cJSON *arr, const char *path, pfsph_scene *s, pfsph_jctx *ctx);

#endif
