/* SPHERIC validation test 2: 3D dam break against a box obstacle (Kleefsman et al. 2005), at a
 * coarse resolution (issue 31; docs/validation.md, "SPHERIC test 2").
 *
 * Geometry (Kleefsman, Fekken, Veldman, Iwanowski & Buchner, "A Volume-of-Fluid based
 * simulation method for wave impact problems", J. Comput. Phys. 206 (2005) 363-393, Fig. 13
 * and the SPHERIC test 2 description, Issa & Violeau 2006), in the experiment's axes x along
 * the tank, y across, z up; pfsph's are x, y up, z across: a closed tank 3.22 x 1 x 1 m; water
 * x 1.992-3.22 m, 0.55 m deep, over the whole width; a box 0.161 (x) x 0.403 (y) x 0.161 (z) m
 * at x 0.6635-0.8245, y 0.2955-0.6985. Pressure sensors P1-P4 on the box's face towards the
 * water (x 0.8245, y 0.471) at z 0.021, 0.061, 0.101, 0.141 m; P5-P8 on its top (z 0.161,
 * y 0.471) at x 0.8035, 0.7635, 0.7235, 0.6835 m. Water heights H1-H4 at x 0.496, 0.992,
 * 1.488, 2.638 m (y 0.5): H1 behind the box, H4 in the reservoir.
 *
 * Run: spacing d = PF_D (0.04 m: 10,500 water particles; the box is 4 d high, so the pressures
 * are read over a kernel as tall as a quarter of the box), PCISPH with the settings of
 * scenes/dam_break_3d.json, water nu 1e-6, walls 2 layers, to PF_T = 6 s (the record's length),
 * sampled every 0.01 s.
 * Measurement: a height is the water volume per area under the gauge, sum d^3 W(r) over the
 * particles with W the 2D Wendland kernel of support 2 d (integral 1) of their horizontal
 * distance r to the gauge, so a splash counts by its mass, not its reach; a pressure is what a
 * transducer reads, force per area: the normal force the box's wall particles exert on the fluid
 * (pressure.c's wall term), spread over the face with the 2D Wendland kernel of support 2 d
 * around the sensor and divided by the kernel's integral over the face (face_pressure; checked at
 * rest by test_sensor_static). Until 2026-12-06 the reading was the mean pressure of the first
 * particle layer, which the wall holds with p_i alone, so that layer carries 1.4-2x the pressure
 * the wall feels: P1 read 2-2.5x the experiment even in the slow flow (still written, as L1-L8
 * of the CSV).
 *
 * Reference, typed in (spheric2_exp.inc): points read from the experiment's records (the SPHERIC
 * test 2 data file, MARIN's measurements at 1 kHz): heights at the time given, pressures a mean
 * over the next ~50 ms; P1's peak, 11.2 kPa at 0.415 s, read from the record. Published SPH
 * comparisons with this experiment exist (DualSPHysics: Crespo et al. 2011, PLoS ONE 6(6)
 * e20685); their figures were not available here, so docs/validation.md quotes none.
 * Checks (why these bounds; measured values in docs/validation.md): the front reaches P1 (the
 * first time its pressure exceeds 1 kPa) within 0.05 s of the experiment's 0.394 s (the front is
 * a few d thick at this spacing); the heights in front of the box (x 0.992) and in the reservoir
 * (x 2.638) within 0.06 m of the experiment at every reference time (about 1.5 d; measured at
 * most 0.048 and 0.045); P1's impact peak between 1 and 5 times the record's 11.2 kPa (a
 * solver that lost the impact, or blew up, fails; PCISPH's impact spike at this spacing reads
 * 1.7x by force, 3.3x by the first layer); P1's and P3's 0.05 s means from 0.8 s on (the flow
 * after the impact) within a factor 2 of the experiment's (measured 1.03-1.31 and 0.77-1.13; the
 * first layer's P1 read 2-2.5x and fails this); no particle lost. Under AddressSanitizer it
 * skips (tu_release_only). Writes validation/spheric2.csv for tools/validation_plots.py, which
 * reads the experiment's points from spheric2_exp.inc beside this file.
 * Study knobs: PF_D (spacing [m]), PF_T (end [s]), PF_SOLVER. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pfsph/sim.h"
#include "testutil.h"

/* pfsph axes: x along the tank, y up, z across (the experiment's y) */
static const char *SCENE =
    "{\"dimension\": 3, \"particle_radius\": %.10g, \"gravity\": [0, -9.81, 0],"
    " \"domain\": {\"min\": [-0.2, -0.2, -0.2], \"max\": [3.42, 1.2, 1.2]},"
    " \"solver\": {\"type\": \"%s\", \"tolerance\": 0.005, \"min_iterations\": 3, \"max_iterations\": 50},"
    " \"time\": {\"end\": %g, \"fps\": 100, \"cfl\": 0.4, \"dt_max\": 0.004},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-6},"
    "   {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [1.992, 0, 0], \"max\": [3.22, 0.55, 1], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [3.22, 1, 1], \"layers\": 2,"
    "   \"phase\": \"wall\"},"
    "   {\"shape\": \"box\", \"min\": [0.6635, 0, 0.2955], \"max\": [0.8245, 0.161, 0.6985], \"layers\": 2,"
    "   \"phase\": \"wall\"}]}";

