/* Unit tests of the pairwise-force parameters: lambda of Eq. 13 against direct integration of
 * the Kirkwood-Buff formula, conversion of surface tension and contact angle targets (Eqs.
 * 13-16, 21) and their errors, the report, and the "pairwise" block of scene files. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/pairwise.h"
#include "pfsph/scene.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

/* Kirkwood-Buff surface tension of a step profile, integrated numerically over the whole
 * plane/space (not the closed form): sigma = -(n^2/2) int max(0, r_z) (r_z^2 - r_x^2) F(r)/r dV
 * for F = cos(3 pi r / 2R) (unit amplitude, n = 1). */
static double kb_numeric(int dim, double R)
{
    const int N = 4000;
    double sum = 0;
    if (dim == 2) {
        /* polar: r_z = r cos t, r_x = r sin t, t in (-pi/2, pi/2) */
        for (int i = 0; i < N; i++) {
            double r = (i + 0.5) * R / N;
            double F = cos(1.5 * PI * r / R);
            for (int j = 0; j < 400; j++) {
                double t = -PI / 2 + (j + 0.5) * PI / 400;
                double rz = r * cos(t), rx = r * sin(t);
                sum += rz * (rz * rz - rx * rx) * F / r * r * (R / N) * (PI / 400);
            }
        }
    } else {
        /* spherical, azimuth integrated analytically: <r_x^2> over phi = r^2 sin^2(t) / 2 */
        for (int i = 0; i < N; i++) {
            double r = (i + 0.5) * R / N;
            double F = cos(1.5 * PI * r / R);
            for (int j = 0; j < 400; j++) {
                double t = (j + 0.5) * (PI / 2) / 400;
                double rz = r * cos(t);
                double rx2 = 0.5 * r * r * sin(t) * sin(t);
                sum += rz * (rz * rz - rx2) * F / r * 2 * PI * r * r * sin(t) * (R / N) * (PI / 2 / 400);
            }
        }
    }
    return -0.5 * sum;
}

static void test_lambda(void **state)
{
    (void)state;
    const double R = 0.037;
    for (int dim = 2; dim <= 3; dim++) {
        double lam = pfsph_pairwise_lambda(dim, R), num = kb_numeric(dim, R);
        print_message("dim %d: lambda = %.6g R^%d (numeric %.6g R^%d)\n", dim, lam / pow(R, dim + 2), dim + 2,
                      num / pow(R, dim + 2), dim + 2);
        assert_true(fabs(lam - num) < 1e-4 * fabs(lam));
        assert_true(lam > 0);
    }
    /* the 3D value of NOTES item 6 */
    assert_true(fabs(pfsph_pairwise_lambda(3, 1.0) - 0.0424) < 5e-4);
    assert_true(fabs(pfsph_pairwise_lambda(2, 1.0) - 0.04757) < 5e-5);
}

/* water (fluid), oil (fluid, lighter), wall (solid, denser), gas */
static pfsph_scene *make_scene(int dim)
{
    pfsph_scene *s = calloc(1, sizeof(*s));
    assert_non_null(s);
    s->dim = dim;
    s->nphases = 4;
    const char *names[4] = {"water", "oil", "wall", "gas"};
    const int kinds[4] = {PFSPH_PHASE_FLUID, PFSPH_PHASE_FLUID, PFSPH_PHASE_SOLID, PFSPH_PHASE_GAS};
    const double rho[4] = {1000, 800, 2500, 100};
    for (int a = 0; a < 4; a++) {
        snprintf(s->phases[a].name, sizeof s->phases[a].name, "%s", names[a]);
        s->phases[a].kind = kinds[a];
        s->phases[a].rest_density = rho[a];
    }
    pfsph_pairwise_defaults(&s->pairwise);
    s->pairwise.enabled = true;
    return s;
}

static void set_sigma(pfsph_scene *s, int a, int b, double v)
{
    s->pairwise.sigma[a][b] = s->pairwise.sigma[b][a] = v;
    s->pairwise.sigma_set[a][b] = s->pairwise.sigma_set[b][a] = true;
}

