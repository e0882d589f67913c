/* Laplace's law at temperature in 2D (issue 11; PF Eqs. 3, 6, 13; docs/thermostat.md, "Surface
 * tension at temperature", "The check"): lattice discs of radius 8, 10, 13, 16 and 20 d
 * (208-1,264 particles), no gravity, sigma target 4 N/m, k 1.7, nu 1e-3, PCISPH, the thermostat at its
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
 * Standard errors from 10 block averages are printed. Measured (seed 7): p_in / (sigma / R_e) =
 * 0.975, 0.912, 0.958, 0.936, 0.905 (+- 0.011-0.024); slope 0.992 sigma, intercept -1.64 Pa
 * (bound 4.99), R^2 0.994. Seeds 1 and 3: slopes 0.899 and 0.891, intercepts +0.75 and +0.51 Pa,
 * R^2 0.998 and 0.994. Five radii over 8-20 d, not three over 10-16 d: with three, a change of
 * rounding alone (the vectorised pair pass of issue 11) moved seed 7's slope from 0.988 to 0.861, because
 * each drop's mean scatters 3-4 % between realisations (several times its block error) and the
 * narrow range of 1 / R amplifies that into the slope. The five drops run in parallel, one per
 * thread, each simulation on one thread (independent, so the bits do not depend on the order): 131 s of CPU in all
 * (label validation). Under AddressSanitizer it skips (tu_release_only).
 * Knobs for studies: PF_SOLVER, PF_TOL (the solver's density tolerance), PF_DTMAX (0.002 s),
 * PF_THETA, PF_SEED (7), PF_T (end [s]), PF_RADII ("8,10,13,16,20" in spacings). */
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
} drop;

static void create_drop(drop *dr)
{
    const double d = 0.01;
    char json[2048], thermo[96] = "", tol[64] = "";
    if (getenv("PF_TOL")) snprintf(tol, sizeof tol, ", \"tolerance\": %s", getenv("PF_TOL"));
    if (getenv("PF_THETA"))
        snprintf(thermo, sizeof thermo, "\"thermostat\": {\"reduced_temperature\": %s},", getenv("PF_THETA"));
    snprintf(json, sizeof json,
             "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": %g, \"gravity\": [0, 0],"
             " \"domain\": {\"min\": [-1, -1], \"max\": [1, 1]},"
             " \"solver\": {\"type\": \"%s\"%s}, \"time\": {\"dt_max\": %s},"
             " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.001}],"
             " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0], \"radius\": %g}],"
             " \"pairwise\": {\"k\": 1.7, %s \"coefficients\": [{\"phases\": [\"water\", \"water\"],"
             " \"sigma\": %g}]}}",
             getenv("PF_SEED") ? atoi(getenv("PF_SEED")) : 7, 0.5 * d,
             getenv("PF_SOLVER") ? getenv("PF_SOLVER") : "pcisph", tol,
             getenv("PF_DTMAX") ? getenv("PF_DTMAX") : "0.002", dr->Rs * d, thermo, SIGMA);
    dr->sim = tu_sim_from_json(json, "laplace.json");
    dr->Re = sqrt((double)pfsph_sim_ctx(dr->sim)->fluid->n * d * d / PI);
}

/* Runs on one thread of the test's parallel loop: no cmocka assertion here (they jump); the
 * outcome goes into dr->rc / dr->msg. */
static void run_drop(drop *dr, double t0, double t_end)
{
    pfsph_sim *sim = dr->sim;
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    const size_t n = f->n;
    pfsph_error err = {0};
    size_t cap = 1 << 14, m = 0;
    pfsph_real *pm = malloc(n * sizeof *pm);
    double *smp = malloc(cap * sizeof *smp);
    dr->rc = !pm || !smp ? PFSPH_ENOMEM : pfsph_sim_advance(sim, t0, &err);
    while (dr->rc == PFSPH_OK && pfsph_sim_time(sim) < t_end - 1e-9) {
        /* whole steps (pfsph_sim_advance would shorten the last one to land on a time) */
        for (int q = 0; q < 2 && dr->rc == PFSPH_OK && pfsph_sim_time(sim) < t_end - 1e-9; q++)
            dr->rc = pfsph_sim_step(sim, t_end, &err);
        if (dr->rc == PFSPH_OK) dr->rc = pfsph_sim_mechanical_pressure(sim, pm);
        if (dr->rc != PFSPH_OK) break;
        double cx = 0, cy = 0, sum = 0;
        int cnt = 0;
        for (size_t i = 0; i < n; i++) cx += f->x[i], cy += f->y[i];
        cx /= (double)n, cy /= (double)n;
        for (size_t i = 0; i < n; i++)
            if (hypot(f->x[i] - cx, f->y[i] - cy) < 0.5 * dr->Re) sum += pm[i], cnt++;
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
    }
    snprintf(dr->msg, sizeof dr->msg, "%s", err.msg);
    dr->m = m;
    dr->removed = (int)pfsph_sim_removed(sim);
    if (dr->rc == PFSPH_OK && m >= NB) tu_block_mean(smp, m, NB, &dr->p, &dr->se, NULL);
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
    double radii[MAXR] = {8, 10, 13, 16, 20};
    int nr = 5;
    nr = tu_env_list("PF_RADII", radii, MAXR, nr);
    double t_end = getenv("PF_T") ? atof(getenv("PF_T")) : 6.0;
    tu_release_only();
    const double t0 = 1.0;
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
        const size_t n = pfsph_sim_ctx(dr[i].sim)->fluid->n;
        print_message("R = %g d (%zu particles, R_e %.4f m): p_in = %.3f +- %.3f Pa over %zu samples; "
                      "sigma / R_e = %.3f Pa (ratio %.3f +- %.3f); %llu steps\n",
                      dr[i].Rs, n, dr[i].Re, dr[i].p, dr[i].se, dr[i].m, SIGMA / dr[i].Re, dr[i].p * dr[i].Re / SIGMA,
                      dr[i].se * dr[i].Re / SIGMA, (unsigned long long)pfsph_sim_steps(dr[i].sim));
        pfsph_sim_destroy(dr[i].sim);
    }
    /* least squares p = a + s x, x = 1 / R_e */
    double x[MAXR], y[MAXR], Rmax = 0;
    for (int i = 0; i < nr; i++) x[i] = 1.0 / dr[i].Re, y[i] = dr[i].p, Rmax = fmax(Rmax, dr[i].Re);
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
