/* Surface tension from pair forces alone (PF Fig. 1c, "configuration reached from a cube") at
 * the thermostat's default temperature: a 2:1:1 box of liquid (20 x 10 x 10 particles, 3D, no
 * gravity) becomes a sphere. A cube's second moments are isotropic from the start, hence the
 * elongated box (moment ratio 0.25 at the start).
 * Scene, and why: the paper's k (Eq. 5 was written for 3D); sigma 4 N/m and nu 3e-3 m^2/s as in
 * the 2D test (Ohnesorge number 0.17: an underdamped drop); theta 0.01, the default; lattice
 * start; DFSPH, the cheapest solver for a free drop (docs/thermostat.md).
 * Size: equipartition of the five l = 2 modes (<a_m^2> = theta d^2 / (4 R^2)) puts the mean
 * ratio at 0.964 for 1,024 particles and 0.971 for 2,000 (R = 7.82 d). At 1,024 (16 x 8 x 8)
 * the seeds read 0.951 / 0.933 / 0.955 over the same window: too close to 0.95.
 * Criteria (issue 11): Rayleigh's omega_l^2 = l (l - 1)(l + 2) sigma / (rho R^3) gives the l = 2
 * period T = 0.767 s. Each of three seeds runs to 3 s (3.9 T), sampled every 0.025 s; over the
 * last 2 T the mean moment ratio must be >= 0.95 and the mean fraction of kernel-neighbour pairs
 * (r < h) closer than d/2 <= 0.1 % (clustering, PF Section 3.2).
 * Measured with the 3D tension factor 0.935 (issue 11, 2026-12-02): seeds 1 / 2 / 3 read
 * 0.9601 / 0.9591 / 0.9574 (floor 0.971); 0.013-0.017 % of the pairs closer than d/2; 47-51 s of
 * CPU per seed. Before that factor (Eq. 13 alone, 7 % stiffer): 0.9561 / 0.9614 / 0.9696,
 * 0.015-0.019 %; first round (ratio 0.9) at 0.53-0.57 s.
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

static void test_box_to_sphere(void **state)
{
    (void)state;
    const int nl = 20, ns = 10;
    const double d = 0.01, sigma = 4, rho = 1000;
    const double R = cbrt(3.0 * nl * ns * ns * d * d * d / (4 * PI)); /* sphere of the same volume */
    /* Rayleigh (1879): omega_l^2 = l (l - 1) (l + 2) sigma / (rho R^3), l = 2 */
    const double T = 2 * PI / sqrt(8 * sigma / (rho * R * R * R));
    print_message("R = %.2f d, capillary period T = %.3f s\n", R / d, T);
#ifdef __SANITIZE_ADDRESS__
    /* the code paths only: an 8 x 4 x 4 block for 0.1 s */
    result r = relax(3, 8, 4, 1, 0.1, 0.05, 0.025);
    print_message("ASan: ratio %.4f, close %.5f\n", r.ratio, r.close);
#else
    double mean = 0;
    for (int seed = 1; seed <= 3; seed++) {
        result r = relax(3, nl, ns, seed, 3.0, 2 * T, 0.025);
        print_message("seed %d: over %.2f - %.2f s (two periods) moment ratio %.4f, %.4f %% of "
                      "pairs closer than d/2; %.1f s CPU\n",
                      seed, 3.0 - 2 * T, 3.0, r.ratio, 100 * r.close, r.cpu);
        assert_true(r.ratio >= 0.95);
        assert_true(r.close <= 0.001);
        mean += r.ratio / 3;
    }
    print_message("three seeds: moment ratio %.4f (floor 0.971)\n", mean);
#endif
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    omp_set_num_threads(1); /* 2,000 particles: threads only add synchronisation */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_box_to_sphere)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