static void set_angle(pfsph_scene *s, int a, int b, double v)
{
    s->pairwise.angle_deg[a][b] = s->pairwise.angle_deg[b][a] = v;
    s->pairwise.angle_set[a][b] = s->pairwise.angle_set[b][a] = true;
}

static void test_resolve(void **state)
{
    (void)state;
    const double d = 0.01, h = (double)(pfsph_real)0.02;
    for (int dim = 2; dim <= 3; dim++) {
        pfsph_scene *s = make_scene(dim);
        pfsph_pairwise_params *pp = &s->pairwise;
        const double lam = pfsph_pairwise_lambda(dim, pp->k * h);
        set_sigma(s, 0, 0, 0.0728);
        pp->c[1][1] = 0.02 / (lam * 800.0 * 800.0); /* oil cohesion given directly */
        set_sigma(s, 0, 1, 0.05);
        set_angle(s, 0, 2, 60.0);
        set_angle(s, 2, 1, 180.0);
        pfsph_error err = {0};
        assert_int_equal(pfsph_pairwise_resolve(s, (pfsph_real)d, (pfsph_real)h, &err), PFSPH_OK);
        assert_true(pp->resolved);
        assert_true(fabs(pp->radius - pp->k * h) < 1e-15 * h);
        /* the thermostat is on at its default temperature: tensions are Eq. 13 times the
         * measured factor at temperature of its dimension */
        assert_true(fabs(pp->theta - PFSPH_THERMO_REDUCED_DEFAULT) < 1e-15);
        const double fs = pfsph_pairwise_sigma_factor(dim, pp->theta);
        assert_true(fabs(pp->sigma_factor - fs) < 1e-15);
        assert_true(fs > 0.5 && fs < 1.5 && fs != 1.0);
        /* Eq. 13 with c_air = 0: sigma = f lambda c rho^2 */
        assert_true(fabs(fs * lam * pp->c[0][0] * 1e6 - 0.0728) < 1e-12);
        /* the reference liquid's own pair gets the scene's factor bit for bit */
        assert_true(pp->sigma_factor_ab[0][0] == fs);
        /* Eq. 13 for the pair, times the factor at the pair's own temperature (the oil's,
         * kT 800 / 1000, against the pair's Eq. 13 tension): recompute sigma from the
         * coefficients */
        const double s13 = lam * (pp->c[0][0] * 1e6 + pp->c[1][1] * 640000.0 - 2 * pp->c[0][1] * 800000.0);
        const double f01 = pp->sigma_factor_ab[0][1];
        assert_true(pp->sigma_factor_ab[1][0] == f01);
        assert_true(fabs(f01 - pfsph_pairwise_sigma_factor(dim, pp->theta * 0.8 * pp->thermo.sigma_ref / s13)) < 1e-9);
        assert_true(fabs(f01 * s13 - 0.05) < 1e-9);
        assert_true(pp->c[1][0] == pp->c[0][1] && pp->c[0][1] > 0);
        /* the adhesion ratio r = c_wa rho_wall / (c_aa rho_water): the measured table at
         * temperature of the dimension (Eq. 21, cos 60 = 2 r - 1, where there is none) */
        const double r = pp->c[0][2] * 2500.0 / (pp->c[0][0] * 1000.0);
        assert_true(fabs(r - pfsph_pairwise_angle_ratio(dim, pp->theta, 60.0)) < 1e-12);
        if (!pfsph_pairwise_angle_measured(dim, pp->theta)) assert_true(fabs(2 * r - 1 - 0.5) < 1e-12);
        assert_true(pp->c[2][0] == pp->c[0][2]);
        assert_true(fabs(pp->c[1][2]) < 1e-12 * pp->c[1][1]); /* 180 degrees: no adhesion */
        /* idempotent */
        double c00 = pp->c[0][0], c01 = pp->c[0][1], c02 = pp->c[0][2];
        assert_int_equal(pfsph_pairwise_resolve(s, (pfsph_real)d, (pfsph_real)h, &err), PFSPH_OK);
        assert_true(pp->c[0][0] == c00 && pp->c[0][1] == c01 && pp->c[0][2] == c02);
        /* report */
        char buf[8192];
        FILE *f = fmemopen(buf, sizeof buf, "w");
        assert_non_null(f);
        pfsph_pairwise_report(s, f);
        fclose(f);
        print_message("%s", buf);
        assert_non_null(strstr(buf, "target: sigma(water, water) = 0.0728"));
        assert_non_null(strstr(buf, "predicted: contact angle of water on wall = 60.0 deg"));
        assert_non_null(strstr(buf, "predicted: sigma(water, oil) = 0.05 N/m"));
        free(s);
    }
}

