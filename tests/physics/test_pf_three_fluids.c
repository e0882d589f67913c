/* Three immiscible fluids (PF paper, Section 4.1.2, Fig. 4 b, c, d), 2D, no gravity, in air
 * (nothing simulated around them). Three 10 x 20 d blocks of 200 particles start side by side,
 * every pair touching (fluid 1 on the left, fluid 2 top right, fluid 3 bottom right). After
 * settling, which phases touch is read from unlike-phase neighbours: n_ab = the number of
 * particles of phase a with at least one particle of phase b closer than h.
 *
 * Expected configurations from Eq. 13 with the air as a fourth phase (c_air = 0):
 * sigma_aa' = lambda rho^2 c_aa (against air), sigma_ab = lambda rho^2 (c_aa + c_bb - 2 c_ab), the
 * work of adhesion W_ab = sigma_a + sigma_b - sigma_ab = 2 lambda rho^2 c_ab, and the spreading
 * coefficient of a over b, S = sigma_b - sigma_a - sigma_ab (units of lambda rho^2 below, the
 * coefficients are the paper's x 1e-3; its absolute scale is unstated):
 *  b: c11 6, c22 10, c33 12, c12 = c23 = 0, c13 2. W_12 = W_23 = 0: nothing holds fluid 2 to the
 *     others, it detaches; W_13 > 0 with S < 0 both ways (-8, -20): 1 and 3 sit side by side on a
 *     partial interface. (The paper's "all three stay in contact" is the Neumann-triangle
 *     argument of Eq. 17, which holds without air; with air a zero cross coefficient means no
 *     adhesion.)
 *  c: c11 10, c22 8, c33 14, c12 = c23 = 6, c13 0. sigma_13 = 24 > sigma_12 + sigma_23 = 6 + 10
 *     (Eq. 17 violated): fluid 2 goes between 1 and 3, which lose contact; S(2 over 1) =
 *     S(2 over 3) = -4 < 0, so the 1-2 and 2-3 interfaces are partial.
 *  d: c11 6, c22 14, c33 14, c12 = c13 = 6, c23 0. sigma_23 = 28 > 8 + 8: fluid 1 goes between 2
 *     and 3, which lose contact (S(1 over 2) = S(1 over 3) = 0: 1 is on the edge of enclosing them).
 * Pass: at t = 2.5, 2.75 and 3 s (the separations are complete by 2 s, measured), a pair that
 * must separate has n_ab = n_ba = 0 (no particle within h of the other phase: at the start every
 * pair has 10-20), and a pair that must touch has n_ab, n_ba >= 5, an interface at least about
 * 5 spacings long (two round drops touching at a point give 1-3). No particle is lost. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/sim.h"
#include "testutil.h"

static const char *SCENE =
    "{\"dimension\": 2, \"particle_radius\": 0.005, \"gravity\": [0, 0],"
    " \"domain\": {\"min\": [-0.5, -0.5], \"max\": [0.5, 0.5]},"
    " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"end\": 3, \"fps\": 25, \"dt_max\": 0.002},"
    " \"phases\": [{\"name\": \"f1\", \"rest_density\": 1000, \"viscosity\": 0.003},"
    "   {\"name\": \"f2\", \"rest_density\": 1000, \"viscosity\": 0.003},"
    "   {\"name\": \"f3\", \"rest_density\": 1000, \"viscosity\": 0.003}],"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [-0.1, -0.1], \"max\": [0, 0.1], \"phase\": \"f1\"},"
    "   {\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.2, 0.1], \"phase\": \"f2\"},"
    "   {\"shape\": \"box\", \"min\": [0, -0.1], \"max\": [0.2, 0], \"phase\": \"f3\"}],"
    " \"pairwise\": {\"k\": 1.7, \"coefficients\": ["
    "   {\"phases\": [\"f1\", \"f1\"], \"c\": %g}, {\"phases\": [\"f2\", \"f2\"], \"c\": %g},"
    "   {\"phases\": [\"f3\", \"f3\"], \"c\": %g}, {\"phases\": [\"f1\", \"f2\"], \"c\": %g},"
    "   {\"phases\": [\"f2\", \"f3\"], \"c\": %g}, {\"phases\": [\"f1\", \"f3\"], \"c\": %g}]}}";

enum { TOUCH = 1, APART = 0 };

/* n[a][b]: particles of phase a with a particle of phase b != a closer than h. */
static void contacts(const pfsph_ctx *c, int n[3][3])
{
    const pfsph_particles *f = c->fluid;
    const double h2 = (double)c->h * (double)c->h;
    memset(n, 0, 9 * sizeof(int));
    for (size_t i = 0; i < f->n; i++) {
        int seen[3] = {0, 0, 0};
        for (size_t j = 0; j < f->n; j++) {
            if (f->phase[j] == f->phase[i]) continue;
            double dx = (double)f->x[i] - f->x[j], dy = (double)f->y[i] - f->y[j];
            if (dx * dx + dy * dy < h2) seen[f->phase[j]] = 1;
        }
        for (int b = 0; b < 3; b++) n[f->phase[i]][b] += seen[b];
    }
}

