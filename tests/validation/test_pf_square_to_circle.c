/* Surface tension from pair forces alone (PF Fig. 1c, Section 3) at the thermostat's default
 * temperature: a 2:1 rectangle of liquid (50 x 25 particles, 2D, no gravity) becomes a disc.
 * Scene, and why: sigma 4 N/m, nu 3e-3 m^2/s and k 1.7 as in the other 2D pairwise tests
 * (k: docs/pairwise.md, "Lattice locking in 2D"); theta 0.01, the default; lattice start (the
 * noise breaks its symmetry); DFSPH, which relaxes this drop like PCISPH and WCSPH at 1/7.7 and
 * 1/2.4 of their CPU time (docs/thermostat.md, "Elongated drops: how they relax").
 * Size: a 2D drop at temperature fluctuates about round. Equipartition of the n = 2 mode puts
 * the mean moment ratio at 0.954 for 450 particles, 0.960 for 800 and 0.964 for this one
 * (R = 19.95 d), and a two-period average scatters by about 0.01, so 0.95 needs this size: at
 * 800 particles the seeds read 0.949 / 0.946 / 0.961.
 * Criteria (issue 11): the capillary period of the n = 2 mode is T = 2 pi / omega_2,
 * omega_n^2 = n (n^2 - 1) sigma / (rho R^3), T = 3.61 s. Each of three seeds (the thermostat's
 * noise) runs to 12.65 s = 3.5 T, sampled every 0.05 s; over the last 2 T the mean moment ratio
 * (smallest / largest principal second moment) must be >= 0.95, and the mean fraction of
 * kernel-neighbour pairs (r < h) closer than d/2 <= 0.1 % (clustering, PF Section 3.2).
 * Measured: seeds 1 / 2 / 3 read 0.9597 / 0.9617 / 0.9604 (floor 0.964); 0.003 % of the pairs
 * closer than d/2; first round (ratio 0.9) at 1.45-1.5 s; 36 s of CPU per seed. A locked drop
 * (theta 0) stays near 0.85.
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "pfsph/eigen.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

typedef struct shape {
    double ratio; /* smallest / largest principal second moment about the centroid */
    double close; /* pairs closer than d/2 / pairs closer than h */
} shape;

static shape measure(const pfsph_ctx *c)
{
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    double m[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) m[0] += f->x[i], m[1] += f->y[i], m[2] += f->z[i];
    for (int a = 0; a < 3; a++) m[a] /= (double)n;
    double C[3][3] = {{0}};
    for (size_t i = 0; i < n; i++) {
        const double q[3] = {f->x[i] - m[0], f->y[i] - m[1], f->z[i] - m[2]};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) C[a][b] += q[a] * q[b];
    }
    shape s;
    if (c->dim == 2) {
        const double C2[2][2] = {{C[0][0], C[0][1]}, {C[0][1], C[1][1]}};
        double w[2], v[2][2];
        pfsph_eigen_sym2(C2, w, v);
        s.ratio = fmin(w[0], w[1]) / fmax(w[0], w[1]);
    } else {
        double w[3], v[3][3];
        pfsph_eigen_sym3(C, w, v);
        s.ratio = fmin(w[0], fmin(w[1], w[2])) / fmax(w[0], fmax(w[1], w[2]));
    }
    const double d = c->spacing, h2 = 4 * d * d, c2 = 0.25 * d * d;
    size_t nh = 0, nc = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            double dx = f->x[i] - f->x[j], dy = f->y[i] - f->y[j], dz = f->z[i] - f->z[j];
            double q = dx * dx + dy * dy + dz * dz;
            nh += q < h2;
            nc += q < c2;
        }
    s.close = nh ? (double)nc / (double)nh : 0;
    return s;
}


typedef struct result {
    double ratio, close; /* averages over the window */
    double cpu;          /* seconds */
} result;

/* One seed: the block runs to t_end, sampled every dt_s (the sample times are part of the scene:
 * the step is an equal division of the interval to the next one); the averages are over the
 * samples after t_end - t_win. */
