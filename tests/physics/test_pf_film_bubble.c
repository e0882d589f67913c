/* Bubbles in air (PF Section 4.2.2, Eq. 24; docs/film.md), 2D, no gravity, the default
 * thermostat, PCISPH. A bubble is a gas block whose outer layer carries a liquid film of
 * fraction a = V_L / (N_s V0).
 *
 * One bubble from an elongated start (a 22 d x 16 d rectangle, 352 particles, moment ratio
 * 0.53) over 4 s, viscosity 0.005 m^2/s (at 0.003 the l = 2 wobble, period ~0.8 s, still has
 * ~10 % amplitude in the second second and the average ratio is 0.893; at 0.01 the relaxation
 * is overdamped and reaches 0.84 only at 2 s; docs/film.md):
 * - film liquid volume sum_i a_i V0 within 2 % of V_L at every sample (the film stage's
 *   bookkeeping: it fails when the fraction lags the surface count or is held at 1). The
 *   fraction itself is printed: it does not simply rise as the rectangle rounds (0.500 ->
 *   0.468), because a thermal liquid's rough surface has more surface particles than a
 *   lattice's flat one (docs/film.md);
 * - enclosed gas volume, measured geometrically: the polygon through the film particles
 *   (sorted by angle about the bubble's centroid) plus the outer half of each film particle,
 *   V_bubble = A_poly + N_s V0 / 2, less the liquid: within 2 % of its start at every sample
 *   (for a rectangle and a disc of one area the formula agrees to 0.1 %);
 * - round at the end: smallest / largest principal second moment averaged over 2-4 s (the second
 *   half) >= 0.88. Not the 0.95: at the default temperature this 352-particle bubble
 *   fluctuates about a thermal floor of its own. Eight seeds (FILM_SEED, FILM_T=4) read 0.934 /
 *   0.918 / 0.928 / 0.947 / 0.928 / 0.951 / 0.910 / 0.911 over 2-4 s: mean 0.928, standard
 *   deviation 0.015 (single samples 0.85-0.99), below a free drop's equipartition mean of 0.951
 *   at this size. The bound is that mean less three deviations. The earlier run to 2 s (bound
 *   0.93 over 1-2 s) averaged the end of the relaxation itself (seed 5 creeps 0.83 / 0.85 / 0.90
 *   / 0.92 at 0.8 / 1.2 / 1.6 / 2 s), so eight seeds read 0.88-0.98 there and 0.93 was a coin
 *   flip; it failed once the pair-force pass's rounding changed (0.9289). Under AddressSanitizer
 *   the run is 1 s and the bound over 0.5-1 s 0.70 (the figures at the code);
 * - closed film: no gas particle (a = 0) farther from the centroid than the film polygon at its
 *   angle, at any sample.
 * Two bubbles (discs of radius 8 d, 2 x 200 particles) driven together at 0.2 m/s each: they
 * touch (closest pair across them below 1.2 d), flatten against each other (moment ratio of
 * one bubble below 0.95 at some sample), and the gas particles (a = 0) form exactly two
 * connected components (links shorter than h) at every sample over 1.5 s: a double bubble, not
 * one drop. That is what the physics asks: soap bubbles that touch share a wall and keep their
 * gases apart until the film drains and ruptures, which this model does not simulate
 * (docs/film.md). Every assertion's measured value is printed. */
#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/eigen.h"
#include "pfsph/emitter.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

/* Phases, pair coefficients; FILM_NU, FILM_SIGMA_GAS, FILM_V, FILM_THETA override (studies,
 * docs/film.md). The temperature is set to 0.01, the 2D default these bounds were measured at:
 * at the 2D default since issue 31, 0.04, the film breaks (docs/viscosity.md, "Open"): the
 * bubble at rest loses 2.95 % of its gas (bound 2 %) and reads a moment ratio of 0.840 (bound
 * 0.88), and the blown bubble does not hold the emitted gas (116 emitted particles outside it,
 * growth 427 % off the blown volume). That is the film model failing in a hotter liquid, not a
 * bound to re-derive; until the film is fixed for it, film scenes need 0.01. With each pair's
 * tension converted at its own temperature (docs/viscosity.md, "A tension factor per phase
 * pair") 0.04 reads +3.58 % and 0.793 at rest, and the blown bubble holds; the cause is the
 * gas's reduced temperature, twice the soap's with sigma 2 against 4: FILM_SIGMA_GAS=4 holds
 * the bubble at rest at 0.04 (0.80 %, 0.910). */