/* A tension factor per phase pair (docs/viscosity.md, "A tension factor per phase pair"): each
 * pair's target is converted with f at the pair's own reduced temperature, theta_ab = kT_ab /
 * (sigma13_ab d^(dim-1)), kT_ab the colder phase's temperature (kT rho / rho_ref, thermostat.c)
 * and sigma13_ab the pair's Eq. 13 tension. Hysing's case 1 in 2D at theta 0.04: water (1000,
 * 24.5 N/m against air), gas (100, 0.245), water-gas 24.5. The water-gas pair runs at a tenth of
 * the water's kT against nearly the water's tension: theta_wg ~ 0.0052, f ~ 1.00, where the
 * water against air has f(0.04) = 0.764; the gas against air (0.245 N/m at a tenth of kT) is
 * far hotter, beyond the table (its last value). With the thermostat off every factor is 1. */
static void test_pair_factors(void **state)
{
    (void)state;
    for (int mode = 0; mode < 3; mode++) { /* theta 0.04, 0.01, thermostat off */
        pfsph_scene *s = make_scene(2);
        pfsph_pairwise_params *pp = &s->pairwise;
        s->phases[3].rest_density = 100;
        set_sigma(s, 0, 0, 24.5);
        set_sigma(s, 3, 3, 0.245);
        set_sigma(s, 0, 3, 24.5);
        if (mode == 0) pp->thermo.reduced = 0.04;
        if (mode == 1) pp->thermo.reduced = 0.01;
        if (mode == 2) pp->thermo.enabled = false;
        pfsph_error err = {0};
        const double d = 0.03125;
        assert_int_equal(pfsph_pairwise_resolve(s, (pfsph_real)d, (pfsph_real)(2 * d), &err), PFSPH_OK);
        const double lam = pp->lambda, rw = 1000, rg = 100;
        const double sw = lam * pp->c[0][0] * rw * rw, sgg = lam * pp->c[3][3] * rg * rg;
        const double swg = lam * (pp->c[0][0] * rw * rw + pp->c[3][3] * rg * rg - 2 * pp->c[0][3] * rw * rg);
        const double fw = pp->sigma_factor_ab[0][0], fg = pp->sigma_factor_ab[3][3], fwg = pp->sigma_factor_ab[0][3];
        print_message("theta %g: f water %.4f gas %.4f water-gas %.4f; Eq. 13 tensions %.4g %.4g %.4g\n", pp->theta, fw,
                      fg, fwg, sw, sgg, swg);
        /* each target is met at its own factor */
        assert_true(fabs(fw * sw - 24.5) < 1e-9 * 24.5);
        assert_true(fabs(fg * sgg - 0.245) < 1e-9 * 24.5);
        assert_true(fabs(fwg * swg - 24.5) < 1e-9 * 24.5);
        assert_true(pp->thermo.rho_ref == rw && pp->thermo.sigma_ref == sw);
        if (mode == 2) {
            assert_true(fw == 1.0 && fg == 1.0 && fwg == 1.0);
            free(s);
            continue;
        }
        /* the water is the reference: its factor is the scene's, at the scene's theta */
        assert_true(pp->theta == pp->thermo.reduced);
        assert_true(fw == pfsph_pairwise_sigma_factor(2, pp->theta) && fw == pp->sigma_factor);
        /* the other pairs at their own temperatures: kT = theta sigma_ref d, the gas's a tenth */
        const double kT = pp->thermo.kT_resolved;
        assert_true(fabs(kT - pp->theta * sw * d) < 1e-12 * kT);
        const double twg = 0.1 * kT / (swg * d), tg = 0.1 * kT / (sgg * d);
        assert_true(fabs(fwg - pfsph_pairwise_sigma_factor(2, twg)) < 1e-9);
        assert_true(fabs(fg - pfsph_pairwise_sigma_factor(2, tg)) < 1e-9);
        /* theta_wg = theta / 10 x sigma_ref / sigma13_wg = theta / 10 x f_wg / f_w */
        assert_true(fabs(twg - 0.1 * pp->theta * fwg / fw) < 1e-9 * twg);
        if (mode == 0) {
            /* the pair is cold (f within 1 % of Eq. 13's), the water hot (0.764); the gas's
             * theta, 0.1 x 0.04 x 32 / 0.3 ~ 0.4, is beyond the table */
            assert_true(fabs(fw - 0.764) < 1e-12 && fwg > 0.99 && fwg < 1.01);
            assert_true(tg > pfsph_pairwise_sigma_theta_max(2) &&
                        fg == pfsph_pairwise_sigma_factor(2, pfsph_pairwise_sigma_theta_max(2)));
        }
        free(s);
    }
}