enum { NP = 8, NH = 4, NMAX = 700 };
/* sensor positions in pfsph axes and the outward normal of their face */
static const double PS[NP][3] = {{0.8245, 0.021, 0.471}, {0.8245, 0.061, 0.471}, {0.8245, 0.101, 0.471},
                                 {0.8245, 0.141, 0.471}, {0.8035, 0.161, 0.471}, {0.7635, 0.161, 0.471},
                                 {0.7235, 0.161, 0.471}, {0.6835, 0.161, 0.471}};
static const double HX[NH] = {0.496, 0.992, 1.488, 2.638};

/* The experiment (SPHERIC test 2 data file, MARIN): mean over the 64 ms from t. Columns t, H1-H4
 * [m], P1, P3, P5, P7 [Pa]; NAN where not read. */
static const double EXP[][9] = {
#include "spheric2_exp.inc"
};
enum { NEXP = sizeof EXP / sizeof EXP[0] };

typedef struct series {
    int n;
    double t[NMAX], h[NMAX][NH], p[NMAX][NP], pl[NMAX][NP]; /* pl: the first layer's pressure */
    size_t np0, np1;
} series;

static double wendland3(double q) /* unnormalised */
{
    if (q >= 1) return 0;
    double a = 1 - q;
    return a * a * a * a * (1 + 4 * q);
}

/* A face of a solid and the sensors on it: the face's plane (axis a at coordinate c, outward
 * normal along +a), its rectangle in the other two axes (u, v) and the boundary particles that
 * make it up (those inside the box lo-hi). */
typedef struct face {
    int a, u, v;
    double c, u0, u1, v0, v1, lo[3], hi[3];
} face;

/* The pressure the wall feels at point s of face F: the normal force the face's particles exert
 * on the fluid (pressure.c's Akinci term, -(p_i / n_i^2) sum_b (V_b / V0) grad W_ib with n_i the
 * number density), spread over the face with a normalised 2D Wendland kernel of support H
 * around s, divided by the kernel's integral over the face (the wetted part of a full support
 * reads its mean; below the floor there is no face). This is what a transducer reads: force per
 * area. The first layer's own pressure is not: the wall pushes with p_i alone (pressure.c), so in
 * a tank at rest that layer carries 1.4x the hydrostatic pressure on a floor and 2x in a corner
 * of two walls (test_sensor_static). */
/* The kernel's integral over the face around s (midpoint rule on 200^2 cells): a property of
 * the sensor alone, computed once per sensor. */
static double face_area(const face *F, const double s[3], double H)
{
    const double norm = 7.0 / (3.14159265358979323846 * H * H);
    double area = 0;
    const int M = 200;
    for (int iu = 0; iu < M; iu++)
        for (int iv = 0; iv < M; iv++) {
            const double du = s[F->u] - H + (iu + 0.5) * 2 * H / M, dv = s[F->v] - H + (iv + 0.5) * 2 * H / M;
            if (du < F->u0 || du > F->u1 || dv < F->v0 || dv > F->v1) continue;
            const double q = sqrt((du - s[F->u]) * (du - s[F->u]) + (dv - s[F->v]) * (dv - s[F->v])) / H;
            area += norm * wendland3(q) * (2 * H / M) * (2 * H / M);
        }
    return area;
}