static const char *phases_and_pairs(void)
{
    static char buf[1024];
    const char *nu = getenv("FILM_NU"), *sg = getenv("FILM_SIGMA_GAS"), *th = getenv("FILM_THETA");
    snprintf(buf, sizeof buf,
             "\"phases\": [{\"name\": \"soap\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": %s},"
             " {\"name\": \"air\", \"kind\": \"gas\", \"rest_density\": 1000, \"viscosity\": %s}],"
             " \"pairwise\": {\"k\": 1.633, \"thermostat\": {\"reduced_temperature\": %s},"
             " \"coefficients\": [{\"phases\": [\"soap\", \"soap\"], \"sigma\": 4},"
             " {\"phases\": [\"air\", \"air\"], \"sigma\": %s}, {\"phases\": [\"soap\", \"air\"], \"sigma\": 0}]}",
             nu ? nu : "0.005", nu ? nu : "0.005", th ? th : "0.01", sg ? sg : "2");
    return buf;
}

typedef struct bubble_m {
    int ns;          /* film particles */
    double a;        /* their fraction (mean) */
    double liquid;   /* sum a_i V0 */
    double gas;      /* A_poly + ns V0 / 2 - liquid */
    double ratio;    /* moment ratio */
    int gas_outside; /* gas particles beyond the film polygon */
} bubble_m;

typedef struct ang {
    double t, r;
} ang;

static int by_angle(const void *a, const void *b)
{
    const ang *p = a, *q = b;
    return p->t < q->t ? -1 : p->t > q->t;
}

/* Polygon radius at angle t (linear in angle between neighbours, wrapping). */
static double poly_r(const ang *A, int n, double t)
{
    int k = 0;
    while (k < n && A[k].t < t) k++;
    const ang *p = &A[(k - 1 + n) % n], *q = &A[k % n];
    double t0 = p->t, t1 = q->t;
    if (k == 0) t0 -= 2 * PI;
    if (k == n) t1 += 2 * PI;
    const double u = t1 > t0 ? (t - t0) / (t1 - t0) : 0.5;
    return p->r + u * (q->r - p->r);
}

/* The particles of bubble k (fluid->bubble == k + 1). */
static bubble_m measure(const pfsph_ctx *c, int k, ang *A)
{
    const pfsph_particles *f = c->fluid;
    const double V0 = c->V0;
    double cx = 0, cy = 0;
    int n = 0;
    for (size_t i = 0; i < f->n; i++)
        if (f->bubble[i] == k + 1) cx += f->x[i], cy += f->y[i], n++;
    cx /= n;
    cy /= n;
    bubble_m m = {0, 0, 0, 0, 0, 0};
    double C[2][2] = {{0, 0}, {0, 0}};
    for (size_t i = 0; i < f->n; i++) {
        if (f->bubble[i] != k + 1) continue;
        const double x = f->x[i] - cx, y = f->y[i] - cy;
        C[0][0] += x * x, C[0][1] += x * y, C[1][1] += y * y;
        if (f->film[i] > 0) {
            A[m.ns].t = atan2(y, x);
            A[m.ns].r = hypot(x, y);
            m.ns++;
            m.liquid += f->film[i] * V0;
        }
    }
    C[1][0] = C[0][1];
    double w[2], v[2][2];
    pfsph_eigen_sym2(C, w, v);
    m.ratio = w[1] / w[0];
    m.a = m.liquid / (m.ns * V0);
    qsort(A, (size_t)m.ns, sizeof *A, by_angle);
    double area = 0;
    for (int q = 0; q < m.ns; q++) {
        const ang *p = &A[q], *r = &A[(q + 1) % m.ns];
        area += 0.5 * p->r * r->r * sin(r->t - p->t + (q + 1 == m.ns ? 2 * PI : 0));
    }
    m.gas = area + 0.5 * m.ns * V0 - m.liquid;
    for (size_t i = 0; i < f->n; i++) {
        if (f->bubble[i] != k + 1 || f->film[i] > 0) continue;
        const double x = f->x[i] - cx, y = f->y[i] - cy;
        if (hypot(x, y) > poly_r(A, m.ns, atan2(y, x))) m.gas_outside++;
    }
    return m;
}