/* The tables at temperature: Eq. 21 and Eq. 13 where they are not calibrated (thermostat off),
 * measured factors in 2D and 3D, continuous, monotonic angle tables whose inverse is their
 * inverse, 180 degrees without adhesion. */
static void test_temperature_tables(void **state)
{
    (void)state;
    assert_true(pfsph_pairwise_sigma_factor(2, 0.0) == 1.0);
    assert_true(pfsph_pairwise_sigma_factor(3, 0.0) == 1.0);
    for (int dim = 2; dim <= 3; dim++)
        for (double th = 0.001; th < 0.2; th *= 1.3) {
            const double f = pfsph_pairwise_sigma_factor(dim, th);
            assert_true(f > 0.5 && f < 1.5);
        }
    assert_true(pfsph_pairwise_angle_measured(2, 0.01) && !pfsph_pairwise_angle_measured(2, 0.0));
    for (int dim = 2; dim <= 3; dim++) {
        for (double a = 0; a <= 180; a += 15) {
            const double eq21 = 0.5 * (1 + cos(a * 3.14159265358979323846 / 180));
            assert_true(fabs(pfsph_pairwise_angle_ratio(dim, 0.0, a) - eq21) < 1e-15);
            if (!pfsph_pairwise_angle_measured(dim, 0.01))
                assert_true(fabs(pfsph_pairwise_angle_ratio(dim, 0.01, a) - eq21) < 1e-15);
        }
        if (pfsph_pairwise_angle_measured(dim, 0.01)) assert_true(pfsph_pairwise_angle_ratio(dim, 0.01, 180.0) == 0.0);
        double prev = -1;
        for (double a = 179; a >= 20; a -= 1) {
            const double r = pfsph_pairwise_angle_ratio(dim, 0.01, a);
            assert_true(r > prev); /* more wetting needs more adhesion */
            prev = r;
            assert_true(fabs(pfsph_pairwise_angle_expected(dim, 0.01, r) - a) < 1e-9);
        }
    }
}

