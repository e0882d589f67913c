/* The "pairwise" block of a scene file: switches and parameters of the pair forces and one
 * entry per phase pair stating a coefficient, a surface tension or a contact angle. Documented
 * key by key in docs/pairwise.md; targets are turned into coefficients later, by
 * pfsph_pairwise_resolve, once the particle spacing and h are known. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/json_util.h"

#define C_MAX 1e30       /* coefficient: any finite value >= 0 (units depend on the scale) */
#define SIGMA_MAX 1e6    /* N/m */

static const char *const center_names[] = {"particle", "mean", NULL}; /* enum order */

static int parse_entry(const cJSON *e, const char *path, pfsph_scene *s, pfsph_jctx *ctx)
{
    static const char *const keys[] = {"phases", "c", "sigma", "contact_angle", "comment", NULL};
    pfsph_pairwise_params *pp = &s->pairwise;
    int rc = pfsph__json_check_keys(e, path, keys, ctx);
    if (rc) return rc;
    char pph[600];
    snprintf(pph, sizeof pph, "%s.phases", path);
    const cJSON *ph = cJSON_GetObjectItemCaseSensitive(e, "phases");
    if (!ph) return pfsph__json_fail(ctx, path, "missing key \"phases\": [\"name\", \"name\"]");
    if (!cJSON_IsArray(ph) || cJSON_GetArraySize(ph) != 2)
        return pfsph__json_fail(ctx, pph, "expected an array of two phase names");
    int idx[2];
    int i = 0;
    for (const cJSON *n = ph->child; n; n = n->next, i++) {
        char np[620];
        snprintf(np, sizeof np, "%s[%d]", pph, i);
        if (!cJSON_IsString(n) || !n->valuestring)
            return pfsph__json_fail(ctx, np, "expected a phase name (string)");
        idx[i] = pfsph_scene_phase_index(s, n->valuestring);
        if (idx[i] < 0) {
            char list[400];
            size_t len = 0;
            list[0] = 0;
            for (int a = 0; a < s->nphases && len + 1 < sizeof list; a++) {
                int w = snprintf(list + len, sizeof list - len, "%s\"%s\"", a ? ", " : "",
                                 s->phases[a].name);
                if (w < 0) break;
                len += (size_t)w;
            }
            return pfsph__json_fail(ctx, np, "unknown phase \"%s\" (phases: %s)", n->valuestring,
                                    list);
        }
    }
    int a = idx[0] < idx[1] ? idx[0] : idx[1], b = idx[0] < idx[1] ? idx[1] : idx[0];
    const bool has_c = cJSON_GetObjectItemCaseSensitive(e, "c") != NULL;
    const bool has_s = cJSON_GetObjectItemCaseSensitive(e, "sigma") != NULL;
    const bool has_t = cJSON_GetObjectItemCaseSensitive(e, "contact_angle") != NULL;
    if ((int)has_c + (int)has_s + (int)has_t != 1)
        return pfsph__json_fail(ctx, path,
                                "give exactly one of \"c\", \"sigma\", \"contact_angle\"");
    if (pp->c_set[a][b] || pp->sigma_set[a][b] || pp->angle_set[a][b])
        return pfsph__json_fail(ctx, path, "phases \"%s\" and \"%s\" are already given",
                                s->phases[a].name, s->phases[b].name);
    const bool sa = s->phases[a].kind == PFSPH_PHASE_SOLID;
    const bool sb = s->phases[b].kind == PFSPH_PHASE_SOLID;
    if (has_c) {
        double c = 0;
        if ((rc = pfsph__json_number(e, path, "c", 0.0, C_MAX, &c, ctx))) return rc;
        pp->c[a][b] = pp->c[b][a] = c;
        pp->c_set[a][b] = pp->c_set[b][a] = true;
    } else if (has_s) {
        char kp[620];
        snprintf(kp, sizeof kp, "%s.sigma", path);
        if (sa || sb)
            return pfsph__json_fail(ctx, kp,
                                    "surface tension needs two fluid phases (\"%s\" is a solid; "
                                    "use \"contact_angle\" or \"c\")",
                                    s->phases[sa ? a : b].name);
        double sg = 0;
        if ((rc = pfsph__json_number(e, path, "sigma", 0.0, SIGMA_MAX, &sg, ctx))) return rc;
        pp->sigma[a][b] = pp->sigma[b][a] = sg;
        pp->sigma_set[a][b] = pp->sigma_set[b][a] = true;
    } else {
        char kp[620];
        snprintf(kp, sizeof kp, "%s.contact_angle", path);
        if (sa == sb)
            return pfsph__json_fail(ctx, kp,
                                    "a contact angle needs one fluid and one solid phase (got "
                                    "\"%s\" and \"%s\")",
                                    s->phases[a].name, s->phases[b].name);
        double th = 0;
        if ((rc = pfsph__json_number(e, path, "contact_angle", 0.0, 180.0, &th, ctx))) return rc;
        pp->angle_deg[a][b] = pp->angle_deg[b][a] = th;
        pp->angle_set[a][b] = pp->angle_set[b][a] = true;
    }
    return PFSPH_OK;
}

