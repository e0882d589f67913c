/* The "pairwise" block of a scene file: switches and parameters of the pair forces and one
 * entry per phase pair stating a coefficient, a surface tension or a contact angle. Documented
 * key by key in docs/pairwise.md; targets are turned into coefficients later, by
 * pfsph_pairwise_resolve, once the particle spacing and h are known. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/json_util.h"

#define C_MAX 1e30    /* coefficient: any finite value >= 0 (units depend on the scale) */
#define SIGMA_MAX 1e6 /* N/m */

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
        if (!cJSON_IsString(n) || !n->valuestring) return pfsph__json_fail(ctx, np, "expected a phase name (string)");
        idx[i] = pfsph_scene_phase_index(s, n->valuestring);
        if (idx[i] < 0) {
            char list[400];
            size_t len = 0;
            list[0] = 0;
            for (int a = 0; a < s->nphases && len + 1 < sizeof list; a++) {
                int w = snprintf(list + len, sizeof list - len, "%s\"%s\"", a ? ", " : "", s->phases[a].name);
                if (w < 0) break;
                len += (size_t)w;
            }
            return pfsph__json_fail(ctx, np, "unknown phase \"%s\" (phases: %s)", n->valuestring, list);
        }
    }
    int a = idx[0] < idx[1] ? idx[0] : idx[1], b = idx[0] < idx[1] ? idx[1] : idx[0];
    const bool has_c = cJSON_GetObjectItemCaseSensitive(e, "c") != NULL;
    const bool has_s = cJSON_GetObjectItemCaseSensitive(e, "sigma") != NULL;
    const bool has_t = cJSON_GetObjectItemCaseSensitive(e, "contact_angle") != NULL;
    if ((int)has_c + (int)has_s + (int)has_t != 1)
        return pfsph__json_fail(ctx, path, "give exactly one of \"c\", \"sigma\", \"contact_angle\"");
    if (pp->c_set[a][b] || pp->sigma_set[a][b] || pp->angle_set[a][b])
        return pfsph__json_fail(ctx, path, "phases \"%s\" and \"%s\" are already given", s->phases[a].name,
                                s->phases[b].name);
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

