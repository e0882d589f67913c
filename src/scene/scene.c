/* Scene loader: JSON text -> a fully validated pfsph_scene (docs/scene-format.md). Everything a
 * run needs is checked here, before any particle exists, so a bad scene fails in milliseconds
 * with "<file>: <JSON path>: <reason>" instead of minutes into a run. */
#include "pfsph/scene.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "physics/solver.h"
#include "scene/json_util.h"
#include "scene/shapes.h"

/* ---------------------------------------------------------------------------------------- */
#include "scene/scene_parser.h"

static const char *const axis_names[] = {"x", "y", "z", NULL};
static const char *const kind_names[] = {"fluid", "gas", "solid", NULL};
static const char *const pressure_scale_names[] = {"phase", "common", NULL}; /* enum order */
static const char *const mode_names[] = {"physical", "interactive", NULL};   /* enum pfsph_mode */

static int axis_index(const char *path, parser *p, const cJSON *obj, int *axis)
{
    return json_enum(p, obj, path, "axis", axis_names, axis);
}

typedef pfsph__geo geo;

/* ---------------------------------------------------------------------------------------- */
/* Sections. */

static int parse_domain(parser *p, const cJSON *root)
{
    pfsph_scene *s = p->s;
    TRY(require(p, root, "$", "domain"));
    const cJSON *d = get(root, "domain");
    static const char *const keys[] = {"min", "max", NULL};
    TRY(pfsph__json_check_keys(d, "$.domain", keys, &p->ctx));
    TRY(require(p, d, "$.domain", "min"));
    TRY(require(p, d, "$.domain", "max"));
    TRY(vecd(p, d, "$.domain", "min", -COORD_MAX, COORD_MAX, s->domain_min));
    TRY(vecd(p, d, "$.domain", "max", -COORD_MAX, COORD_MAX, s->domain_max));
    for (int k = 0; k < s->dim; k++)
        if (!(s->domain_min[k] < s->domain_max[k]))
            return pfsph__json_fail(&p->ctx, "$.domain", "min[%d] = %g must be less than max[%d] = %g", k,
                                    s->domain_min[k], k, s->domain_max[k]);
    return PFSPH_OK;
}

/* The solver block: the keys every solver shares, then the chosen solver's own (its registry row
 * gives names, defaults and ranges). Keys of other solvers are accepted and range-checked, so
 * that switching "type" is a one-word change, but only the chosen solver's are kept. */
static int parse_solver(parser *p, const cJSON *root)
{
    pfsph_scene *s = p->s;
    const cJSON *o = get(root, "solver");
    if (!o) return PFSPH_OK;
    static const char *const common[] = {"type", "sound_speed", "gamma", "pressure_scale"};
    const char *keys[4 + PFSPH_MAX_SOLVERS * PFSPH_SOLVER_MAX_KEYS + 1];
    const char *names[PFSPH_MAX_SOLVERS + 1];
    int nk = 0, nn = 0;
    for (int k = 0; k < 4; k++) keys[nk++] = common[k];
    for (int i = 0; pfsph_solver_at(i); i++) {
        const pfsph_solver_ops *ops = pfsph_solver_at(i);
        names[nn++] = ops->name;
        for (int k = 0; k < ops->nkeys; k++) {
            int seen = 0;
            for (int m = 0; m < nk && !seen; m++) seen = !strcmp(keys[m], ops->keys[k].name);
            if (!seen && nk < (int)(sizeof keys / sizeof *keys) - 1) keys[nk++] = ops->keys[k].name;
        }
    }
    keys[nk] = NULL;
    names[nn] = NULL;
    const char *P = "$.solver";
    TRY(pfsph__json_check_keys(o, P, keys, &p->ctx));
    if (get(o, "type")) {
        int which = 0;
        TRY(json_enum(p, o, P, "type", names, &which));
        pfsph_scene_set_solver(s, names[which]);
    }
    const pfsph_solver_ops *self = pfsph_solver_find(s->solver);
    for (int i = 0; pfsph_solver_at(i); i++) {
        const pfsph_solver_ops *ops = pfsph_solver_at(i);
        for (int k = 0; k < ops->nkeys; k++) {
            const pfsph_solver_key *key = &ops->keys[k];
            double v = key->def;
            if (key->integer == PFSPH_KEY_AUTO_BOOL) {
                int iv = (int)key->def;
                TRY(pfsph__json_tristate(o, P, key->name, &iv, &p->ctx));
                v = iv;
            } else if (key->integer) {
                int iv = (int)key->def;
                TRY(pfsph__json_int(o, P, key->name, (long)key->min, (long)key->max, &iv, &p->ctx));
                v = iv;
            } else {
                TRY(pfsph__json_number(o, P, key->name, key->min, key->max, &v, &p->ctx));
            }
            if (ops == self) s->solver_settings[k] = v;
        }
    }
    char msg[256];
    const char *bad = NULL;
    if (self && self->check && self->check(s->solver_settings, &bad, msg, sizeof msg)) {
        char kp[512];
        path_key(kp, sizeof kp, P, bad);
        return pfsph__json_fail(&p->ctx, kp, "%s", msg);
    }
    TRY(pfsph__json_number(o, P, "sound_speed", 0.0, 1e5, &s->sound_speed, &p->ctx));
    TRY(pfsph__json_number(o, P, "gamma", 1.0, 10.0, &s->gamma, &p->ctx));
    TRY(json_enum(p, o, P, "pressure_scale", pressure_scale_names, &s->pressure_scale));
    return PFSPH_OK;
}

