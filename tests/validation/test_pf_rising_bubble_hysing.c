/* Rising bubble after Hysing et al. 2009 (Int. J. Numer. Meth. Fluids 60, 1259), test case 1, 2D,
 * at two particle spacings: rise velocity, centroid, circularity and aspect ratio (issue 11).
 *
 * Setup (Hysing's): a 1 x 2 box of liquid (rho 1000, mu 10) with a gas bubble (rho 100, mu 1) of
 * radius 0.25 centred at (0.5, 0.5); nu = 0.01 in both; g = 0.98; sigma = 24.5; Eotvos number
 * rho g D^2 / sigma = 10, Reynolds number rho sqrt(g D) D / mu = 35. Side walls free slip, top and
 * bottom no slip (3 layers each). PCISPH, pair forces k 1.7, default thermostat (theta 0.01).
 * The tension: water against the unsimulated air 24.5 N/m, gas cohesion 0.245 N/m (1 %), and the
 * water-gas pair given its own target, sigma_wg = 24.5 N/m (Eq. 13 solved for c_wg = 0.199, with
 * the factor at temperature); water on the walls 90 degrees, as in test_pf_rising_bubble.
 * Spacings: bubble diameter D = 16 d (2,048 fluid particles, 208 gas) and 20 d (3,200, 316 gas).
 *
 * Measured every 0.05 s to t = 3 s:
 *  - rise velocity: the gas particles' mean vertical velocity (Hysing's definition); U = its mean
 *    over 1-3 s; vmax = the largest 0.2 s running mean (a single sample carries the thermal
 *    noise, 0.015 m/s sd for the resting bubble);
 *  - centroid: the gas particles' mean position;
 *  - circularity: 2 sqrt(pi A) / P of the outline, the 0.5 contour of the Shepard colour field
 *    c = sum_gas W / sum W (Wendland, support 2 d) on a grid of d / 2, traced by marching squares;
 *    A is the area inside that contour. The grid contour of a particle field is rough, so even the
 *    resting bubble reads 0.994, not 1; the minimum is taken from 0.5 s on (the lattice disc's
 *    staircase relaxes over the first ~0.3 s);
 *  - aspect: sqrt of the smaller / larger eigenvalue of the gas positions' second moments, and
 *    h/w = sqrt(<dy^2> / <dx^2>) for the orientation (16 d: down to 0.84, the bubble flattens);
 *  - the noise floor: the same bubble without gravity, D = 16 d, 0.2-1 s.
 *
 * With `viscosity_correction` (docs/thermostat.md, "The viscosity of the hot liquid"; on in this
 * test since 2026-12-02): the hot particle liquid flows as ~0.034 m^2/s when set to 0.01 (a
 * 30-spacing box of this water measured 0.037), so the correction applies the floor Morris
 * viscosity 1.38e-3 to the water (the least the hot liquid reaches, ~0.017, is still above
 * Hysing's 0.01; check warns) and 1.89e-3 to the gas.
 *
 * Measured (2026-12-02, one core), with the correction:
 *   at rest (D 16 d): circularity 0.9938 +- 0.0009 (sd), aspect 0.9653 +- 0.0087
 *   | D    | U (1-3 s) | U (0.5-1.5 s) | vmax (at)        | yc(3)  | circularity min (at) | aspect min |
 *   | 16 d | 0.2018    | 0.2110        | 0.2202 (0.95 s)  | 1.0614 | 0.9213 (1.85 s)      | 0.596      |
 *   | 20 d | 0.1971    | 0.2136        | 0.2304 (0.90 s)  | 1.0627 | 0.9165 (2.15 s)      | 0.584      |
 *   | Hysing |         |               | 0.2417 (0.92 s)  | 1.0813 | 0.9013 (1.90 s)      |            |
 *   20 d / 16 d: U 0.977, U (0.5-1.5 s) 1.012, vmax 1.046. Against Hysing: vmax -8.9 % / -4.7 %,
 *   rise yc(3) - 0.5 -3.4 % / -3.2 %, 1 - circularity 0.079 / 0.083 against 0.099, both at
 *   Hysing's times. CPU (Release, one core): 171 s for the test; 6,207 and 8,626 steps.
 * Before it (set nu 0.01 applied as is):
 *   | 16 d | 0.1971    | 0.1868        | 0.2121 (2.05 s)  | 1.0278 | 0.9720 (2.95 s)      | 0.832      |
 *   | 20 d | 0.1788    | 0.1717        | 0.1920 (1.90 s)  | 1.0011 | 0.9795 (2.95 s)      | 0.877      |
 *   | 24 d | 0.1726    | 0.1564        | 0.1848 (2.60 s)  | 0.9742 | 0.9853 (2.55 s)      | 0.898      |
 *   (vmax -12 / -21 / -24 %, a third to a fifth of Hysing's deformation, slower at each
 *   refinement: the hot liquid's own viscosity grows relative to the benchmark's as d falls.)
 *
 * Checks and why these bounds:
 *  - refinement, the criterion: U at the two spacings within 10 % of each other (0.977).
 *  - Hysing: vmax within 15 % and the rise yc(3) - 0.5 within 10 % of the benchmark, at both
 *    spacings (measured -9 / -5 % and -3.4 / -3.2 %; the 0.2 s running mean of vmax carries ~3 %
 *    of thermal noise). Before the correction these bounds were 25 % each, a bound on a deficit.
 *  - deformation: the circularity minimum and the aspect minimum lie more than 5 sd of the
 *    resting bubble's noise below its mean, and 1 - circularity is at least half of Hysing's.
 *  The correction's table is a box calibration (docs/thermostat.md): part of what it removes is
 *  a wall/size term, so this agreement is for a tank of this size, and the water still flows
 *  ~1.7x thicker than Hysing's (the floor).
 * Under AddressSanitizer it skips (tu_release_only): a run short enough measures nothing.
 * Study knobs: PF_N1, PF_N2 (particles per diameter), PF_T, PF_TR (rest run), PF_NU, PF_SOLVER,
 * PF_VCORR (false: the viscosity as set), PF_PW (text inserted in the pairwise block). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pf_measure.h"
#include "pfsph/sim.h"
#include "testutil.h"

enum { WATER = 0, GAS = 1 };
#define PI 3.14159265358979323846

/* Hysing test case 1: 1 x 2 box, bubble of radius 0.25 centred at (0.5, 0.5); rho 1000 / 100,
 * mu 10 / 1 (nu 0.01 in both), g 0.98, sigma 24.5. Side walls free slip, top and bottom no slip. */