int pfsph__scene_parse_pairwise(const cJSON *node, const char *path, pfsph_scene *s, pfsph_jctx *ctx)
{
    static const char *const keys[] = {"enabled",      "k",          "filter",
                                       "eta",          "eps_min",    "center",
                                       "shifting",     "thermostat", "viscosity_correction",
                                       "coefficients", "comment",    NULL};
    pfsph_pairwise_params *pp = &s->pairwise;
    int rc = pfsph__json_check_keys(node, path, keys, ctx);
    if (rc) return rc;
    /* Writing the block turns the forces on unless it says "enabled": false. */
    pp->enabled = true;
    /* the default temperature depends on the dimension (docs/viscosity.md) */
    pp->thermo.reduced = pfsph_thermo_reduced_default(s->dim);
    /* and the Morris viscosity is the one that makes the hot liquid flow as set, in 2D and 3D
     * (docs/viscosity.md; 2D since 2026-12-06, docs/validation.md "Hysing case 1") */
    pp->visc_correct = true;
    if ((rc = pfsph__json_bool(node, path, "enabled", &pp->enabled, ctx))) return rc;
    if ((rc = pfsph__json_bool(node, path, "viscosity_correction", &pp->visc_correct, ctx))) return rc;
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
        if (found < 0) return pfsph__json_fail(ctx, kp, "expected \"particle\" or \"mean\"");
        pp->center = found;
    }
    const cJSON *sh = cJSON_GetObjectItemCaseSensitive(node, "shifting");
    if (sh) {
        static const char *const skeys[] = {"diffusivity", "speed_factor", "surface", "max_step", "comment", NULL};
        char sp[600];
        snprintf(sp, sizeof sp, "%s.shifting", path);
        if (!cJSON_IsObject(sh)) return pfsph__json_fail(ctx, sp, "expected an object {\"diffusivity\": D, ...}");
        if ((rc = pfsph__json_check_keys(sh, sp, skeys, ctx))) return rc;
        if ((rc = pfsph__json_number(sh, sp, "diffusivity", 0.0, 10.0, &pp->shift.D, ctx))) return rc;
        if ((rc = pfsph__json_number(sh, sp, "speed_factor", 0.0, 100.0, &pp->shift.A, ctx))) return rc;
        if ((rc = pfsph__json_number(sh, sp, "surface", 0.0, 1.0, &pp->shift.surface, ctx))) return rc;
        if ((rc = pfsph__json_number(sh, sp, "max_step", 0.0, 0.25, &pp->shift.max_frac, ctx))) return rc;
    }
    const cJSON *th = cJSON_GetObjectItemCaseSensitive(node, "thermostat");
    if (th) {
        static const char *const tkeys[] = {"enabled", "kT", "reduced_temperature", "comment", NULL};
        char tp[600];
        snprintf(tp, sizeof tp, "%s.thermostat", path);
        if (cJSON_IsBool(th)) {
            pp->thermo.enabled = cJSON_IsTrue(th);
        } else {
            if (!cJSON_IsObject(th))
                return pfsph__json_fail(ctx, tp, "expected true, false or an object {\"kT\": J, ...}");
            if ((rc = pfsph__json_check_keys(th, tp, tkeys, ctx))) return rc;
            if ((rc = pfsph__json_bool(th, tp, "enabled", &pp->thermo.enabled, ctx))) return rc;
            if ((rc = pfsph__json_number(th, tp, "kT", 0.0, 1e6, &pp->thermo.kT, ctx))) return rc;
            if ((rc = pfsph__json_number(th, tp, "reduced_temperature", 0.0, 10.0, &pp->thermo.reduced, ctx)))
                return rc;
            if (cJSON_GetObjectItemCaseSensitive(th, "kT") &&
                cJSON_GetObjectItemCaseSensitive(th, "reduced_temperature")) {
                char kp[620];
                snprintf(kp, sizeof kp, "%s.kT", tp);
                return pfsph__json_fail(ctx, kp, "give kT or reduced_temperature, not both");
            }
        }
    }
    const cJSON *co = cJSON_GetObjectItemCaseSensitive(node, "coefficients");
    if (co) {
        char cp[600];
        snprintf(cp, sizeof cp, "%s.coefficients", path);
        if (!cJSON_IsArray(co)) return pfsph__json_fail(ctx, cp, "expected an array of {\"phases\": [a, b], ...}");
        int i = 0;
        for (const cJSON *e = co->child; e; e = e->next, i++) {
            char ep[620];
            snprintf(ep, sizeof ep, "%s[%d]", cp, i);
            if ((rc = parse_entry(e, ep, s, ctx))) return rc;
        }
    }
    return PFSPH_OK;
}

/* ---- targets -> coefficients, once the spacing and h are known ---- */

pfsph_real pfsph_pairwise_radius(const pfsph_scene *s, pfsph_real h)
{
    if (!s->pairwise.enabled) return 0;
    return (pfsph_real)(s->pairwise.k * (double)h);
}

static bool is_solid(const pfsph_scene *s, int a) { return s->phases[a].kind == PFSPH_PHASE_SOLID; }

/* Steps 1-3 of the conversion: targets -> coefficients with the tension constant of each pair,
 * Eq. 13's lambda times the factor of the tension at the pair's temperature, fab[a][b].
 * Coefficients the scene gave are kept. */