static int parse_time(parser *p, const cJSON *root)
{
    pfsph_scene *s = p->s;
    const cJSON *o = get(root, "time");
    if (!o) return PFSPH_OK;
    static const char *const keys[] = {"end", "fps", "cfl", "dt_min", "dt_max", NULL};
    const char *P = "$.time";
    TRY(pfsph__json_check_keys(o, P, keys, &p->ctx));
    TRY(positive(p, o, P, "end", PFSPH_MAX_END, &s->end_time));
    TRY(positive(p, o, P, "fps", 1e4, &s->fps));
    TRY(positive(p, o, P, "cfl", 1.0, &s->cfl));
    TRY(positive(p, o, P, "dt_min", 1.0, &s->dt_min));
    TRY(positive(p, o, P, "dt_max", 1.0, &s->dt_max));
    if (s->dt_min > s->dt_max)
        return pfsph__json_fail(&p->ctx, "$.time.dt_min", "dt_min (%g s) is greater than dt_max (%g s)", s->dt_min,
                                s->dt_max);
    if (s->end_time * s->fps > PFSPH_MAX_FRAMES)
        return pfsph__json_fail(&p->ctx, "$.time.end",
                                "end %g s at %g fps makes %.3g frames, more than the %d one run "
                                "holds",
                                s->end_time, s->fps, s->end_time * s->fps, PFSPH_MAX_FRAMES);
    return PFSPH_OK;
}

static int parse_phases(parser *p, const cJSON *root)
{
    pfsph_scene *s = p->s;
    const cJSON *arr;
    TRY(array_of(p, root, "$", "phases", PFSPH_MAX_PHASES, &arr));
    if (!arr || cJSON_GetArraySize(arr) == 0) {
        /* No phases: one water phase, so that the smallest scenes stay small. */
        s->nphases = 1;
        pfsph_phase *ph = &s->phases[0];
        memset(ph, 0, sizeof *ph);
        strcpy(ph->name, "water");
        ph->kind = PFSPH_PHASE_FLUID;
        ph->rest_density = 1000.0;
        ph->viscosity = 1e-3;
        memcpy(ph->color, palette[0], sizeof ph->color);
        return PFSPH_OK;
    }
    static const char *const keys[] = {"name", "kind", "rest_density", "viscosity", "color", "comment", NULL};
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        char P[128];
        path_index(P, sizeof P, "$.phases", i);
        TRY(pfsph__json_check_keys(e, P, keys, &p->ctx));
        pfsph_phase *ph = &s->phases[i];
        memset(ph, 0, sizeof *ph);
        TRY(require(p, e, P, "name"));
        TRY(pfsph__json_string(e, P, "name", ph->name, sizeof ph->name, &p->ctx));
        char kp[160];
        path_key(kp, sizeof kp, P, "name");
        if (!ph->name[0]) return pfsph__json_fail(&p->ctx, kp, "a phase name must not be empty");
        for (int j = 0; j < i; j++)
            if (strcmp(s->phases[j].name, ph->name) == 0)
                return pfsph__json_fail(&p->ctx, kp, "duplicate phase name \"%s\" (also $.phases[%d])", ph->name, j);
        ph->kind = PFSPH_PHASE_FLUID;
        TRY(json_enum(p, e, P, "kind", kind_names, &ph->kind));
        /* Defaults by kind: water for liquids and walls, air for gas; viscosity see docs. */
        ph->rest_density = ph->kind == PFSPH_PHASE_GAS ? 1.2 : 1000.0;
        ph->viscosity = ph->kind == PFSPH_PHASE_SOLID ? 0.0 : 1e-3;
        if (ph->kind == PFSPH_PHASE_SOLID) memcpy(ph->color, solid_grey, sizeof ph->color);
        else memcpy(ph->color, palette[i % 8], sizeof ph->color);
        TRY(pfsph__json_number(e, P, "rest_density", 0.01, 1e5, &ph->rest_density, &p->ctx));
        TRY(pfsph__json_number(e, P, "viscosity", 0.0, 100.0, &ph->viscosity, &p->ctx));
        double c[3] = {ph->color[0], ph->color[1], ph->color[2]};
        TRY(pfsph__json_vec(e, P, "color", 3, 0.0, 1.0, c, &p->ctx));
        for (int k = 0; k < 3; k++) ph->color[k] = (float)c[k];
        ph->color_set = cJSON_GetObjectItemCaseSensitive(e, "color") != NULL;
    }
    s->nphases = i;
    return PFSPH_OK;
}

/* Phase named under "phase" in obj, which must be of a solid kind (want_solid) or not. When
 * absent, *out keeps the default set by the caller (-1: none available). */
