/* The "emitters" array of scene files: nozzles that feed fluid into a running scene, validated
 * key by key. Keys, units, defaults and ranges: docs/scene-format.md#emitters; the design:
 * docs/emitters.md. What needs the lattice (the nozzle's site count, a rate's entry speed) is
 * checked when the simulation or the estimate is built (pfsph_emitters_create). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/json_util.h"

#define COORD_MAX 1e6
#define SPEED_MAX 1e3 /* m/s, as block velocities */
#define RATE_MAX 1e9  /* m^3/s; the entry speed it implies is checked against SPEED_MAX */
#define TIME_MAX 1e9  /* s */

static const char *const shape_names[] = {"disc", "rectangle", "segment", NULL}; /* enum pfsph_nozzle */

static bool has(const cJSON *e, const char *key) { return cJSON_GetObjectItemCaseSensitive(e, key) != NULL; }

static int require(const cJSON *e, const char *P, const char *key, pfsph_jctx *ctx)
{
    if (has(e, key)) return PFSPH_OK;
    char kp[192];
    snprintf(kp, sizeof kp, "%s.%s", P, key);
    return pfsph__json_fail(ctx, kp, "missing required key \"%s\"", key);
}

/* > 0 and <= hi (the helpers check closed ranges only) */
static int positive(const cJSON *e, const char *P, const char *key, double hi, double *out, pfsph_jctx *ctx)
{
    double v = *out;
    int rc = pfsph__json_number(e, P, key, -HUGE_VAL, hi, &v, ctx);
    if (rc) return rc;
    if (!(v > 0)) {
        char kp[192];
        snprintf(kp, sizeof kp, "%s.%s", P, key);
        return pfsph__json_fail(ctx, kp, "value %g is out of range: must be > 0", v);
    }
    *out = v;
    return PFSPH_OK;
}

