/* The oscillating drop: a free drop's l = 2 mode against Rayleigh and Lamb (pf_drop.h). */
#include "pf_drop.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pfsph/io.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

/* deformation of the fluid about its centroid (pf_drop.h), and with v its rate of change */
static double deformation(const pfsph_ctx *c, double *rate)
{
    const pfsph_particles *f = c->fluid;
    double m[3] = {0, 0, 0};
    for (size_t i = 0; i < f->n; i++) m[0] += f->x[i], m[1] += f->y[i], m[2] += f->z[i];
    for (int a = 0; a < 3; a++) m[a] /= (double)f->n;
    double I[3] = {0, 0, 0}, dI[3] = {0, 0, 0};
    for (size_t i = 0; i < f->n; i++) {
        const double q[3] = {f->x[i] - m[0], f->y[i] - m[1], f->z[i] - m[2]};
        const double v[3] = {f->vx[i], f->vy[i], f->vz[i]};
        for (int a = 0; a < 3; a++) I[a] += q[a] * q[a], dI[a] += 2 * q[a] * v[a];
    }
    double num, den, dnum, dden;
    if (c->dim == 2) {
        num = I[0] - I[1], den = I[0] + I[1], dnum = dI[0] - dI[1], dden = dI[0] + dI[1];
    } else {
        num = I[2] - 0.5 * (I[0] + I[1]), den = I[0] + I[1] + I[2];
        dnum = dI[2] - 0.5 * (dI[0] + dI[1]), dden = dI[0] + dI[1] + dI[2];
    }
    if (rate) *rate = dnum / den - num * dden / (den * den);
    return num / den;
}

/* least squares of s = exp(-g t) (B sin w t + C cos w t) + E for fixed (w, g): the residual */
static double resid(const double *t, const double *s, size_t n, double w, double g)
{
    double A[3][3] = {{0}}, b[3] = {0};
    for (size_t i = 0; i < n; i++) {
        const double e = exp(-g * t[i]), f[3] = {e * sin(w * t[i]), e * cos(w * t[i]), 1};
        for (int p = 0; p < 3; p++) {
            b[p] += f[p] * s[i];
            for (int q = 0; q < 3; q++) A[p][q] += f[p] * f[q];
        }
    }
    /* Cramer's rule on the 3 x 3 normal equations */
    const double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
        A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    if (!(fabs(det) > 0)) return INFINITY;
    double x[3];
    for (int k = 0; k < 3; k++) {
        double M[3][3];
        memcpy(M, A, sizeof M);
        for (int p = 0; p < 3; p++) M[p][k] = b[p];
        x[k] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) /
            det;
    }
    double r = 0;
    for (size_t i = 0; i < n; i++) {
        const double e = exp(-g * t[i]);
        const double q = s[i] - (e * (x[0] * sin(w * t[i]) + x[1] * cos(w * t[i])) + x[2]);
        r += q * q;
    }
    return r;
}

/* the (w, g) of least residual: a coarse grid over w in [0.3, 2] w0 and g in [0, 2] w0, then two
 * finer grids about the best point */
static void fit(const double *t, const double *s, size_t n, double w0, double *w, double *g)
{
    double bw = w0, bg = 0, best = INFINITY, lw = 0.3 * w0, hw = 2 * w0, lg = 0, hg = 2 * w0;
    for (int pass = 0; pass < 3; pass++) {
        const int N = 60;
        for (int a = 0; a <= N; a++)
            for (int b = 0; b <= N; b++) {
                const double ww = lw + (hw - lw) * a / N, gg = lg + (hg - lg) * b / N;
                const double r = resid(t, s, n, ww, gg);
                if (r < best) best = r, bw = ww, bg = gg;
            }
        const double sw = 2 * (hw - lw) / N, sg = 2 * (hg - lg) / N;
        lw = bw - sw, hw = bw + sw, lg = fmax(0, bg - sg), hg = bg + sg;
    }
    *w = bw, *g = bg;
}

/* one realisation (thermostat seed `seed`): its deformation added to r->s, its start to *s0 and
 * *s0rate (allocates r's arrays on the first call) */