static void test_resolve_errors(void **state)
{
    (void)state;
    pfsph_error err = {0};
    /* interfacial tension beyond what c_ab = 0 gives */
    pfsph_scene *s = make_scene(2);
    set_sigma(s, 0, 0, 0.07);
    set_sigma(s, 1, 1, 0.02);
    set_sigma(s, 0, 1, 0.2);
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_EINPUT);
    print_message("%s\n", err.msg);
    assert_non_null(strstr(err.msg, "at most 0.09"));
    /* exactly the c = 0 limit is fine: the pair's Eq. 13 tension with c_ab = 0 times the factor
     * at the pair's temperature there (the oil's kT, 800 / 1000 of the water's) */
    s->pairwise.sigma[0][1] = s->pairwise.sigma[1][0] = 0.05;
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_OK);
    const pfsph_pairwise_params *pp = &s->pairwise;
    const double s0 = pp->lambda * (pp->c[0][0] * 1e6 + pp->c[1][1] * 640000.0);
    s->pairwise.sigma[0][1] = s->pairwise.sigma[1][0] =
        s0 * pfsph_pairwise_sigma_factor(2, pp->theta * 0.8 * pp->thermo.sigma_ref / s0);
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_OK);
    assert_true(s->pairwise.c[0][1] < 1e-6 * s->pairwise.c[0][0]);
    free(s);
    /* contact angle on a fluid without cohesion */
    s = make_scene(3);
    set_angle(s, 1, 2, 90);
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "cohesion"));
    free(s);
    /* sigma on a solid, angle on two fluids (the parser refuses these too) */
    s = make_scene(3);
    set_sigma(s, 2, 2, 0.1);
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_EINPUT);
    free(s);
    s = make_scene(3);
    s->pairwise.c[0][0] = 1;
    set_angle(s, 0, 1, 90);
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_EINPUT);
    free(s);
    /* negative coefficient */
    s = make_scene(3);
    s->pairwise.c[0][1] = s->pairwise.c[1][0] = -1;
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_EINPUT);
    /* disabled: nothing to do */
    s->pairwise.enabled = false;
    assert_int_equal(pfsph_pairwise_resolve(s, 0.01f, 0.02f, &err), PFSPH_OK);
    assert_true(pfsph_pairwise_radius(s, 0.02f) == 0);
    s->pairwise.enabled = true;
    assert_true(fabs(pfsph_pairwise_radius(s, 0.02f) - 0.02 * cbrt(80.0 / 30.0)) < 1e-7);
    free(s);
}

static const char *scene_head =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"domain\": {\"min\": [0, 0], \"max\": [1, 1]},"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"oil\", \"rest_density\": 800},"
    " {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0.1, 0.1], \"max\": [0.2, 0.2], \"phase\": \"water\"}],";

static int parse(const char *pairwise, pfsph_scene *s, pfsph_error *err)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s \"pairwise\": %s}", scene_head, pairwise);
    return pfsph_scene_parse(s, buf, "t.json", err);
}