static int parse_one(const cJSON *e, const char *P, pfsph_scene *s, pfsph_emitter_params *m, pfsph_jctx *ctx)
{
    static const char *const keys[] = {"shape", "phase", "center", "direction", "radius", "size",    "width",
                                       "speed", "rate",  "start",  "stop",      "bubble", "comment", NULL};
    int rc;
    char kp[192];
    if (!cJSON_IsObject(e)) return pfsph__json_fail(ctx, P, "expected an object");
    if ((rc = pfsph__json_check_keys(e, P, keys, ctx))) return rc;
    memset(m, 0, sizeof *m);
    m->stop = INFINITY;
    /* shape: the one the dimension allows by default */
    m->shape = s->dim == 2 ? PFSPH_NOZZLE_SEGMENT : PFSPH_NOZZLE_DISC;
    const cJSON *sv = cJSON_GetObjectItemCaseSensitive(e, "shape");
    if (sv) {
        snprintf(kp, sizeof kp, "%s.shape", P);
        int k = -1;
        if (cJSON_IsString(sv) && sv->valuestring)
            for (int i = 0; shape_names[i]; i++)
                if (strcmp(sv->valuestring, shape_names[i]) == 0) k = i;
        bool ok2 = k == PFSPH_NOZZLE_SEGMENT;
        if (k < 0 || (s->dim == 2) != ok2)
            return pfsph__json_fail(ctx, kp, "expected %s in %dD",
                                    s->dim == 2 ? "\"segment\"" : "\"disc\" or \"rectangle\"", s->dim);
        m->shape = k;
    }
    /* phase: the first fluid or gas phase unless named */
    m->phase = -1;
    for (int i = 0; i < s->nphases && m->phase < 0; i++)
        if (s->phases[i].kind != PFSPH_PHASE_SOLID) m->phase = i;
    const cJSON *pv = cJSON_GetObjectItemCaseSensitive(e, "phase");
    snprintf(kp, sizeof kp, "%s.phase", P);
    if (pv) {
        if (!cJSON_IsString(pv) || !pv->valuestring) return pfsph__json_fail(ctx, kp, "expected a phase name (string)");
        int idx = pfsph_scene_phase_index(s, pv->valuestring);
        if (idx < 0) return pfsph__json_fail(ctx, kp, "unknown phase \"%.64s\"", pv->valuestring);
        if (s->phases[idx].kind == PFSPH_PHASE_SOLID)
            return pfsph__json_fail(ctx, kp,
                                    "phase \"%s\" is a solid phase; an emitter needs a phase of kind "
                                    "\"fluid\" or \"gas\"",
                                    s->phases[idx].name);
        m->phase = idx;
    }
    /* bubble: the fluid block (index into $.fluid) of a bubble that the gas is blown into; its
     * particles then carry that bubble's id and the film spreads over the grown surface
     * (docs/film.md, "Blowing a bubble"). Without "phase" the emitter takes the bubble's gas. */
    if (has(e, "bubble")) {
        int bi = -1;
        snprintf(kp, sizeof kp, "%s.bubble", P);
        const cJSON *bv = cJSON_GetObjectItemCaseSensitive(e, "bubble");
        if (!cJSON_IsNumber(bv) || bv->valuedouble != floor(bv->valuedouble))
            return pfsph__json_fail(ctx, kp, "expected the index of a fluid block with a \"bubble\" key (an integer)");
        if (!(bv->valuedouble >= 0 && bv->valuedouble < s->nblocks))
            return pfsph__json_fail(ctx, kp, "%g is not a fluid block: $.fluid has %d (indices 0 .. %d)",
                                    bv->valuedouble, s->nblocks, s->nblocks - 1);
        bi = (int)bv->valuedouble;
        const pfsph_block *b = &s->blocks[bi];
        if (b->bubble < 0)
            return pfsph__json_fail(ctx, kp, "%d: $.fluid[%d] is not a bubble (it has no \"bubble\" key)", bi, bi);
        const int gas = s->film.gas[b->bubble];
        if (!pv) m->phase = gas;
        else if (m->phase != gas)
            return pfsph__json_fail(ctx, kp,
                                    "%d: the emitter's phase \"%s\" is not the gas \"%s\" of bubble "
                                    "$.fluid[%d]; blow that gas (or leave \"phase\" out)",
                                    bi, s->phases[m->phase].name, s->phases[gas].name, bi);
        m->bubble = b->bubble + 1;
    }
    if (m->phase < 0) return pfsph__json_fail(ctx, kp, "no fluid or gas phase is defined in $.phases");

    if ((rc = require(e, P, "center", ctx)) || (rc = require(e, P, "direction", ctx))) return rc;
    if ((rc = pfsph__json_vec(e, P, "center", s->dim, -COORD_MAX, COORD_MAX, m->center, ctx))) return rc;
    for (int a = 0; a < s->dim; a++)
        if (!(m->center[a] > s->domain_min[a] && m->center[a] < s->domain_max[a])) {
            snprintf(kp, sizeof kp, "%s.center", P);
            return pfsph__json_fail(ctx, kp,
                                    "the nozzle's centre lies outside the domain (component %d = %g, "
                                    "domain %g .. %g)",
                                    a, m->center[a], s->domain_min[a], s->domain_max[a]);
        }
    if ((rc = pfsph__json_vec(e, P, "direction", s->dim, -1e6, 1e6, m->direction, ctx))) return rc;
    double n2 = 0, big = 0;
    for (int a = 0; a < s->dim; a++) {
        n2 += m->direction[a] * m->direction[a];
        if (fabs(m->direction[a]) > big) {
            big = fabs(m->direction[a]);
            m->axis = a;
        }
    }
    if (!(n2 > 0)) {
        snprintf(kp, sizeof kp, "%s.direction", P);
        return pfsph__json_fail(ctx, kp, "must not be zero");
    }
    for (int a = 0; a < 3; a++) m->direction[a] = a < s->dim ? m->direction[a] / sqrt(n2) : 0;

    /* the opening: exactly the keys its shape uses */
    const char *want = m->shape == PFSPH_NOZZLE_DISC ? "radius" : m->shape == PFSPH_NOZZLE_RECTANGLE ? "size" : "width";
    static const char *const opening[] = {"radius", "size", "width"};
    for (int k = 0; k < 3; k++)
        if (strcmp(opening[k], want) != 0 && has(e, opening[k])) {
            snprintf(kp, sizeof kp, "%s.%s", P, opening[k]);
            return pfsph__json_fail(ctx, kp, "not used by a \"%s\" nozzle (it takes \"%s\")", shape_names[m->shape],
                                    want);
        }
    if ((rc = require(e, P, want, ctx))) return rc;
    if (m->shape == PFSPH_NOZZLE_DISC) {
        if ((rc = positive(e, P, "radius", COORD_MAX, &m->radius, ctx))) return rc;
    } else if (m->shape == PFSPH_NOZZLE_SEGMENT) {
        if ((rc = positive(e, P, "width", COORD_MAX, &m->size[0], ctx))) return rc;
    } else {
        if ((rc = pfsph__json_vec(e, P, "size", 2, -COORD_MAX, COORD_MAX, m->size, ctx))) return rc;
        for (int k = 0; k < 2; k++)
            if (!(m->size[k] > 0)) {
                snprintf(kp, sizeof kp, "%s.size", P);
                return pfsph__json_fail(ctx, kp, "size[%d] = %g must be > 0", k, m->size[k]);
            }
    }

    /* a speed or a rate: one of them, the other follows from the nozzle's lattice sites */
    bool hs = has(e, "speed"), hr = has(e, "rate");
    if (hs == hr) {
        snprintf(kp, sizeof kp, "%s.%s", P, hs ? "rate" : "speed");
        return pfsph__json_fail(ctx, kp,
                                hs ? "give \"speed\" or \"rate\", not both (the rate follows from the speed "
                                     "and the nozzle's lattice sites, and the other way round)"
                                   : "missing required key \"speed\" (m/s) or \"rate\" (volume per second)");
    }
    if (hs && (rc = positive(e, P, "speed", SPEED_MAX, &m->speed, ctx))) return rc;
    if (hr && (rc = positive(e, P, "rate", RATE_MAX, &m->rate, ctx))) return rc;
    if ((rc = pfsph__json_number(e, P, "start", 0, TIME_MAX, &m->start, ctx))) return rc;
    if (has(e, "stop")) {
        if ((rc = pfsph__json_number(e, P, "stop", 0, TIME_MAX, &m->stop, ctx))) return rc;
        if (!(m->stop > m->start)) {
            snprintf(kp, sizeof kp, "%s.stop", P);
            return pfsph__json_fail(ctx, kp, "stop %g s must be after start %g s", m->stop, m->start);
        }
    }
    return PFSPH_OK;
}

int pfsph__scene_parse_emitters(const cJSON *arr, const char *path, pfsph_scene *s, pfsph_jctx *ctx)
{
    if (!arr) return PFSPH_OK;
    if (!cJSON_IsArray(arr)) return pfsph__json_fail(ctx, path, "expected an array of emitters");
    int n = cJSON_GetArraySize(arr);
    if (n > PFSPH_MAX_EMITTERS)
        return pfsph__json_fail(ctx, path, "too many entries (%d, at most %d)", n, PFSPH_MAX_EMITTERS);
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        char P[128];
        snprintf(P, sizeof P, "%s[%d]", path, i);
        int rc = parse_one(e, P, s, &s->emitters[i], ctx);
        if (rc) return rc;
    }
    s->nemitters = i;
    return PFSPH_OK;
}
