/* Surface tension of the pair-force liquid at temperature, measured on a free 2D drop
 * (docs/thermostat.md, "Surface tension at temperature"). The calibration tool behind the
 * table of pfsph_pairwise_sigma_factor; not a test.
 *
 *   pf_sigma R_in_spacings [theta=0.01] [t_end=5] [t0=1] [solver=pcisph] [k=1.7] [nu=1e-3]
 *            [seed=1] [raw=0]
 *
 * A lattice disc of radius R (d = 1 cm, sigma target 4 N/m, no gravity) runs to t_end; from t0
 * on, every 0.004 s, the virial tensor of every particle is summed,
 *   Pi_i = m_i u_i (x) u_i + 1/2 sum_j F_ji (x) r_ij     (pair forces with the filter, and the
 *                                                         solver's pressure forces)
 * with u_i the velocity relative to the drop's. The viscous and random forces are left out:
 * their virial averages to zero in a steady state. Estimators, each a time average:
 *   sigma_A = sum_i (Pi_rr - Pi_tt) / (2 pi R_e): the stress anisotropy of the whole drop, which
 *             only the interface carries (Irving-Kirkwood: int (P_N - P_T) dn = sigma over a
 *             perimeter 2 pi R); the isotropic bulk virials (~800 Pa) cancel particle by
 *             particle instead of being differenced. R_e = sqrt(N d^2 / pi).
 *   dp_A    = sum_{r_i > R/2} (Pi_rr - Pi_tt) / (2 pi r_i^2): mechanical equilibrium,
 *             dp = int (P_rr - P_tt) / r dr (the stress-anisotropy route of docs/pairwise.md).
 *   P_in    = mean mechanical pressure (pfsph_sim_mechanical_pressure, the frames' field) of
 *             the particles within R/2 of the centroid.
 *   V_tot   = sum_i tr Pi_i / (dim A): the whole drop's virial pressure. It is zero for an
 *             isolated drop (virial theorem), whatever sigma is: a check, not an estimator.
 * Standard errors from 10 block averages. With raw=1 the samples are printed. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/pairwise.h"
#include "pfsph/sim.h"

static const double PI = 3.14159265358979323846;
#define NB 10

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: pf_sigma R_spacings [theta t_end t0 solver k nu seed raw]\n");
        return 2;
    }
    const double Rs = atof(argv[1]);
    const double theta = argc > 2 ? atof(argv[2]) : 0.01;
    const double t_end = argc > 3 ? atof(argv[3]) : 5.0;
    const double t0 = argc > 4 ? atof(argv[4]) : 1.0;
    const char *solver = argc > 5 ? argv[5] : "pcisph";
    const char *kk = argc > 6 ? argv[6] : "1.7";
    const char *nu = argc > 7 ? argv[7] : "0.001";
    const int seed = argc > 8 ? atoi(argv[8]) : 1;
    const int raw = argc > 9 ? atoi(argv[9]) : 0;
    const int back = getenv("PF_BACK") ? atoi(getenv("PF_BACK")) : 1;
    const double d = 0.01, sigma_t = 4.0;
    omp_set_num_threads(1);
    char json[2048], thermo[128];
    if (theta > 0) snprintf(thermo, sizeof thermo, "\"thermostat\": {\"reduced_temperature\": %g},", theta);
    else snprintf(thermo, sizeof thermo, "\"thermostat\": false,");
    snprintf(json, sizeof json,
             "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": %g, \"gravity\": [0, 0],"
             " \"domain\": {\"min\": [-1, -1], \"max\": [1, 1]},"
             " \"solver\": {\"type\": \"%s\"}, \"time\": {\"dt_max\": 0.002},"
             " \"phases\": [{\"name\": \"water\", \"viscosity\": %s}],"
             " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0], \"radius\": %g}],"
             " \"pairwise\": {%s \"k\": %s, %s \"coefficients\": [{\"phases\": [\"water\", \"water\"],"
             " \"sigma\": %g}]}}",
             seed, 0.5 * d, solver, nu, Rs * d, getenv("PF_PW") ? getenv("PF_PW") : "", kk, thermo, sigma_t);
    static pfsph_scene s;
    pfsph_error err = {0};
    if (pfsph_scene_parse(&s, json, "pf_sigma", &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    pfsph_sim *sim = NULL;
    if (pfsph_sim_create(&sim, &s, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 2;
    }
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *f = c->fluid;
    const size_t n = f->n;
    /* the sigma the coefficients are meant to give (the scene's target) and Eq. 13's value for
     * the coefficient actually used (they differ once a temperature factor is applied) */
    const double rho = c->rest_density[0];
    const double sigma0 = c->pairwise->lambda * c->pairwise->c[0][0] * rho * rho;
    const double Re = sqrt((double)n * d * d / PI), A = (double)n * d * d;
    printf("# R %g d, N %zu, R_e %.4f m, theta %g, %s, k %s, nu %s, seed %d; target sigma %g, "
           "Eq. 13 of c: %.4g N/m, kT %.4g\n",
           Rs, n, Re, theta, solver, kk, nu, seed, sigma_t, sigma0, c->pairwise->thermo.kT_resolved);
    double *vir = malloc(n * sizeof *vir), *W = malloc(9 * n * sizeof *W);
    pfsph_real *pm = malloc(n * sizeof *pm);
    /* PF_EVERY: sample every that many steps (default: every 0.004 s) */
    const int every = getenv("PF_EVERY") ? atoi(getenv("PF_EVERY")) : 0;
    const int ns = every ? 4000000 : (int)lround((t_end - t0) / 0.004);
    double *smp[4];
    for (int q = 0; q < 4; q++) smp[q] = malloc((size_t)(ns + 1) * sizeof(double));
    if (pfsph_sim_advance(sim, t0, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        return 3;
    }
    int m = 0;
    for (int k = 1; k <= ns; k++) {
        if (every) {
            if (pfsph_sim_time(sim) >= t_end - 1e-12) break;
            for (int q = 0; q < every && pfsph_sim_time(sim) < t_end - 1e-9; q++)
                if (pfsph_sim_step(sim, t_end, &err)) {
                    fprintf(stderr, "%s\n", err.msg);
                    return 3;
                }
        } else if (pfsph_sim_advance(sim, t0 + 0.004 * k, &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 3;
        }
        double cx = 0, cy = 0, vx = 0, vy = 0;
        for (size_t i = 0; i < n; i++) cx += f->x[i], cy += f->y[i], vx += f->vx[i], vy += f->vy[i];
        cx /= (double)n, cy /= (double)n, vx /= (double)n, vy /= (double)n;
        pfsph_sim_mechanical_pressure(sim, pm);
        /* the forces of the last step acted at x_n = x_{n+1} - dt v_{n+1} (symplectic Euler):
         * with back = 1 the virials are taken there (the discrete virial theorem:
         * <sum m v_{n+1}^2 + sum x_n . F_n> = 0) */
        pfsph_particles *fw = (pfsph_particles *)f;
        const double dtl = back ? pfsph_sim_stats(sim)->dt : 0;
        for (size_t i = 0; i < n; i++)
            fw->x[i] -= (pfsph_real)(dtl * f->vx[i]), fw->y[i] -= (pfsph_real)(dtl * f->vy[i]);
        pfsph_pairwise_diagnose_tensor(NULL, c, vir, NULL, W);
        const double mass = c->mass[0], h = c->h;
        double an = 0, dp = 0, tr = 0, pin = 0;
        int nin = 0;
        for (size_t i = 0; i < n; i++) {
            double P[2][2];
            const double ux = f->vx[i] - vx, uy = f->vy[i] - vy;
            P[0][0] = mass * ux * ux + 0.5 * W[9 * i + 0];
            P[0][1] = mass * ux * uy + 0.5 * W[9 * i + 1];
            P[1][0] = mass * uy * ux + 0.5 * W[9 * i + 3];
            P[1][1] = mass * uy * uy + 0.5 * W[9 * i + 4];
            /* the solver's pressure force on i from j, -(p_i/n_i^2 + p_j/n_j^2) grad W_ij
             * (number-density form), as F (x) r */
            const double pi = f->p[i] / ((double)c->nd[i] * c->nd[i]);
            for (size_t j = 0; j < n; j++) {
                if (j == i) continue;
                const double dx = f->x[i] - f->x[j], dy = f->y[i] - f->y[j], r2 = dx * dx + dy * dy;
                if (r2 >= h * h) continue;
                const double r = sqrt(r2);
                const double g =
                    -(pi + f->p[j] / ((double)c->nd[j] * c->nd[j])) * pfsph_kernel_dw_r(&c->kern, (pfsph_real)r);
                P[0][0] += 0.5 * g * dx * dx;
                P[0][1] += 0.5 * g * dx * dy;
                P[1][0] += 0.5 * g * dy * dx;
                P[1][1] += 0.5 * g * dy * dy;
            }
            const double rx = f->x[i] - cx, ry = f->y[i] - cy, rr = hypot(rx, ry);
            tr += P[0][0] + P[1][1];
            if (rr > 0.5 * d) {
                const double er[2] = {rx / rr, ry / rr}, et[2] = {-ry / rr, rx / rr};
                double prr = 0, ptt = 0;
                for (int a = 0; a < 2; a++)
                    for (int b = 0; b < 2; b++) {
                        prr += er[a] * P[a][b] * er[b];
                        ptt += et[a] * P[a][b] * et[b];
                    }
                an += prr - ptt;
                if (rr > 0.5 * Re) dp += (prr - ptt) / (2 * PI * rr * rr);
            }
            if (rr < 0.5 * Re) pin += pm[i], nin++;
        }
        for (size_t i = 0; i < n; i++)
            fw->x[i] += (pfsph_real)(dtl * f->vx[i]), fw->y[i] += (pfsph_real)(dtl * f->vy[i]);
        smp[0][m] = an / (2 * PI * Re);
        smp[1][m] = dp;
        smp[2][m] = nin ? pin / nin : 0;
        smp[3][m] = tr / (2 * A);
        if (raw) printf("%.4f %.4f %.4f %.4f %.4f\n", pfsph_sim_time(sim), smp[0][m], smp[1][m], smp[2][m], smp[3][m]);
        m++;
    }
    const char *nm[4] = {"sigma_A [N/m]", "dp_A [Pa]", "P_in [Pa]", "V_tot [Pa]"};
    const double ref[4] = {sigma_t, sigma_t / Re, sigma_t / Re, 0};
    for (int q = 0; q < 4; q++) {
        double bm[NB], mean = 0;
        const int bl = m / NB;
        for (int b = 0; b < NB; b++) {
            bm[b] = 0;
            for (int i = b * bl; i < (b + 1) * bl; i++) bm[b] += smp[q][i];
            bm[b] /= bl;
            mean += bm[b] / NB;
        }
        double var = 0;
        for (int b = 0; b < NB; b++) var += (bm[b] - mean) * (bm[b] - mean);
        const double se = sqrt(var / (NB - 1) / NB);
        printf("%-14s %9.4f +- %7.4f  (target %8.4f: ratio %.3f +- %.3f)\n", nm[q], mean, se, ref[q],
               ref[q] != 0 ? mean / ref[q] : 0, ref[q] != 0 ? se / ref[q] : 0);
    }
    printf("# steps %llu\n", (unsigned long long)pfsph_sim_steps(sim));
    pfsph_sim_destroy(sim);
    return 0;
}