static pfsph_sim *make(const char *json, const char *name)
{
    pfsph_sim *sim = tu_sim_from_json(json, name);
    return sim;
}

static void test_bubble_at_rest(void **state)
{
    (void)state;
    char json[4096], seed[64] = "";
    if (getenv("FILM_SEED")) /* studies: the thermostat's noise; the test uses the default */
        snprintf(seed, sizeof seed, "\"seed\": %d, ", atoi(getenv("FILM_SEED")));
    snprintf(json, sizeof json,
             "{\"dimension\": 2, %s\"particle_radius\": 0.005, \"gravity\": [0, 0],"
             " \"domain\": {\"min\": [-0.5, -0.5], \"max\": [0.5, 0.5]}, \"time\": {\"dt_max\": 0.002}, %s,"
             " \"fluid\": [{\"shape\": \"box\", \"min\": [-0.11, -0.08], \"max\": [0.11, 0.08], \"phase\": \"air\","
             " \"bubble\": {\"film\": \"soap\", \"thickness\": 0.005}}]}",
             seed, phases_and_pairs());
    pfsph_sim *sim = make(json, "bubble.json");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    ang *A = malloc(c->fluid->n * sizeof *A);
    assert_non_null(A);
    const bubble_m m0 = measure(c, 0, A);
    const double VL = m0.liquid;
    print_message("t = 0: %zu particles, %d film, a = %.4f, film liquid %.4g m^2, gas %.4g m^2, moment ratio %.3f\n",
                  c->fluid->n, m0.ns, m0.a, m0.liquid, m0.gas, m0.ratio);
    assert_true(fabs(m0.a - 0.5) < 1e-6); /* thickness d / 2 */
    double max_dl = 0, max_dg = 0, avg_ratio = 0;
    int navg = 0, outside = 0;
#ifdef __SANITIZE_ADDRESS__
    /* ~5x slower: 1 s, the bookkeeping as below and a relaxation half done. Over 0.5-1 s
     * seeds 1-7 (FILM_SEED, FILM_T=1, Release; the test's is 1) read 0.901 / 0.860 / 0.869 /
     * 0.797 / 0.818 / 0.893 / 0.893 from 0.53: mean 0.861, deviation 0.040, and the bound is
     * the mean less four deviations */
    const double dt = 0.05, T = 1.0, ratio_min = 0.70;
#else
    const double dt = 0.05, T = getenv("FILM_T") ? atof(getenv("FILM_T")) : 4.0, ratio_min = 0.88;
#endif
    const int ns = (int)lround(T / dt);
    bubble_m m = m0;
    for (int k = 1; k <= ns; k++) {
        tu_advance(sim, k * dt);
        m = measure(c, 0, A);
        max_dl = fmax(max_dl, fabs(m.liquid / VL - 1));
        max_dg = fmax(max_dg, fabs(m.gas / m0.gas - 1));
        outside += m.gas_outside;
        if (2 * k > ns) avg_ratio += m.ratio, navg++;
        if (k % 8 == 0)
            print_message("t = %.2f s: %d film particles, a = %.4f, liquid %+.3f %%, gas %+.3f %%, moment ratio %.3f, "
                          "gas outside the film %d\n",
                          k * dt, m.ns, m.a, 100 * (m.liquid / VL - 1), 100 * (m.gas / m0.gas - 1), m.ratio,
                          m.gas_outside);
    }
    avg_ratio /= navg;
    print_message("over %g s: largest change of the film liquid %.3f %%, of the enclosed gas %.3f %% (bound 2 %%); "
                  "moment ratio over the second half %.4f (bound %.2f); a %.4f -> %.4f; gas particles outside the "
                  "film, summed over the samples: %d\n",
                  T, 100 * max_dl, 100 * max_dg, avg_ratio, ratio_min, m0.a, m.a, outside);
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_true(max_dl <= 0.02);
    assert_true(max_dg <= 0.02);
    assert_true(avg_ratio >= ratio_min);
    assert_int_equal(outside, 0);
    free(A);
    pfsph_sim_destroy(sim);
}