static int convert_targets(pfsph_scene *s, double lam, const double (*fab)[PFSPH_MAX_PHASES], double theta,
                           const double *rho, pfsph_error *err, bool *over)
{
    *over = false;
    pfsph_pairwise_params *pp = &s->pairwise;
    const int np = s->nphases;
    /* 1. Cohesion from a surface tension against the (unsimulated) air: Eq. 13 with
     * c_beta = 0, sigma = lambda c rho^2 (Eq. 14 with n m = rho). */
    for (int a = 0; a < np; a++) {
        if (!pp->sigma_set[a][a]) continue;
        if (is_solid(s, a) || !(rho[a] > 0))
            return pfsph_fail(err, PFSPH_EINPUT,
                              "pairwise: surface tension target on phase \"%s\" needs a fluid "
                              "phase with rest_density > 0",
                              s->phases[a].name);
        const double lam_t = fab[a][a] * lam;
        pp->c[a][a] = pp->sigma[a][a] / (lam_t * rho[a] * rho[a]);
    }
    /* 2. Interfacial tension between two fluids: Eq. 13 solved for c_ab. */
    for (int a = 0; a < np; a++)
        for (int b = a + 1; b < np; b++) {
            if (!pp->sigma_set[a][b]) continue;
            if (is_solid(s, a) || is_solid(s, b) || !(rho[a] > 0) || !(rho[b] > 0))
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "pairwise: surface tension between \"%s\" and \"%s\": both "
                                  "must be fluid phases with rest_density > 0 (use "
                                  "contact_angle for a solid)",
                                  s->phases[a].name, s->phases[b].name);
            const double lam_t = fab[a][b] * lam;
            double self = pp->c[a][a] * rho[a] * rho[a] + pp->c[b][b] * rho[b] * rho[b];
            double cab = (self - pp->sigma[a][b] / lam_t) / (2.0 * rho[a] * rho[b]);
            /* beyond the c_ab = 0 limit: reported by the caller if it holds at the factors'
             * fixed point (an earlier pass's factors may put a target at the limit beyond it) */
            if (cab < -1e-9 * self / (2.0 * rho[a] * rho[b]) && !*over) {
                *over = true;
                pfsph_fail(err, PFSPH_EINPUT,
                           "pairwise: surface tension %g N/m between \"%s\" and \"%s\" is "
                           "more than their cohesions give with c = 0 (at most %g N/m); "
                           "raise the cohesion c (or sigma) of \"%s\" or \"%s\"",
                           pp->sigma[a][b], s->phases[a].name, s->phases[b].name, lam_t * self, s->phases[a].name,
                           s->phases[b].name);
            }
            pp->c[a][b] = pp->c[b][a] = cab > 0 ? cab : 0.0;
        }
    /* 3. Static contact angle of a fluid on a solid: Eq. 21 with cbar = n m c = rho c. It is
     * Young's law with the Kirkwood-Buff tensions of Eq. 13 (the wall a half-space of density
     * rho_w), so the factor of the tensions at temperature cancels in it; but the particle
     * liquid at temperature wets less than Eq. 21 says, so there the ratio comes from a
     * measured table (docs/pairwise.md). */
    for (int a = 0; a < np; a++)
        for (int b = a + 1; b < np; b++) {
            if (!pp->angle_set[a][b]) continue;
            int fl = is_solid(s, a) ? b : a, so = is_solid(s, a) ? a : b;
            if (!is_solid(s, so) || is_solid(s, fl))
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "pairwise: contact angle between \"%s\" and \"%s\" needs one "
                                  "fluid and one solid phase",
                                  s->phases[a].name, s->phases[b].name);
            if (!(pp->c[fl][fl] > 0))
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "pairwise: contact angle of \"%s\" on \"%s\" needs a cohesion "
                                  "(c or sigma of \"%s\" with itself) > 0 (Eq. 21)",
                                  s->phases[fl].name, s->phases[so].name, s->phases[fl].name);
            if (!(rho[so] > 0))
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "pairwise: contact angle on \"%s\" needs its rest_density > 0 "
                                  "(boundary particle mass)",
                                  s->phases[so].name);
            /* Eq. 21's ratio, or at temperature the measured one (pfsph_pairwise_angle_ratio) */
            double cw =
                pfsph_pairwise_angle_ratio(s->dim, theta, pp->angle_deg[a][b]) * pp->c[fl][fl] * rho[fl] / rho[so];
            if (cw < 0) cw = 0; /* cos(180 deg) rounding */
            pp->c[a][b] = pp->c[b][a] = cw;
        }
    return PFSPH_OK;
}