static int phase_ref(parser *p, const cJSON *obj, const char *path, bool want_solid, int *out)
{
    const cJSON *v = get(obj, "phase");
    char kp[160];
    path_key(kp, sizeof kp, path, "phase");
    if (!v) return PFSPH_OK;
    if (!cJSON_IsString(v) || !v->valuestring) return pfsph__json_fail(&p->ctx, kp, "expected a phase name (string)");
    int idx = pfsph_scene_phase_index(p->s, v->valuestring);
    if (idx < 0) {
        char list[400] = "";
        size_t n = 0;
        for (int i = 0; i < p->s->nphases; i++) {
            int w = snprintf(list + n, sizeof list - n, "%s\"%s\"", i ? ", " : "", p->s->phases[i].name);
            if (w > 0 && (size_t)w < sizeof list - n) n += (size_t)w;
        }
        return pfsph__json_fail(&p->ctx, kp, "unknown phase \"%.64s\" (phases: %s)", v->valuestring, list);
    }
    int kind = p->s->phases[idx].kind;
    if (want_solid && kind != PFSPH_PHASE_SOLID)
        return pfsph__json_fail(&p->ctx, kp, "phase \"%s\" is a %s phase; solids need a phase of kind \"solid\"",
                                p->s->phases[idx].name, kind_names[kind]);
    if (!want_solid && kind == PFSPH_PHASE_SOLID)
        return pfsph__json_fail(&p->ctx, kp,
                                "phase \"%s\" is a solid phase; fluid blocks need a phase of kind "
                                "\"fluid\" or \"gas\"",
                                p->s->phases[idx].name);
    *out = idx;
    return PFSPH_OK;
}

/* Shape-specific geometry keys shared by fluid blocks and solids. */
static int parse_geometry(parser *p, const cJSON *e, const char *P, int shape, double *min, double *max, double *center,
                          double *radius, double *height, int *axis)
{
    pfsph_scene *s = p->s;
    if (shape == PFSPH_SHAPE_BOX || shape == PFSPH_SHAPE_CONTAINER) {
        TRY(require(p, e, P, "min"));
        TRY(require(p, e, P, "max"));
        TRY(vecd(p, e, P, "min", -COORD_MAX, COORD_MAX, min));
        TRY(vecd(p, e, P, "max", -COORD_MAX, COORD_MAX, max));
        for (int k = 0; k < s->dim; k++)
            if (!(min[k] < max[k])) {
                char kp[160];
                path_key(kp, sizeof kp, P, "max");
                return pfsph__json_fail(&p->ctx, kp, "max[%d] = %g must be greater than min[%d] = %g", k, max[k], k,
                                        min[k]);
            }
        return PFSPH_OK;
    }
    TRY(require(p, e, P, "center"));
    TRY(require(p, e, P, "radius"));
    TRY(vecd(p, e, P, "center", -COORD_MAX, COORD_MAX, center));
    TRY(positive(p, e, P, "radius", COORD_MAX, radius));
    if (shape != PFSPH_SHAPE_CYLINDER) return PFSPH_OK;
    char kp[160];
    if (s->dim == 2) {
        /* A 2D cylinder is its cross-section, a disc in the xy plane. */
        *axis = 2;
        TRY(axis_index(P, p, e, axis));
        path_key(kp, sizeof kp, P, "axis");
        if (*axis != 2)
            return pfsph__json_fail(&p->ctx, kp,
                                    "in 2D a cylinder's axis must be \"z\" (it is a "
                                    "disc in the xy plane)");
        if (get(e, "height")) {
            path_key(kp, sizeof kp, P, "height");
            return pfsph__json_fail(&p->ctx, kp, "not used in 2D (a 2D cylinder is a disc)");
        }
        *height = 0.0;
        return PFSPH_OK;
    }
    *axis = 1;
    TRY(axis_index(P, p, e, axis));
    TRY(require(p, e, P, "height"));
    TRY(positive(p, e, P, "height", COORD_MAX, height));
    return PFSPH_OK;
}

static const char *const solid_shapes[] = {"box",       "sphere", "cylinder",
                                           "container", "plane",  NULL}; /* enum pfsph_shape order */
static const char *const block_shapes[] = {"box", "sphere", "cylinder", NULL};