/* Connected components of the gas particles (a = 0, any bubble), links shorter than 1.5 d
 * (nearest neighbours: the first minimum of a 2D liquid's pair distribution; across two film
 * layers pressed to 0.8 d the gases of two bubbles come within 2 d without touching). Returns
 * the number of components; *mixed: how many hold gas of both bubbles. */
static int gas_components(const pfsph_ctx *c, int *par, int *mixed)
{
    const pfsph_particles *f = c->fluid;
    const double l2 = 2.25 * (double)c->spacing * (double)c->spacing;
    for (size_t i = 0; i < f->n; i++) par[i] = (int)i;
    for (size_t i = 0; i < f->n; i++) {
        if (!f->bubble[i] || f->film[i] > 0) continue;
        for (size_t j = i + 1; j < f->n; j++) {
            if (!f->bubble[j] || f->film[j] > 0) continue;
            const double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j];
            if (dx * dx + dy * dy < l2) {
                int a = (int)i, b = (int)j;
                while (par[a] != a) a = par[a];
                while (par[b] != b) b = par[b];
                if (a != b) par[a] = b;
            }
        }
    }
    int n = 0;
    *mixed = 0;
    for (size_t i = 0; i < f->n; i++) {
        if (!f->bubble[i] || f->film[i] > 0) continue;
        int r = (int)i;
        while (par[r] != r) r = par[r];
        if (r == (int)i) n++;
    }
    for (size_t i = 0; i < f->n; i++) { /* a root holding both: some member of the other bubble */
        if (!f->bubble[i] || f->film[i] > 0 || par[i] != (int)i) continue;
        bool has[3] = {false, false, false};
        for (size_t j = 0; j < f->n; j++) {
            if (!f->bubble[j] || f->film[j] > 0) continue;
            int r = (int)j;
            while (par[r] != r) r = par[r];
            if (r == (int)i) has[f->bubble[j] > 2 ? 0 : f->bubble[j]] = true;
        }
        if (has[1] && has[2]) (*mixed)++;
    }
    return n;
}

static void test_two_bubbles(void **state)
{
    (void)state;
    char json[4096];
    snprintf(json, sizeof json,
             "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
             " \"domain\": {\"min\": [-0.5, -0.5], \"max\": [0.5, 0.5]}, \"time\": {\"dt_max\": 0.002}, %s,"
             " \"fluid\": [{\"shape\": \"sphere\", \"center\": [-0.09, 0.0], \"radius\": 0.08, \"phase\": \"air\","
             " \"velocity\": [%s, 0], \"bubble\": {\"film\": \"soap\", \"thickness\": 0.005}},"
             " {\"shape\": \"sphere\", \"center\": [0.09, 0.02], \"radius\": 0.08, \"phase\": \"air\","
             " \"velocity\": [-%s, 0], \"bubble\": {\"film\": \"soap\", \"thickness\": 0.005}}]}",
             phases_and_pairs(), getenv("FILM_V") ? getenv("FILM_V") : "0.1",
             getenv("FILM_V") ? getenv("FILM_V") : "0.1");
    pfsph_sim *sim = make(json, "two_bubbles.json");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const size_t n = c->fluid->n;
    int *par = malloc(n * sizeof *par);
    ang *A = malloc(n * sizeof *A);
    assert_true(par && A);
    int mixed = 0, comp0 = gas_components(c, par, &mixed);
    print_message("t = 0: %zu particles, gas components %d\n", n, comp0);
    assert_int_equal(comp0, 2);
    int mixed_max = 0, comp_max = 2;
    double closest = 1e9, min_ratio = 1;
    int worst_comp = 2;
    const double dt = 0.05, T = 1.5;
    const int ns = (int)lround(T / dt);
    for (int k = 1; k <= ns; k++) {
        tu_advance(sim, k * dt);
        const pfsph_particles *f = c->fluid;
        double dmin2 = 1e30;
        for (size_t i = 0; i < n; i++)
            if (f->bubble[i] == 1)
                for (size_t j = 0; j < n; j++)
                    if (f->bubble[j] == 2) {
                        const double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j];
                        dmin2 = fmin(dmin2, dx * dx + dy * dy);
                    }
        const double dmin = sqrt(dmin2) / c->spacing;
        closest = fmin(closest, dmin);
        const int comp = gas_components(c, par, &mixed);
        if (comp != 2) worst_comp = comp;
        if (comp > comp_max) comp_max = comp;
        if (mixed > mixed_max) mixed_max = mixed;
        const bubble_m m1 = measure(c, 0, A), m2 = measure(c, 1, A);
        min_ratio = fmin(min_ratio, fmin(m1.ratio, m2.ratio));
        if (k % 5 == 0)
            print_message("t = %.2f s: closest pair across %.3f d, gas components %d (%d with both gases), moment "
                          "ratios %.3f %.3f, film a %.3f %.3f\n",
                          k * dt, dmin, comp, mixed, m1.ratio, m2.ratio, m1.a, m2.a);
    }
    print_message("over %.1f s: closest pair across the bubbles %.3f d (bound 1.2 d), smallest moment ratio %.3f "
                  "(bound 0.95), gas components always 2: %s (most %d; most holding both gases %d)\n",
                  T, closest, min_ratio, worst_comp == 2 ? "yes" : "no", comp_max, mixed_max);
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_true(closest < 1.2);
    assert_true(min_ratio < 0.95);
    assert_int_equal(worst_comp, 2);
    free(par);
    free(A);
    pfsph_sim_destroy(sim);
}