/* convert_targets' "pairwise: ..." message, which names the phases, with the file and the block's
 * path instead of its prefix */
static int in_block(const pfsph_scene *s, int rc, pfsph_error *err)
{
    char msg[sizeof err->msg];
    snprintf(msg, sizeof msg, "%s", err->msg + (strncmp(err->msg, "pairwise: ", 10) ? 0 : 10));
    return pfsph_fail(err, rc, "%s: $.pairwise: %s", s->source, msg);
}

int pfsph_pairwise_resolve(pfsph_scene *s, pfsph_real spacing, pfsph_real h, pfsph_error *err)
{
    pfsph_pairwise_params *pp = &s->pairwise;
    pp->resolved = false;
    if (!pp->enabled) return PFSPH_OK;
    if (!(spacing > 0) || !(h > 0) || !(pp->k >= 1.0))
        return pfsph_fail(err, PFSPH_EINPUT, "pairwise: need spacing > 0, h > 0 and k >= 1 (got %g, %g, %g)",
                          (double)spacing, (double)h, pp->k);
    const int np = s->nphases;
    const double R = pp->k * (double)h;
    const double lam = pfsph_pairwise_lambda(s->dim, R);
    const double dd = pow((double)spacing, s->dim - 1);
    double rho[PFSPH_MAX_PHASES];
    for (int a = 0; a < np; a++) rho[a] = s->phases[a].rest_density;
    pfsph_thermostat_params *tp = &pp->thermo;

    /* The tension at temperature is f(theta) lambda c rho^2 (docs/thermostat.md), so a target
     * sigma asks for c = sigma / (f lambda rho^2). theta = kT / (sigma_ref d^(dim-1)) with
     * sigma_ref the largest Eq. 13 liquid-air tension of the coefficients. Each pair runs at its
     * own temperature (thermostat.c: phase a at kT rho_a / rho_ref, a pair at the colder of its
     * two phases), and its interface's reduced temperature compares that with its own Eq. 13
     * tension: theta_ab = kT_ab / (sigma13_ab d^(dim-1)) (docs/viscosity.md, "A tension factor
     * per phase pair"); for the reference liquid against air that is theta itself. theta_ab
     * depends on c and c on f(theta_ab): a fixed point that a few passes reach (f varies slowly;
     * with the reduced temperature given and one liquid, one pass settles it). */
    double theta = tp->enabled && tp->kT < 0 ? tp->reduced : 0.0;
    double f = pfsph_pairwise_sigma_factor(s->dim, theta);
    double(*fab)[PFSPH_MAX_PHASES] = pp->sigma_factor_ab;
    for (int a = 0; a < np; a++)
        for (int b = 0; b < np; b++) fab[a][b] = f;
    for (int it = 0; it < 32; it++) {
        bool over;
        int rc = convert_targets(s, lam, (const double(*)[PFSPH_MAX_PHASES])fab, theta, rho, err, &over);
        if (!rc && over && it == 31) rc = PFSPH_EINPUT;
        if (rc) return in_block(s, rc, err);
        tp->sigma_ref = 0;
        tp->rho_ref = 0;
        for (int a = 0; a < np; a++)
            if (!is_solid(s, a)) {
                double sg = lam * pp->c[a][a] * rho[a] * rho[a];
                if (sg > tp->sigma_ref) tp->sigma_ref = sg, tp->rho_ref = rho[a];
            }
        const double tn = !tp->enabled ? 0.0
            : tp->kT >= 0              ? (tp->sigma_ref > 0 ? tp->kT / (tp->sigma_ref * dd) : 0.0)
                                       : tp->reduced;
        const double fn = pfsph_pairwise_sigma_factor(s->dim, tn);
        bool done = fabs(fn - f) <= 1e-12 * fn && fabs(tn - theta) <= 1e-12 * tn;
        f = fn;
        theta = tn;
        /* each fluid pair's factor: theta_ab = theta (kT_ab / kT) (sigma_ref / sigma13_ab), written
         * so that the reference liquid's own pair gets theta bit for bit */
        for (int a = 0; a < np; a++)
            for (int b = a; b < np; b++) {
                if (is_solid(s, a) || is_solid(s, b) || !(rho[a] > 0) || !(rho[b] > 0)) continue;
                const double s13 = a == b ? lam * pp->c[a][a] * rho[a] * rho[a]
                                          : lam *
                        (pp->c[a][a] * rho[a] * rho[a] + pp->c[b][b] * rho[b] * rho[b] -
                         2.0 * pp->c[a][b] * rho[a] * rho[b]);
                const double ts = tp->rho_ref > 0 ? fmin(rho[a], rho[b]) / tp->rho_ref : 1.0;
                const double tab = theta > 0 && s13 > 0 ? theta * ts * (tp->sigma_ref / s13) : 0.0;
                const double fo = fab[a][b];
                fab[a][b] = fab[b][a] = tab > 0 ? pfsph_pairwise_sigma_factor(s->dim, tab) : f;
                if (!(fabs(fab[a][b] - fo) <= 1e-12 * fab[a][b])) done = false;
            }
        if (done && over) return in_block(s, PFSPH_EINPUT, err); /* beyond c_ab = 0 at the fixed point */
        if (done) break;
    }
    for (int a = 0; a < np; a++)
        for (int b = 0; b < np; b++) {
            if (pp->c[a][b] != pp->c[b][a]) pp->c[b][a] = pp->c[a][b] = 0.5 * (pp->c[a][b] + pp->c[b][a]);
            if (!isfinite(pp->c[a][b]) || pp->c[a][b] < 0)
                return pfsph_fail(err, PFSPH_EINPUT,
                                  "pairwise: coefficient between \"%s\" and \"%s\" is %g; it "
                                  "must be finite and >= 0",
                                  s->phases[a].name, s->phases[b].name, pp->c[a][b]);
        }
    pp->radius = R;
    pp->lambda = lam;
    pp->theta = theta;
    pp->sigma_factor = f;
    /* Thermostat: kT = reduced * sigma_ref * d^(dim-1), sigma_ref the largest (Eq. 13)
     * liquid-air tension of the table (docs/thermostat.md). */
    tp->kT_resolved = 0;
    if (tp->enabled) tp->kT_resolved = tp->kT >= 0 ? tp->kT : tp->reduced * tp->sigma_ref * dd;
    /* The hot liquid's own viscosity (docs/viscosity.md): nu_eff = nu_0 F(nu_morris / nu_0),
     * nu_0 = sqrt(sigma_a d / rho_a) with sigma_a the phase's own tension at temperature and F
     * the wall-free measurement at theta_a, the phase's reduced temperature. */
    for (int a = 0; a < np; a++) {
        const double nu = s->phases[a].viscosity;
        pp->nu_morris[a] = nu;
        pp->nu_struct[a] = pp->nu_floor[a] = 0;
        if (is_solid(s, a) || !(tp->kT_resolved > 0) || !(pp->c[a][a] > 0) || !(rho[a] > 0)) continue;
        /* theta as the thermostat counts it (Eq. 13's tension); nu_0 from the tension at
         * temperature (the bench's sigma target) */
        const double s13 = lam * pp->c[a][a] * rho[a] * rho[a], sg = f * s13;
        const double kTa = tp->kT_resolved * (tp->rho_ref > 0 ? rho[a] / tp->rho_ref : 1.0);
        const double tha = kTa / (s13 * dd);
        /* 2D away from the temperatures of the wall-free tables: applied as set, with the box
         * estimate (docs/thermostat.md) for check; the box correction itself is retired (a
         * wall/size term, docs/viscosity.md): the wall-free table replaced it at 0.01 */
        if (s->dim == 2 && !isfinite(pfsph_pairwise_visc_eff(2, tha, 0.0))) {
            const double g = pfsph_pairwise_visc_struct(s->dim, kTa / (s13 * dd));
            if (!(g > 0)) continue;
            const double nu0 = sqrt(sg * (double)spacing / rho[a]);
            pp->nu_struct[a] = g * nu0;
            pp->nu_floor[a] = PFSPH_VISC_FLOOR * nu0;
            continue;
        }
        const double nu0 = sqrt(sg * (double)spacing / rho[a]);
        if (!isfinite(pfsph_pairwise_visc_eff(s->dim, tha, 0.0)) || !(nu0 > 0)) continue;
        pp->nu_floor[a] = PFSPH_VISC_FLOOR * nu0;
        if (pp->visc_correct && pfsph_pairwise_visc_corrects(s->dim, tha))
            pp->nu_morris[a] = fmax(pfsph_pairwise_visc_morris(s->dim, tha, nu / nu0), PFSPH_VISC_FLOOR) * nu0;
        pp->nu_struct[a] = pfsph_pairwise_visc_eff(s->dim, tha, pp->nu_morris[a] / nu0) * nu0;
    }
    pp->resolved = true;
    return PFSPH_OK;
}

