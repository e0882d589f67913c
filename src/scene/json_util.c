/* Validated reads from cJSON objects (see json_util.h): every failure becomes one message
 * "<file>: <JSON path>: <reason>" with code PFSPH_EINPUT, so users can find the bad value. */
#include "scene/json_util.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int pfsph__json_fail(pfsph_jctx *ctx, const char *path, const char *fmt, ...)
{
    char reason[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(reason, sizeof reason, fmt, ap);
    va_end(ap);
    return pfsph_fail(ctx->err, PFSPH_EINPUT, "%s: %s: %s", ctx->source ? ctx->source : "<scene>",
                      path && path[0] ? path : "$", reason);
}

/* JSON type name for "expected X, got Y" messages. */
static const char *type_name(const cJSON *v)
{
    if (!v || cJSON_IsInvalid(v)) return "nothing";
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsBool(v)) return "a boolean";
    if (cJSON_IsNumber(v)) return "a number";
    if (cJSON_IsString(v)) return "a string";
    if (cJSON_IsArray(v)) return "an array";
    if (cJSON_IsObject(v)) return "an object";
    return "an unknown value";
}

/* Levenshtein distance of two short keys, capped at 64 characters each (keys are short; a cap
 * keeps the table on the stack). */
static int edit_distance(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b);
    if (na > 64) na = 64;
    if (nb > 64) nb = 64;
    int prev[65], cur[65];
    for (size_t j = 0; j <= nb; j++) prev[j] = (int)j;
    for (size_t i = 1; i <= na; i++) {
        cur[0] = (int)i;
        for (size_t j = 1; j <= nb; j++) {
            int sub = prev[j - 1] + (a[i - 1] != b[j - 1]);
            int del = prev[j] + 1, ins = cur[j - 1] + 1;
            int m = sub < del ? sub : del;
            cur[j] = m < ins ? m : ins;
        }
        memcpy(prev, cur, (nb + 1) * sizeof prev[0]);
    }
    return prev[nb];
}

/* Child path "<path>.<key>" (truncated safely; paths only feed messages). */
static void child_path(char *out, size_t cap, const char *path, const char *key)
{
    snprintf(out, cap, "%s.%s", path && path[0] ? path : "$", key);
}

int pfsph__json_check_keys(const cJSON *obj, const char *path, const char *const *allowed, pfsph_jctx *ctx)
{
    if (!cJSON_IsObject(obj)) return pfsph__json_fail(ctx, path, "expected an object, got %s", type_name(obj));
    for (const cJSON *c = obj->child; c; c = c->next) {
        const char *key = c->string ? c->string : "";
        char kp[512];
        child_path(kp, sizeof kp, path, key);
        /* cJSON keeps duplicate keys and lookups return the first: a silent trap. */
        for (const cJSON *d = obj->child; d != c; d = d->next)
            if (d->string && strcmp(d->string, key) == 0) return pfsph__json_fail(ctx, kp, "duplicate key \"%s\"", key);
        bool ok = false;
        for (const char *const *a = allowed; *a; a++)
            if (strcmp(*a, key) == 0) {
                ok = true;
                break;
            }
        if (ok) continue;
        /* Suggest the closest valid key when it is close enough to be a typo. */
        const char *best = NULL;
        int bestd = 1 << 30;
        for (const char *const *a = allowed; *a; a++) {
            int d = edit_distance(key, *a);
            if (d < bestd) {
                bestd = d;
                best = *a;
            }
        }
        int limit = (int)strlen(key) / 3;
        if (limit < 2) limit = 2;
        if (best && bestd <= limit)
            return pfsph__json_fail(ctx, kp, "unknown key \"%s\" (did you mean \"%s\"?)", key, best);
        char list[400];
        size_t n = 0;
        list[0] = 0;
        for (const char *const *a = allowed; *a && n + 1 < sizeof list; a++) {
            int w = snprintf(list + n, sizeof list - n, "%s%s", a == allowed ? "" : ", ", *a);
            if (w < 0) break;
            n += (size_t)w;
        }
        return pfsph__json_fail(ctx, kp, "unknown key \"%s\" (valid keys: %s)", key, list);
    }
    return PFSPH_OK;
}

/* The value under key, or NULL when the key is absent. */
static const cJSON *get(const cJSON *obj, const char *key)
{
    return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
}