static double face_pressure(const pfsph_ctx *c, const face *F, const double s[3], double H, double area)
{
    const pfsph_particles *f = c->fluid, *b = c->boundary;
    const pfsph_kernel *k = &c->kern;
    const double h = k->h, inv_v0 = 1.0 / c->V0, norm = 7.0 / (3.14159265358979323846 * H * H);
    if (area < 1e-6) return 0;
    double sum = 0;
    for (size_t i = 0; i < f->n; i++) {
        const double xi[3] = {f->x[i], f->y[i], f->z[i]};
        const double dn = xi[F->a] - F->c;
        if (dn < -0.5 * h || dn > h || f->p[i] <= 0) continue;
        const double q =
            sqrt((xi[F->u] - s[F->u]) * (xi[F->u] - s[F->u]) + (xi[F->v] - s[F->v]) * (xi[F->v] - s[F->v])) / H;
        if (q >= 1) continue;
        const double nd = f->rho[i] / c->mass[f->phase[i]];
        double fn = 0;
        pfsph_ranges r;
        pfsph_grid_ranges(c->bgrid, f->x[i], f->y[i], f->z[i], &r);
        for (int g = 0; g < r.n; g++)
            for (uint32_t j = r.b[g]; j < r.e[g]; j++) {
                const double xb[3] = {b->x[j], b->y[j], b->z[j]};
                if (xb[0] < F->lo[0] || xb[0] > F->hi[0] || xb[1] < F->lo[1] || xb[1] > F->hi[1] || xb[2] < F->lo[2] ||
                    xb[2] > F->hi[2])
                    continue;
                const double dx = xi[0] - xb[0], dy = xi[1] - xb[1], dz = xi[2] - xb[2];
                const double rr = sqrt(dx * dx + dy * dy + dz * dz);
                if (rr >= h || rr == 0) continue;
                const double d3[3] = {dx, dy, dz};
                fn += b->aux[j] * inv_v0 * pfsph_kernel_dw_r(k, (pfsph_real)rr) * d3[F->a];
            }
        sum += norm * wendland3(q) * (-(f->p[i] / (nd * nd)) * fn);
    }
    return sum / area;
}

static void measure(const pfsph_ctx *c, double *h, double *p, double *pl)
{
    const pfsph_particles *f = c->fluid;
    const double d = c->spacing, H = 2 * d;
    /* a full support's weight sum on the lattice, for the dry threshold */
    static double wfull = 0;
    if (wfull == 0)
        for (int i = -3; i <= 3; i++)
            for (int j = -3; j <= 3; j++)
                for (int k = -3; k <= 3; k++) wfull += wendland3(sqrt(i * i + j * j + k * k) * d / H);
    double vol[NH] = {0};
    double sw[NP] = {0}, swp[NP] = {0};
    for (size_t i = 0; i < f->n; i++) {
        const double x = f->x[i], y = f->y[i], z = f->z[i];
        for (int g = 0; g < NH; g++) { /* 2D Wendland C2, support H, normalised: 7 / (pi H^2) */
            double q = sqrt((x - HX[g]) * (x - HX[g]) + (z - 0.5) * (z - 0.5)) / H;
            if (q < 1) vol[g] += 7.0 / (3.14159265358979323846 * H * H) * wendland3(q) * d * d * d;
        }
        if (x > 1.0 || y > 0.25) continue; /* no sensor near */
        for (int s = 0; s < NP; s++) {
            double sx = PS[s][0] + (s < 4 ? 0.5 * d : 0), sy = PS[s][1] + (s < 4 ? 0 : 0.5 * d), sz = PS[s][2];
            double r = sqrt((x - sx) * (x - sx) + (y - sy) * (y - sy) + (z - sz) * (z - sz));
            double w = wendland3(r / H);
            sw[s] += w;
            swp[s] += w * f->p[i];
        }
    }
    for (int g = 0; g < NH; g++) h[g] = vol[g];
    for (int s = 0; s < NP; s++) pl[s] = sw[s] >= 0.25 * wfull ? swp[s] / sw[s] : 0;
    /* the box's front face (x = 0.8245, normal +x) and top (y = 0.161, normal +y) */
    static const face front = {0, 1, 2, 0.8245, 0, 0.161, 0.2955, 0.6985, {0.6, -1e-3, 0.28}, {0.83, 0.17, 0.71}};
    static const face top = {1, 0, 2, 0.161, 0.6635, 0.8245, 0.2955, 0.6985, {0.6, -1e-3, 0.28}, {0.83, 0.17, 0.71}};
    static double area[NP] = {0};
    for (int s = 0; s < NP; s++) {
        if (area[s] == 0) area[s] = face_area(s < 4 ? &front : &top, PS[s], H);
        p[s] = face_pressure(c, s < 4 ? &front : &top, PS[s], H, area[s]);
    }
}

