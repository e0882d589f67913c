/* Laplace's law at temperature in 3D (issue 11; PF Eqs. 3, 6, 13; docs/thermostat.md, "Surface
 * tension at temperature", 3D, "Why 3D missed" and "What passes: balls of 6 to 10 d"). Lattice balls of radius
 * 6, 7, 8, 9 and 10 d (912-4,224 particles), no gravity, sigma target 4 N/m, k 1.7, h = 2 d,
 * nu 1e-3, DFSPH with tolerance 1e-4 (at its default 0.001 a 3D core stays 0.15 % compressed and
 * reads ~150 Pa low), seed 7, the thermostat at its default temperature, the target converted
 * with the shipped 3D factor 0.935. The pressure inside is the frames' mechanical pressure
 * (pfsph_sim_mechanical_pressure) averaged over the particles within R_e / 2 of the centroid,
 * sampled every 4 steps from 0.5 s to 5.5 s (the 5 s). The fit p = a + s x, x = 2 / R_e
 * (R_e = (3 N d^3 / (4 pi))^(1/3)), must give s within 15 % of sigma, |a| <= 0.25 sigma / R_max
 * and R^2 >= 0.9.
 * Why these radii: the mechanical pressure is a virial over the pair support (k h = 3.4 d), so
 * under the surface it overshoots for 1-2 d (+270 to +330 Pa) before the surface shell goes
 * negative; a ball needs R >= 6 d for a flat core within R_e / 2. Balls of 4 and 5 d have none
 * and read 13 % and 4 % high (slope 1.44 sigma, intercept -60 Pa: the reason this test was
 * pending).
 * Measured (seed 7): p_in / (2 sigma / R_e) = 0.964 +- 0.012, 0.964 +- 0.008, 1.001 +- 0.007,
 * 0.937 +- 0.007, 0.948 +- 0.012 (block errors); slope 0.993 sigma, intercept -2.9 Pa (bound
 * 9.97), R^2 0.989. Seeds 1 and 3: slopes 0.985 and 0.961, intercepts -3.5 and +0.4 Pa, R^2
 * 0.973 and 0.994. The five drops run in parallel, one per thread (each simulation
 * on one thread: 900-4,200 particles gain nothing from more); 5 s of all five cost about
 * 400 s of CPU (label validation). Under AddressSanitizer it skips (tu_release_only).
 * Knobs for studies: PF_SOLVER (dfsph), PF_SOLVER_KEYS (solver keys appended, default
 * ', "tolerance": 0.0001'), PF_THETA, PF_SEED (7), PF_T0 (start of the average, 0.5 s), PF_T
 * (end, 5.5 s), PF_EVERY (steps between samples, 4), PF_RADII ("6,7,8,9,10" in spacings),
 * PF_PROFILE (radial profile in shells of 1 d, gyration radius, block means). */
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
#define MAXR 8

typedef struct {
    double Rs;
    pfsph_sim *sim;
    double Re, p, se;
    size_t m;
    int rc, removed;
    char msg[256];
    char log[1024];
} drop;

static void create_drop(drop *dr)
{
    const double d = 0.01;
    char json[2048], thermo[96] = "";
    if (getenv("PF_THETA"))
        snprintf(thermo, sizeof thermo, "\"thermostat\": {\"reduced_temperature\": %s},", getenv("PF_THETA"));
    snprintf(
        json, sizeof json,
        "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": %g, \"gravity\": [0, 0, 0],"
        " \"domain\": {\"min\": [-1, -1, -1], \"max\": [1, 1, 1]},"
        " \"solver\": {\"type\": \"%s\"%s}, \"time\": {\"dt_max\": 0.002},"
        " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.001}],"
        " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0, 0], \"radius\": %g}],"
        " \"pairwise\": {\"k\": 1.7, %s \"coefficients\": [{\"phases\": [\"water\", \"water\"],"
        " \"sigma\": %g}]}}",
        getenv("PF_SEED") ? atoi(getenv("PF_SEED")) : 7, 0.5 * d, getenv("PF_SOLVER") ? getenv("PF_SOLVER") : "dfsph",
        getenv("PF_SOLVER_KEYS") ? getenv("PF_SOLVER_KEYS") : ", \"tolerance\": 0.0001", dr->Rs * d, thermo, SIGMA);
    dr->sim = tu_sim_from_json(json, "laplace.json");
    const size_t n = pfsph_sim_ctx(dr->sim)->fluid->n;
    dr->Re = cbrt(3.0 * (double)n * d * d * d / (4.0 * PI));
}

/* Runs on one thread of the test's parallel loop: no cmocka assertion here (they jump); the
 * outcome goes into dr->rc / dr->msg and the report into dr->log. */
