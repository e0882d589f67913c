/* The viscosity of the hot pair-force liquid (issue 11, docs/thermostat.md, "The viscosity of the
 * hot liquid"): with `viscosity_correction` the liquid flows with the viscosity the scene sets.
 *
 * A 30 x 30 box of one liquid (d = 1 cm, rho 1000, sigma 4 N/m, k 1.7, thermostat theta 0.01,
 * set explicitly because the box table was measured there; at the 2D default, 0.04, the liquid
 * flows as set wall-free with no correction, while this box reads 3.98x uncorrected and 1.61x
 * corrected at set 8e-3: its wall/size term or the strong friction, not resolved,
 * docs/viscosity.md) between free-slip walls, no gravity, DFSPH, melted 0.5 s at rest; then the
 * lowest Taylor-Green mode of the box, u = A sin(pi x / L) cos(pi y / L), v = -A cos(pi x / L)
 * sin(pi y / L) with A = 0.1 m/s, is added to the thermal motion. It meets free slip on all four
 * walls and solves the Navier-Stokes equations exactly, so its amplitude (the least-squares
 * projection of the particle velocities on the mode) decays as exp(-2 nu (pi / L)^2 t); nu_eff is
 * read from a least-squares fit of ln a over 0.1 s until a falls below A / 4.
 *
 * Measured (bench/pf_visc.c, the same scene, seed 1): set nu 8e-3
 *   without the correction: nu_eff = (see the test's output; 9.2e-3 at set 3e-3, 22.5e-3 at 1e-2)
 *   with it (Morris viscosity 2.4e-3 applied): nu_eff = see docs/thermostat.md
 * Bounds: with the correction nu_eff within 25 % of the set 8e-3. The seed-to-seed scatter of one
 * nu_eff is +-0.5e-3 m^2/s (sd of seeds 1-3 at set 1e-3: 4.9, 5.7, 5.0e-3), 6 % of 8e-3; the table
 * itself is known to about +-0.08 sqrt(sigma d / rho) = +-0.5e-3 m^2/s. Without the correction the
 * liquid must read at least 1.5x the set viscosity: the effect the correction removes (so that
 * the test fails if the correction stops acting). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "pfsph/sim.h"
#include "testutil.h"

#define PI 3.14159265358979323846

static const char *SCENE =
    "{\"dimension\": 2, \"seed\": 1, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
    " \"domain\": {\"min\": [-0.06, -0.06], \"max\": [0.36, 0.36]},"
    " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": %g},"
    "   {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.3, 0.3], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.3, 0.3], \"layers\": 3,"
    "   \"slip\": \"free-slip\"}],"
    " \"pairwise\": {\"k\": 1.7, \"viscosity_correction\": %s, \"thermostat\": {\"reduced_temperature\": 0.01},"
    " \"coefficients\": ["
    "   {\"phases\": [\"water\", \"water\"], \"sigma\": 4},"
    "   {\"phases\": [\"water\", \"wall\"], \"contact_angle\": 90}]}}";

static const double L = 0.3, A = 0.1;

static void mode(double x, double y, double *u, double *v)
{
    *u = sin(PI * x / L) * cos(PI * y / L);
    *v = -cos(PI * x / L) * sin(PI * y / L);
}

static double amplitude(const pfsph_particles *f)
{
    double num = 0, den = 0;
    for (size_t i = 0; i < f->n; i++) {
        double u, v;
        mode(f->x[i], f->y[i], &u, &v);
        num += f->vx[i] * u + f->vy[i] * v;
        den += u * u + v * v;
    }
    return num / den;
}

/* nu_eff of the liquid with set viscosity nu; t_end: the longest the fit may run. */
static double nu_eff(double nu, int corrected, double t_end)
{
    char json[4096];
    snprintf(json, sizeof json, SCENE, nu, corrected ? "true" : "false");
    static pfsph_scene s;
    pfsph_error err = {0};
    if (pfsph_scene_parse(&s, json, "pf_viscosity", &err)) fail_msg("%s", err.msg);
    pfsph_sim *sim;
    if (pfsph_sim_create(&sim, &s, &err)) fail_msg("%s", err.msg);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const double teq = 0.5, dts = 0.02;
    if (pfsph_sim_advance(sim, teq, &err)) fail_msg("%s", err.msg);
    pfsph_particles *f = c->fluid;
    for (size_t i = 0; i < f->n; i++) {
        double u, v;
        mode(f->x[i], f->y[i], &u, &v);
        f->vx[i] += (pfsph_real)(A * u);
        f->vy[i] += (pfsph_real)(A * v);
    }
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (int k = 1; k * dts <= t_end + 1e-9; k++) {
        if (pfsph_sim_advance(sim, teq + k * dts, &err)) fail_msg("%s", err.msg);
        const double t = k * dts, a = amplitude(f);
        if (t < 0.1) continue;
        if (a < 0.25 * A) break;
        sx += t, sy += log(a), sxx += t * t, sxy += t * log(a);
        n++;
    }
    const double applied = (double)c->nu[0];
    pfsph_sim_destroy(sim);
    assert_true(n >= 8);
    const double rate = -(n * sxy - sx * sy) / (n * sxx - sx * sx);
    const double ne = rate * L * L / (2 * PI * PI);
    printf("set nu %g, correction %s (Morris viscosity applied %.4g): fit over %d samples, rate %.4f /s, "
           "nu_eff %.4g m^2/s = %.3f x the set one\n",
           nu, corrected ? "on" : "off", applied, n, rate, ne, ne / nu);
    return ne;
}

static void test_viscosity(void **state)
{
    (void)state;
    const double nu = 8e-3;
    /* the same under ASan: 2 s of CPU in Release, the short fits would save a quarter */
    const double on = nu_eff(nu, 1, 2.0), off = nu_eff(nu, 0, 2.0);
    assert_true(fabs(on / nu - 1) <= 0.25);
    assert_true(off / nu >= 1.5);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_viscosity)};
    return tu_run_group(tests, NULL, NULL);
}
