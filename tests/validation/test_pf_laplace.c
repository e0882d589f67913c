/* Laplace's law at temperature in 2D (issue 11; PF Eqs. 3, 6, 13; docs/thermostat.md, "Surface
 * tension at temperature"): lattice discs of radius 10, 13 and 16 d (316, 530 and 812
 * particles), no gravity, sigma target 4 N/m, k 1.7, nu 1e-3, PCISPH, the thermostat at its
 * default temperature. The pressure inside is the mechanical pressure the frames carry
 * (pfsph_sim_mechanical_pressure: solver pressure force virial + pair virial + kinetic part)
 * averaged over the particles within R/2 of the centroid, sampled every 2 steps from 1 s to
 * 6 s (5 s of averaging, as the issue asks). Sampled at frames instead (every 0.05 s) it is too
 * noisy: PCISPH's pressure answers each step's random kicks, about 45 Pa rms per sample
 * against a signal of 25-40 Pa, and those kicks decorrelate from one step to the next, so the
 * error of the mean falls as one over the square root of the samples taken (every 10 steps:
 * 1.1-1.3 Pa per drop, a slope known to 11 %; every 2 steps: about 0.5 Pa, 5 %).
 * The fit p = a + s / R_e (R_e = sqrt(N d^2 / pi), the drop's equivalent radius) must give
 * s within 15 % of the target sigma, |a| <= 0.25 sigma / R_max and R^2 >= 0.9. The target is
 * converted with the factor of the tension at temperature (pfsph_pairwise_sigma_factor),
 * calibrated once on discs of 15 d with WCSPH: these radii and this solver are a check of it.
 * Standard errors from 10 block averages are printed. Measured: p_in / (sigma / R_e) =
 * 0.939 +- 0.014, 0.888 +- 0.010, 0.918 +- 0.011; slope 0.988 sigma, intercept -2.24 Pa (bound
 * 6.22), R^2 0.991. Run time 144 s of CPU on one core (label validation). Under AddressSanitizer the three drops run 0.3 s and only the code
 * paths are checked.
 * Knobs for studies: PF_SOLVER, PF_THETA, PF_T (end [s]), PF_RADII ("10,13,16" in spacings). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/sim.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;
#define SIGMA 4.0 /* N/m */
#define NB 10

typedef struct {
    double Re, p, se;
} drop_result;