/* Temperature, thermal speed and how fast the viscosity couples the particles to it. */
static void thermo_report(const pfsph_scene *s, FILE *out)
{
    const pfsph_thermostat_params *tp = &s->pairwise.thermo;
    if (!tp->enabled) {
        fprintf(out, "  thermostat off (the pair-force liquid has no temperature: it freezes)\n");
        return;
    }
    if (!s->pairwise.resolved) return;
    double d = 2.0 * s->particle_radius, V = pow(d, s->dim);
    const char *unit = s->dim == 2 ? "J/m" : "J";
    if (!(tp->kT_resolved > 0)) {
        fprintf(out, "  thermostat on, kT = 0 (no liquid-air tension to scale it by)\n");
        return;
    }
    fprintf(out, "  thermostat on: kT = %.4g %s", tp->kT_resolved, unit);
    if (tp->sigma_ref > 0)
        fprintf(out, " = %.4g sigma d^%d (sigma = %.4g N/m, Eq. 13 of the coefficients)",
                tp->kT_resolved / (tp->sigma_ref * pow(d, s->dim - 1)), s->dim - 1, tp->sigma_ref);
    fprintf(out, "\n");
    for (int a = 0; a < s->nphases; a++) {
        if (is_solid(s, a)) continue;
        double m = s->phases[a].rest_density * V, nu = s->phases[a].viscosity;
        double h = s->support_factor * d;
        double ts = tp->rho_ref > 0 && s->phases[a].rest_density > 0 ? s->phases[a].rest_density / tp->rho_ref : 1;
        fprintf(out, "    %s: kT x %.3g, thermal speed sqrt(kT/m) = %.3g m/s per component", s->phases[a].name, ts,
                sqrt(ts * tp->kT_resolved / m));
        /* relaxation time of a particle's velocity against its neighbours' friction, about
         * h^2 / (2 (d + 2) nu) for the cubic spline (docs/thermostat.md) */
        const pfsph_pairwise_params *pp = &s->pairwise;
        const double num = pp->nu_morris[a];
        if (num > 0) fprintf(out, ", velocity relaxation ~%.3g s\n", h * h / (2.0 * (s->dim + 2) * num));
        else fprintf(out, "; viscosity 0: no friction, so no noise either (set a viscosity)\n");
        if (s->dim == 2 && !isfinite(pfsph_pairwise_visc_eff(2, pp->theta, 0.0))) {
            /* the hot liquid's own viscosity (docs/thermostat.md, "The viscosity of the hot liquid") */
            if (!(pp->nu_struct[a] > 0)) continue;
            fprintf(out,
                    "      viscosity %.4g m^2/s set and applied as the Morris viscosity (no wall-free table at "
                    "this temperature); the hot liquid is expected to flow as ~%.3g (structural %.3g + %.3g x "
                    "the set one, a box figure; docs/viscosity.md)\n",
                    nu, pp->nu_struct[a] + PFSPH_VISC_GAIN * nu, pp->nu_struct[a], PFSPH_VISC_GAIN);
            continue;
        }
        /* the hot liquid's own viscosity (docs/viscosity.md) */
        if (!(pp->nu_struct[a] > 0)) {
            fprintf(out,
                    "      viscosity %.4g m^2/s set and applied as the Morris viscosity (no measured 3D "
                    "correction at this temperature: the hot liquid may flow about twice as thick, "
                    "docs/viscosity.md)\n",
                    nu);
            continue;
        }
        const double nu0 = pp->nu_floor[a] / PFSPH_VISC_FLOOR;
        const double reach = pfsph_pairwise_visc_eff(s->dim, pp->theta, PFSPH_VISC_FLOOR) * nu0;
        const int corrected = pp->visc_correct && pfsph_pairwise_visc_corrects(s->dim, pp->theta);
        fprintf(out, "      viscosity %.4g m^2/s set, expected %.4g (Morris viscosity %.4g applied%s)\n", nu,
                pp->nu_struct[a], num,
                corrected                                                            ? ""
                    : s->dim == 2 && pfsph_pairwise_visc_corrects(s->dim, pp->theta) ? "; viscosity_correction is off"
                    : s->dim == 2 ? ", as set: at this temperature the 2D liquid is Newtonian"
                                  : "; viscosity_correction is off");
        /* 2D applies the viscosity as set: the liquid's own excess is what it adds (docs/viscosity.md) */
        if (s->dim == 2 && !corrected && pp->nu_struct[a] > 1.15 * nu)
            fprintf(out,
                    "      warning: %s's viscosity %.4g m^2/s is below what the hot 2D liquid reaches with it "
                    "(its own excess is ~%.3g m^2/s at this spacing, tension and temperature): it will flow "
                    "as ~%.3g. A smaller viscosity is not reached at this spacing; how the excess scales "
                    "with spacing and temperature in 2D is not measured (docs/viscosity.md)\n",
                    s->phases[a].name, nu, pp->nu_struct[a] - nu, pp->nu_struct[a]);
        if (corrected && nu < 0.99 * reach)
            fprintf(out,
                    "      warning: %s's viscosity %.4g m^2/s is below the least the hot liquid reaches with "
                    "the least Morris friction that holds its temperature (~%.3g m^2/s at this spacing, "
                    "tension and temperature): it will flow as ~%.3g. That least viscosity scales as "
                    "sqrt(spacing): a spacing %.2g times finer reaches the set one; a hotter liquid is "
                    "thinner too (docs/viscosity.md)\n",
                    s->phases[a].name, nu, reach, pp->nu_struct[a], reach * reach / (nu * nu));
    }
}