static void run_drop(drop *dr, double t0, double t_end)
{
    const double d = 0.01;
    pfsph_sim *sim = dr->sim;
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    pfsph_error err = {0};
    size_t cap = 1 << 12, m = 0;
    double prof[16] = {0}, rg = 0;
    long pcnt[16] = {0};
    pfsph_real *pm = malloc(n * sizeof *pm);
    double *smp = malloc(cap * sizeof *smp);
    dr->rc = !pm || !smp ? PFSPH_ENOMEM : pfsph_sim_advance(sim, t0, &err);
    const int every = getenv("PF_EVERY") ? atoi(getenv("PF_EVERY")) : 4;
    while (dr->rc == PFSPH_OK && pfsph_sim_time(sim) < t_end - 1e-9) {
        /* whole steps (pfsph_sim_advance would shorten the last one to land on a time) */
        for (int q = 0; q < every && dr->rc == PFSPH_OK && pfsph_sim_time(sim) < t_end - 1e-9; q++)
            dr->rc = pfsph_sim_step(sim, t_end, &err);
        if (dr->rc == PFSPH_OK) dr->rc = pfsph_sim_mechanical_pressure(sim, pm);
        if (dr->rc != PFSPH_OK) break;
        double cx = 0, cy = 0, cz = 0, sum = 0;
        int cnt = 0;
        for (size_t i = 0; i < n; i++) cx += f->x[i], cy += f->y[i], cz += f->z[i];
        cx /= (double)n, cy /= (double)n, cz /= (double)n;
        for (size_t i = 0; i < n; i++)
            if (hypot(hypot(f->x[i] - cx, f->y[i] - cy), f->z[i] - cz) < 0.5 * dr->Re) sum += pm[i], cnt++;
        if (cnt == 0) {
            snprintf(err.msg, sizeof err.msg, "no particle within R_e / 2 of the centroid at t = %g s",
                     pfsph_sim_time(sim));
            dr->rc = PFSPH_EUNSTABLE;
            break;
        }
        if (m == cap) {
            double *grown = realloc(smp, 2 * cap * sizeof *smp);
            if (!grown) {
                dr->rc = PFSPH_ENOMEM;
                break;
            }
            smp = grown, cap *= 2;
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
    }
    snprintf(dr->msg, sizeof dr->msg, "%s", err.msg);
    dr->m = m;
    dr->removed = (int)pfsph_sim_removed(sim);
    if (dr->rc == PFSPH_OK && m >= NB) {
        double bm[NB];
        tu_block_mean(smp, m, NB, &dr->p, &dr->se, bm);
        int o = snprintf(dr->log, sizeof dr->log,
                         "R = %g d (%zu particles, R_e %.4f m): p_in = %.3f +- %.3f Pa over %zu samples; "
                         "2 sigma / R_e = %.3f Pa (ratio %.3f +- %.3f); %llu steps\n",
                         dr->Rs, n, dr->Re, dr->p, dr->se, m, 2 * SIGMA / dr->Re, dr->p * dr->Re / (2 * SIGMA),
                         dr->se * dr->Re / (2 * SIGMA), (unsigned long long)pfsph_sim_steps(sim));
        if (getenv("PF_PROFILE")) {
            o += snprintf(dr->log + o, sizeof dr->log - (size_t)o, "  blocks:");
            for (int b = 0; b < NB; b++) o += snprintf(dr->log + o, sizeof dr->log - (size_t)o, " %.1f", bm[b]);
            o += snprintf(dr->log + o, sizeof dr->log - (size_t)o,
                          "\n  R from gyration sqrt(5/3) Rg = %.3f d (R_e %.3f d); shells [Pa]:", rg / (double)m / d,
                          dr->Re / d);
            for (int k = 0; k < 16 && pcnt[k] && o < (int)sizeof dr->log; k++)
                o += snprintf(dr->log + o, sizeof dr->log - (size_t)o, " %d:%.1f", k, prof[k] / (double)pcnt[k]);
            if (o < (int)sizeof dr->log) snprintf(dr->log + o, sizeof dr->log - (size_t)o, "\n");
        }
    }
    free(pm);
    free(smp);
}

typedef struct {
    drop *dr;
    double t0, t_end;
} drop_job;

static void run_job(void *arg, int i)
{
    drop_job *j = arg;
    run_drop(&j->dr[i], j->t0, j->t_end);
}

static void test_laplace(void **state)
{
    (void)state;
    tu_release_only();
    double radii[MAXR] = {6, 7, 8, 9, 10};
    int nr = 5;
    nr = tu_env_list("PF_RADII", radii, MAXR, nr);
    double t_end = getenv("PF_T") ? atof(getenv("PF_T")) : 5.5;
    const double t0 = getenv("PF_T0") ? atof(getenv("PF_T0")) : 0.5;
    drop dr[MAXR];
    memset(dr, 0, sizeof dr);
    for (int i = 0; i < nr; i++) {
        dr[i].Rs = radii[i];
        create_drop(&dr[i]);
    }
    drop_job job = {dr, t0, t_end};
    tu_parallel_largest_first(nr, radii, run_job, &job);

    for (int i = 0; i < nr; i++) {
        if (dr[i].rc != PFSPH_OK) print_message("R = %g d: %s\n", dr[i].Rs, dr[i].msg);
        assert_int_equal(dr[i].rc, PFSPH_OK);
        assert_int_equal(dr[i].removed, 0);
        assert_true(dr[i].m >= NB);
        print_message("%s", dr[i].log);
        pfsph_sim_destroy(dr[i].sim);
    }
    /* least squares p = a + s x, x = 2 / R_e (Laplace in 3D: dp = 2 sigma / R) */
    double x[MAXR], y[MAXR], Rmax = 0;
    for (int i = 0; i < nr; i++) x[i] = 2.0 / dr[i].Re, y[i] = dr[i].p, Rmax = fmax(Rmax, dr[i].Re);
    const tu_line fit = tu_line_fit(nr, x, y);
    const double slope = fit.slope, icpt = fit.icpt, r2 = fit.r2;
    print_message("fit: slope %.4f N/m = %.3f sigma, intercept %.3f Pa (bound %.3f), R^2 %.4f\n", slope, slope / SIGMA,
                  icpt, 0.25 * SIGMA / Rmax, r2);
    assert_true(fabs(slope / SIGMA - 1) <= 0.15);
    assert_true(fabs(icpt) <= 0.25 * SIGMA / Rmax);
    assert_true(r2 >= 0.9);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_laplace)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