/* Blowing a bubble (issue 12, Table 1 "Blowing bubbles"), 2D, no gravity: a disc bubble of
 * radius 6 d (112 particles, film 0.5 d) with a gas nozzle of 3 sites at its centre pointing up,
 * whose emitter key "bubble": 0 makes every particle it pushes join bubble 0. It blows
 * 0.01 m^2/s (0.33 m/s) from 0.1 s to 1.0 s, then relaxes until 1.4 s. Sites blocked by the gas
 * around the nozzle are refused, so 64 particles of 90 owed enter (67 % of the start's gas).
 * The jet's momentum carries the bubble up while the nozzle stays put: from about 0.5 s the
 * bubble draws a neck of gas and film down to the nozzle, as a soap bubble does on a straw.
 * At every 0.05 s sample:
 * - all emitted gas joins the bubble: its count is the start's plus the emitter's `emitted`,
 *   exactly, every particle carries the id, and none is lost;
 * - the film liquid sum_i a_i V0 within 2 % of V_L (the fraction follows the grown surface);
 * - the enclosed gas, measured geometrically as in test_bubble_at_rest (the polygon through the
 *   film particles sorted by angle about the centroid, plus their outer half, less the liquid;
 *   at the start 0.0095 m^2 against N V0 - V_L = 0.0096), grows by the blown volume n_e V0:
 *   within 20 % while blowing, once 20 % of the start's gas is blown, and within 10 % at the end
 *   (the last 5 samples averaged, 0.2 s after the nozzle closed). Why: the polygon, star-shaped
 *   about the centroid, misses part of the neck while it exists (measured down to -17 % at
 *   0.7 s, with 36 blown); at rest the measure moves by 0.8 % of the gas with the thermal
 *   wobble (test_bubble_at_rest), 1.2 % of this blown volume, so 10 % at the end is loose
 *   enough for noise and fails a bubble that lost or failed to take a sixth of the gas;
 * - the film stays closed: every gas particle meets a film particle along rays in all 16
 *   directions (passing within 1.5 d of its centre: a single surface particle missed by the
 *   detection leaves a gap of about 2 d in the film that rays through it would slip, while a
 *   gas particle really outside has a half plane without film). Not tested: the particles
 *   emitted in the last step (no film stage yet) and those in the nozzle's inlet slab, whose
 *   flag lags a step behind the inlet that moves them. The polygon test of test_bubble_at_rest
 *   does not serve here: the neck is not star-shaped about the centroid.
 * Under ASan (~4x slower) it blows until 0.7 s (36 particles) and ends at 1.1 s. BLOW_RATE,
 * BLOW_W (the nozzle's width) and BLOW_STOP override (studies). */
