/* Effective shear viscosity of a box of liquid (docs/thermostat.md, "The structural viscosity");
 * the study tool behind the viscosity table, not a test.
 *
 *   pf_visc n [theta=0.01] [nu=1e-3] [sigma=4] [t_end=3] [solver=dfsph] [seed=1] [d=0.01]
 *           [rho=1000] [k=1.7] [A=0.1] [angle=90] [dim=2] [nz=6]
 *
 * theta < 0: no pair forces at all; theta 0: pair forces, thermostat off.
 * A square box of n x n particles (side L = n d; 3D: n x n x nz, the mode uniform in z) is filled
 * with one liquid between free-slip walls (3 layers), no gravity. The fluid starts in the lowest
 * Taylor-Green mode of the box,
 *     u = A sin(pi x / L) cos(pi y / L),  v = -A cos(pi x / L) sin(pi y / L),
 * which meets free slip on all four walls and solves the Navier-Stokes equations exactly (its
 * vorticity is proportional to its stream function), so its amplitude decays as
 * exp(-2 nu (pi / L)^2 t) at any amplitude. Every 0.02 s it prints t, the amplitude a (least
 * squares projection of the particle velocities on the mode at their current positions) and the
 * kinetic temperature of the rest of the motion over kT. At the end: the least-squares fit of ln a
 * over the samples with a > a_stop (PF_ASTOP, default 0.25 A) from t0 = 0.1 s, the rate, and
 * nu_eff = rate L^2 / (2 pi^2). PF_TEQ: seconds at rest before the mode is added (times are
 * counted from then). PF_PW adds pairwise keys, PF_VX phase keys. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_util.h"
#include "pfsph/sim.h"
#include "pfsph/thermostat.h"

#define PI 3.14159265358979323846

static double L_box;

static void mode(double x, double y, double *u, double *v)
{
    const double kx = PI * x / L_box, ky = PI * y / L_box;
    *u = sin(kx) * cos(ky);
    *v = -cos(kx) * sin(ky);
}

/* amplitude and kinetic temperature (per degree of freedom, J) of the residual motion */
static void measure(const pfsph_ctx *c, double *amp, double *kin)
{
    const pfsph_particles *f = c->fluid;
    double num = 0, den = 0;
    for (size_t i = 0; i < f->n; i++) {
        double u, v;
        mode(f->x[i], f->y[i], &u, &v);
        num += f->vx[i] * u + f->vy[i] * v;
        den += u * u + v * v;
    }
    const double a = num / den;
    double e = 0;
    for (size_t i = 0; i < f->n; i++) {
        double u, v;
        mode(f->x[i], f->y[i], &u, &v);
        const double du = f->vx[i] - a * u, dv = f->vy[i] - a * v, dw = c->dim == 3 ? f->vz[i] : 0;
        e += (double)c->mass[f->phase[i]] * (du * du + dv * dv + dw * dw);
    }
    *amp = a;
    *kin = e / (c->dim * (double)f->n);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: pf_visc n [theta nu sigma t_end solver seed d rho k A angle dim nz]\n");
        return 2;
    }
    const int n = atoi(argv[1]);
    const double theta = argc > 2 ? atof(argv[2]) : 0.01;
    const char *nu = argc > 3 ? argv[3] : "0.001";
    const char *sig = argc > 4 ? argv[4] : "4";
    const double t_end = argc > 5 ? atof(argv[5]) : 3;
    const char *solver = argc > 6 ? argv[6] : "dfsph";
    const int seed = argc > 7 ? atoi(argv[7]) : 1;
    const double d = argc > 8 ? atof(argv[8]) : 0.01;
    const char *rho = argc > 9 ? argv[9] : "1000";
    const char *k = argc > 10 ? argv[10] : "1.7";
    const double A = argc > 11 ? atof(argv[11]) : 0.1;
    const char *angle = argc > 12 ? argv[12] : "90";
    const int dim = argc > 13 ? atoi(argv[13]) : 2;
    const int nz = argc > 14 ? atoi(argv[14]) : 6;
    const double astop = getenv("PF_ASTOP") ? atof(getenv("PF_ASTOP")) : 0.25;
    omp_set_num_threads(1);
    const double L = n * d, Z = nz * d, w = 3 * d;
    L_box = L;
    char pw[1024], json[8192];
    if (theta < 0) snprintf(pw, sizeof pw, " ");
    else
        snprintf(pw, sizeof pw,
                 ", \"pairwise\": {%s \"thermostat\": %s, \"k\": %s, \"coefficients\": ["
                 "{\"phases\": [\"water\", \"water\"], \"sigma\": %s},"
                 "{\"phases\": [\"water\", \"wall\"], \"contact_angle\": %s}]}",
                 getenv("PF_PW") ? getenv("PF_PW") : "", theta > 0 ? "{\"reduced_temperature\": 0}" : "false", k, sig,
                 angle);
    if (theta > 0) { /* put theta in */
        char tmp[1024];
        snprintf(tmp, sizeof tmp,
                 ", \"pairwise\": {%s \"thermostat\": {\"reduced_temperature\": %g}, \"k\": %s, "
                 "\"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": %s},"
                 "{\"phases\": [\"water\", \"wall\"], \"contact_angle\": %s}]}",
                 getenv("PF_PW") ? getenv("PF_PW") : "", theta, k, sig, angle);
        snprintf(pw, sizeof pw, "%s", tmp);
    }
    const char *vx = getenv("PF_VX") ? getenv("PF_VX") : "";
    if (dim == 2)
        snprintf(json, sizeof json,
                 "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": %.10g, \"gravity\": [0, 0],"
                 " \"domain\": {\"min\": [%g, %g], \"max\": [%g, %g]},"
                 " \"solver\": {\"type\": \"%s\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"rest_density\": %s, \"viscosity\": %s %s},"
                 "   {\"name\": \"wall\", \"kind\": \"solid\"}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [%.10g, %.10g], \"phase\": \"water\"}],"
                 " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [%.10g, %.10g],"
                 " \"layers\": 3, \"slip\": \"free-slip\"}] %s}",
                 seed, 0.5 * d, -2 * w, -2 * w, L + 2 * w, L + 2 * w, solver, rho, nu, vx, L, L, L, L, pw);
    else
        snprintf(json, sizeof json,
                 "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": %.10g, \"gravity\": [0, 0, 0],"
                 " \"domain\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]},"
                 " \"solver\": {\"type\": \"%s\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"rest_density\": %s, \"viscosity\": %s %s},"
                 "   {\"name\": \"wall\", \"kind\": \"solid\"}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [%.10g, %.10g, %.10g], \"phase\": "
                 "\"water\"}],"
                 " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [%.10g, %.10g, %.10g],"
                 " \"layers\": 3, \"slip\": \"free-slip\"}] %s}",
                 seed, 0.5 * d, -2 * w, -2 * w, -2 * w, L + 2 * w, L + 2 * w, Z + 2 * w, solver, rho, nu, vx, L, L, Z,
                 L, L, Z, pw);
    pfsph_sim *sim = bench_sim_from_json(json, "pf_visc");
    if (!sim) return 2;
    pfsph_error err = {0};
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    pfsph_particles *f = c->fluid;
    /* melt the lattice at rest first (PF_TEQ seconds), then add the mode to the thermal motion */
    const double teq = getenv("PF_TEQ") ? atof(getenv("PF_TEQ")) : 0;
    if (teq > 0 && pfsph_sim_advance(sim, teq, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    for (size_t i = 0; i < f->n; i++) {
        double u, v;
        mode(f->x[i], f->y[i], &u, &v);
        f->vx[i] += (pfsph_real)(A * u);
        f->vy[i] += (pfsph_real)(A * v);
    }
    const double kT = pfsph_thermostat_kT(c);
    printf("# n %zu L %g kT %g\n", f->n, L, kT);
    const double dts = 0.02, t0 = 0.1;
    const int nsamp = (int)lround(t_end / dts);
    double sx = 0, sy = 0, sxx = 0, sxy = 0, tk = 0;
    int nfit = 0, ntk = 0, stopped = 0;
    const clock_t c0 = clock();
    for (int i = 1; i <= nsamp; i++) {
        if (pfsph_sim_advance(sim, teq + dts * i, &err) != PFSPH_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        double a, kin;
        measure(c, &a, &kin);
        const double t = pfsph_sim_time(sim) - teq;
        printf("%.3f %.6f %.4g\n", t, a, kT > 0 ? kin / kT : kin / (0.5 * (double)c->mass[0] * A * A));
        if (t >= t0 && !stopped) {
            if (a > astop * A) {
                sx += t, sy += log(a), sxx += t * t, sxy += t * log(a);
                nfit++;
            } else stopped = 1;
        }
        if (t >= t0) tk += kin, ntk++;
    }
    const double slope = (nfit * sxy - sx * sy) / (nfit * sxx - sx * sx);
    const double rate = -slope, nu_eff = rate * L * L / (2 * PI * PI);
    printf("# fit n %d rate %.4f nu_eff %.5g nu_set %s kin/kT %.3f\n", nfit, rate, nu_eff, nu,
           kT > 0 ? tk / ntk / kT : tk / ntk);
    printf("# cpu %.1f s, steps %llu, removed %zu\n", (double)(clock() - c0) / CLOCKS_PER_SEC,
           (unsigned long long)pfsph_sim_steps(sim), pfsph_sim_removed(sim));
    pfsph_sim_destroy(sim);
    return 0;
}