static double p1_arrival(const series *r) /* first time P1 exceeds 1 kPa */
{
    for (int k = 0; k < r->n; k++)
        if (r->p[k][0] > 1000) return r->t[k];
    return NAN;
}

static double h_at(const series *r, int g, double t) /* mean over [t, t + 0.064] */
{
    double m = 0;
    int c = 0;
    for (int k = 0; k < r->n; k++)
        if (r->t[k] >= t - 1e-9 && r->t[k] <= t + 0.064) m += r->h[k][g], c++;
    return c ? m / c : NAN;
}

static double p_at(const series *r, int s, double t) /* mean over [t, t + 0.05] */
{
    double m = 0;
    int c = 0;
    for (int k = 0; k < r->n; k++)
        if (r->t[k] >= t - 1e-9 && r->t[k] <= t + 0.05 + 1e-9) m += r->p[k][s], c++;
    return c ? m / c : NAN;
}

static void test_spheric2(void **state)
{
    (void)state;
    tu_release_only();
    const double d = tu_env_num("PF_D", 0.04), T = tu_env_num("PF_T", 6);
    char json[4096];
    snprintf(json, sizeof json, SCENE, 0.5 * d, tu_env("PF_SOLVER", "pcisph"), T);
    pfsph_sim *sim = tu_sim_from_json(json, "SPHERIC test 2");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    static series r;
    r.np0 = c->fluid->n;
    printf("SPHERIC test 2, d = %g m: %zu water particles\n", d, r.np0);
    for (int k = 0; k <= (int)lround(T / 0.01) && k < NMAX; k++) {
        if (k) tu_advance(sim, 0.01 * k);
        r.t[r.n] = 0.01 * k;
        measure(c, r.h[r.n], r.p[r.n], r.pl[r.n]);
        if (k % 10 == 0) {
            printf("t=%.2f H %.3f %.3f %.3f %.3f P1-4 %.0f %.0f %.0f %.0f P5-8 %.0f %.0f %.0f %.0f\n", r.t[r.n],
                   r.h[r.n][0], r.h[r.n][1], r.h[r.n][2], r.h[r.n][3], r.p[r.n][0], r.p[r.n][1], r.p[r.n][2],
                   r.p[r.n][3], r.p[r.n][4], r.p[r.n][5], r.p[r.n][6], r.p[r.n][7]);
            fflush(stdout);
        }
        r.n++;
    }
    r.np1 = c->fluid->n;
    printf("steps %llu, particles %zu -> %zu\n", (unsigned long long)pfsph_sim_steps(sim), r.np0, r.np1);
    pfsph_sim_destroy(sim);

    mkdir("validation", 0777);
    FILE *fp = fopen("validation/spheric2.csv", "w");
    if (fp) { /* the plot data are a by-product; the checks do not depend on them */
        fprintf(fp, "t,H1,H2,H3,H4,P1,P2,P3,P4,P5,P6,P7,P8,L1,L2,L3,L4,L5,L6,L7,L8\n");
        for (int k = 0; k < r.n; k++) {
            fprintf(fp, "%.3f", r.t[k]);
            for (int g = 0; g < NH; g++) fprintf(fp, ",%.4f", r.h[k][g]);
            for (int s = 0; s < NP; s++) fprintf(fp, ",%.1f", r.p[k][s]);
            for (int s = 0; s < NP; s++) fprintf(fp, ",%.1f", r.pl[k][s]);
            fprintf(fp, "\n");
        }
        fclose(fp);
    }

    /* against the experiment's points */
    double pk = 0;
    const double pk_exp = 11240; /* the record's P1 maximum, at 0.415 s (1 kHz) */
    for (int k = 0; k < r.n; k++)
        if (r.t[k] < 1.0 && r.p[k][0] > pk) pk = r.p[k][0];
    printf("   t    H1 (exp)      H2 (exp)      H3 (exp)      H4 (exp)\n");
    for (int e = 0; e < NEXP; e++) {
        if (EXP[e][0] > T) continue;
        printf("%5.2f", EXP[e][0]);
        for (int g = 0; g < NH; g++) printf("  %.3f (%.3f)", h_at(&r, g, EXP[e][0]), EXP[e][1 + g]);
        printf("\n");
    }
    const double ta = p1_arrival(&r);
    double dh2 = 0, dh4 = 0, r3lo = 1e9, r3hi = 0, r1lo = 1e9, r1hi = 0;
    printf("   t    P1 (exp)        P3 (exp)        P5 (exp)        P7 (exp)   [Pa, 0.05 s means]\n");
    for (int e = 0; e < NEXP; e++) {
        if (EXP[e][0] > T) continue;
        printf("%5.2f  %6.0f (%5.0f)  %6.0f (%5.0f)  %6.0f (%5.0f)  %6.0f (%5.0f)\n", EXP[e][0], p_at(&r, 0, EXP[e][0]),
               EXP[e][5], p_at(&r, 2, EXP[e][0]), EXP[e][6], p_at(&r, 4, EXP[e][0]), EXP[e][7], p_at(&r, 6, EXP[e][0]),
               EXP[e][8]);
        dh2 = fmax(dh2, fabs(h_at(&r, 1, EXP[e][0]) - EXP[e][2]));
        dh4 = fmax(dh4, fabs(h_at(&r, 3, EXP[e][0]) - EXP[e][4]));
        if (EXP[e][0] >= 0.8) {
            const double q = p_at(&r, 2, EXP[e][0]) / EXP[e][6], q1 = p_at(&r, 0, EXP[e][0]) / EXP[e][5];
            r3lo = fmin(r3lo, q), r3hi = fmax(r3hi, q);
            r1lo = fmin(r1lo, q1), r1hi = fmax(r1hi, q1);
        }
    }
    printf("P1 arrival (> 1 kPa) %.2f s (experiment 0.394 s); P1 peak before 1 s %.0f Pa (0.01 s samples; the "
           "experiment's record %.0f Pa: ratio %.2f); worst height differences H2 %.3f m, H4 %.3f m; P3 from 0.8 s "
           "over the experiment's %.2f-%.2f, P1 %.2f-%.2f\n",
           ta, pk, pk_exp, pk / pk_exp, dh2, dh4, r3lo, r3hi, r1lo, r1hi);
    fflush(stdout);
    if (d != 0.04 || T < 6) return; /* study runs */
    assert_true(r.np1 == r.np0);
    assert_true(fabs(ta - 0.394) <= 0.05);
    assert_true(dh2 <= 0.06 && dh4 <= 0.06);
    assert_true(pk >= pk_exp && pk <= 5 * pk_exp);
    assert_true(r3lo >= 0.5 && r3hi <= 2.0);
    assert_true(r1lo >= 0.5 && r1hi <= 2.0);
}