#define NDIR 16

/* Whether (px, py) is enclosed by the film particles (fx, fy; nf of them): a ray in each of
 * NDIR directions passes within hit of one of them, ahead of the point. */
static bool enclosed(double px, double py, const double *fx, const double *fy, int nf, double hit)
{
    for (int k = 0; k < NDIR; k++) {
        const double ux = cos(2 * PI * k / NDIR), uy = sin(2 * PI * k / NDIR);
        bool met = false;
        for (int j = 0; j < nf && !met; j++) {
            const double dx = fx[j] - px, dy = fy[j] - py, along = dx * ux + dy * uy;
            met = along > 0 && fabs(dx * uy - dy * ux) < hit;
        }
        if (!met) return false;
    }
    return true;
}

/* The nozzle of test_blow_bubble (exit plane y = -0.005 m, 3 sites about x = 0) and the two
 * spacings of jet in front of it: the inlet sets these particles' velocities and places new
 * layers among them between two film stages, so their film flag lags by a step. */
static bool at_nozzle(double x, double y, double d)
{
    return fabs(x) <= 2 * d && y >= -0.005 - 0.5 * d && y <= -0.005 + 2 * d;
}

/* measure()'s figures, with gas_outside from the enclosure test (hit: 1 d; film particles of a
 * rough surface sit up to ~2 d apart, and a gas particle really outside has a half plane
 * without film). */
static bubble_m measure_blow(const pfsph_ctx *c, ang *A, double *fx, double *fy, size_t fresh)
{
    const pfsph_particles *f = c->fluid;
    bubble_m m = measure(c, 0, A);
    int nf = 0;
    for (size_t i = 0; i < f->n; i++)
        if (f->bubble[i] == 1 && f->film[i] > 0) fx[nf] = f->x[i], fy[nf] = f->y[i], nf++;
    m.gas_outside = 0;
    for (size_t i = 0; i < fresh; i++) /* from fresh on: emitted in the last step, no film stage yet */
        if (f->bubble[i] == 1 && !(f->film[i] > 0) && !at_nozzle(f->x[i], f->y[i], c->spacing) &&
            !enclosed(f->x[i], f->y[i], fx, fy, nf, 1.5 * c->spacing))
            m.gas_outside++;
    return m;
}

