/* The "diffuse" block of scene files: parameters of the diffuse material (DF Tables 1-3,
 * Sections 4 and 6), validated key by key. Keys, units, defaults: docs/diffuse.md. */
#include <stdio.h>

#include "scene/json_util.h"

static const char *const type_names[PFSPH_DIFFUSE_NTYPES] = {"spray", "foam", "bubble"};

static int parse_coupling(const cJSON *node, const char *path, pfsph_diffuse_coupling *c, pfsph_jctx *ctx)
{
    static const char *const keys[] = {"k_ext", "k_b", "k_cp", "k_t", "comment", NULL};
    int rc;
    if ((rc = pfsph__json_check_keys(node, path, keys, ctx)) != PFSPH_OK) return rc;
    if ((rc = pfsph__json_number(node, path, "k_ext", -100, 100, &c->k_ext, ctx)) ||
        (rc = pfsph__json_number(node, path, "k_b", -100, 100, &c->k_b, ctx)) ||
        (rc = pfsph__json_number(node, path, "k_cp", 0, 1, &c->k_cp, ctx)) ||
        (rc = pfsph__json_number(node, path, "k_t", 0, 100, &c->k_t, ctx)))
        return rc;
    return PFSPH_OK;
}

int pfsph__scene_parse_diffuse(const cJSON *node, const char *path, pfsph_scene *s, pfsph_jctx *ctx)
{
    static const char *const keys[] = {"enabled",
                                       "max_particles",
                                       "sampling_rate",
                                       "phi_v_min",
                                       "phi_v_max",
                                       "phi_e_min",
                                       "phi_e_max",
                                       "energy_mass",
                                       "emit_radius",
                                       "emit_radius_scale",
                                       "emit_height_scale",
                                       "lifetime_min",
                                       "lifetime_max",
                                       "foam_min_neighbors",
                                       "foam_max_neighbors",
                                       "spray",
                                       "foam",
                                       "bubble",
                                       "comment",
                                       NULL};
    pfsph_diffuse_params *p = &s->diffuse;
    int rc;
    if (!node) return PFSPH_OK;
    if ((rc = pfsph__json_check_keys(node, path, keys, ctx)) != PFSPH_OK) return rc;
    /* A block present without "enabled" means the user wants diffuse material. */
    p->enabled = true;
    int maxp = p->max_particles > 2000000000L ? 2000000000 : (int)p->max_particles;
    if ((rc = pfsph__json_bool(node, path, "enabled", &p->enabled, ctx)) ||
        (rc = pfsph__json_int(node, path, "max_particles", 0, 2000000000L, &maxp, ctx)) ||
        (rc = pfsph__json_number(node, path, "sampling_rate", 0, 1e9, &p->sampling_rate, ctx)) ||
        (rc = pfsph__json_number(node, path, "phi_v_min", 0, 1e9, &p->phi_v_min, ctx)) ||
        (rc = pfsph__json_number(node, path, "phi_v_max", 0, 1e9, &p->phi_v_max, ctx)) ||
        (rc = pfsph__json_number(node, path, "phi_e_min", 0, 1e30, &p->phi_e_min, ctx)) ||
        (rc = pfsph__json_number(node, path, "phi_e_max", 0, 1e30, &p->phi_e_max, ctx)) ||
        (rc = pfsph__json_number(node, path, "energy_mass", 0, 1e30, &p->energy_mass, ctx)) ||
        (rc = pfsph__json_number(node, path, "emit_radius", 0, 1e6, &p->emit_radius, ctx)) ||
        (rc = pfsph__json_number(node, path, "emit_radius_scale", 0, 1e3, &p->emit_radius_scale, ctx)) ||
        (rc = pfsph__json_number(node, path, "emit_height_scale", 0, 1e3, &p->emit_height_scale, ctx)) ||
        (rc = pfsph__json_number(node, path, "lifetime_min", 0, 1e6, &p->lifetime_min, ctx)) ||
        (rc = pfsph__json_number(node, path, "lifetime_max", 0, 1e6, &p->lifetime_max, ctx)) ||
        (rc = pfsph__json_int(node, path, "foam_min_neighbors", -1, 100000, &p->foam_min_neighbors, ctx)) ||
        (rc = pfsph__json_int(node, path, "foam_max_neighbors", -1, 100000, &p->foam_max_neighbors, ctx)))
        return rc;
    p->max_particles = maxp;
    for (int t = 0; t < PFSPH_DIFFUSE_NTYPES; t++) {
        const cJSON *c = cJSON_GetObjectItemCaseSensitive(node, type_names[t]);
        if (!c) continue;
        char cp[512];
        snprintf(cp, sizeof cp, "%s.%s", path && path[0] ? path : "$", type_names[t]);
        if ((rc = parse_coupling(c, cp, &p->type[t], ctx)) != PFSPH_OK) return rc;
    }
    if (p->phi_v_max <= p->phi_v_min)
        return pfsph__json_fail(ctx, path, "phi_v_max (%g) must exceed phi_v_min (%g)", p->phi_v_max, p->phi_v_min);
    if (p->phi_e_max <= p->phi_e_min)
        return pfsph__json_fail(ctx, path, "phi_e_max (%g) must exceed phi_e_min (%g)", p->phi_e_max, p->phi_e_min);
    if (p->lifetime_max < p->lifetime_min)
        return pfsph__json_fail(ctx, path, "lifetime_max (%g) is below lifetime_min (%g)", p->lifetime_max,
                                p->lifetime_min);
    if (p->lifetime_max <= 0) return pfsph__json_fail(ctx, path, "lifetime_max must be positive");
    if (p->foam_min_neighbors >= 0 && p->foam_max_neighbors >= 0 && p->foam_max_neighbors < p->foam_min_neighbors)
        return pfsph__json_fail(ctx, path, "foam_max_neighbors (%d) is below foam_min_neighbors (%d)",
                                p->foam_max_neighbors, p->foam_min_neighbors);
    return PFSPH_OK;
}