static int parse_solids(parser *p, const cJSON *root)
{
    pfsph_scene *s = p->s;
    const cJSON *arr;
    TRY(array_of(p, root, "$", "solids", PFSPH_MAX_SOLIDS, &arr));
    if (!arr) return PFSPH_OK;
    /* Default phase of a solid: the first solid phase, else one named "solid" made on demand. */
    int def = -1;
    for (int i = 0; i < s->nphases; i++)
        if (s->phases[i].kind == PFSPH_PHASE_SOLID) {
            def = i;
            break;
        }
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        char P[128];
        path_index(P, sizeof P, "$.solids", i);
        if (!cJSON_IsObject(e)) return pfsph__json_fail(&p->ctx, P, "expected an object");
        TRY(require(p, e, P, "shape"));
        pfsph_solid *so = &s->solids[i];
        memset(so, 0, sizeof *so);
        TRY(json_enum(p, e, P, "shape", solid_shapes, &so->shape));
        static const char *const k_box[] = {"shape", "phase", "layers",  "slip", "viscosity",
                                            "min",   "max",   "comment", NULL};
        static const char *const k_cont[] = {"shape", "phase", "layers",   "slip",    "viscosity",
                                             "min",   "max",   "open_top", "comment", NULL};
        static const char *const k_sph[] = {"shape",  "phase",  "layers",  "slip", "viscosity",
                                            "center", "radius", "comment", NULL};
        static const char *const k_cyl[] = {"shape",  "phase",  "layers", "slip",    "viscosity", "center",
                                            "radius", "height", "axis",   "comment", NULL};
        static const char *const k_plane[] = {"shape", "phase",  "layers",  "slip", "viscosity",
                                              "point", "normal", "comment", NULL};
        const char *const *keys = so->shape == PFSPH_SHAPE_BOX ? k_box
            : so->shape == PFSPH_SHAPE_CONTAINER               ? k_cont
            : so->shape == PFSPH_SHAPE_SPHERE                  ? k_sph
            : so->shape == PFSPH_SHAPE_CYLINDER                ? k_cyl
                                                               : k_plane;
        TRY(pfsph__json_check_keys(e, P, keys, &p->ctx));
        so->layers = 2;
        TRY(pfsph__json_int(e, P, "layers", 1, 10, &so->layers, &p->ctx));
        /* wall friction (docs/scene-format.md, "Wall friction"): free slip has none to scale */
        static const char *const slips[] = {"no-slip", "free-slip", NULL}; /* enum pfsph_slip order */
        TRY(json_enum(p, e, P, "slip", slips, &so->slip));
        TRY(pfsph__json_number(e, P, "viscosity", 0.0, 100.0, &so->viscosity, &p->ctx));
        so->own_viscosity = get(e, "viscosity") != NULL;
        if (so->slip == PFSPH_FREE_SLIP && get(e, "viscosity")) {
            char kp[160];
            path_key(kp, sizeof kp, P, "viscosity");
            return pfsph__json_fail(&p->ctx, kp,
                                    "a free-slip wall has no friction: its viscosity would not be used "
                                    "(remove it, or make the wall \"no-slip\")");
        }
        TRY(pfsph__json_bool(e, P, "open_top", &so->open_top, &p->ctx));
        if (so->shape == PFSPH_SHAPE_PLANE) {
            TRY(require(p, e, P, "point"));
            TRY(require(p, e, P, "normal"));
            TRY(vecd(p, e, P, "point", -COORD_MAX, COORD_MAX, so->center));
            TRY(vecd(p, e, P, "normal", -COORD_MAX, COORD_MAX, so->normal));
            double n2 = 0;
            for (int k = 0; k < s->dim; k++) n2 += so->normal[k] * so->normal[k];
            char kp[160];
            path_key(kp, sizeof kp, P, "normal");
            if (!(n2 > 1e-24)) return pfsph__json_fail(&p->ctx, kp, "the normal must not be zero");
            for (int k = 0; k < 3; k++) so->normal[k] /= sqrt(n2);
            /* Bounding box for the domain check: the point itself. */
            for (int k = 0; k < 3; k++) so->min[k] = so->max[k] = so->center[k];
        } else {
            TRY(parse_geometry(p, e, P, so->shape, so->min, so->max, so->center, &so->radius, &so->height, &so->axis));
        }
        /* Phase. */
        if (get(e, "phase")) {
            TRY(phase_ref(p, e, P, true, &so->phase));
        } else {
            if (def < 0) {
                int idx = pfsph_scene_phase_index(s, "solid");
                if (idx >= 0) {
                    char kp[160];
                    path_key(kp, sizeof kp, P, "phase");
                    return pfsph__json_fail(&p->ctx, kp,
                                            "no phase given and the default solid phase \"solid\" "
                                            "cannot be made: the name is taken by a %s phase",
                                            kind_names[s->phases[idx].kind]);
                }
                if (s->nphases >= PFSPH_MAX_PHASES)
                    return pfsph__json_fail(&p->ctx, "$.phases",
                                            "too many phases: %d, and solids without a phase need "
                                            "one more, \"solid\" (at most %d in all)",
                                            s->nphases, PFSPH_MAX_PHASES);
                def = s->nphases++;
                pfsph_phase *ph = &s->phases[def];
                memset(ph, 0, sizeof *ph);
                strcpy(ph->name, "solid");
                ph->kind = PFSPH_PHASE_SOLID;
                ph->rest_density = 1000.0;
                ph->viscosity = 0.0;
                memcpy(ph->color, solid_grey, sizeof ph->color);
            }
            so->phase = def;
        }
        /* A solid wholly outside the domain is certainly a mistake. */
        geo g = pfsph__geo_of(s->dim, so->shape == PFSPH_SHAPE_CONTAINER ? PFSPH_SHAPE_BOX : so->shape, so->min,
                              so->max, so->center, so->radius, so->height, so->axis);
        for (int k = 0; k < s->dim; k++)
            if (g.max[k] < s->domain_min[k] || g.min[k] > s->domain_max[k]) {
                char a[96], b[96];
                pfsph__fmt_vec(a, sizeof a, s->dim, s->domain_min);
                pfsph__fmt_vec(b, sizeof b, s->dim, s->domain_max);
                return pfsph__json_fail(&p->ctx, P, "solid lies outside the domain %s .. %s", a, b);
            }
    }
    s->nsolids = i;
    return PFSPH_OK;
}