static int check_number(const cJSON *v, const char *path, double lo, double hi, double *out, pfsph_jctx *ctx)
{
    if (!cJSON_IsNumber(v)) return pfsph__json_fail(ctx, path, "expected a number, got %s", type_name(v));
    double x = v->valuedouble;
    if (!isfinite(x)) return pfsph__json_fail(ctx, path, "value is not a finite number");
    if (x < lo || x > hi) return pfsph__json_fail(ctx, path, "value %g is out of range [%g, %g]", x, lo, hi);
    *out = x;
    return PFSPH_OK;
}

int pfsph__json_number(const cJSON *obj, const char *path, const char *key, double lo, double hi, double *out,
                       pfsph_jctx *ctx)
{
    const cJSON *v = get(obj, key);
    if (!v) return PFSPH_OK;
    char kp[512];
    child_path(kp, sizeof kp, path, key);
    return check_number(v, kp, lo, hi, out, ctx);
}

int pfsph__json_int(const cJSON *obj, const char *path, const char *key, long lo, long hi, int *out, pfsph_jctx *ctx)
{
    const cJSON *v = get(obj, key);
    if (!v) return PFSPH_OK;
    char kp[512];
    child_path(kp, sizeof kp, path, key);
    if (!cJSON_IsNumber(v)) return pfsph__json_fail(ctx, kp, "expected an integer, got %s", type_name(v));
    double x = v->valuedouble;
    if (!isfinite(x) || x != floor(x)) return pfsph__json_fail(ctx, kp, "expected an integer, got %g", x);
    if (x < (double)lo || x > (double)hi)
        return pfsph__json_fail(ctx, kp, "value %g is out of range [%ld, %ld]", x, lo, hi);
    *out = (int)x;
    return PFSPH_OK;
}

int pfsph__json_bool(const cJSON *obj, const char *path, const char *key, bool *out, pfsph_jctx *ctx)
{
    const cJSON *v = get(obj, key);
    if (!v) return PFSPH_OK;
    char kp[512];
    child_path(kp, sizeof kp, path, key);
    if (!cJSON_IsBool(v)) return pfsph__json_fail(ctx, kp, "expected true or false, got %s", type_name(v));
    *out = cJSON_IsTrue(v);
    return PFSPH_OK;
}

int pfsph__json_tristate(const cJSON *obj, const char *path, const char *key, int *out, pfsph_jctx *ctx)
{
    const cJSON *v = get(obj, key);
    if (!v) return PFSPH_OK;
    char kp[512];
    child_path(kp, sizeof kp, path, key);
    if (cJSON_IsBool(v)) *out = cJSON_IsTrue(v) ? 1 : -1;
    else if (cJSON_IsString(v) && v->valuestring && !strcmp(v->valuestring, "auto")) *out = 0;
    else if (cJSON_IsString(v) && v->valuestring)
        return pfsph__json_fail(ctx, kp, "expected true, false or \"auto\", got \"%.64s\"", v->valuestring);
    else return pfsph__json_fail(ctx, kp, "expected true, false or \"auto\", got %s", type_name(v));
    return PFSPH_OK;
}

int pfsph__json_string(const cJSON *obj, const char *path, const char *key, char *out, size_t cap, pfsph_jctx *ctx)
{
    const cJSON *v = get(obj, key);
    if (!v) return PFSPH_OK;
    char kp[512];
    child_path(kp, sizeof kp, path, key);
    if (!cJSON_IsString(v) || !v->valuestring)
        return pfsph__json_fail(ctx, kp, "expected a string, got %s", type_name(v));
    size_t n = strlen(v->valuestring);
    if (n >= cap) return pfsph__json_fail(ctx, kp, "string is too long (%zu characters, at most %zu)", n, cap - 1);
    memcpy(out, v->valuestring, n + 1);
    return PFSPH_OK;
}

