/* Surface tension from pairwise forces alone in 3D (PF Fig. 1c, "configuration reached from a
 * cube"): a 2:1:1 box of liquid without gravity becomes a sphere. A cube's second moments are
 * already isotropic, so the box is elongated: the ratio of the smallest to the largest principal
 * second moment is 0.25 at the start and must reach >= 0.95; no two particles closer than half
 * the spacing at any sampled time (no clustering, PF Section 3.2). Paper's k (Eq. 5 was written
 * for 3D: about 30 SPH neighbours within h = 2 d, about 80 within k h).
 * Exploration knobs: PF_K, PF_NU, PF_SIG, PF_T (end time [s]), PF_N (particles along the short
 * side), PF_PW (extra keys for the pairwise block), PF_SOLVER, PF_TH (threads). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "pfsph/eigen.h"
#include "pfsph/sim.h"
#include "testutil.h"

typedef struct shape_stats {
    double ratio; /* smallest / largest principal second moment about the centroid */
    double dmin;  /* smallest particle distance [m] */
} shape_stats;

static shape_stats measure(const pfsph_ctx *c)
{
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    double m[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        m[0] += f->x[i];
        m[1] += f->y[i];
        m[2] += f->z[i];
    }
    for (int a = 0; a < 3; a++) m[a] /= (double)n;
    double C[3][3] = {{0}};
    for (size_t i = 0; i < n; i++) {
        const double q[3] = {f->x[i] - m[0], f->y[i] - m[1], f->z[i] - m[2]};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) C[a][b] += q[a] * q[b];
    }
    double w[3], v[3][3];
    pfsph_eigen_sym3(C, w, v);
    double lo = fmin(w[0], fmin(w[1], w[2])), hi = fmax(w[0], fmax(w[1], w[2]));
    shape_stats s;
    s.ratio = lo / hi;
    double d2 = 1e300;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            double dx = f->x[i] - f->x[j], dy = f->y[i] - f->y[j], dz = f->z[i] - f->z[j];
            d2 = fmin(d2, dx * dx + dy * dy + dz * dz);
        }
    s.dmin = sqrt(d2);
    return s;
}

static void test_box_to_sphere(void **state)
{
    (void)state;
    omp_set_num_threads(getenv("PF_TH") ? atoi(getenv("PF_TH")) : 1);
    const int N = getenv("PF_N") ? atoi(getenv("PF_N")) : 8;
    const double d = 0.01, a = 0.5 * N * d; /* half the short side */
    char json[2048];
    snprintf(json, sizeof json,
        "{\"dimension\": 3, \"particle_radius\": 0.005, \"gravity\": [0, 0, 0],"
        " \"domain\": {\"min\": [-0.3, -0.3, -0.3], \"max\": [0.3, 0.3, 0.3]},"
        " \"solver\": {\"type\": \"%s\"}, \"time\": {\"dt_max\": 0.002},"
        " \"phases\": [{\"name\": \"water\", \"viscosity\": %s}],"
        " \"fluid\": [{\"shape\": \"box\", \"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}],"
        " \"pairwise\": {%s \"k\": %s, \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": %s}]}}",
        getenv("PF_SOLVER") ? getenv("PF_SOLVER") : "pcisph", getenv("PF_NU") ? getenv("PF_NU") : "0.003",
        -2 * a, -a, -a, 2 * a, a, a, getenv("PF_PW") ? getenv("PF_PW") : "",
        getenv("PF_K") ? getenv("PF_K") : "1.3867", getenv("PF_SIG") ? getenv("PF_SIG") : "4");
    pfsph_scene *s = malloc(sizeof *s);
    pfsph_error err = {0};
    int rc = pfsph_scene_parse(s, json, "box3d.json", &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    pfsph_sim *sim = NULL;
    rc = pfsph_sim_create(&sim, s, &err);
    if (rc) print_message("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    shape_stats st = measure(c);
    print_message("n = %zu; t = 0: moment ratio %.3f\n", c->fluid->n, st.ratio);
    assert_true(st.ratio < 0.3);
    double dmin = st.dmin;
    const int nk = (int)lround(4 * (getenv("PF_T") ? atof(getenv("PF_T")) : 2.0));
    for (int k = 1; k <= nk; k++) {
        rc = pfsph_sim_advance(sim, 0.25 * k, &err);
        if (rc) print_message("%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        st = measure(c);
        dmin = fmin(dmin, st.dmin);
        print_message("t = %.2f s: moment ratio %.4f, closest pair %.3f d, ekin %.3g J\n",
                      pfsph_sim_time(sim), st.ratio, st.dmin / d, pfsph_sim_stats(sim)->ekin);
    }
    assert_int_equal(pfsph_sim_removed(sim), 0);
    assert_true(st.ratio >= 0.95);
    assert_true(dmin >= 0.5 * d);
    pfsph_sim_destroy(sim);
    free(s);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_box_to_sphere)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