static drop_result run_drop(double Rs, double t0, double t_end)
{
    const double d = 0.01;
    char json[2048], thermo[96] = "";
    if (getenv("PF_THETA"))
        snprintf(thermo, sizeof thermo, "\"thermostat\": {\"reduced_temperature\": %s},",
                 getenv("PF_THETA"));
    snprintf(json, sizeof json,
             "{\"dimension\": 2, \"seed\": 7, \"particle_radius\": %g, \"gravity\": [0, 0],"
             " \"domain\": {\"min\": [-1, -1], \"max\": [1, 1]},"
             " \"solver\": {\"type\": \"%s\"}, \"time\": {\"dt_max\": 0.002},"
             " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.001}],"
             " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0], \"radius\": %g}],"
             " \"pairwise\": {\"k\": 1.7, %s \"coefficients\": [{\"phases\": [\"water\", \"water\"],"
             " \"sigma\": %g}]}}",
             0.5 * d, getenv("PF_SOLVER") ? getenv("PF_SOLVER") : "pcisph", Rs * d, thermo, SIGMA);
    pfsph_sim *sim = tu_sim_from_json(json, "laplace.json");
    pfsph_error err = {0};
    int rc;
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    drop_result r = {sqrt((double)n * d * d / PI), 0, 0};
    pfsph_real *pm = malloc(n * sizeof *pm);
    size_t cap = 1 << 16, m = 0;
    double *smp = malloc(cap * sizeof *smp);
    assert_true(pm && smp);
    rc = pfsph_sim_advance(sim, t0, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    while (pfsph_sim_time(sim) < t_end - 1e-9) {
        /* whole steps (pfsph_sim_advance would shorten the last one to land on a time) */
        for (int q = 0; q < 2 && pfsph_sim_time(sim) < t_end - 1e-9; q++) {
            rc = pfsph_sim_step(sim, t_end, &err);
            if (rc) print_message("%s\n", err.msg);
            assert_int_equal(rc, PFSPH_OK);
        }
        assert_int_equal(pfsph_sim_mechanical_pressure(sim, pm), PFSPH_OK);
        double cx = 0, cy = 0, sum = 0;
        int cnt = 0;
        for (size_t i = 0; i < n; i++) cx += f->x[i], cy += f->y[i];
        cx /= (double)n, cy /= (double)n;
        for (size_t i = 0; i < n; i++)
            if (hypot(f->x[i] - cx, f->y[i] - cy) < 0.5 * r.Re) sum += pm[i], cnt++;
        assert_true(cnt > 0);
        if (m == cap) {
            cap *= 2;
            smp = realloc(smp, cap * sizeof *smp);
            assert_non_null(smp);
        }
        smp[m++] = sum / cnt;
    }
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_true(m >= NB);
    double bm[NB];
    const size_t bl = m / NB;
    for (int b = 0; b < NB; b++) {
        bm[b] = 0;
        for (size_t i = (size_t)b * bl; i < (size_t)(b + 1) * bl; i++) bm[b] += smp[i];
        bm[b] /= (double)bl;
        r.p += bm[b] / NB;
    }
    for (int b = 0; b < NB; b++) r.se += (bm[b] - r.p) * (bm[b] - r.p);
    r.se = sqrt(r.se / (NB - 1) / NB);
    print_message("R = %g d (%zu particles, R_e %.4f m): p_in = %.3f +- %.3f Pa over %zu samples; "
                  "sigma / R_e = %.3f Pa (ratio %.3f +- %.3f); %llu steps\n",
                  Rs, n, r.Re, r.p, r.se, m, SIGMA / r.Re, r.p * r.Re / SIGMA, r.se * r.Re / SIGMA,
                  (unsigned long long)pfsph_sim_steps(sim));
    free(pm);
    free(smp);
    pfsph_sim_destroy(sim);
    return r;
}

static void test_laplace(void **state)
{
    (void)state;
    double radii[8] = {10, 13, 16};
    int nr = 3;
    if (getenv("PF_RADII")) {
        nr = 0;
        for (char *p = getenv("PF_RADII"); *p && nr < 8;) {
            radii[nr++] = strtod(p, &p);
            if (*p == ',') p++;
        }
    }
    double t_end = getenv("PF_T") ? atof(getenv("PF_T")) : 6.0;
#ifdef __SANITIZE_ADDRESS__
    t_end = 0.3;
    const double t0 = 0.1;
#else
    const double t0 = 1.0;
#endif
    drop_result res[8];
    for (int i = 0; i < nr; i++) res[i] = run_drop(radii[i], t0, t_end);
    /* least squares p = a + s x, x = 1 / R_e */
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, Rmax = 0;
    for (int i = 0; i < nr; i++) {
        const double x = 1.0 / res[i].Re, y = res[i].p;
        sx += x, sy += y, sxx += x * x, sxy += x * y, syy += y * y;
        Rmax = fmax(Rmax, res[i].Re);
    }
    const double det = nr * sxx - sx * sx;
    const double slope = (nr * sxy - sx * sy) / det, icpt = (sy - slope * sx) / nr;
    const double cov = sxy / nr - sx * sy / (nr * nr), vx = sxx / nr - sx * sx / (nr * nr),
                 vy = syy / nr - sy * sy / (nr * nr);
    const double r2 = vy > 0 ? cov * cov / (vx * vy) : 0;
    print_message("fit: slope %.4f N/m = %.3f sigma, intercept %.3f Pa (bound %.3f), R^2 %.4f\n",
                  slope, slope / SIGMA, icpt, 0.25 * SIGMA / Rmax, r2);
#ifndef __SANITIZE_ADDRESS__
    assert_true(fabs(slope / SIGMA - 1) <= 0.15);
    assert_true(fabs(icpt) <= 0.25 * SIGMA / Rmax);
    assert_true(r2 >= 0.9);
#endif
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1); /* 300-800 particles: threads only add synchronisation */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_laplace)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