/* A fluid block that is a bubble in air (PF Section 4.2.2, docs/film.md): "bubble": {"film":
 * liquid phase, "thickness": m | "liquid_volume": m^dim}. The block's phase is the gas. */
static int parse_bubble(parser *p, const cJSON *e, const char *P, int index, pfsph_block *b)
{
    pfsph_scene *s = p->s;
    char BP[160], kp[200];
    path_key(BP, sizeof BP, P, "bubble");
    const cJSON *o = get(e, "bubble");
    if (!cJSON_IsObject(o))
        return pfsph__json_fail(&p->ctx, BP, "expected an object {\"film\": phase, \"thickness\": m}");
    static const char *const keys[] = {"film", "thickness", "liquid_volume", "comment", NULL};
    TRY(pfsph__json_check_keys(o, BP, keys, &p->ctx));
    TRY(require(p, o, BP, "film"));
    if (s->film.nbubbles >= PFSPH_MAX_BUBBLES)
        return pfsph__json_fail(&p->ctx, BP, "too many bubbles (at most %d)", PFSPH_MAX_BUBBLES);
    path_key(kp, sizeof kp, P, "phase");
    if (s->phases[b->phase].kind != PFSPH_PHASE_GAS)
        return pfsph__json_fail(&p->ctx, kp,
                                "phase \"%s\" is a %s phase; a bubble's block is its gas: give a phase "
                                "of kind \"gas\"",
                                s->phases[b->phase].name, kind_names[s->phases[b->phase].kind]);
    char name[PFSPH_NAME_LEN];
    TRY(pfsph__json_string(o, BP, "film", name, sizeof name, &p->ctx));
    path_key(kp, sizeof kp, BP, "film");
    const int film = pfsph_scene_phase_index(s, name);
    if (film < 0) return pfsph__json_fail(&p->ctx, kp, "unknown phase \"%.64s\"", name);
    if (s->phases[film].kind != PFSPH_PHASE_FLUID)
        return pfsph__json_fail(&p->ctx, kp, "phase \"%s\" is a %s phase; a film is a liquid (kind \"fluid\")", name,
                                kind_names[s->phases[film].kind]);
    if (s->film.film[b->phase] >= 0 && s->film.film[b->phase] != film)
        return pfsph__json_fail(&p->ctx, kp,
                                "gas \"%s\" already has the film \"%s\" (one film liquid per gas "
                                "phase)",
                                s->phases[b->phase].name, s->phases[s->film.film[b->phase]].name);
    const bool th = get(o, "thickness") != NULL, vol = get(o, "liquid_volume") != NULL;
    if (th == vol)
        return pfsph__json_fail(&p->ctx, BP, "give exactly one of \"thickness\" (m) and \"liquid_volume\" (m^%d)",
                                s->dim);
    const int k = s->film.nbubbles;
    double t = 0, v = 0;
    const double sp = 2.0 * s->particle_radius;
    if (th) {
        /* a film thicker than a particle is no film: the fraction a = t / d must stay <= 1 */
        TRY(pfsph__json_number(o, BP, "thickness", 0.0, sp, &t, &p->ctx));
        path_key(kp, sizeof kp, BP, "thickness");
        if (!(t > 0)) return pfsph__json_fail(&p->ctx, kp, "thickness %g m: must be above 0", t);
    } else {
        TRY(pfsph__json_number(o, BP, "liquid_volume", 0.0, 1e6, &v, &p->ctx));
        path_key(kp, sizeof kp, BP, "liquid_volume");
        if (!(v > 0)) return pfsph__json_fail(&p->ctx, kp, "liquid volume %g m^%d: must be above 0", v, s->dim);
    }
    s->film.film[b->phase] = film;
    s->film.gas[k] = b->phase;
    s->film.block[k] = index;
    s->film.thickness[k] = t;
    s->film.volume[k] = v;
    s->film.nbubbles = k + 1;
    b->bubble = k;
    return PFSPH_OK;
}