static int one_drop(const pfm_osc *cfg, int seed, pfm_osc_result *r, double *s0sum, double *ratesum)
{
    const int D = cfg->dim;
    const double R = cfg->R, d = cfg->d, L = 4 * R, rho = 1000;
    char json[2048];
    const char *pw = tu_env("PF_PW", cfg->pw ? cfg->pw : ""); /* extra pairwise keys, each followed by a comma */
    if (D == 2)
        snprintf(
            json, sizeof json,
            "{\"dimension\": 2, \"seed\": %d, \"particle_radius\": %.10g, \"gravity\": [0, 0],"
            " \"domain\": {\"min\": [%g, %g], \"max\": [%g, %g]},"
            " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"dt_max\": 0.002},"
            " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": %.10g}],"
            " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0], \"radius\": %.10g}],"
            " \"pairwise\": {\"k\": 1.7, %s \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": %g}]}}",
            seed, 0.5 * d, -L, -L, L, L, cfg->nu, R, pw, cfg->sigma);
    else
        snprintf(json, sizeof json,
                 "{\"dimension\": 3, \"seed\": %d, \"particle_radius\": %.10g, \"gravity\": [0, 0, 0],"
                 " \"domain\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]},"
                 " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"dt_max\": 0.002},"
                 " \"phases\": [{\"name\": \"water\", \"rest_density\": 1000, \"viscosity\": %.10g}],"
                 " \"fluid\": [{\"shape\": \"sphere\", \"center\": [0, 0, 0], \"radius\": %.10g}],"
                 " \"pairwise\": {%s \"coefficients\": [{\"phases\": [\"water\", \"water\"], \"sigma\": %g}]}}",
                 seed, 0.5 * d, -L, -L, -L, L, L, L, cfg->nu, R, pw, cfg->sigma);
    pfsph_sim *sim = tu_sim_from_json(json, "drop.json");
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    pfsph_particles *f = c->fluid;
    const size_t n0 = f->n;
    r->n = n0;
    r->R_e = D == 2 ? sqrt((double)n0 * d * d / PI) : cbrt(3.0 * (double)n0 * d * d * d / (4.0 * PI));
    const double Re = r->R_e;
    r->omega0 = sqrt((D == 2 ? 6.0 : 8.0) * cfg->sigma / (rho * Re * Re * Re));
    r->T0 = 2 * PI / r->omega0;
    r->gamma_lamb = (D == 2 ? 4.0 : 5.0) * cfg->nu / (Re * Re);
    const double wd2 = r->omega0 * r->omega0 - r->gamma_lamb * r->gamma_lamb;
    r->T_damped = wd2 > 0 ? 2 * PI / sqrt(wd2) : INFINITY;
    pfsph_error err = {0};
    if (cfg->t_melt > 0 && pfsph_sim_advance(sim, cfg->t_melt, &err) != PFSPH_OK) {
        fprintf(stderr, "drop: %s\n", err.msg);
        pfsph_sim_destroy(sim);
        return -1;
    }
    double m[3] = {0, 0, 0};
    for (size_t i = 0; i < f->n; i++) m[0] += f->x[i], m[1] += f->y[i], m[2] += f->z[i];
    for (int a = 0; a < 3; a++) m[a] /= (double)f->n;
    const double A = cfg->eps0 * r->omega0;
    for (size_t i = 0; i < f->n; i++) {
        const double q[3] = {f->x[i] - m[0], f->y[i] - m[1], f->z[i] - m[2]};
        if (D == 2) {
            f->vx[i] += (pfsph_real)(A * q[0]);
            f->vy[i] -= (pfsph_real)(A * q[1]);
        } else {
            f->vx[i] -= (pfsph_real)(0.5 * A * q[0]);
            f->vy[i] -= (pfsph_real)(0.5 * A * q[1]);
            f->vz[i] += (pfsph_real)(A * q[2]);
        }
    }
    double s0rate;
    const double s0 = deformation(c, &s0rate);
    *s0sum += s0, *ratesum += s0rate;
    const double dts = r->T0 / 40;
    const size_t ns = (size_t)lround(cfg->periods * 40);
    if (!r->t) {
        r->ns = ns + 1;
        r->t = malloc(r->ns * sizeof(double));
        r->s = calloc(r->ns, sizeof(double));
        r->s_theory = malloc(r->ns * sizeof(double));
        if (!r->t || !r->s || !r->s_theory) {
            pfsph_sim_destroy(sim);
            return -1;
        }
    }
    r->t[0] = 0, r->s[0] += s0;
    for (size_t k = 1; k <= ns; k++) {
        if (pfsph_sim_advance(sim, cfg->t_melt + dts * (double)k, &err) != PFSPH_OK) {
            fprintf(stderr, "drop: %s\n", err.msg);
            pfsph_sim_destroy(sim);
            return -1;
        }
        r->t[k] = dts * (double)k;
        r->s[k] += deformation(c, NULL);
    }
    const size_t lost = pfsph_sim_removed(sim);
    pfsph_sim_destroy(sim);
    if (lost) {
        fprintf(stderr, "drop: %zu particles left the domain\n", lost);
        return -1;
    }
    return 0;
}

