/* Dam-break surge front against Martin & Moyce (1952), 2D (issue 31; docs/validation.md, "Dam
 * break: the surge front"). Labels validation and physics (CMakeLists.txt).
 *
 * Setup, Martin & Moyce's n^2 = 2 series at their scale: a water column a = 2.25 in (0.05715 m)
 * wide and 2a high collapses onto a dry floor; the tank is 16 a long (their data reach Z = 14),
 * container walls 2 layers, PCISPH and the settings of scenes/dam_break_2d.json (tolerance
 * 0.005, cfl 0.4), water nu 1e-6. Two spacings, a / d = 20 and 40 (800 and 3,200 particles).
 * The shipped scene scenes/dam_break_2d.json itself (a 0.6 x 0.8 m column, n^2 = 4/3, a = 0.6 m)
 * runs too, until its front reaches the far wall (Z = 3.33).
 * Front: the farthest fluid particle centre plus d / 2 (centres sit half a spacing inside the
 * surface), every 0.005 s; Z = z / a, T = t sqrt(2 g / a).
 *
 * Reference: J. C. Martin and W. J. Moyce, Phil. Trans. R. Soc. Lond. A 244 (1952) 312-324,
 * Fig. 3 (n^2 = 2, a = 2.25 in), points as digitised in PySPH's examples/db_exp_data.py (the
 * digitisation of the same series that python/examples/dam_break_front.py types in agrees within
 * 0.04 in Z); the table below gives T, Z.
 * The gate: in the experiment a paper diaphragm was removed, so the column starts to collapse
 * later than T = 0 of the record and its front lags; SPH codes start from rest at T = 0 and so
 * lead the data (Colagrossi & Landrini 2003 and most since shift by about dT 0.2-0.4 or compare
 * the slope). We report both the unshifted error and the shift dT that best fits (a least-squares
 * scan over dT in [0, 1]), and the front speed dZ/dT over T 2-6 against the data's.
 *
 * Checks (why these bounds): the a / d = 40 front, unshifted, within 20 % of Z at every reference
 * point with T >= 1 (issue 31 measured a lead of 10 % mean, 17 % worst on the Python example);
 * the best shift dT within [0, 0.8] (a negative shift, a front that lags an experiment that
 * itself lags, would be an error) and, after it, the rms difference in Z below 0.3; the front
 * speed within 15 % of the data's (the gate cannot change the speed of the developed surge);
 * the two spacings within 10 % of each other at T = 3. Measured: see docs/validation.md.
 * Writes validation/dam_break_front.csv (T, Z per run) in the working directory for
 * tools/validation_plots.py. Under AddressSanitizer it skips (tu_release_only). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pfsph/sim.h"
#include "testutil.h"

#define G 9.81
#define A_MM 0.05715 /* 2.25 in */

/* Martin & Moyce 1952, Fig. 3, n^2 = 2, a = 2.25 in: T = t sqrt(2 g / a), Z = z / a (PySPH's
 * digitisation, examples/db_exp_data.py, mm_data_2). */
static const double MM[][2] = {{0.832, 1.217}, {1.219, 1.474},  {1.997, 2.292},  {2.547, 2.995},  {3.345, 4.134},
                               {4.034, 4.944}, {4.418, 5.881},  {5.091, 6.980},  {5.685, 7.945},  {6.306, 8.966},
                               {6.822, 9.986}, {7.439, 10.963}, {8.031, 11.977}, {8.633, 13.005}, {9.237, 13.970}};
enum { NMM = sizeof MM / sizeof MM[0], NMAX = 512 };

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": %.10g, \"gravity\": [0, -9.81],"
    " \"domain\": {\"min\": [%.10g, %.10g], \"max\": [%.10g, %.10g]},"
    " \"solver\": {\"type\": \"pcisph\", \"tolerance\": 0.005, \"min_iterations\": 3, \"max_iterations\": 50},"
    " \"time\": {\"end\": %.10g, \"fps\": 200, \"cfl\": 0.4},"
    " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": 1e-6},"
    "   {\"name\": \"wall\", \"kind\": \"solid\"}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [%.10g, %.10g], \"phase\": \"water\"}],"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [%.10g, %.10g], \"open_top\": true,"
    "   \"layers\": 2, \"phase\": \"wall\"}]}";