static int parse_fluid(parser *p, const cJSON *root)
{
    pfsph_scene *s = p->s;
    const cJSON *arr;
    TRY(array_of(p, root, "$", "fluid", PFSPH_MAX_BLOCKS, &arr));
    /* a scene that starts empty is fine when an emitter fills it */
    const cJSON *em = get(root, "emitters");
    if ((!arr || cJSON_GetArraySize(arr) == 0) && !(cJSON_IsArray(em) && cJSON_GetArraySize(em) > 0))
        return pfsph__json_fail(&p->ctx, "$.fluid",
                                "a scene needs at least one fluid block (\"fluid\": [ {...} ]) or an emitter "
                                "(\"emitters\": [ {...} ])");
    if (!arr) return PFSPH_OK;
    int def = -1;
    for (int i = 0; i < s->nphases; i++)
        if (s->phases[i].kind != PFSPH_PHASE_SOLID) {
            def = i;
            break;
        }
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        char P[128];
        path_index(P, sizeof P, "$.fluid", i);
        if (!cJSON_IsObject(e)) return pfsph__json_fail(&p->ctx, P, "expected an object");
        TRY(require(p, e, P, "shape"));
        pfsph_block *b = &s->blocks[i];
        memset(b, 0, sizeof *b);
        TRY(json_enum(p, e, P, "shape", block_shapes, &b->shape));
        static const char *const k_box[] = {"shape", "phase",  "velocity", "jitter", "min",
                                            "max",   "bubble", "comment",  NULL};
        static const char *const k_sph[] = {"shape",  "phase",  "velocity", "jitter", "center",
                                            "radius", "bubble", "comment",  NULL};
        static const char *const k_cyl[] = {"shape",  "phase", "velocity", "jitter",  "center", "radius",
                                            "height", "axis",  "bubble",   "comment", NULL};
        const char *const *keys = b->shape == PFSPH_SHAPE_BOX ? k_box : b->shape == PFSPH_SHAPE_SPHERE ? k_sph : k_cyl;
        TRY(pfsph__json_check_keys(e, P, keys, &p->ctx));
        TRY(parse_geometry(p, e, P, b->shape, b->min, b->max, b->center, &b->radius, &b->height, &b->axis));
        TRY(vecd(p, e, P, "velocity", -VEL_MAX, VEL_MAX, b->velocity));
        TRY(pfsph__json_number(e, P, "jitter", 0.0, 0.5, &b->jitter, &p->ctx));
        b->phase = def;
        TRY(phase_ref(p, e, P, false, &b->phase));
        if (b->phase < 0) {
            char kp[160];
            path_key(kp, sizeof kp, P, "phase");
            return pfsph__json_fail(&p->ctx, kp, "no fluid or gas phase is defined in $.phases");
        }
        b->bubble = -1;
        if (get(e, "bubble")) TRY(parse_bubble(p, e, P, i, b));
        /* Spheres and cylinders also get their bounding box in min/max (used by samplers and
         * the checks below). */
        geo g = pfsph__geo_of(s->dim, b->shape, b->min, b->max, b->center, b->radius, b->height, b->axis);
        if (b->shape != PFSPH_SHAPE_BOX)
            for (int k = 0; k < 3; k++) {
                b->min[k] = g.min[k];
                b->max[k] = g.max[k];
            }
    }
    s->nblocks = i;
    return PFSPH_OK;
}

/* Checks across blocks and solids, once all of them are known. */

/* ---------------------------------------------------------------------------------------- */

void pfsph_scene_defaults(pfsph_scene *s)
{
    memset(s, 0, sizeof *s);
    snprintf(s->source, sizeof s->source, "<scene>");
    snprintf(s->name, sizeof s->name, "scene");
    s->dim = 3;
    s->particle_radius = 0.01;
    s->support_factor = 2.0;
    s->gravity[1] = -9.81;
    pfsph_scene_set_solver(s, "pcisph");
    s->cfl = 0.4;
    s->dt_min = 1e-6;
    s->dt_max = 0.005;
    s->end_time = 1.0;
    s->fps = 25.0;
    s->seed = 1;
    s->threads = 0;
    s->sound_speed = 0.0;
    s->gamma = 7.0;
    pfsph_pairwise_defaults(&s->pairwise);
    pfsph_diffuse_defaults(&s->diffuse);
    pfsph_film_defaults(&s->film);
    snprintf(s->output.dir, sizeof s->output.dir, "runs/scene");
    s->output.vtp = true;
    s->output.ply = false;
    s->output.write_boundary = true;
    s->output.fields = 0;
    s->output.frame_interval = 1;
    s->output.checkpoint_interval = 10;
    s->output.surface_layer = true;
    s->output.surface = (pfsph_surface_output){.on = false, .ply = true, .obj = false, .vtp = true};
    s->camera.set = false;
    s->camera.up[1] = 1.0;
    s->camera.eye[2] = 1.0;
    s->camera.fov_deg = 40.0;
    s->camera.width = 960;
    s->camera.height = 540;
    snprintf(s->camera.color_by, sizeof s->camera.color_by, "phase");
}

const char *pfsph_scene_solver_name(const pfsph_scene *s) { return s->solver; }

int pfsph_scene_set_solver(pfsph_scene *s, const char *name)
{
    const pfsph_solver_ops *ops = pfsph_solver_find(name);
    if (!ops) return PFSPH_EINPUT;
    snprintf(s->solver, sizeof s->solver, "%s", ops->name);
    memset(s->solver_settings, 0, sizeof s->solver_settings);
    for (int k = 0; k < ops->nkeys && k < PFSPH_SOLVER_MAX_KEYS; k++) s->solver_settings[k] = ops->keys[k].def;
    return PFSPH_OK;
}

double pfsph_scene_solver_setting(const pfsph_scene *s, const char *key)
{
    int k = pfsph_solver_key_index(pfsph_solver_find(s->solver), key);
    return k >= 0 ? s->solver_settings[k] : NAN;
}

int pfsph_scene_phase_index(const pfsph_scene *s, const char *name)
{
    if (!s || !name) return -1;
    for (int i = 0; i < s->nphases; i++)
        if (strcmp(s->phases[i].name, name) == 0) return i;
    return -1;
}