void pfsph_pairwise_report(const pfsph_scene *s, FILE *out)
{
    const pfsph_pairwise_params *pp = &s->pairwise;
    if (!pp->enabled) {
        fprintf(out, "pairwise forces: off\n");
        return;
    }
    const int np = s->nphases;
    fprintf(out, "pairwise forces: k = %.4g", pp->k);
    if (pp->resolved) fprintf(out, ", radius k*h = %.4g m, lambda = %.4g m^%d", pp->radius, pp->lambda, s->dim + 2);
    if (pp->filter && pp->eta > 0)
        fprintf(out, "\n  anisotropic filter on: eta = %g, eps_min = %g, centre = %s\n", pp->eta, pp->eps_min,
                pp->center == PFSPH_PW_CENTER_MEAN ? "mean" : "particle");
    else fprintf(out, "\n  anisotropic filter off (momentum conserved exactly)\n");
    if (pp->shift.D > 0 || pp->shift.A > 0)
        fprintf(out,
                "  particle shifting on: diffusivity %g m^2/s, speed factor %g, surface %g, "
                "max step %g d\n",
                pp->shift.D, pp->shift.A, pp->shift.surface, pp->shift.max_frac);
    thermo_report(s, out);
    fprintf(out, "  coefficients c[a][b] (%s):\n  %-14s", s->dim == 2 ? "N m/kg^2, 2D" : "N/kg^2", "");
    for (int b = 0; b < np; b++) fprintf(out, " %12.12s", s->phases[b].name);
    fprintf(out, "\n");
    for (int a = 0; a < np; a++) {
        fprintf(out, "  %-14.14s", s->phases[a].name);
        for (int b = 0; b < np; b++) fprintf(out, " %12.5g", pp->c[a][b]);
        fprintf(out, "\n");
    }
    for (int a = 0; a < np; a++)
        for (int b = a; b < np; b++) {
            if (pp->sigma_set[a][b])
                fprintf(out, "  target: sigma(%s, %s) = %g N/m -> c = %.6g\n", s->phases[a].name, s->phases[b].name,
                        pp->sigma[a][b], pp->c[a][b]);
            if (pp->angle_set[a][b])
                fprintf(out, "  target: contact angle(%s, %s) = %g deg -> c = %.6g (%s)\n", s->phases[a].name,
                        s->phases[b].name, pp->angle_deg[a][b], pp->c[a][b],
                        pfsph_pairwise_angle_measured(s->dim, pp->theta) ? "table at temperature" : "Eq. 21");
        }
    if (!pp->resolved) return;
    /* what the liquid is expected to do at its temperature: Eq. 13's tension times the
     * measured factor f(theta) (docs/thermostat.md) */
    if (!s->pairwise.thermo.enabled)
        fprintf(out,
                "  expected tensions: Eq. 13 (thermostat off: the liquid freezes, and a frozen "
                "drop's Laplace pressure reads 0.76-0.88 of it)\n");
    else
        fprintf(out,
                "  expected tensions at theta = %.4g: Eq. 13 x %.3f (measured %dD factor at "
                "temperature, docs/thermostat.md; other pairs at their own temperature)%s\n",
                pp->theta, pp->sigma_factor, s->dim,
                pp->theta > pfsph_pairwise_sigma_theta_max(s->dim) ? "; theta beyond the measured table: "
                                                                     "its last value is used"
                                                                   : "");
    for (int a = 0; a < np; a++) {
        if (s->phases[a].kind == PFSPH_PHASE_SOLID) continue;
        double ra = s->phases[a].rest_density;
        if (pp->c[a][a] > 0)
            fprintf(out, "  predicted: sigma(%s, air) = %.5g N/m (Eq. 16 with c_air = 0)\n", s->phases[a].name,
                    pp->sigma_factor_ab[a][a] * pp->lambda * pp->c[a][a] * ra * ra);
        for (int b = a + 1; b < np; b++) {
            double rb = s->phases[b].rest_density;
            if (s->phases[b].kind == PFSPH_PHASE_SOLID) {
                if (!(pp->c[a][a] > 0) || !(rb > 0)) continue;
                const double r = pp->c[a][b] * rb / (pp->c[a][a] * ra);
                const bool table = pfsph_pairwise_angle_measured(s->dim, pp->theta);
                const double ang = pfsph_pairwise_angle_expected(s->dim, pp->theta, r);
                const char *note = !table && r > 1                        ? " (complete wetting)"
                    : table && r > pfsph_pairwise_angle_ratio_max(s->dim) ? " (beyond the measured table: extrapolated)"
                                                                          : "";
                fprintf(out, "  predicted: contact angle of %s on %s = %.1f deg%s (%s)\n", s->phases[a].name,
                        s->phases[b].name, ang, note, table ? "measured at temperature, docs/pairwise.md" : "Eq. 21");
            } else {
                const double lab = pp->sigma_factor_ab[a][b] * pp->lambda;
                double sg = lab * (pp->c[a][a] * ra * ra + pp->c[b][b] * rb * rb - 2.0 * pp->c[a][b] * ra * rb);
                if (pp->c[a][a] > 0 || pp->c[b][b] > 0 || pp->c[a][b] > 0)
                    fprintf(out, "  predicted: sigma(%s, %s) = %.5g N/m (Eq. 13 x %.3f)%s\n", s->phases[a].name,
                            s->phases[b].name, sg, pp->sigma_factor_ab[a][b],
                            sg < 0 ? " -- negative: the fluids mix" : "");
            }
        }
    }
}