static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": %.10g, \"gravity\": [0, %g],"
    " \"domain\": {\"min\": [%.10g, %.10g], \"max\": [%.10g, %.10g]},"
    " \"solver\": {\"type\": \"%s\"}, \"time\": {\"end\": 3, \"fps\": 20},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": %g},"
    "   {\"name\": \"gas\", \"kind\": \"gas\", \"rest_density\": 100, \"viscosity\": %g},"
    "   {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [1, 2], \"phase\": \"water\"},"
    "   {\"shape\": \"sphere\", \"center\": [0.5, 0.5], \"radius\": 0.25, \"phase\": \"gas\"}],"
    " \"solids\": [{\"shape\": \"box\", \"min\": [%.10g, %.10g], \"max\": [%.10g, 0], \"layers\": 3},"
    "   {\"shape\": \"box\", \"min\": [%.10g, 2], \"max\": [%.10g, %.10g], \"layers\": 3},"
    "   {\"shape\": \"box\", \"min\": [%.10g, 0], \"max\": [0, 2], \"layers\": 3, \"slip\": \"free-slip\"},"
    "   {\"shape\": \"box\", \"min\": [1, 0], \"max\": [%.10g, 2], \"layers\": 3, \"slip\": \"free-slip\"}],"
    " \"pairwise\": {\"k\": 1.7, \"viscosity_correction\": %s, %s \"coefficients\": ["
    "   {\"phases\": [\"water\", \"water\"], \"sigma\": 24.5},"
    "   {\"phases\": [\"gas\", \"gas\"], \"sigma\": 0.245},"
    "   {\"phases\": [\"water\", \"gas\"], \"sigma\": 24.5},"
    "   {\"phases\": [\"water\", \"wall\"], \"contact_angle\": 90}]}}";

enum { NMAX = 128, SMOOTH = 5 };

typedef struct run_result {
    int n, nk, ngas;
    double t[NMAX], yc[NMAX], vy[NMAX], circ[NMAX], aspect[NMAX], hw[NMAX];
    double vmax, t_vmax;                          /* largest 0.2 s running mean of the gas's mean vertical velocity */
    double circ_min, t_circ_min, hw_min, asp_min; /* after 0.5 s */
    double circ_mean, circ_sd, asp_mean, asp_sd;  /* over the samples after 0.2 s */
    unsigned long long steps;
} run_result;