int pfsph_scene_density_range(const pfsph_scene *s, double *lo, double *hi)
{
    int n = 0;
    *lo = INFINITY;
    *hi = 0;
    for (int a = 0; a < s->nphases; a++)
        if (s->phases[a].kind != PFSPH_PHASE_SOLID) {
            *lo = fmin(*lo, s->phases[a].rest_density);
            *hi = fmax(*hi, s->phases[a].rest_density);
            n++;
        }
    return n;
}

static int parse_root(parser *p, const cJSON *root)
{
    pfsph_scene *s = p->s;
    static const char *const keys[] = {
        "name",    "dimension", "particle_radius", "support_factor", "gravity", "domain", "solver",   "time",
        "seed",    "threads",   "phases",          "fluid",          "solids",  "bodies", "emitters", "pairwise",
        "diffuse", "output",    "camera",          "comment",        "mode",    NULL};
    if (!cJSON_IsObject(root)) return pfsph__json_fail(&p->ctx, "$", "a scene must be a JSON object { ... }");
    TRY(pfsph__json_check_keys(root, "$", keys, &p->ctx));
    /* Dimension first: it decides how many components every vector has. */
    const cJSON *dv = get(root, "dimension");
    if (dv && (!cJSON_IsNumber(dv) || (dv->valuedouble != 2.0 && dv->valuedouble != 3.0)))
        return pfsph__json_fail(&p->ctx, "$.dimension", "must be 2 or 3");
    TRY(pfsph__json_int(root, "$", "dimension", 2, 3, &s->dim, &p->ctx));
    if (s->dim == 2) s->gravity[2] = 0;
    const cJSON *nv = get(root, "name");
    TRY(pfsph__json_string(root, "$", "name", s->name, sizeof s->name, &p->ctx));
    if (nv && !s->name[0]) return pfsph__json_fail(&p->ctx, "$.name", "must not be empty");
    TRY(pfsph__json_number(root, "$", "particle_radius", 1e-5, 10.0, &s->particle_radius, &p->ctx));
    TRY(pfsph__json_number(root, "$", "support_factor", 1.0, 4.0, &s->support_factor, &p->ctx));
    TRY(vecd(p, root, "$", "gravity", -GRAVITY_MAX, GRAVITY_MAX, s->gravity));
    double seed = (double)s->seed;
    TRY(pfsph__json_number(root, "$", "seed", 0.0, SEED_MAX, &seed, &p->ctx));
    if (seed != floor(seed)) return pfsph__json_fail(&p->ctx, "$.seed", "expected an integer, got %g", seed);
    s->seed = (uint64_t)seed;
    TRY(pfsph__json_int(root, "$", "threads", 0, 4096, &s->threads, &p->ctx));
    TRY(json_enum(p, root, "$", "mode", mode_names, &s->mode));
    TRY(parse_domain(p, root));
    TRY(parse_solver(p, root));
    TRY(parse_time(p, root));
    /* interactive: steps of up to half a 1/30 s frame unless the scene bounds them itself */
    if (s->mode == PFSPH_MODE_INTERACTIVE && !(get(root, "time") && get(get(root, "time"), "dt_max")))
        s->dt_max = 1.0 / 60;
    TRY(parse_phases(p, root));
    TRY(parse_solids(p, root));
    TRY(parse_fluid(p, root));
    TRY(pfsph__scene_check_blocks(p));
    const cJSON *bd = get(root, "bodies");
    if (bd) TRY(pfsph__scene_parse_bodies(bd, "$.bodies", s, &p->ctx));
    TRY(pfsph__scene_parse_emitters(get(root, "emitters"), "$.emitters", s, &p->ctx));
    /* Sub-parsers of other modules see every phase, the default solid phase included. */
    const cJSON *pw = get(root, "pairwise");
    if (pw) {
        if (!cJSON_IsObject(pw)) return pfsph__json_fail(&p->ctx, "$.pairwise", "expected an object");
        TRY(pfsph__scene_parse_pairwise(pw, "$.pairwise", s, &p->ctx));
    }
    const cJSON *df = get(root, "diffuse");
    if (df) {
        if (!cJSON_IsObject(df)) return pfsph__json_fail(&p->ctx, "$.diffuse", "expected an object");
        TRY(pfsph__scene_parse_diffuse(df, "$.diffuse", s, &p->ctx));
    }
    pfsph__scene_auto_camera(s);
    TRY(pfsph__scene_parse_output(p, root));
    TRY(pfsph__scene_parse_camera(p, root));
    return PFSPH_OK;
}

/* Line and column (1-based) of position pos in text. */
static void line_col(const char *text, const char *pos, int *line, int *col)
{
    *line = 1;
    *col = 1;
    for (const char *c = text; *c && c < pos; c++) {
        if (*c == '\n') {
            (*line)++;
            *col = 1;
        } else (*col)++;
    }
}