int pfsph__scene_parse_pairwise(const cJSON *node, const char *path, pfsph_scene *s,
                                pfsph_jctx *ctx)
{
    static const char *const keys[] = {"enabled", "k", "filter", "eta", "eps_min", "center",
                                       "shifting", "coefficients", "comment", NULL};
    pfsph_pairwise_params *pp = &s->pairwise;
    int rc = pfsph__json_check_keys(node, path, keys, ctx);
    if (rc) return rc;
    /* Writing the block turns the forces on unless it says "enabled": false. */
    pp->enabled = true;
    if ((rc = pfsph__json_bool(node, path, "enabled", &pp->enabled, ctx))) return rc;
    if ((rc = pfsph__json_number(node, path, "k", 1.0, 4.0, &pp->k, ctx))) return rc;
    if ((rc = pfsph__json_bool(node, path, "filter", &pp->filter, ctx))) return rc;
    if ((rc = pfsph__json_number(node, path, "eta", 0.0, 1.0, &pp->eta, ctx))) return rc;
    if ((rc = pfsph__json_number(node, path, "eps_min", 1e-6, 1.0, &pp->eps_min, ctx))) return rc;
    const cJSON *cv = cJSON_GetObjectItemCaseSensitive(node, "center");
    if (cv) {
        char kp[600];
        snprintf(kp, sizeof kp, "%s.center", path);
        int found = -1;
        if (cJSON_IsString(cv) && cv->valuestring)
            for (int i = 0; center_names[i]; i++)
                if (strcmp(cv->valuestring, center_names[i]) == 0) found = i;
        if (found < 0)
            return pfsph__json_fail(ctx, kp, "expected \"particle\" or \"mean\"");
        pp->center = found;
    }
    const cJSON *sh = cJSON_GetObjectItemCaseSensitive(node, "shifting");
    if (sh) {
        static const char *const skeys[] = {"diffusivity", "speed_factor", "surface",
                                            "max_step", "comment", NULL};
        char sp[600];
        snprintf(sp, sizeof sp, "%s.shifting", path);
        if (!cJSON_IsObject(sh))
            return pfsph__json_fail(ctx, sp, "expected an object {\"diffusivity\": D, ...}");
        if ((rc = pfsph__json_check_keys(sh, sp, skeys, ctx))) return rc;
        if ((rc = pfsph__json_number(sh, sp, "diffusivity", 0.0, 10.0, &pp->shift.D, ctx)))
            return rc;
        if ((rc = pfsph__json_number(sh, sp, "speed_factor", 0.0, 100.0, &pp->shift.A, ctx)))
            return rc;
        if ((rc = pfsph__json_number(sh, sp, "surface", 0.0, 1.0, &pp->shift.surface, ctx)))
            return rc;
        if ((rc = pfsph__json_number(sh, sp, "max_step", 0.0, 0.25, &pp->shift.max_frac, ctx)))
            return rc;
    }
    const cJSON *co = cJSON_GetObjectItemCaseSensitive(node, "coefficients");
    if (co) {
        char cp[600];
        snprintf(cp, sizeof cp, "%s.coefficients", path);
        if (!cJSON_IsArray(co))
            return pfsph__json_fail(ctx, cp, "expected an array of {\"phases\": [a, b], ...}");
        int i = 0;
        for (const cJSON *e = co->child; e; e = e->next, i++) {
            char ep[620];
            snprintf(ep, sizeof ep, "%s[%d]", cp, i);
            if ((rc = parse_entry(e, ep, s, ctx))) return rc;
        }
    }
    return PFSPH_OK;
}