typedef struct front {
    int n;
    double T[NMAX], Z[NMAX];
    size_t np;
} front;

static double front_x(const pfsph_ctx *c)
{
    double m = -1e30;
    for (size_t i = 0; i < c->fluid->n; i++)
        if (c->fluid->x[i] > m) m = c->fluid->x[i];
    return m + 0.5 * c->spacing;
}

/* Runs sim to T_end (dimensionless), recording the front every dt seconds. */
static void record(pfsph_sim *sim, double a, double T_end, double dt, front *f)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const double s = sqrt(2 * G / a);
    f->n = 0;
    f->np = c->fluid->n;
    f->T[f->n] = 0;
    f->Z[f->n++] = front_x(c) / a;
    for (int k = 1; k * dt * s <= T_end + 1e-9 && f->n < NMAX; k++) {
        tu_advance(sim, k * dt);
        f->T[f->n] = k * dt * s;
        f->Z[f->n++] = front_x(c) / a;
    }
}

static void run_mm(int n_per_a, front *f)
{
    const double a = A_MM, d = a / n_per_a, L = 16 * a, w = 3 * d, T_end = 9.3;
    char json[4096];
    snprintf(json, sizeof json, SCENE, 0.5 * d, -w, -w, L + w, 3 * a, T_end / sqrt(2 * G / a), a, 2 * a, L, 2.5 * a);
    pfsph_sim *sim = tu_sim_from_json(json, "Martin & Moyce dam break");
    record(sim, a, T_end, 0.005 * sqrt(a / 0.2), f); /* the same ~0.01 of T at both scales */
    pfsph_sim_destroy(sim);
}

/* Z of run f at T (linear interpolation; the last value past the end). */
static double z_at(const front *f, double T)
{
    if (T <= f->T[0]) return f->Z[0];
    for (int k = 1; k < f->n; k++)
        if (f->T[k] >= T) return f->Z[k - 1] + (f->Z[k] - f->Z[k - 1]) * (T - f->T[k - 1]) / (f->T[k] - f->T[k - 1]);
    return f->Z[f->n - 1];
}

/* rms of Z(T - dT) - Z_ref over the reference points with T <= T_max */
static double rms_shift(const front *f, double dT, double T_max)
{
    double s = 0;
    int m = 0;
    for (int k = 0; k < NMM; k++)
        if (MM[k][0] <= T_max) {
            double e = z_at(f, MM[k][0] - dT) - MM[k][1];
            s += e * e;
            m++;
        }
    return sqrt(s / m);
}

/* least-squares slope dZ/dT of the points (T, Z) with T in [t0, t1] */
static double slope(const double *T, const double *Z, int n, int stride, double t0, double t1)
{
    double st = 0, sz = 0, stt = 0, stz = 0;
    int m = 0;
    for (int k = 0; k < n; k++) {
        double t = T[k * stride], z = Z[k * stride];
        if (t < t0 || t > t1) continue;
        st += t, sz += z, stt += t * t, stz += t * z, m++;
    }
    return (m * stz - st * sz) / (m * stt - st * st);
}

static void report(const char *name, const front *f, double T_max, double *worst, double *best_dT, double *best_rms)
{
    double wr = 0, mr = 0;
    int m = 0;
    printf("%s (%zu particles):   T    Z (M&M)   Z (pfsph)   rel\n", name, f->np);
    for (int k = 0; k < NMM; k++) {
        if (MM[k][0] > T_max) continue;
        double z = z_at(f, MM[k][0]), r = z / MM[k][1] - 1;
        printf("  %6.3f  %6.3f  %6.3f  %+6.3f\n", MM[k][0], MM[k][1], z, r);
        if (MM[k][0] >= 1) {
            mr += r;
            m++;
            if (fabs(r) > fabs(wr)) wr = r;
        }
    }
    *best_rms = 1e30;
    for (double dT = 0; dT <= 1.0 + 1e-9; dT += 0.01) {
        double r = rms_shift(f, dT, T_max);
        if (r < *best_rms) *best_rms = r, *best_dT = dT;
    }
    *worst = wr;
    printf("%s: unshifted mean %+.3f worst %+.3f (T >= 1), rms in Z %.3f; best shift dT %.2f, rms %.3f\n", name,
           m ? mr / m : 0, wr, rms_shift(f, 0, T_max), *best_dT, *best_rms);
}