static void run(int n, double t_end, int rest, run_result *r)
{
    const double d = 0.5 / n, w = 3 * d;
    const double nu = getenv("PF_NU") ? atof(getenv("PF_NU")) : 0.01;
    char json[8192];
    snprintf(json, sizeof json, SCENE, 0.5 * d, rest ? 0.0 : -0.98, -w - d, -w - d, 1 + w + d, 2 + w + d,
             getenv("PF_SOLVER") ? getenv("PF_SOLVER") : "pcisph", nu, nu, -w, -w, 1 + w, -w, 1 + w, 2 + w, -w, 1 + w,
             getenv("PF_VCORR") ? getenv("PF_VCORR") : "true", getenv("PF_PW") ? getenv("PF_PW") : "");
    pfsph_sim *sim = tu_sim_from_json(json, "hysing bubble");
    pfsph_error err = {0};
    int rc;
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    memset(r, 0, sizeof *r);
    r->n = n;
    const double dt_s = 0.05;
    r->nk = (int)lround(t_end / dt_s);
    assert_true(r->nk < NMAX);
    pfm_bubble s;
    pfm_bubble_measure(c, GAS, &s);
    r->ngas = s.ngas;
    printf("n=%d%s: %d gas particles (area %.4f, pi/16 = %.4f), outline area %.4f, circularity %.4f at t=0\n", n,
           rest ? " at rest" : "", s.ngas, s.ngas * d * d, PI / 16, s.area, s.circ);
    for (int k = 1; k <= r->nk; k++) {
        const double t = k * dt_s;
        rc = pfsph_sim_advance(sim, t, &err);
        if (rc) fprintf(stderr, "%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        pfm_bubble_measure(c, GAS, &s);
        assert_int_equal(s.ngas, r->ngas);
        r->t[k] = t;
        r->yc[k] = s.cy;
        r->vy[k] = s.vy;
        r->circ[k] = s.circ;
        r->aspect[k] = s.aspect;
        r->hw[k] = s.hw;
        printf("n=%d%s t=%.2f: yc %.4f vy %.4f circ %.4f aspect %.4f h/w %.4f perim %.4f area %.4f\n", n,
               rest ? " rest" : "", t, s.cy, s.vy, s.circ, s.aspect, s.hw, s.perim, s.area);
        fflush(stdout);
    }
    r->vmax = -1e9;
    r->circ_min = r->hw_min = r->asp_min = 1e9;
    double s1 = 0, s2 = 0, a1 = 0, a2 = 0;
    int ns = 0;
    for (int k = 1; k <= r->nk; k++) {
        if (k + SMOOTH - 1 <= r->nk) {
            double m = 0;
            for (int q = 0; q < SMOOTH; q++) m += r->vy[k + q];
            m /= SMOOTH;
            if (m > r->vmax) {
                r->vmax = m;
                r->t_vmax = r->t[k + SMOOTH / 2];
            }
        }
        if (r->t[k] > 0.2 + 1e-9) {
            s1 += r->circ[k];
            s2 += r->circ[k] * r->circ[k];
            a1 += r->aspect[k];
            a2 += r->aspect[k] * r->aspect[k];
            ns++;
        }
        if (r->t[k] < 0.5 - 1e-9) continue; /* the lattice disc's staircase relaxes over the first ~0.3 s */
        if (r->circ[k] < r->circ_min) {
            r->circ_min = r->circ[k];
            r->t_circ_min = r->t[k];
        }
        if (r->hw[k] < r->hw_min) r->hw_min = r->hw[k];
        if (r->aspect[k] < r->asp_min) r->asp_min = r->aspect[k];
    }
    r->circ_mean = s1 / ns;
    r->circ_sd = sqrt(fmax(0, s2 / ns - r->circ_mean * r->circ_mean));
    r->asp_mean = a1 / ns;
    r->asp_sd = sqrt(fmax(0, a2 / ns - r->asp_mean * r->asp_mean));
    r->steps = (unsigned long long)pfsph_sim_steps(sim);
    printf("n=%d%s: vmax (0.2 s mean) %.4f at %.2f s, circularity min %.4f at %.2f s, mean %.4f sd %.4f; aspect "
           "mean %.4f sd %.4f, min %.4f; h/w min %.4f; yc(end) %.4f; steps %llu\n",
           n, rest ? " at rest" : "", r->vmax, r->t_vmax, r->circ_min, r->t_circ_min, r->circ_mean, r->circ_sd,
           r->asp_mean, r->asp_sd, r->asp_min, r->hw_min, r->yc[r->nk], r->steps);
    fflush(stdout);
    pfsph_sim_destroy(sim);
}

/* mean of a sampled quantity over [ta, tb] */
static double mean_over(const run_result *r, const double *q, double ta, double tb)
{
    double m = 0;
    int c = 0;
    for (int k = 1; k <= r->nk; k++)
        if (r->t[k] >= ta - 1e-9 && r->t[k] <= tb + 1e-9) {
            m += q[k];
            c++;
        }
    return c ? m / c : 0;
}

/* Hysing et al. 2009, test case 1, the benchmark values (TP2D, finest grid): */
#define H_VMAX 0.2417 /* maximal rise velocity, at t = 0.921 */
#define H_CMIN 0.9013 /* minimal circularity, at t = 1.904 */
#define H_YC3 1.0813  /* centroid height at t = 3 */

static void test_hysing(void **state)
{
    (void)state;
    static run_result rest, a, b;
    tu_release_only();
    const int n1 = getenv("PF_N1") ? atoi(getenv("PF_N1")) : 16, n2 = getenv("PF_N2") ? atoi(getenv("PF_N2")) : 20;
    const double T = getenv("PF_T") ? atof(getenv("PF_T")) : 3.0;
    run(n1, getenv("PF_TR") ? atof(getenv("PF_TR")) : 1.0, 1, &rest);
    run(n1, T, 0, &a);
    run(n2, T, 0, &b);
    /* rise velocity: the gas's mean velocity averaged over 1-3 s (41 samples: its sampling noise,
     * 0.015 m/s per sample at rest, averages to ~0.3 %; the maximum of a 0.2 s mean is reported
     * but carries ~3 %) */
    const double ua = mean_over(&a, a.vy, 1.0, 3.0), ub = mean_over(&b, b.vy, 1.0, 3.0);
    const double ua1 = mean_over(&a, a.vy, 0.5, 1.5), ub1 = mean_over(&b, b.vy, 0.5, 1.5);
    printf("summary: at rest (D = %d d, 0.2-1 s) circularity %.4f +- %.4f (sd), aspect %.4f +- %.4f\n", n1,
           rest.circ_mean, rest.circ_sd, rest.asp_mean, rest.asp_sd);
    const run_result *rr[2] = {&a, &b};
    for (int i = 0; i < 2; i++)
        printf("summary D = %d d: vmax %.4f at %.2f s (Hysing %.4f at 0.92 s: %.3f), yc(3) %.4f (Hysing %.4f; rise "
               "%.3f of Hysing's), circularity min %.4f at %.2f s (Hysing %.4f at 1.9 s), aspect min %.4f, h/w min "
               "%.4f, steps %llu\n",
               rr[i]->n, rr[i]->vmax, rr[i]->t_vmax, H_VMAX, rr[i]->vmax / H_VMAX, rr[i]->yc[rr[i]->nk], H_YC3,
               (rr[i]->yc[rr[i]->nk] - 0.5) / (H_YC3 - 0.5), rr[i]->circ_min, rr[i]->t_circ_min, H_CMIN, rr[i]->asp_min,
               rr[i]->hw_min, rr[i]->steps);
    printf("summary: rise velocity 1-3 s %.4f / %.4f (ratio %.3f), 0.5-1.5 s %.4f / %.4f (ratio %.3f), vmax ratio "
           "%.3f\n",
           ua, ub, ub / ua, ua1, ub1, ub1 / ua1, b.vmax / a.vmax);
    fflush(stdout);
    if (T < 3) return; /* study runs */
    /* refinement (the issue): the two spacings' rise velocities within 10 % of each other */
    assert_true(fabs(ub / ua - 1) <= 0.10);
    for (int i = 0; i < 2; i++) {
        const run_result *r = rr[i];
        /* against Hysing, with the viscosity correction: vmax within 15 % (measured -9 % / -5 %),
         * the rise by 3 s within 10 % (-3.4 % / -3.2 %); see the header */
        assert_true(fabs(r->vmax / H_VMAX - 1) <= 0.15);
        assert_true(fabs((r->yc[r->nk] - 0.5) / (H_YC3 - 0.5) - 1) <= 0.10);
        /* deformation: the rising bubble leaves the range of the resting one's thermal noise, and
         * deforms at least half as much as Hysing's (1 - c: measured 0.079 / 0.083 against 0.099) */
        assert_true(r->circ_min < rest.circ_mean - 5 * rest.circ_sd);
        assert_true(r->asp_min < rest.asp_mean - 5 * rest.asp_sd);
        assert_true(1 - r->circ_min >= 0.5 * (1 - H_CMIN));
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_hysing)};
    return tu_run_group(tests, NULL, NULL);
}