int pfm_oscillation(const pfm_osc *cfg, pfm_osc_result *r)
{
    memset(r, 0, sizeof *r);
    const clock_t c0 = clock();
    const int nseeds = cfg->nseeds > 0 ? cfg->nseeds : 1;
    double s0 = 0, s0rate = 0;
    for (int q = 0; q < nseeds; q++)
        if (one_drop(cfg, cfg->seed + q, r, &s0, &s0rate)) return -1;
    for (size_t k = 0; k < r->ns; k++) r->s[k] /= nseeds;
    s0 /= nseeds, s0rate /= nseeds;
    const double wd2 = r->omega0 * r->omega0 - r->gamma_lamb * r->gamma_lamb;
    r->cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    /* Rayleigh-Lamb: a damped oscillator from s(0) with the measured initial rate */
    const double wd = wd2 > 0 ? sqrt(wd2) : 0, gl = r->gamma_lamb;
    for (size_t k = 0; k < r->ns; k++) {
        const double t = r->t[k];
        r->s_theory[k] = exp(-gl * t) * (s0 * cos(wd * t) + (s0rate + gl * s0) / (wd > 0 ? wd : 1) * sin(wd * t));
    }
    double w, g;
    fit(r->t, r->s, r->ns, r->omega0, &w, &g);
    r->T = 2 * PI / w;
    r->gamma = g;
    return 0;
}

void pfm_osc_free(pfm_osc_result *r)
{
    free(r->t), free(r->s), free(r->s_theory);
    r->t = r->s = r->s_theory = NULL;
}

void pfm_osc_report(const pfm_osc *cfg, const pfm_osc_result *r, const char *tag)
{
    printf("%s: %dD drop, %zu particles, R_e = %.4g m (%.1f d), sigma %g, nu %g, eps0 %g, CPU %.1f s\n", tag, cfg->dim,
           r->n, r->R_e, r->R_e / cfg->d, cfg->sigma, cfg->nu, cfg->eps0, r->cpu);
    printf("  period  %.4f s   (Rayleigh %.4f s: %.3f; damped oscillator %.4f s: %.3f)\n", r->T, r->T0, r->T / r->T0,
           r->T_damped, r->T / r->T_damped);
    printf("  damping %.4f /s  (Lamb %.4f /s: %.3f; as a viscosity %.4g m^2/s)\n", r->gamma, r->gamma_lamb,
           r->gamma / r->gamma_lamb, r->gamma * r->R_e * r->R_e / (cfg->dim == 2 ? 4.0 : 5.0));
    const char *dir = getenv("PF_PLOT");
    if (!dir || !*dir) return;
    char path[1024];
    snprintf(path, sizeof path, "%s/drop_%s.csv", dir, tag);
    FILE *fp = fopen(path, "w");
    if (fp) {
        fprintf(fp, "t,deformation,rayleigh_lamb\n");
        for (size_t k = 0; k < r->ns; k++) fprintf(fp, "%.6g,%.6g,%.6g\n", r->t[k], r->s[k], r->s_theory[k]);
        fclose(fp);
    }
    snprintf(path, sizeof path, "%s/drop_%s.png", dir, tag);
    char title[160];
    snprintf(title, sizeof title, "%dD drop, %zu particles: l = 2 mode", cfg->dim, r->n);
    const pfsph_plot_series ser[2] = {{"pfsph", r->t, r->s, r->ns, 0},
                                      {"Rayleigh frequency, Lamb damping", r->t, r->s_theory, r->ns, 0}};
    pfsph_error err = {0};
    if (pfsph_plot_lines(path, title, "time [s]", "deformation", ser, 2, &err) != PFSPH_OK)
        fprintf(stderr, "%s\n", err.msg);
}