int pfsph_scene_parse(pfsph_scene *out, const char *json, const char *source, pfsph_error *err)
{
    if (!source) source = "<scene>";
    pfsph_jctx ctx = {source, err};
    if (!out || !json) return pfsph__json_fail(&ctx, "$", "no scene text");
    /* Parse into a scratch scene so that *out is untouched on error. */
    pfsph_scene *s = malloc(sizeof *s);
    if (!s) return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", source);
    pfsph_scene_defaults(s);
    snprintf(s->source, sizeof s->source, "%s", source);
    char stem[PFSPH_NAME_LEN];
    pfsph__scene_source_stem(source, stem, sizeof stem);
    snprintf(s->name, sizeof s->name, "%s", stem);
    snprintf(s->output.dir, sizeof s->output.dir, "runs/%s", stem);

    const char *p0 = json;
    while (*p0 == ' ' || *p0 == '\t' || *p0 == '\n' || *p0 == '\r') p0++;
    if (!*p0) {
        free(s);
        return pfsph__json_fail(&ctx, "$", "invalid JSON: the text is empty");
    }
    if (pfsph__json_check_nul_escapes(json, &ctx)) {
        free(s);
        return PFSPH_EINPUT;
    }
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithOpts(json, &end, 1);
    if (!root) {
        int line, col;
        const char *pos = end ? end : json;
        line_col(json, pos, &line, &col);
        /* the bytes there, printable: control and non-ASCII bytes as \xNN */
        char near[16 * 4 + 1];
        size_t n = 0;
        for (const char *c = pos; *c && c - pos < 16; c++) {
            unsigned char u = (unsigned char)*c;
            if (*c == '\n' || *c == '\t' || *c == '\r') near[n++] = ' ';
            else if (u < 0x20 || u >= 0x7f || u == '"' || u == '\\')
                n += (size_t)snprintf(near + n, sizeof near - n, "\\x%02x", u);
            else near[n++] = *c;
        }
        near[n] = 0;
        /* cJSON stops at CJSON_NESTING_LIMIT levels: say so rather than "invalid" */
        int depth = 0, in_str = 0;
        for (const char *c = json; c < pos; c++) {
            if (in_str) {
                if (*c == '\\' && c + 1 < pos) c++;
                else if (*c == '"') in_str = 0;
            } else if (*c == '"') in_str = 1;
            else if (*c == '[' || *c == '{') depth++;
            else if (*c == ']' || *c == '}') depth--;
        }
        free(s);
        if (depth >= CJSON_NESTING_LIMIT)
            return pfsph__json_fail(&ctx, "$",
                                    "JSON nested too deep: more than %d arrays and objects within "
                                    "each other at line %d, column %d",
                                    CJSON_NESTING_LIMIT, line, col);
        if (!*pos)
            return pfsph__json_fail(&ctx, "$",
                                    "invalid JSON: unexpected end of text at line %d, column %d "
                                    "(missing '}' or ']'?)",
                                    line, col);
        return pfsph__json_fail(&ctx, "$", "invalid JSON at line %d, column %d, near \"%s\"", line, col, near);
    }
    parser p = {s, ctx};
    int rc = pfsph__json_check_strings(root, &ctx);
    if (!rc) rc = parse_root(&p, root);
    cJSON_Delete(root);
    if (rc == PFSPH_OK) {
        memcpy(out, s, sizeof *s);
        if (err) {
            err->code = PFSPH_OK;
            err->msg[0] = 0;
        }
    }
    free(s);
    return rc;
}

int pfsph_scene_read_text(const char *path, char **text, pfsph_error *err)
{
    *text = NULL;
    if (!path) return pfsph_fail(err, PFSPH_EIO, "no scene file given");
    FILE *f = fopen(path, "rb");
    if (!f) return pfsph_fail(err, PFSPH_EIO, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fileno(f), &sb) == 0 && S_ISDIR(sb.st_mode)) {
        fclose(f);
        return pfsph_fail(err, PFSPH_EINPUT, "%s: is a directory, not a scene file", path);
    }
    /* Scenes are small; a limit keeps a wrong argument (a frame file, /dev/zero) harmless. */
    const size_t cap = PFSPH_SCENE_MAX_BYTES;
    size_t n = 0, size = 4096;
    char *buf = malloc(size);
    if (!buf) {
        fclose(f);
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    }
    for (;;) {
        if (n + 1 >= size) {
            if (size >= cap) {
                free(buf);
                fclose(f);
                return pfsph_fail(err, PFSPH_EINPUT, "%s: $: file is larger than %zu MiB; not a scene", path,
                                  cap >> 20);
            }
            char *nb = realloc(buf, size * 2);
            if (!nb) {
                free(buf);
                fclose(f);
                return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
            }
            buf = nb;
            size *= 2;
        }
        size_t r = fread(buf + n, 1, size - n - 1, f);
        n += r;
        if (r == 0) break;
    }
    int bad = ferror(f), e = errno;
    fclose(f);
    if (bad) {
        free(buf);
        return pfsph_fail(err, PFSPH_EIO, "%s: cannot read: %s", path, strerror(e));
    }
    buf[n] = 0;
    if (strlen(buf) != n) {
        free(buf);
        return pfsph_fail(err, PFSPH_EINPUT, "%s: $: not a scene file (it holds a NUL byte; scenes are JSON text)",
                          path);
    }
    *text = buf;
    return PFSPH_OK;
}

int pfsph_scene_load(pfsph_scene *s, const char *path, pfsph_error *err)
{
    char *buf;
    int rc = pfsph_scene_read_text(path, &buf, err);
    if (rc) return rc;
    rc = pfsph_scene_parse(s, buf, path, err);
    free(buf);
    return rc;
}