/* c = {c11, c22, c33, c12, c23, c13}; want = {12, 23, 13} as TOUCH / APART */
static void run_case(const char *name, const double cf[6], const int want[3])
{
    char json[4096];
    snprintf(json, sizeof json, SCENE, cf[0], cf[1], cf[2], cf[3], cf[4], cf[5]);
    pfsph_sim *sim = tu_sim_from_json(json, name);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const size_t n0 = c->fluid->n;
    assert_int_equal(n0, 600);
    int n[3][3];
    contacts(c, n);
    printf("%s: start n12 %d n21 %d n23 %d n32 %d n13 %d n31 %d\n", name, n[0][1], n[1][0], n[1][2], n[2][1], n[0][2],
           n[2][0]);
    const int pa[3] = {0, 1, 0}, pb[3] = {1, 2, 2};
    const char *pname[3] = {"1-2", "2-3", "1-3"};
    int ok = 1;
    for (int k = 0; k < 3; k++) {
        double t = 2.5 + 0.25 * k;
        tu_advance(sim, t);
        assert_int_equal(c->fluid->n, n0);
        contacts(c, n);
        printf("%s t=%.2f s:", name, t);
        for (int q = 0; q < 3; q++) {
            int ab = n[pa[q]][pb[q]], ba = n[pb[q]][pa[q]];
            int pass = want[q] == TOUCH ? (ab >= 5 && ba >= 5) : (ab == 0 && ba == 0);
            printf("  %s %s: %d/%d (%.3f/%.3f)%s", pname[q], want[q] == TOUCH ? "touch" : "apart", ab, ba, ab / 200.0,
                   ba / 200.0, pass ? "" : " FAIL");
            ok &= pass;
        }
        printf("  vmax %.3f m/s\n", pfsph_sim_stats(sim)->vmax);
    }
    fflush(stdout);
    pfsph_sim_destroy(sim);
    assert_true(ok);
}

/* Fig. 4b: 1 and 3 side by side, 2 detached (no adhesion to either) */
static void test_fig4b(void **state)
{
    (void)state;
    const double cf[6] = {6, 10, 12, 0, 0, 2};
    const int want[3] = {APART, APART, TOUCH};
    run_case("fig4b", cf, want);
}

/* Fig. 4c (caption's coefficients): 2 between 1 and 3 */
static void test_fig4c(void **state)
{
    (void)state;
    const double cf[6] = {10, 8, 14, 6, 6, 0};
    const int want[3] = {TOUCH, TOUCH, APART};
    run_case("fig4c", cf, want);
}

/* Fig. 4d (caption's coefficients): 1 between 2 and 3 */
static void test_fig4d(void **state)
{
    (void)state;
    const double cf[6] = {6, 14, 14, 6, 0, 6};
    const int want[3] = {TOUCH, APART, TOUCH};
    run_case("fig4d", cf, want);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
#ifdef __SANITIZE_ADDRESS__
    /* The sanitizer build (CI's asan preset, ~4x slower) runs one case: the three share every
     * code path, and the physics is checked by the release run. */
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fig4c)};
    (void)test_fig4b;
    (void)test_fig4d;
#else
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fig4b), cmocka_unit_test(test_fig4c),
                                       cmocka_unit_test(test_fig4d)};
#endif
    return tu_run_group(tests, NULL, NULL);
}