static result relax(int dim, int nl, int ns, int seed, double t_end, double t_win, double dt_s)
{
    char json[2048];
    const double d = 0.01, a = 0.5 * nl * d, b = 0.5 * ns * d;
    if (dim == 2)
        snprintf(json, sizeof json,
                 "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
                 " \"domain\": {\"min\": [-1, -1], \"max\": [1, 1]},"
                 " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.003}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [%g, %g], \"max\": [%g, %g]}],"
                 " \"pairwise\": {\"thermostat\": {\"reduced_temperature\": 0.01}, \"k\": 1.7,"
                 " \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 4}]}}",
                 seed, -a, -b, a, b);
    else
        snprintf(json, sizeof json,
                 "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": 0.005, \"gravity\": [0, 0, 0],"
                 " \"domain\": {\"min\": [-0.5, -0.5, -0.5], \"max\": [0.5, 0.5, 0.5]},"
                 " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.003}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}],"
                 " \"pairwise\": {\"thermostat\": {\"reduced_temperature\": 0.01}, \"k\": 1.3867,"
                 " \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": 4}]}}",
                 seed, -a, -b, -b, a, b, b);
    pfsph_scene *s = malloc(sizeof *s);
    assert_non_null(s);
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(s, json, "block.json", &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    pfsph_sim *sim = NULL;
    rc = pfsph_sim_create(&sim, s, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    shape st = measure(c);
    assert_true(st.ratio < 0.3); /* 2:1 block: 0.25 */
    result r = {0, 0, 0};
    int navg = 0;
    const int ns_tot = (int)lround(t_end / dt_s);
    const double c0 = ((double)clock() / CLOCKS_PER_SEC);
    for (int i = 1; i <= ns_tot; i++) {
        rc = pfsph_sim_advance(sim, dt_s * i, &err);
        if (rc) print_message("%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        st = measure(c);
        if (dt_s * i > t_end - t_win + 1e-9) {
            r.ratio += st.ratio;
            r.close += st.close;
            navg++;
        }
        if (i % (int)lround(0.5 / dt_s) == 0)
            print_message("  seed %d t = %.2f s: moment ratio %.4f, %.4f %% of pairs closer than d/2\n",
                          seed, pfsph_sim_time(sim), st.ratio, 100 * st.close);
    }
    r.cpu = ((double)clock() / CLOCKS_PER_SEC) - c0;
    r.ratio /= navg;
    r.close /= navg;
    assert_int_equal(pfsph_sim_removed(sim), 0);
    pfsph_sim_destroy(sim);
    free(s);
    return r;
}

static void test_rectangle_to_disc(void **state)
{
    (void)state;
    const int nl = 50, ns = 25;
    const double d = 0.01, sigma = 4, rho = 1000, theta = 0.01;
    const double R = sqrt(nl * ns * d * d / PI); /* disc of the same area */
    /* 2D drop, mode n: omega^2 = n (n^2 - 1) sigma / (rho R^3) (Rayleigh 1879, in the plane) */
    const double T = 2 * PI / sqrt(6 * sigma / (rho * R * R * R));
    /* Thermal floor: equipartition gives each of the two n = 2 amplitudes <a^2> / R^2 =
     * theta d / (3 pi R); the ratio is (1 - 2|a|/R) / (1 + 2|a|/R) with |a| Rayleigh-distributed,
     * mean sqrt(pi/4) of its rms. */
    const double a_mean = sqrt(PI / 4) * sqrt(2 * theta * d / (3 * PI * R));
    const double ratio_floor = (1 - 2 * a_mean) / (1 + 2 * a_mean);
    print_message("R = %.2f d, capillary period T = %.3f s, thermal floor of the ratio %.4f\n",
                  R / d, T, ratio_floor);
#ifdef __SANITIZE_ADDRESS__
    /* the code paths only: a 20 x 10 block for 0.5 s */
    result r = relax(2, 20, 10, 1, 0.5, 0.25, 0.05);
    print_message("ASan: ratio %.4f, close %.5f\n", r.ratio, r.close);
#else
    double mean = 0;
    for (int seed = 1; seed <= 3; seed++) {
        result r = relax(2, nl, ns, seed, 12.65, 2 * T, 0.05);
        print_message("seed %d: over %.2f - %.2f s (two periods) moment ratio %.4f, %.4f %% of "
                      "pairs closer than d/2; %.1f s CPU\n",
                      seed, 12.65 - 2 * T, 12.65, r.ratio, 100 * r.close, r.cpu);
        assert_true(r.ratio >= 0.95);
        assert_true(r.close <= 0.001);
        mean += r.ratio / 3;
    }
    print_message("three seeds: moment ratio %.4f (floor %.4f)\n", mean, ratio_floor);
#endif
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1); /* 1,250 particles: threads only add synchronisation */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_rectangle_to_disc)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