static void test_parse(void **state)
{
    (void)state;
    pfsph_scene *s = calloc(1, sizeof(*s));
    pfsph_error err = {0};
    int rc = parse("{\"k\": 1.5, \"filter\": false, \"eta\": 0.3, \"eps_min\": 0.4, \"center\": \"mean\","
                   " \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 0.0728},"
                   " {\"phases\": [\"oil\", \"oil\"], \"c\": 6000},"
                   " {\"phases\": [\"oil\", \"water\"], \"c\": 100},"
                   " {\"phases\": [\"wall\", \"water\"], \"contact_angle\": 60}]}",
                   s, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    const pfsph_pairwise_params *pp = &s->pairwise;
    assert_true(pp->enabled && !pp->filter && pp->k == 1.5 && pp->eta == 0.3 && pp->eps_min == 0.4);
    assert_int_equal(pp->center, PFSPH_PW_CENTER_MEAN);
    assert_true(pp->sigma_set[0][0] && pp->sigma[0][0] == 0.0728);
    assert_true(pp->c[1][1] == 6000 && pp->c[0][1] == 100 && pp->c[1][0] == 100);
    assert_true(pp->angle_set[0][2] && pp->angle_set[2][0] && pp->angle_deg[2][0] == 60);
    /* an empty block switches the forces on with defaults */
    assert_int_equal(parse("{}", s, &err), PFSPH_OK);
    assert_true(s->pairwise.enabled && s->pairwise.filter && s->pairwise.eta == 0.2);
    assert_int_equal(parse("{\"enabled\": false}", s, &err), PFSPH_OK);
    assert_false(s->pairwise.enabled);

    struct {
        const char *json, *msg;
    } bad[] = {
        {"{\"eta\": 1.5}", "$.pairwise.eta"},
        {"{\"etta\": 0.1}", "did you mean \"eta\""},
        {"{\"center\": \"middle\"}", "$.pairwise.center"},
        {"{\"coefficients\": {}}", "$.pairwise.coefficients"},
        {"{\"coefficients\": [{\"phases\": [\"water\", \"air\"], \"c\": 1}]}", "unknown phase \"air\""},
        {"{\"coefficients\": [{\"phases\": [\"water\"], \"c\": 1}]}", "two phase names"},
        {"{\"coefficients\": [{\"phases\": [\"water\", \"water\"]}]}", "exactly one of"},
        {"{\"coefficients\": [{\"phases\": [\"water\", \"water\"], \"c\": 1, \"sigma\": 2}]}", "exactly one of"},
        {"{\"coefficients\": [{\"phases\": [\"water\", \"water\"], \"c\": -1}]}", "$.pairwise.coefficients[0].c"},
        {"{\"coefficients\": [{\"phases\": [\"water\", \"oil\"], \"c\": 1},"
         " {\"phases\": [\"oil\", \"water\"], \"c\": 2}]}",
         "already given"},
        {"{\"coefficients\": [{\"phases\": [\"wall\", \"water\"], \"sigma\": 0.07}]}", "contact_angle"},
        {"{\"coefficients\": [{\"phases\": [\"oil\", \"water\"], \"contact_angle\": 30}]}", "one fluid and one solid"},
        {"{\"coefficients\": [{\"phases\": [\"wall\", \"water\"], \"contact_angle\": 190}]}", "out of range"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        memset(&err, 0, sizeof err);
        rc = parse(bad[i].json, s, &err);
        if (rc != PFSPH_EINPUT || !strstr(err.msg, bad[i].msg))
            print_message("case %zu: rc %d, message: %s\n", i, rc, err.msg);
        assert_int_equal(rc, PFSPH_EINPUT);
        assert_non_null(strstr(err.msg, bad[i].msg));
        assert_non_null(strstr(err.msg, "t.json"));
    }
    free(s);
}

/* Every shipped scene with a pairwise block loads and its targets resolve. */
/* 2D viscosity_correction (on by default since 2026-12-06): at the default temperature 0.01
 * nu_morris = max(F^-1(nu / nu_0), floor) nu_0 with F the 2D wall-free table at 0.01 (as in 3D);
 * at 0.04 (Newtonian) the viscosity is applied as set with the 0.04 table's expectation; away
 * from both tables (0.02) as set with the box estimate (the box correction is retired); with the
 * key false the viscosity is applied as set. The reference liquid's theta is the scene's
 * reduced temperature, its tension the target. */
static void test_viscosity_correction(void **state)
{
    (void)state;
    pfsph_scene *s = calloc(1, sizeof(*s));
    pfsph_error err = {0};
    for (int mode = 0; mode <= 3; mode++) { /* 0: default, 1: the correction off, 2: theta 0.04, 3: 0.02 */
        const int on = mode != 1;
        const char *pw = on ? "{\"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 4}]}"
                            : "{\"viscosity_correction\": false, \"coefficients\": [{\"phases\": [\"water\", "
                              "\"water\"], \"sigma\": 4}]}";
        const double theta = mode == 2 ? PFSPH_VISC_TABLE_THETA_2D : mode == 3 ? 0.02 : PFSPH_THERMO_REDUCED_DEFAULT_2D;
        for (int k = 0; k < 2; k++) {
            assert_int_equal(parse(pw, s, &err), PFSPH_OK);
            s->pairwise.thermo.reduced = theta;
            s->phases[0].viscosity = k ? 1e-2 : 1e-3; /* above and below what the liquid reaches */
            assert_int_equal(pfsph_pairwise_resolve(s, 0.01, (pfsph_real)(s->support_factor * 0.01), &err), PFSPH_OK);
            const pfsph_pairwise_params *pp = &s->pairwise;
            const double nu0 = sqrt(4 * 0.01 / 1000.0), nu = s->phases[0].viscosity;
            assert_true(pp->visc_correct == (on == 1));
            assert_true(fabs(pp->theta - theta) < 1e-15);
            assert_true(fabs(pp->nu_floor[0] - PFSPH_VISC_FLOOR * nu0) < 1e-6 * nu0);
            assert_true(pp->nu_morris[2] == s->phases[2].viscosity); /* the wall: as set */
            if (mode == 3) {                                         /* no wall-free table: as set, the box estimate */
                assert_true(fabs(pp->nu_struct[0] - pfsph_pairwise_visc_struct(2, pp->theta) * nu0) < 1e-6 * nu0);
                assert_true(pp->nu_morris[0] == nu);
                continue;
            }
            const double want =
                mode == 0 ? fmax(pfsph_pairwise_visc_morris(2, pp->theta, nu / nu0), PFSPH_VISC_FLOOR) * nu0 : nu;
            assert_true(fabs(pp->nu_morris[0] - want) < 1e-6 * want);
            /* the expectation: the wall-free table at the Morris viscosity applied */
            assert_true(fabs(pp->nu_struct[0] - pfsph_pairwise_visc_eff(2, pp->theta, pp->nu_morris[0] / nu0) * nu0) <
                        1e-6 * nu0);
            if (mode == 0) { /* the set one above the reach (1e-2), the reach below it (1e-3) */
                const double reach = pfsph_pairwise_visc_eff(2, pp->theta, PFSPH_VISC_FLOOR) * nu0;
                assert_true(fabs(pp->nu_struct[0] - fmax(nu, reach)) < 1e-6 * nu);
                assert_true(k ? pp->nu_morris[0] < nu : fabs(pp->nu_morris[0] / (PFSPH_VISC_FLOOR * nu0) - 1) < 1e-6);
            }
        }
    }
    assert_true(pfsph_pairwise_visc_struct(3, 0.01) == 0.0 && pfsph_pairwise_visc_struct(2, 0.0) == 0.0);
    assert_true(pfsph_pairwise_visc_corrects(2, 0.01) && !pfsph_pairwise_visc_corrects(2, 0.04) &&
                !pfsph_pairwise_visc_corrects(2, 0.02) && pfsph_pairwise_visc_corrects(3, 0.01));
    for (double y = 0.7; y < 3; y *= 1.5) { /* the 2D inverse at 0.01 */
        const double x = pfsph_pairwise_visc_morris(2, 0.01, y);
        assert_true(fabs(pfsph_pairwise_visc_eff(2, 0.01, x) - y) < 1e-12);
    }
    free(s);
}

/* 3D viscosity_correction (on by default in 3D): nu_morris = max(F^-1(nu / nu_0), floor) nu_0 for
 * the reference liquid, F the measured wall-free viscosity (its theta is the scene's reduced
 * temperature, its tension the target); 2D: above */
static void test_viscosity_bulk_3d(void **state)
{
    (void)state;
    pfsph_scene *s = calloc(1, sizeof(*s));
    pfsph_error err = {0};
    for (int dim = 3; dim <= 3; dim++)
        for (int on = 0; on <= 1; on++) {
            char pw[256];
            snprintf(pw, sizeof pw, "{%s \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 4}]}",
                     on ? "" : "\"viscosity_correction\": false,");
            for (int k = 0; k < 2; k++) {
                assert_int_equal(parse(pw, s, &err), PFSPH_OK);
                s->dim = dim; /* the scene was parsed as 2D: what a 3D parse sets */
                s->pairwise.thermo.reduced = pfsph_thermo_reduced_default(dim);
                s->pairwise.visc_correct = on == 1;
                s->phases[0].viscosity = k ? 1e-2 : 1e-3; /* above and below what the liquid reaches */
                assert_int_equal(pfsph_pairwise_resolve(s, 0.01, (pfsph_real)(s->support_factor * 0.01), &err),
                                 PFSPH_OK);
                const pfsph_pairwise_params *pp = &s->pairwise;
                const double nu = s->phases[0].viscosity;
                const double nu0 = sqrt(4 * 0.01 / 1000.0); /* the tension at temperature is the target */
                assert_true(pp->visc_correct == (on == 1));
                assert_true(fabs(pp->theta - pfsph_thermo_reduced_default(dim)) < 1e-15);
                assert_true(pp->nu_morris[2] == s->phases[2].viscosity); /* the wall: as set */
                if (dim == 2) {                                          /* no table: as set, no expectation */
                    assert_true(pp->nu_morris[0] == nu && pp->nu_struct[0] == 0);
                    continue;
                }
                assert_true(fabs(pp->nu_floor[0] - PFSPH_VISC_FLOOR * nu0) < 1e-6 * nu0);
                const double want =
                    on ? fmax(pfsph_pairwise_visc_morris(3, pp->theta, nu / nu0), PFSPH_VISC_FLOOR) * nu0 : nu;
                assert_true(fabs(pp->nu_morris[0] - want) < 1e-6 * want);
                /* the expected viscosity: the set one above the reach, the reach below it */
                const double reach = pfsph_pairwise_visc_eff(3, pp->theta, PFSPH_VISC_FLOOR) * nu0;
                assert_true(fabs(pp->nu_struct[0] -
                                 pfsph_pairwise_visc_eff(3, pp->theta, pp->nu_morris[0] / nu0) * nu0) < 1e-9);
                if (on) assert_true(fabs(pp->nu_struct[0] - fmax(nu, reach)) < 1e-6 * nu);
            }
        }
    /* the table holds in 3D at its default temperature only */
    assert_true(isfinite(pfsph_pairwise_visc_eff(3, 0.01, 0.1)) && isnan(pfsph_pairwise_visc_eff(3, 0.04, 0.1)));
    assert_true(isfinite(pfsph_pairwise_visc_eff(2, 0.01, 0.1)) && isnan(pfsph_pairwise_visc_eff(3, 0.0, 0.1)));
    assert_true(isnan(pfsph_pairwise_visc_eff(2, 0.02, 0.1)));
    assert_true(isfinite(pfsph_pairwise_visc_eff(2, PFSPH_VISC_TABLE_THETA_2D, 0.1)));
    for (double y = 0.3; y < 3; y *= 1.7) { /* the inverse */
        const double x = pfsph_pairwise_visc_morris(3, 0.01, y);
        assert_true(fabs(pfsph_pairwise_visc_eff(3, 0.01, x) - y) < 1e-12);
    }
    free(s);
}

static void test_scenes(void **state)
{
    (void)state;
    char path[2048];
    const char *names[] = {"pf_cube_to_sphere.json", "pf_drop_on_plane.json", "pf_three_fluids.json",
                           "pf_wetting.json",        "pf_rising_bubble.json", "pf_square_to_circle_2d.json"};
    pfsph_scene *s = calloc(1, sizeof(*s));
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(path, sizeof path, "%s/scenes/%s", tu_source_dir(), names[i]);
        FILE *f = fopen(path, "r");
        if (!f) continue; /* written as the figures are reached */
        fclose(f);
        pfsph_error err = {0};
        int rc = pfsph_scene_load(s, path, &err);
        if (rc) print_message("%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        assert_true(s->pairwise.enabled);
        double d = 2 * s->particle_radius;
        rc = pfsph_pairwise_resolve(s, (pfsph_real)d, (pfsph_real)(s->support_factor * d), &err);
        if (rc) print_message("%s: %s\n", names[i], err.msg);
        assert_int_equal(rc, PFSPH_OK);
    }
    free(s);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lambda),
        cmocka_unit_test(test_resolve),
        cmocka_unit_test(test_resolve_errors),
        cmocka_unit_test(test_pair_factors),
        cmocka_unit_test(test_temperature_tables),
        cmocka_unit_test(test_viscosity_correction),
        cmocka_unit_test(test_viscosity_bulk_3d),
        cmocka_unit_test(test_parse),
        cmocka_unit_test(test_scenes),
    };
    return tu_run_group(tests, NULL, NULL);
}
