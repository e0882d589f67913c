/* The integrator: symplectic Euler v += dt (a + a_p), x += dt v; it measures what the next step's
 * time step and the blow-up check need (largest accelerations and speed, kinetic energy). */
#include <math.h>

#include "core/dist.h"
#include "core/reduce.h"
#include "pfsph/pairwise.h"
#include "pfsph/thermostat.h"
#include "physics/solver.h"
#include "physics/stages.h"

static int integrate_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)err;
    pfsph_ctx *c = st->ctx;
    pfsph_particles *f = c->fluid;
    size_t lo, n; /* a distributed run integrates what it owns (its halo is sent afresh) */
    pfsph__owned(c, &lo, &n);
    const pfsph_real *apx = st->ap[0], *apy = st->ap[1], *apz = st->ap[2];
    const double dt = c->dt;
    const pfsph_real fdt = (pfsph_real)dt;
    double amax2 = 0, anp2 = 0;
    pfsph_real *ek = st->scratch[0];
    double emax = 0, v2max = 0;
    int bad_ = 0;
    /* The thermostat's random accelerations scale as dt^(-1/2) (their velocity kick as
     * dt^(1/2)): left in the force criteria they would shrink the next step without end. */
    const bool noise = st->noise[0] && pfsph_thermostat_kT(c) > 0;
    const pfsph_real *nx = noise ? st->noise[0] : NULL, *ny = noise ? st->noise[1] : NULL,
                     *nz = noise ? st->noise[2] : NULL;
#pragma omp parallel for schedule(static) reduction(max : amax2, anp2, emax, v2max) reduction(| : bad_)
    for (size_t i = lo; i < n; i++) {
        pfsph_real bx = c->ax[i], by = c->ay[i], bz = c->az[i];
        if (noise) {
            bx -= nx[i];
            by -= ny[i];
            bz -= nz[i];
        }
        double b2 = (double)bx * bx + (double)by * by + (double)bz * bz;
        if (b2 > anp2) anp2 = b2;
        pfsph_real cx = bx + apx[i], cy = by + apy[i], cz = bz + apz[i];
        double a2 = (double)cx * cx + (double)cy * cy + (double)cz * cz;
        if (a2 > amax2) amax2 = a2;
        pfsph_real axi = c->ax[i] + apx[i], ayi = c->ay[i] + apy[i], azi = c->az[i] + apz[i];
        f->vx[i] += fdt * axi;
        f->vy[i] += fdt * ayi;
        f->vz[i] += fdt * azi;
        f->x[i] += fdt * f->vx[i];
        f->y[i] += fdt * f->vy[i];
        f->z[i] += fdt * f->vz[i];
        double e = (double)c->nd[i] / (double)c->nd0 - 1;
        if (e > emax) emax = e;
        ek[i] =
            (pfsph_real)0.5 * c->mass[f->phase[i]] * (f->vx[i] * f->vx[i] + f->vy[i] * f->vy[i] + f->vz[i] * f->vz[i]);
        double v2 = (double)f->vx[i] * f->vx[i] + (double)f->vy[i] * f->vy[i] + (double)f->vz[i] * f->vz[i];
        if (!isfinite(v2) || !isfinite(f->x[i] + f->y[i] + f->z[i])) bad_ = 1;
        else if (v2 > v2max) v2max = v2;
    }
    st->amax = sqrt(amax2);
    st->amax_np = st->solver->np_cap_without_viscosity ? st->gmag + pfsph_pairwise_amax(st->pw) : sqrt(anp2);
    st->stats.ekin = pfsph__fluid_sum(c, ek);
    st->stats.density_err_max = emax;
    st->stats.dt = dt;
    double vmax = bad_ ? NAN : sqrt(v2max);
    st->stats.vmax = vmax;
    if (bad_ || vmax > st->vbound) {
        size_t worst;
        vmax = pfsph__max_speed(f, &worst); /* rare: find the particle to name */
        if (!isfinite(vmax)) return pfsph__blowup(bad, worst, "non-finite velocity or position", vmax);
        return pfsph__blowup(bad, worst, "speed [m/s]", vmax);
    }
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_integrate = {.name = "integrate",
                                               .slot = PFSPH_STAGE_INTEGRATE,
                                               .reads = PFSPH_D_ACC | PFSPH_D_AP | PFSPH_D_NOISE | PFSPH_D_DT |
                                                   PFSPH_D_DENSITY,
                                               .writes = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_STATS,
                                               .nscratch = 1,
                                               .run = integrate_run};
