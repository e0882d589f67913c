/* Laplace's law at temperature in 3D (issue 11; PF Eqs. 3, 6, 13; docs/thermostat.md, "Surface
 * tension at temperature", 3D, and "Why 3D misses"). PENDING: it fails, for a known reason.
 * Lattice balls of radius 4, 5 and 6 d (280, 552 and 912 particles), no gravity, sigma target
 * 4 N/m, k 1.7, h = 2 d, nu 1e-3, DFSPH with tolerance 1e-4 (at its default 0.001 a 3D core stays
 * 0.15 % compressed and reads ~150 Pa low), seed 7, the thermostat at its default temperature,
 * the target converted with the shipped 3D factor 0.935. The pressure inside is the frames'
 * mechanical pressure (pfsph_sim_mechanical_pressure) averaged over the particles within R_e / 2
 * of the centroid, sampled every 4 steps from 0.5 s to 5.5 s (the 5 s). The fit
 * p = a + s x, x = 2 / R_e (R_e = (3 N d^3 / (4 pi))^(1/3)), must give s within 15 % of sigma,
 * |a| <= 0.25 sigma / R_max and R^2 >= 0.9.
 * Measured (360 s of CPU on one core): p_in / (2 sigma / R_e) = 1.134 +- 0.007, 1.039 +- 0.005,
 * 0.992 +- 0.010 (block errors; over 5 s the seeds agree: 4 d reads 225.2 and 222.4 Pa for seeds
 * 1 and 7 at tolerance 0.001); slope 1.44 sigma, intercept -60 Pa (bound 16.6), R^2 0.998: FAILS.
 * Why: the radial profile of the mechanical pressure overshoots 1-2 d under the surface (+334 Pa
 * at 4 d, +289 at 5 d, +271 at 6 d) and only the 6 d ball has a flat core (126-148 Pa against
 * 133); the 4 and 5 d cores lie in or reach the overshoot and read high. Passing needs three
 * drops with a bulk (R >= 6 d: 6, 8, 10 d would cost about 1,200 s of CPU) or a depth-based core.
 * Under AddressSanitizer the drops are 3, 4, 5 d and run 0.05 s.
 * Knobs for studies: PF_SOLVER (dfsph), PF_SOLVER_KEYS (solver keys appended, default
 * ', "tolerance": 0.0001'), PF_THETA, PF_SEED (7), PF_T0 (start of the average, 0.5 s), PF_T
 * (end, 5.5 s), PF_EVERY (steps between samples, 4), PF_RADII ("4,5,6" in spacings),
 * PF_PROFILE (radial profile, gyration radius, block means), PF_DIAG=k (the core pressure's
 * parts every k samples). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/pairwise.h"
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
             "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": %g, \"gravity\": [0, 0, 0],"
             " \"domain\": {\"min\": [-1, -1, -1], \"max\": [1, 1, 1]},"
             " \"solver\": {\"type\": \"%s\"%s}, \"time\": {\"dt_max\": 0.002},"
             " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.001}],"
             " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0, 0], \"radius\": %g}],"
             " \"pairwise\": {\"k\": 1.7, %s \"coefficients\": [{\"phases\": [\"water\", \"water\"],"
             " \"sigma\": %g}]}}",
             getenv("PF_SEED") ? atoi(getenv("PF_SEED")) : 7, 0.5 * d, getenv("PF_SOLVER") ? getenv("PF_SOLVER") : "dfsph",
             getenv("PF_SOLVER_KEYS") ? getenv("PF_SOLVER_KEYS") : ", \"tolerance\": 0.0001", Rs * d, thermo, SIGMA);
    pfsph_scene *s = malloc(sizeof *s);
    assert_non_null(s);
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(s, json, "laplace.json", &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    pfsph_sim *sim = NULL;
    rc = pfsph_sim_create(&sim, s, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    drop_result r = {cbrt(3.0 * (double)n * d * d * d / (4.0 * PI)), 0, 0};
    pfsph_real *pm = malloc(n * sizeof *pm);
    size_t cap = 1 << 16, m = 0;
    double prof[16] = {0}, rg = 0;
    long pcnt[16] = {0};
    double *smp = malloc(cap * sizeof *smp);
    assert_true(pm && smp);
    rc = pfsph_sim_advance(sim, t0, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    const int every = getenv("PF_EVERY") ? atoi(getenv("PF_EVERY")) : 4;
    while (pfsph_sim_time(sim) < t_end - 1e-9) {
        /* whole steps (pfsph_sim_advance would shorten the last one to land on a time) */
        for (int q = 0; q < every && pfsph_sim_time(sim) < t_end - 1e-9; q++) {
            rc = pfsph_sim_step(sim, t_end, &err);
            if (rc) print_message("%s\n", err.msg);
            assert_int_equal(rc, PFSPH_OK);
        }
        assert_int_equal(pfsph_sim_mechanical_pressure(sim, pm), PFSPH_OK);
        double cx = 0, cy = 0, cz = 0, sum = 0;
        int cnt = 0;
        for (size_t i = 0; i < n; i++) cx += f->x[i], cy += f->y[i], cz += f->z[i];
        cx /= (double)n, cy /= (double)n, cz /= (double)n;
        for (size_t i = 0; i < n; i++)
            if (hypot(hypot(f->x[i] - cx, f->y[i] - cy), f->z[i] - cz) < 0.5 * r.Re) sum += pm[i], cnt++;
        assert_true(cnt > 0);
        if (m == cap) {
            cap *= 2;
            smp = realloc(smp, cap * sizeof *smp);
            assert_non_null(smp);
        }
        smp[m++] = sum / cnt;
        if (getenv("PF_PROFILE")) { /* radial profile of the mechanical pressure, shells of 1 d; gyration radius */
            double g2 = 0;
            for (size_t i = 0; i < n; i++) {
                const double rr = hypot(hypot(f->x[i] - cx, f->y[i] - cy), f->z[i] - cz);
                g2 += rr * rr;
                const int k = (int)(rr / d);
                if (k < 16) prof[k] += pm[i], pcnt[k]++;
            }
            rg += sqrt(5.0 / 3.0 * g2 / (double)n);
        }
        if (getenv("PF_DIAG") && m % atoi(getenv("PF_DIAG")) == 0) {
            /* the parts of the core's mechanical pressure: pressure-force virial, pair virial, kinetic */
            static pfsph_real *z, *q;
            static double *vir;
            z = realloc(z, n * sizeof *z), q = realloc(q, n * sizeof *q), vir = realloc(vir, n * sizeof *vir);
            memset(z, 0, n * sizeof *z);
            pfsph_pairwise_mechanical_pressure(NULL, c, z, vir, q);
            double a = 0, b = 0, pp = 0, ndm = 0;
            for (size_t i = 0; i < n; i++)
                if (hypot(hypot(f->x[i] - cx, f->y[i] - cy), f->z[i] - cz) < 0.5 * r.Re)
                    a += q[i], b += c->nd[i] / 3.0 * 0.5 * vir[i], pp += f->p[i], ndm += c->nd[i] / c->nd0;
            print_message("t %.3f total %.2f press-virial %.2f pair %.2f kin %.2f | p %.2f nd/nd0 %.4f\n",
                          pfsph_sim_time(sim), sum / cnt, sum / cnt - a / cnt, b / cnt, (a - b) / cnt, pp / cnt,
                          ndm / cnt);
        }
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
                  "2 sigma / R_e = %.3f Pa (ratio %.3f +- %.3f); %llu steps\n",
                  Rs, n, r.Re, r.p, r.se, m, 2 * SIGMA / r.Re, r.p * r.Re / (2 * SIGMA), r.se * r.Re / (2 * SIGMA),
                  (unsigned long long)pfsph_sim_steps(sim));
    if (getenv("PF_PROFILE")) {
        print_message("  blocks:");
        for (int b = 0; b < NB; b++) print_message(" %.1f", bm[b]);
        print_message("\n  R from gyration sqrt(5/3) Rg = %.3f d (R_e %.3f d); shells [Pa]:", rg / (double)m / d, r.Re / d);
        for (int k = 0; k < 16 && pcnt[k]; k++) print_message(" %d:%.1f", k, prof[k] / (double)pcnt[k]);
        print_message("\n");
    }
    free(pm);
    free(smp);
    pfsph_sim_destroy(sim);
    free(s);
    return r;
}