static void write_csv(const front *runs[], const char *names[], int nr)
{
    mkdir("validation", 0777);
    FILE *fp = fopen("validation/dam_break_front.csv", "w");
    if (!fp) return; /* the plot data are a by-product; the checks do not depend on them */
    fprintf(fp, "run,particles,T,Z\n");
    for (int r = 0; r < nr; r++)
        for (int k = 0; k < runs[r]->n; k++)
            fprintf(fp, "%s,%zu,%.4f,%.4f\n", names[r], runs[r]->np, runs[r]->T[k], runs[r]->Z[k]);
    for (int k = 0; k < NMM; k++) fprintf(fp, "martin_moyce_1952,0,%.3f,%.3f\n", MM[k][0], MM[k][1]);
    fclose(fp);
}

static void test_front(void **state)
{
    (void)state;
    tu_release_only();
    static front f20, f40, fs;
    run_mm(20, &f20);
    run_mm(40, &f40);
    /* the shipped scene, as it is, to when its front reaches the far wall (x = 2 m: Z = 3.33) */
    {
        char path[4096];
        snprintf(path, sizeof path, "%s/scenes/dam_break_2d.json", tu_source_dir());
        static pfsph_scene sc;
        pfsph_error err = {0};
        int rc = pfsph_scene_load(&sc, path, &err);
        if (rc) fprintf(stderr, "%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        sc.output.vtp = sc.output.ply = false; /* measured here, nothing written */
        pfsph_sim *sim;
        rc = pfsph_sim_create(&sim, &sc, &err);
        if (rc) fprintf(stderr, "%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        record(sim, 0.6, 3.0, 0.01, &fs);
        pfsph_sim_destroy(sim);
    }
    double w20 = 0, w40 = 0, ws = 0, dT20 = 0, dT40 = 0, dTs = 0, r20 = 0, r40 = 0, rs = 0;
    report("M&M a/d = 20", &f20, 9.3, &w20, &dT20, &r20);
    report("M&M a/d = 40", &f40, 9.3, &w40, &dT40, &r40);
    report("scenes/dam_break_2d.json (n^2 = 4/3)", &fs, 3.0, &ws, &dTs, &rs);
    const double s_ref = slope(&MM[0][0], &MM[0][1], NMM, 2, 2, 6), s40 = slope(f40.T, f40.Z, f40.n, 1, 2, 6),
                 s20 = slope(f20.T, f20.Z, f20.n, 1, 2, 6);
    printf("front speed dZ/dT over T 2-6: M&M %.3f, a/d 20 %.3f (%+.3f), a/d 40 %.3f (%+.3f)\n", s_ref, s20,
           s20 / s_ref - 1, s40, s40 / s_ref - 1);
    printf("Z(T = 3): a/d 20 %.3f, a/d 40 %.3f (ratio %.3f)\n", z_at(&f20, 3), z_at(&f40, 3),
           z_at(&f20, 3) / z_at(&f40, 3));
    const front *runs[] = {&f20, &f40, &fs};
    const char *names[] = {"mm_a20", "mm_a40", "dam_break_2d"};
    write_csv(runs, names, 3);
    fflush(stdout);
    assert_true(fabs(w40) <= 0.20);
    assert_true(dT40 >= 0 && dT40 <= 0.8);
    assert_true(r40 < 0.3);
    assert_true(fabs(s40 / s_ref - 1) <= 0.15);
    assert_true(fabs(z_at(&f20, 3) / z_at(&f40, 3) - 1) <= 0.10);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_front)};
    return tu_run_group(tests, NULL, NULL);
}