int pfsph__json_vec(const cJSON *obj, const char *path, const char *key, int n, double lo, double hi, double *out,
                    pfsph_jctx *ctx)
{
    const cJSON *v = get(obj, key);
    if (!v) return PFSPH_OK;
    char kp[512];
    child_path(kp, sizeof kp, path, key);
    if (!cJSON_IsArray(v)) return pfsph__json_fail(ctx, kp, "expected an array of %d numbers, got %s", n, type_name(v));
    int len = cJSON_GetArraySize(v);
    if (len != n)
        return pfsph__json_fail(ctx, kp, "expected %d numbers, got %d%s", n, len,
                                n == 2 ? " (2D scenes use [x, y])" : (n == 3 ? " (3D scenes use [x, y, z])" : ""));
    double tmp[16];
    if (n > 16) return pfsph__json_fail(ctx, kp, "vector too long");
    int i = 0;
    for (const cJSON *e = v->child; e; e = e->next, i++) {
        char ep[560];
        snprintf(ep, sizeof ep, "%s[%d]", kp, i);
        int rc = check_number(e, ep, lo, hi, &tmp[i], ctx);
        if (rc) return rc;
    }
    memcpy(out, tmp, (size_t)n * sizeof *out);
    return PFSPH_OK;
}

int pfsph__json_check_nul_escapes(const char *json, pfsph_jctx *ctx)
{
    int in_str = 0, line = 1;
    const char *line0 = json;
    for (const char *c = json; *c; c++) {
        if (*c == '\n') line++, line0 = c + 1;
        if (!in_str) {
            in_str = *c == '"';
            continue;
        }
        if (*c == '"') in_str = 0;
        else if (*c == '\\' && c[1]) {
            if (c[1] == 'u' && c[2] == '0' && c[3] == '0' && c[4] == '0' && c[5] == '0')
                return pfsph__json_fail(ctx, "$",
                                        "\"\\u0000\" (a NUL character) in a string at line %d, column %d: names "
                                        "and text cannot hold one",
                                        line, (int)(c - line0) + 1);
            c++; /* the escaped character */
        }
    }
    return PFSPH_OK;
}

/* Length of the valid UTF-8 sequence at p (1..4), 0 if it is not one. */
static int utf8_len(const unsigned char *p)
{
    if (p[0] < 0x80) return 1;
    int n = p[0] >= 0xc2 && p[0] <= 0xdf ? 2 : p[0] >= 0xe0 && p[0] <= 0xef ? 3 : p[0] >= 0xf0 && p[0] <= 0xf4 ? 4 : 0;
    for (int k = 1; k < n; k++)
        if ((p[k] & 0xc0) != 0x80) return 0;
    if ((p[0] == 0xe0 && p[1] < 0xa0) || (p[0] == 0xed && p[1] >= 0xa0) || (p[0] == 0xf0 && p[1] < 0x90) ||
        (p[0] == 0xf4 && p[1] >= 0x90))
        return 0; /* overlong, a surrogate, past U+10FFFF */
    return n;
}

static int check_text(const char *t, const char *path, const char *what, pfsph_jctx *ctx)
{
    size_t n = strlen(t);
    if (n > PFSPH_JSON_MAX_STRING)
        return pfsph__json_fail(ctx, path, "%s of %zu bytes, more than the %d a scene holds", what, n,
                                PFSPH_JSON_MAX_STRING);
    for (const unsigned char *p = (const unsigned char *)t; *p;) {
        int len = utf8_len(p);
        if (!len)
            return pfsph__json_fail(ctx, path, "%s is not valid UTF-8 (byte 0x%02x at offset %zu)", what, *p,
                                    (size_t)(p - (const unsigned char *)t));
        p += len;
    }
    return PFSPH_OK;
}

static int check_tree(const cJSON *v, char *path, size_t len, size_t cap, pfsph_jctx *ctx)
{
    int rc;
    if (cJSON_IsString(v) && v->valuestring && (rc = check_text(v->valuestring, path, "the string", ctx))) return rc;
    int i = 0;
    for (const cJSON *c = v->child; c; c = c->next, i++) {
        if (cJSON_IsObject(v) && c->string) {
            snprintf(path + len, cap - len, ".%.64s", c->string);
            if ((rc = check_text(c->string, path, "the key", ctx))) return rc;
        } else snprintf(path + len, cap - len, "[%d]", i);
        if ((rc = check_tree(c, path, strlen(path), cap, ctx))) return rc;
        path[len] = 0;
    }
    return PFSPH_OK;
}

int pfsph__json_check_strings(const cJSON *root, pfsph_jctx *ctx)
{
    char path[1024] = "$";
    return check_tree(root, path, 1, sizeof path, ctx);
}