static void test_laplace(void **state)
{
    (void)state;
#ifdef __SANITIZE_ADDRESS__
    double radii[8] = {3, 4, 5}; /* code paths only */
#else
    double radii[8] = {4, 5, 6};
#endif
    int nr = 3;
    if (getenv("PF_RADII")) {
        nr = 0;
        for (char *p = getenv("PF_RADII"); *p && nr < 8;) {
            radii[nr++] = strtod(p, &p);
            if (*p == ',') p++;
        }
    }
    double t_end = getenv("PF_T") ? atof(getenv("PF_T")) : 5.5;
#ifdef __SANITIZE_ADDRESS__
    t_end = 0.05;
    const double t0 = 0.01;
#else
    const double t0 = getenv("PF_T0") ? atof(getenv("PF_T0")) : 0.5;
#endif
    drop_result res[8];
    for (int i = 0; i < nr; i++) res[i] = run_drop(radii[i], t0, t_end);
    /* least squares p = a + s x, x = 2 / R_e (Laplace in 3D: dp = 2 sigma / R) */
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, Rmax = 0;
    for (int i = 0; i < nr; i++) {
        const double x = 2.0 / res[i].Re, y = res[i].p;
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
    omp_set_num_threads(1); /* 250-2,200 particles: threads only add synchronisation */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_laplace)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
