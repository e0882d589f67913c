/* Changing the model while it runs (sim.h; docs/viewer.md): gravity, pair coefficients, surface
 * tension and contact-angle targets, dragging a body. */
#include <math.h>
#include <string.h>

#include "sim_internal.h"

int pfsph_sim_set_gravity(pfsph_sim *sim, const double g[3], pfsph_error *err)
{
    for (int a = 0; a < 3; a++)
        if (!isfinite(g[a]) || fabs(g[a]) > 1e6)
            return pfsph_fail(err, PFSPH_EINPUT, "gravity %g %g %g: expected finite components of at most 1e6 m/s^2",
                              g[0], g[1], g[2]);
    for (int a = 0; a < 3; a++) sim->scene.gravity[a] = a < sim->scene.dim ? g[a] : 0;
    memcpy(sim->ctx.gravity, sim->scene.gravity, sizeof sim->ctx.gravity);
    pfsph_bodies_set_gravity(sim->st.bodies, sim->scene.dim, sim->scene.gravity);
    return PFSPH_OK;
}

/* Check a phase pair; `what` names the change in messages. */
static int pair_ok(const pfsph_sim *sim, int a, int b, const char *what, pfsph_error *err)
{
    const pfsph_scene *s = &sim->scene;
    if (!s->pairwise.enabled || !sim->st.pw)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: the scene has pair forces off (no \"pairwise\" block)", what);
    if (a < 0 || b < 0 || a >= s->nphases || b >= s->nphases)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: phase index %d or %d out of range (the scene has %d phases)", what, a,
                          b, s->nphases);
    return PFSPH_OK;
}

/* Install one pair's new statement (kind 0 c, 1 sigma, 2 angle) and resolve every target again;
 * on failure the old parameters come back. */
static int set_pair(pfsph_sim *sim, int a, int b, int kind, double v, pfsph_error *err)
{
    pfsph_pairwise_params *pp = &sim->scene.pairwise;
    pfsph_pairwise_params old = *pp;
    pp->c_set[a][b] = pp->c_set[b][a] = kind == 0;
    pp->sigma_set[a][b] = pp->sigma_set[b][a] = kind == 1;
    pp->angle_set[a][b] = pp->angle_set[b][a] = kind == 2;
    if (kind == 0) pp->c[a][b] = pp->c[b][a] = v;
    if (kind == 1) pp->sigma[a][b] = pp->sigma[b][a] = v;
    if (kind == 2) pp->angle_deg[a][b] = pp->angle_deg[b][a] = v;
    int rc = pfsph_pairwise_resolve(&sim->scene, sim->ctx.spacing, sim->ctx.h, err);
    if (rc) *pp = old;
    pfsph__sim_apply_viscosity(&sim->ctx, &sim->scene);
    return rc;
}

int pfsph_sim_set_pair_coefficient(pfsph_sim *sim, int a, int b, double c, pfsph_error *err)
{
    int rc = pair_ok(sim, a, b, "pair coefficient", err);
    if (rc) return rc;
    if (!isfinite(c) || c < 0 || c > 1e30)
        return pfsph_fail(err, PFSPH_EINPUT, "pair coefficient of \"%s\" and \"%s\": %g is not in 0..1e30",
                          sim->scene.phases[a].name, sim->scene.phases[b].name, c);
    return set_pair(sim, a, b, 0, c, err);
}

int pfsph_sim_set_pair_sigma(pfsph_sim *sim, int a, int b, double sigma, pfsph_error *err)
{
    int rc = pair_ok(sim, a, b, "surface tension", err);
    if (rc) return rc;
    const pfsph_scene *s = &sim->scene;
    if (s->phases[a].kind == PFSPH_PHASE_SOLID || s->phases[b].kind == PFSPH_PHASE_SOLID)
        return pfsph_fail(err, PFSPH_EINPUT, "surface tension of \"%s\" and \"%s\": needs two fluid phases",
                          s->phases[a].name, s->phases[b].name);
    if (!isfinite(sigma) || sigma < 0 || sigma > 1e6)
        return pfsph_fail(err, PFSPH_EINPUT, "surface tension of \"%s\" and \"%s\": %g N/m is not in 0..1e6",
                          s->phases[a].name, s->phases[b].name, sigma);
    return set_pair(sim, a, b, 1, sigma, err);
}

int pfsph_sim_set_pair_contact_angle(pfsph_sim *sim, int a, int b, double deg, pfsph_error *err)
{
    int rc = pair_ok(sim, a, b, "contact angle", err);
    if (rc) return rc;
    const pfsph_scene *s = &sim->scene;
    if ((s->phases[a].kind == PFSPH_PHASE_SOLID) == (s->phases[b].kind == PFSPH_PHASE_SOLID))
        return pfsph_fail(err, PFSPH_EINPUT, "contact angle of \"%s\" and \"%s\": needs one fluid and one solid phase",
                          s->phases[a].name, s->phases[b].name);
    if (!isfinite(deg) || deg < 0 || deg > 180)
        return pfsph_fail(err, PFSPH_EINPUT, "contact angle of \"%s\" and \"%s\": %g degrees is not in 0..180",
                          s->phases[a].name, s->phases[b].name, deg);
    return set_pair(sim, a, b, 2, deg, err);
}

int pfsph_sim_drag_body(pfsph_sim *sim, int body, const double target[3], pfsph_error *err)
{
    int nb = pfsph_bodies_count(sim->st.bodies);
    if (body < 0 || body >= nb) return pfsph_fail(err, PFSPH_EINPUT, "drag: no body %d (the scene has %d)", body, nb);
    if (!pfsph_bodies_draggable(sim->st.bodies, body))
        return pfsph_fail(err, PFSPH_EINPUT,
                          "drag: body \"%s\" is moved by keyframes; dynamic bodies and kinematic "
                          "bodies without keyframes can be dragged",
                          pfsph_bodies_name(sim->st.bodies, body));
    /* no faster than the flows the scene is set up for (a tenth of its sound speed, Mach 0.1),
     * and well inside the blow-up bound */
    double vmax = fmin(0.1 * sim->sound_speed, 0.2 * sim->st.solver->speed_bound(sim->st.solver_state, &sim->ctx));
    if (pfsph_bodies_drag(sim->st.bodies, body, target, vmax))
        return pfsph_fail(err, PFSPH_EINPUT, "drag: target %g %g %g is not finite", target[0], target[1], target[2]);
    return PFSPH_OK;
}