/* The sensor at rest: a tank 1.2 x 1 x 0.4 m with a step 0.3 long and 0.161 high across its
 * width (the box's height and its corner with the floor), water 0.4 m deep over it, the test's
 * spacing and settings, 1 s to settle; the readings averaged over 1-2 s (every 0.02 s) against
 * rho g (h - y), with h the water's surface over the sensor measured at each sample (the
 * spheric2 height gauge, d / 2 clear of the face: the tank's first sloshing mode has a period of
 * about 1.2 s, so a global level would read its slosh as the sensor's error). Checks: the force
 * readings whose kernel lies on the face (its support, 2 d, clear of a convex edge; the floor's
 * concave corner is allowed) within 5 % of hydrostatic (the kernel's mean over a linear profile
 * is the point's value; what is left is the discrete wall and the slosh's dynamic pressure); the
 * sensor 0.02 m under the step's convex top edge (the SPHERIC box's P4) is printed, not
 * checked: its kernel reaches past the edge, where the wall is thinner (measured 0.84-0.86); and
 * the first layer's own pressure at the corner at least 1.5 x (what the sensor had read before:
 * if this no longer holds, the wall term has changed and the spheric2 figures need reading
 * again). */
static void test_sensor_static(void **state)
{
    (void)state;
    tu_release_only();
    const double d = 0.04, H = 2 * d;
    char json[2048];
    snprintf(
        json, sizeof json,
        "{\"dimension\": 3, \"particle_radius\": %g, \"gravity\": [0, -9.81, 0],"
        " \"domain\": {\"min\": [-0.2, -0.2, -0.2], \"max\": [1.4, 1.2, 0.6]},"
        " \"solver\": {\"type\": \"pcisph\", \"tolerance\": 0.005, \"min_iterations\": 3, \"max_iterations\": 50},"
        " \"time\": {\"end\": 2, \"fps\": 100, \"cfl\": 0.4, \"dt_max\": 0.004},"
        " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-6},"
        "   {\"name\": \"wall\", \"kind\": \"solid\"}],"
        " \"fluid\": [{\"shape\": \"box\", \"min\": [0.3, 0, 0], \"max\": [1.2, 0.4, 0.4], \"phase\": \"water\"},"
        "   {\"shape\": \"box\", \"min\": [0, 0.161, 0], \"max\": [0.3, 0.4, 0.4], \"phase\": \"water\"}],"
        " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [1.2, 1, 0.4], \"layers\": 2,"
        "   \"phase\": \"wall\"},"
        "   {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.3, 0.161, 0.4], \"layers\": 2, \"phase\": \"wall\"}]}",
        0.5 * d);
    pfsph_sim *sim = tu_sim_from_json(json, "SPHERIC sensor at rest");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    static const face F = {0, 1, 2, 0.3, 0, 0.161, 0, 0.4, {1e-3, 1e-3, -1e-3}, {0.31, 0.17, 0.401}};
    static const face T = {1, 0, 2, 0.161, 0, 0.3, 0, 0.4, {1e-3, 1e-3, -1e-3}, {0.31, 0.17, 0.401}};
    enum { NS = 6 };
    static const double S[NS][3] = {{0.3, 0.021, 0.2}, {0.3, 0.061, 0.2}, {0.3, 0.101, 0.2},
                                    {0.3, 0.141, 0.2}, {0.2, 0.161, 0.2}, {0.1, 0.161, 0.2}};
    double pf[NS] = {0}, pl[NS] = {0}, hy[NS] = {0}, hsurf = 0, area[NS];
    for (int s = 0; s < NS; s++) area[s] = face_area(s < 4 ? &F : &T, S[s], H);
    int m = 0;
    for (int k = 50; k <= 100; k++, m++) {
        tu_advance(sim, 0.02 * k);
        const pfsph_particles *f = c->fluid;
        for (int s = 0; s < NS; s++) {
            pf[s] += face_pressure(c, s < 4 ? &F : &T, S[s], H, area[s]);
            const double px = S[s][0] + (s < 4 ? 0.5 * d : 0), py = S[s][1] + (s < 4 ? 0 : 0.5 * d), pz = S[s][2];
            /* the surface over the sensor: the water's volume per area under a gauge (2D Wendland,
             * support H, normalised) at the sensor, or H + d / 2 off the face */
            const double gx = s < 4 ? S[s][0] + H + 0.5 * d : S[s][0], gz = S[s][2];
            double sw = 0, swp = 0, v = 0;
            for (size_t i = 0; i < f->n; i++) {
                const double r = sqrt((f->x[i] - px) * (f->x[i] - px) + (f->y[i] - py) * (f->y[i] - py) +
                                      (f->z[i] - pz) * (f->z[i] - pz));
                const double w = wendland3(r / H);
                sw += w, swp += w * f->p[i];
                const double q = sqrt((f->x[i] - gx) * (f->x[i] - gx) + (f->z[i] - gz) * (f->z[i] - gz)) / H;
                if (q < 1 && (s < 4 || f->y[i] > 0.161))
                    v += 7.0 / (3.14159265358979323846 * H * H) * wendland3(q) * d * d * d;
            }
            pl[s] += swp / sw;
            const double surf = (s < 4 ? 0 : 0.161) + v;
            hy[s] += 1000 * 9.81 * (surf - S[s][1]);
            if (s == 0) hsurf += surf;
        }
    }
    const double top = hsurf / m;
    double worst = 0;
    for (int s = 0; s < NS; s++) {
        pf[s] /= m, pl[s] /= m;
        const double hyd = hy[s] / m;
        printf("sensor %s (%.3f, %.3f): force %.0f Pa, first layer %.0f Pa, hydrostatic %.0f Pa: %.3f, %.3f\n",
               s < 4 ? "face" : "top ", S[s][0], S[s][1], pf[s], pl[s], hyd, pf[s] / hyd, pl[s] / hyd);
        if (s != 3) worst = fmax(worst, fabs(pf[s] / hyd - 1));
    }
    printf("surface over the face %.4f m (mean); worst force reading clear of the edge %.1f %% off hydrostatic\n", top,
           100 * worst);
    pfsph_sim_destroy(sim);
    assert_true(worst <= 0.05);
    assert_true(pl[0] >= 1.5 * hy[0] / m);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads((int)tu_env_num("PF_THREADS", 1));
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_sensor_static), cmocka_unit_test(test_spheric2)};
    return tu_run_group(tests, NULL, NULL);
}