static void test_blow_bubble(void **state)
{
    (void)state;
    char json[4096];
#ifdef __SANITIZE_ADDRESS__
    const double stop = 0.7, T = stop + 0.4;
#else
    const double stop = getenv("BLOW_STOP") ? atof(getenv("BLOW_STOP")) : 1.0, T = stop + 0.4;
#endif
    const char *rate = getenv("BLOW_RATE") ? getenv("BLOW_RATE") : "0.01";
    snprintf(json, sizeof json,
             "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
             " \"domain\": {\"min\": [-0.5, -0.5], \"max\": [0.5, 0.5]}, \"time\": {\"dt_max\": 0.002}, %s,"
             " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0], \"radius\": 0.06, \"phase\": \"air\","
             " \"bubble\": {\"film\": \"soap\", \"thickness\": 0.005}}],"
             " \"emitters\": [{\"center\": [0, -0.005], \"direction\": [0, 1], \"width\": %s, \"rate\": %s,"
             " \"start\": 0.1, \"stop\": %g, \"bubble\": 0}]}",
             phases_and_pairs(), getenv("BLOW_W") ? getenv("BLOW_W") : "0.03", rate, stop);
    pfsph_sim *sim = make(json, "blow.json");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_emitters *em = pfsph_sim_emitters(sim);
    assert_int_equal(pfsph_emitters_count(em), 1);
    const size_t n0 = c->fluid->n, room = 8 * n0; /* the grown bubble's film */
    double *fx = malloc(room * sizeof *fx), *fy = malloc(room * sizeof *fy);
    ang *A = malloc(room * sizeof *A);
    assert_true(fx && fy && A);
    const double V0 = c->V0;
    const bubble_m m0 = measure_blow(c, A, fx, fy, n0);
    const double VL = m0.liquid;
    print_message("t = 0: %zu particles, %d film, a = %.4f, film liquid %.4g m^2, gas %.4g m^2 (N V0 - V_L = %.4g)\n",
                  n0, m0.ns, m0.a, m0.liquid, m0.gas, (double)n0 * V0 - VL);
    double max_dl = 0, max_grow = 0, end_gas = 0;
    int outside = 0, count_bad = 0;
    const double dt = 0.05;
    const int ns = (int)lround(T / dt);
    bubble_m m = m0;
    pfsph_emitter_state st = {0};
    for (int k = 1; k <= ns; k++) {
        pfsph_error err = {0};
        size_t fresh = c->fluid->n;
        while (pfsph_sim_time(sim) < k * dt - 1e-9) { /* step by step: which particles are fresh */
            fresh = c->fluid->n;
            int rc = pfsph_sim_step(sim, k * dt, &err);
            if (rc) print_message("%s\n", err.msg);
            assert_int_equal(rc, PFSPH_OK);
        }
        const pfsph_particles *f = c->fluid;
        size_t nb = 0;
        for (size_t i = 0; i < f->n; i++) nb += f->bubble[i] == 1;
        pfsph_emitters_get_state(em, 0, &st);
        if (nb != n0 + st.emitted || nb != f->n) count_bad++;
        assert_true(f->n <= room);
        m = measure_blow(c, A, fx, fy, fresh);
        const double blown = (double)st.emitted * V0, grew = m.gas - m0.gas;
        max_dl = fmax(max_dl, fabs(m.liquid / VL - 1));
        if (blown >= 0.2 * m0.gas) max_grow = fmax(max_grow, fabs(grew - blown) / blown);
        if (k > ns - 5) end_gas += m.gas / 5; /* the last 5 samples: the thermal wobble averaged */
        outside += m.gas_outside;
        if (k % 4 == 0 || k == ns || m.gas_outside)
            print_message("t = %.2f s: %zu in the bubble (%zu + %llu emitted, %llu refused), %d film, a = %.4f, "
                          "liquid %+.3f %%, gas grew %.4g m^2 for %.4g blown (%+.2f %%), outside %d\n",
                          k * dt, nb, n0, (unsigned long long)st.emitted, (unsigned long long)st.refused, m.ns, m.a,
                          100 * (m.liquid / VL - 1), grew, blown, blown > 0 ? 100 * (grew / blown - 1) : 0.0,
                          m.gas_outside);
    }
    const double blown = (double)st.emitted * V0, end_err = (end_gas - m0.gas - blown) / blown;
    print_message("blowing: %llu gas particles emitted (%.0f %% of the start's gas), all in the bubble: %s; film "
                  "liquid largest change %.3f %% (bound 2 %%); gas growth against the blown volume, largest relative "
                  "difference once 20 %% is blown %.2f %% (bound 20 %%), at the end %+.2f %% (bound 10 %%, last 5 "
                  "samples); a %.4f "
                  "-> %.4f; gas outside the film, summed over samples: %d\n",
                  (unsigned long long)st.emitted, 100 * blown / m0.gas, count_bad ? "no" : "yes", 100 * max_dl,
                  100 * max_grow, 100 * end_err, m0.a, m.a, outside);
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_int_equal(count_bad, 0);
    assert_true(blown >= 0.2 * m0.gas);
    assert_true(max_dl <= 0.02);
    assert_true(max_grow <= 0.20);
    assert_true(fabs(end_err) <= 0.10);
    assert_int_equal(outside, 0);
    free(fx);
    free(fy);
    free(A);
    pfsph_sim_destroy(sim);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1); /* a few hundred particles: threads only add synchronisation */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_bubble_at_rest), cmocka_unit_test(test_two_bubbles),
                                       cmocka_unit_test(test_blow_bubble)};
    if (getenv("FILM_ONLY")) { /* studies: one test by number */
        const struct CMUnitTest one[1] = {tests[atoi(getenv("FILM_ONLY")) % 3]};
        return tu_run_group(one, NULL, NULL);
    }
    return tu_run_group(tests, NULL, NULL);
}
