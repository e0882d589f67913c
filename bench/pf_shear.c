/* Bulk shear viscosity of the pair-force liquid, wall-free (docs/viscosity.md); the study tool
 * behind the viscosity table, not a test.
 *
 *   pf_shear dim H [nu=1e-3] [t_end=2] [seed=1] [d=0.01] [sigma=4] [A=0.1] [solver=dfsph]
 *
 * A free slab of liquid, no walls and no gravity: H particles thick (y), 3 H long (x) and, in 3D,
 * H / 2 deep (z). It melts at rest for PF_TEQ seconds (default 0.3), then gets the shear mode
 *     u_x = A cos(2 pi y / H),
 * whose shear stress vanishes on the slab's two free faces (y = 0, H) and, in 3D, on its z faces:
 * in an infinite slab an exact Navier-Stokes solution decaying as exp(-nu (2 pi / H)^2 t). The
 * slab's ends (x = 0, 3 H) are free too; they round and retract, so the amplitude (least-squares
 * projection of u_x on the mode) is read only from the middle third in x, H or more from either
 * end. Every 0.02 s (PF_DTS) it prints t and the amplitude; at the end the least-squares fit of ln a from
 * PF_T0 (0.1 s) until a < PF_ASTOP A (default 0.3) and nu_eff = rate / k^2. The thermostat's default
 * temperature; k 1.7 in 2D, Eq. 5's in 3D (the scenes'). PF_PW adds pairwise keys, PF_K sets k. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_util.h"
#include "pfsph/sim.h"
#include "pfsph/thermostat.h"

#define PI 3.14159265358979323846

/* amplitude of u_x on cos(kw (y - y0)) over the particles with |x - xc| < W / 6 */
static double amplitude(const pfsph_ctx *c, double xc, double W, double y0, double kw)
{
    const pfsph_particles *f = c->fluid;
    double num = 0, den = 0;
    for (size_t i = 0; i < f->n; i++) {
        if (fabs(f->x[i] - xc) > W / 6) continue;
        const double m = cos(kw * (f->y[i] - y0));
        num += f->vx[i] * m;
        den += m * m;
    }
    return den > 0 ? num / den : 0;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: pf_shear dim H [nu t_end seed d sigma A solver]\n");
        return 2;
    }
    const int dim = atoi(argv[1]), n = atoi(argv[2]);
    const char *nu = argc > 3 ? argv[3] : "0.001";
    const double t_end = argc > 4 ? atof(argv[4]) : 2;
    const int seed = argc > 5 ? atoi(argv[5]) : 1;
    const double d = argc > 6 ? atof(argv[6]) : 0.01;
    const char *sig = argc > 7 ? argv[7] : "4";
    const double A = argc > 8 ? atof(argv[8]) : 0.1;
    const char *solver = argc > 9 ? argv[9] : "dfsph";
    const double astop = getenv("PF_ASTOP") ? atof(getenv("PF_ASTOP")) : 0.3;
    const double teq = getenv("PF_TEQ") ? atof(getenv("PF_TEQ")) : 0.3;
    const char *pwx = getenv("PF_PW") ? getenv("PF_PW") : "";
    char kkey[64] = "";
    if (getenv("PF_K")) snprintf(kkey, sizeof kkey, "\"k\": %s,", getenv("PF_K"));
    else if (dim == 2) snprintf(kkey, sizeof kkey, "\"k\": 1.7,");
    omp_set_num_threads(getenv("PF_THREADS") ? atoi(getenv("PF_THREADS")) : 1);
    const double H = n * d, W = 3 * H, Z = dim == 3 ? (n / 2) * d : 0, m = 0.5 * H;
    char json[8192];
    if (dim == 2)
        snprintf(json, sizeof json,
                 "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": %.10g, \"gravity\": [0, 0],"
                 " \"domain\": {\"min\": [%g, %g], \"max\": [%g, %g]},"
                 " \"solver\": {\"type\": \"%s\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": %s}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [%.10g, %.10g], \"phase\": \"water\"}],"
                 " \"pairwise\": {%s %s \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": %s}]}}",
                 seed, 0.5 * d, -m, -m, W + m, H + m, solver, nu, W, H, kkey, pwx, sig);
    else
        snprintf(json, sizeof json,
                 "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": %.10g, \"gravity\": [0, 0, 0],"
                 " \"domain\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]},"
                 " \"solver\": {\"type\": \"%s\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": %s}],"
                 " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [%.10g, %.10g, %.10g], \"phase\": "
                 "\"water\"}],"
                 " \"pairwise\": {%s %s \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": %s}]}}",
                 seed, 0.5 * d, -m, -m, -m, W + m, H + m, Z + m, solver, nu, W, H, Z, kkey, pwx, sig);
    pfsph_sim *sim = bench_sim_from_json(json, "pf_shear");
    if (!sim) return 2;
    pfsph_error err = {0};
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    pfsph_particles *f = c->fluid;
    if (teq > 0 && pfsph_sim_advance(sim, teq, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    const double kw = 2 * PI / H;
    double y0 = 0, xc = 0;
    for (size_t i = 0; i < f->n; i++) xc += f->x[i], y0 += f->y[i];
    xc /= (double)f->n;
    y0 = y0 / (double)f->n - 0.5 * H;
    for (size_t i = 0; i < f->n; i++) f->vx[i] += (pfsph_real)(A * cos(kw * (f->y[i] - y0)));
    printf("# n %zu H %g kT %g a0 %.5f\n", f->n, H, pfsph_thermostat_kT(c), amplitude(c, xc, W, y0, kw));
    const double dts = getenv("PF_DTS") ? atof(getenv("PF_DTS")) : 0.02,
                 t0 = getenv("PF_T0") ? atof(getenv("PF_T0")) : 0.1;
    const int nsamp = (int)lround(t_end / dts);
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int nfit = 0, stopped = 0;
    const clock_t c0 = clock();
    for (int i = 1; i <= nsamp && !stopped; i++) {
        if (pfsph_sim_advance(sim, teq + dts * i, &err) != PFSPH_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        const double a = amplitude(c, xc, W, y0, kw), t = pfsph_sim_time(sim) - teq;
        printf("%.3f %.6f\n", t, a);
        if (t >= t0) {
            if (a > astop * A) {
                sx += t, sy += log(a), sxx += t * t, sxy += t * log(a);
                nfit++;
            } else stopped = 1;
        }
    }
    const double slope = (nfit * sxy - sx * sy) / (nfit * sxx - sx * sx);
    const double rate = -slope, nu_eff = rate / (kw * kw);
    printf("# fit n %d rate %.4f nu_eff %.5g nu_set %s nu_morris %g\n", nfit, rate, nu_eff, nu, (double)c->nu[0]);
    printf("# cpu %.1f s, steps %llu\n", (double)(clock() - c0) / CLOCKS_PER_SEC,
           (unsigned long long)pfsph_sim_steps(sim));
    pfsph_sim_destroy(sim);
    return 0;
}
