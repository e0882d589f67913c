/* Measurements of the pair-force liquid shared by its tests (see pf_measure.h). */
#include "pf_measure.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pfsph/params.h"
#include "pfsph/sim.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

/* "[x, y]" or "[x, y, z]" */
static const char *vec(char *buf, size_t cap, int dim, double x, double y, double z)
{
    if (dim == 2) snprintf(buf, cap, "[%g, %g]", x, y);
    else snprintf(buf, cap, "[%g, %g, %g]", x, y, z);
    return buf;
}

/* Appends a row to validation/<name> in the working directory (the data of
 * tools/validation_plots.py), writing the header first when the file is new; a by-product: the
 * checks do not depend on it, so a failure to write is ignored. */
void pfm_csv_row(const char *name, const char *header, const char *fmt, ...)
{
    char path[256];
    mkdir("validation", 0777);
    snprintf(path, sizeof path, "validation/%s", name);
    FILE *probe = fopen(path, "r");
    const int fresh = probe == NULL;
    if (probe) fclose(probe);
    FILE *fp = fopen(path, "a");
    if (!fp) return;
    if (fresh) fprintf(fp, "%s\n", header);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(fp, fmt, ap);
    va_end(ap);
    fprintf(fp, "\n");
    fclose(fp);
}

/* ---- contact angles ---- */

enum { NS2 = 72, NPOL = 12, NAZ = 24, NBIN = NPOL * NAZ };

/* Kasa fit of a circle (dim 2) or sphere (3) to the m points p: minimise
 * sum (|x|^2 + a . x + e)^2; the centre into c, the return value the radius (NAN with fewer
 * than 6 points in 2D, 12 in 3D). */
static double kasa_fit(int dim, const double (*p)[3], int m, double *c)
{
    const int N = dim + 1;
    double A[4][5] = {{0}};
    for (int k = 0; k < m; k++) {
        double row[4], r2 = 0;
        for (int a = 0; a < dim; a++) row[a] = p[k][a], r2 += p[k][a] * p[k][a];
        row[dim] = 1;
        const double rhs = -r2;
        for (int a = 0; a < N; a++) {
            for (int b = 0; b < N; b++) A[a][b] += row[a] * row[b];
            A[a][N] += row[a] * rhs;
        }
    }
    if (m < (dim == 2 ? 6 : 12)) return NAN;
    for (int a = 0; a < N; a++) { /* Gauss-Jordan with partial pivoting */
        int q = a;
        for (int r = a + 1; r < N; r++)
            if (fabs(A[r][a]) > fabs(A[q][a])) q = r;
        for (int col = 0; col < N + 1; col++) {
            const double t = A[a][col];
            A[a][col] = A[q][col];
            A[q][col] = t;
        }
        for (int r = 0; r < N; r++) {
            if (r == a) continue;
            const double fct = A[r][a] / A[a][a];
            for (int col = a; col < N + 1; col++) A[r][col] -= fct * A[a][col];
        }
    }
    double s = 0;
    for (int a = 0; a < dim; a++) c[a] = -0.5 * (A[a][N] / A[a][a]), s += c[a] * c[a];
    return sqrt(s - A[dim][N] / A[dim][dim]);
}

double pfm_drop_angle(const pfsph_ctx *c, double x0, double x1)
{
    const pfsph_particles *f = c->fluid;
    const int dim = c->dim;
    const double d = c->spacing;
    double cx = 0, cy = 0, cz = 0;
    int n = 0;
    for (size_t i = 0; i < f->n; i++)
        if (f->x[i] >= x0 && f->x[i] < x1) {
            cx += f->x[i], cy += f->y[i], n++;
            if (dim == 3) cz += f->z[i];
        }
    if (n < (dim == 2 ? 10 : 20)) return NAN;
    cx /= n, cy /= n, cz /= n;
    /* the outline: the farthest particle from the centroid in each sector (bin of solid angle) */
    double best[NBIN], bp[NBIN][3];
    const int nb = dim == 2 ? NS2 : NBIN;
    for (int k = 0; k < nb; k++) best[k] = -1;
    for (size_t i = 0; i < f->n; i++) {
        if (f->x[i] < x0 || f->x[i] >= x1) continue;
        const double dx = f->x[i] - cx, dy = f->y[i] - cy;
        double r;
        int k;
        if (dim == 2) {
            r = hypot(dx, dy);
            k = (int)floor((atan2(dy, dx) + PI) / (2 * PI) * NS2);
            k = k < 0 ? 0 : k >= NS2 ? NS2 - 1 : k;
        } else {
            const double dz = f->z[i] - cz;
            r = sqrt(dx * dx + dy * dy + dz * dz);
            if (r <= 0) continue;
            int a = (int)floor((dy / r + 1) * 0.5 * NPOL), b = (int)floor((atan2(dz, dx) + PI) / (2 * PI) * NAZ);
            a = a < 0 ? 0 : a >= NPOL ? NPOL - 1 : a;
            b = b < 0 ? 0 : b >= NAZ ? NAZ - 1 : b;
            k = a * NAZ + b;
        }
        if (r > best[k]) best[k] = r, bp[k][0] = f->x[i], bp[k][1] = f->y[i], bp[k][2] = dim == 3 ? f->z[i] : 0;
    }
    /* the points more than 1.5 d above the face */
    int m = 0;
    for (int k = 0; k < nb; k++)
        if (best[k] >= 0 && bp[k][1] >= 1.5 * d) {
            for (int a = 0; a < 3; a++) bp[m][a] = bp[k][a];
            m++;
        }
    double ctr[3];
    const double R = kasa_fit(dim, (const double(*)[3])bp, m, ctr) + 0.5 * d;
    if (isnan(R)) return NAN;
    double cs = -ctr[1] / R;
    if (cs < -1) cs = -1;
    if (cs > 1) cs = 1;
    return acos(cs) * 180.0 / PI;
}

/* A spherical cap of contact angle theta (plate face y = 0): its centroid height over V^(1/3).
 * With c = cos theta and the sphere's radius R, V = pi R^3 (1 - c)^2 (2 + c) / 3 and the
 * centroid sits at R (3 (1 + c)^2 / (4 (2 + c)) - c) above the face (3 R / 8 at 90 degrees, R at
 * 180); 1 - c = 2 sin^2(theta / 2) keeps thin caps exact. */
static double cap_centroid(double theta)
{
    const double c = cos(theta), omc = 2 * sin(0.5 * theta) * sin(0.5 * theta);
    const double v = PI * omc * omc * (2 + c) / 3; /* V / R^3 */
    return (3 * (1 + c) * (1 + c) / (4 * (2 + c)) - c) / cbrt(v);
}

double pfm_drop_angle_cap(const pfsph_ctx *c, double x0, double x1)
{
    const pfsph_particles *f = c->fluid;
    const double d = c->spacing;
    double sy = 0, ylo = 1e30, s1 = 0;
    int n = 0, n1 = 0;
    if (c->dim != 3) return NAN;
    for (size_t i = 0; i < f->n; i++)
        if (f->x[i] >= x0 && f->x[i] < x1) sy += f->y[i], n++, ylo = fmin(ylo, f->y[i]);
    if (n < 20) return NAN;
    /* the first layer: the particles within d/2 of the lowest; it stands for the slab [0, d) */
    for (size_t i = 0; i < f->n; i++)
        if (f->x[i] >= x0 && f->x[i] < x1 && f->y[i] < ylo + 0.5 * d) s1 += f->y[i], n1++;
    const double base = s1 / n1 - 0.5 * d; /* where the liquid's cells start: 0 on a lattice */
    /* each particle stands for d^3 of liquid (its centre is its cell's centroid) */
    const double g = (sy / n - base) / cbrt(n * d * d * d);
    double lo = 1e-4, hi = PI; /* cap_centroid rises with theta: bisection */
    if (g <= cap_centroid(lo)) return 0;
    if (g >= cap_centroid(hi)) return 180;
    for (int it = 0; it < 50; it++) {
        const double mid = 0.5 * (lo + hi);
        if (cap_centroid(mid) < g) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi) * 180.0 / PI;
}

/* The scene of nd drops (see pfm_contact) into json[cap]. */
static void contact_scene(const pfm_contact *cfg, const double *target, const double *ratio, int nd, char *json,
                          size_t cap)
{
    const int D = cfg->dim;
    const double P = cfg->pitch, H = cfg->half;
    char a[96], b[96], g[32];
    int len = snprintf(json, cap,
                       "{\"dimension\": %d, \"seed\": %d, \"particle_radius\": 0.005, \"gravity\": %s,"
                       " \"domain\": {\"min\": %s, \"max\": %s},"
                       " \"solver\": {\"type\": \"pcisph\"}, \"time\": {\"dt_max\": 0.002},"
                       " \"phases\": [{\"name\": \"water\", \"viscosity\": %s}",
                       D, cfg->seed, vec(g, sizeof g, D, 0, 0, 0), vec(a, sizeof a, D, -0.05, -0.1, -0.5 * P - 0.05),
                       vec(b, sizeof b, D, nd * P + 0.05, cfg->top, 0.5 * P + 0.05), cfg->nu);
    /* PF_SKIN=1 (a study knob): the plate's top layer is a solid phase of its own without
     * adhesion, so the wall attracts from its second layer down */
    const int skin = (int)tu_env_num("PF_SKIN", 0);
    for (int q = 0; q < nd; q++) {
        len += snprintf(json + len, cap - (size_t)len, ", {\"name\": \"p%d\", \"kind\": \"solid\"}", q);
        if (skin) len += snprintf(json + len, cap - (size_t)len, ", {\"name\": \"s%d\", \"kind\": \"solid\"}", q);
    }
    len += snprintf(json + len, cap - (size_t)len, "], \"fluid\": [");
    for (int q = 0; q < nd; q++)
        len += snprintf(json + len, cap - (size_t)len, "%s{\"shape\": \"box\", \"min\": %s, \"max\": %s}",
                        q ? ", " : "", vec(a, sizeof a, D, q * P + 0.5 * P - H, 0, -H),
                        vec(b, sizeof b, D, q * P + 0.5 * P + H, 2 * H, H));
    len += snprintf(json + len, cap - (size_t)len, "], \"solids\": [");
    /* the plate: 6 cells (0.06 m) thick, filled (a box keeps the 3 layers inside each face),
     * deeper than the pair reach k h = 3.4 d; PF_WALL gives another thickness in cells (a study
     * knob: docs/pairwise.md, "The wall's thickness and make") */
    const int wc = (int)tu_env_num("PF_WALL", 6);
    /* layers enough to fill the box; 2 at least, so that every plate of more than one cell has
     * the fluid's volume V0 (sim.c: a one-layer wall takes Akinci's volumes) */
    int wl = (wc - skin + 1) / 2 > 2 || wc - skin < 2 ? (wc - skin + 1) / 2 : 2;
    /* PF_AKINCI=1: "layers": 1, so the wall takes Akinci's volumes 1 / sum W (larger than V0 on a
     * thin plate: the liquid is held further off); fills plates of one or two cells only */
    if (tu_env_num("PF_AKINCI", 0) > 0) wl = 1;
    for (int q = 0; q < nd; q++)
        len += snprintf(json + len, cap - (size_t)len,
                        "%s{\"shape\": \"box\", \"min\": %s, \"max\": %s, \"layers\": %d, \"phase\": \"p%d\"}",
                        q ? ", " : "", vec(a, sizeof a, D, q * P, -0.01 * wc, -0.5 * P),
                        vec(b, sizeof b, D, (q + 1) * P, skin ? -0.01 : 0, 0.5 * P), wl, q);
    /* PF_BCC=1 (a study knob): a second lattice of the plate's phase offset by half a cell along
     * every axis (a body-centred wall of twice the liquid's number density, each particle with
     * V0: the wall's density term holds the liquid further off) */
    for (int q = 0; q < nd && tu_env_num("PF_BCC", 0) > 0; q++)
        len += snprintf(json + len, cap - (size_t)len,
                        ", {\"shape\": \"box\", \"min\": %s, \"max\": %s, \"layers\": %d, \"phase\": \"p%d\"}",
                        vec(a, sizeof a, D, q * P + 0.005, -0.01 * wc + 0.005, -0.5 * P + 0.005),
                        vec(b, sizeof b, D, (q + 1) * P - 0.005, -0.005, 0.5 * P - 0.005), wc > 2 ? wc / 2 : 2, q);
    for (int q = 0; q < nd && skin; q++)
        len += snprintf(json + len, cap - (size_t)len,
                        ", {\"shape\": \"box\", \"min\": %s, \"max\": %s, \"layers\": 1, \"phase\": \"s%d\"}",
                        vec(a, sizeof a, D, q * P, -0.01, -0.5 * P), vec(b, sizeof b, D, (q + 1) * P, 0, 0.5 * P), q);
    len += snprintf(json + len, cap - (size_t)len,
                    "], \"pairwise\": {%s \"k\": %g, \"coefficients\": [{\"phases\": [\"water\", "
                    "\"water\"], \"sigma\": 4}",
                    cfg->pw, cfg->k);
    /* c_aa as the scene resolves it: sigma / (f(theta) lambda rho^2) in 3D, at theta 0.01 (the
     * default); the 2D calibration gave it without f(theta) */
    const double lam = pfsph_pairwise_lambda(D, cfg->k * 0.02);
    const double caa = D == 2 ? 4.0 / (lam * 1e6) : 4.0 / (pfsph_pairwise_sigma_factor(3, 0.01) * lam * 1e6);
    for (int q = 0; q < nd; q++)
        if (ratio)
            len += snprintf(json + len, cap - (size_t)len, ", {\"phases\": [\"water\", \"p%d\"], \"c\": %.9g}", q,
                            ratio[q] * caa);
        else
            len += snprintf(json + len, cap - (size_t)len,
                            ", {\"phases\": [\"water\", \"p%d\"], \"contact_angle\": %g}", q, target[q]);
    len += snprintf(json + len, cap - (size_t)len, "]}}");
    assert_true(len < (int)cap);
}

void pfm_contact_run(const pfm_contact *cfg, const double *target, const double *ratio, int nd)
{
    const double P = cfg->pitch;
    char json[8192];
    contact_scene(cfg, target, ratio, nd, json, sizeof json);
    pfsph_sim *sim = tu_sim_from_json(json, cfg->dim == 2 ? "contact.json" : "contact3d.json");
    pfsph_error err = {0};
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    print_message("%zu fluid particles, %zu boundary particles\n", c->fluid->n,
                  c->boundary ? c->boundary->n : (size_t)0);
    /* [0]: the angle checked (cfg->cap: the centroid's, else the outline fit's), [1]: the other */
    double sum[2][PFM_MAXDROP] = {{0}}, sum2[2][PFM_MAXDROP] = {{0}}, th[2][PFM_MAXDROP], low[PFM_MAXDROP],
           top[PFM_MAXDROP];
    int cnt[2][PFM_MAXDROP] = {{0}};
    for (int k = 1; k <= cfg->nsamples; k++) {
        const int rc = pfsph_sim_advance(sim, cfg->dt_s * k, &err);
        if (rc) print_message("%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        for (int q = 0; q < nd; q++) {
            const double fit = pfm_drop_angle(c, q * P, q * P + P), cap = pfm_drop_angle_cap(c, q * P, q * P + P);
            th[0][q] = cfg->cap ? cap : fit;
            th[1][q] = cfg->cap ? fit : cap;
            low[q] = 1e30, top[q] = -1e30;
            for (size_t i = 0; i < c->fluid->n; i++)
                if (c->fluid->x[i] >= q * P && c->fluid->x[i] < (q + 1) * P) {
                    low[q] = fmin(low[q], c->fluid->y[i] / c->spacing);
                    top[q] = fmax(top[q], c->fluid->y[i] / c->spacing + 0.5);
                }
            for (int w = 0; w < 2; w++)
                if (k > cfg->avg_after && isfinite(th[w][q]))
                    sum[w][q] += th[w][q], sum2[w][q] += th[w][q] * th[w][q], cnt[w][q]++;
        }
        if (k % 10 == 0) {
            char line[512];
            int l = snprintf(line, sizeof line, "t = %.2f s:", pfsph_sim_time(sim));
            for (int q = 0; q < nd; q++)
                l += snprintf(line + l, sizeof line - (size_t)l, " %6.1f [%5.1f] (%.1f-%.1f d)", th[0][q], th[1][q],
                              low[q], top[q]);
            print_message("%s\n", line);
            if (getenv("PF_LAYERS")) /* the first two layers: count and disc radius sqrt(2 <r^2>) [d] */
                for (int q = 0; q < nd; q++) {
                    double cx = 0, cz = 0, r2[2] = {0, 0};
                    int m = 0, nl[2] = {0, 0};
                    for (size_t i = 0; i < c->fluid->n; i++)
                        if (c->fluid->x[i] >= q * P && c->fluid->x[i] < (q + 1) * P)
                            cx += c->fluid->x[i], cz += c->dim == 3 ? c->fluid->z[i] : 0, m++;
                    cx /= m, cz /= m;
                    for (size_t i = 0; i < c->fluid->n; i++) {
                        /* the layers' centres sit near y = 0 and d (the first below the face on
                         * a wetting plate): bins centred on them */
                        const int L = (int)floor(c->fluid->y[i] / c->spacing + 0.5);
                        if (c->fluid->x[i] < q * P || c->fluid->x[i] >= (q + 1) * P || L < 0 || L > 1) continue;
                        const double dx = c->fluid->x[i] - cx, dz = c->dim == 3 ? c->fluid->z[i] - cz : 0;
                        r2[L] += dx * dx + dz * dz, nl[L]++;
                    }
                    print_message("  drop %d: layer 1: %d, radius %.1f d; layer 2: %d, radius %.1f d\n", q, nl[0],
                                  sqrt(2 * r2[0] / fmax(nl[0], 1)) / c->spacing, nl[1],
                                  sqrt(2 * r2[1] / fmax(nl[1], 1)) / c->spacing);
                    /* the liquid next to the plate: particles below 0.5 d (centres sink below
                     * the face on a wetting plate), their mean height and their registry with
                     * the plate's lattice (cell centres at q P + (i + 1/2) w, w = P / round(P / d)):
                     * <cos> of the phase along x and z is +1 on top of wall particles, -1 in the
                     * hollows between four, 0 for no registry */
                    const double w = P / floor(P / c->spacing + 0.5);
                    double sy0 = 0, cxs = 0, czs = 0, cc = 0;
                    int n0 = 0, nb = 0;
                    for (size_t i = 0; i < c->fluid->n; i++) {
                        const double y = c->fluid->y[i] / c->spacing;
                        if (c->fluid->x[i] < q * P || c->fluid->x[i] >= (q + 1) * P || y >= 0.5) continue;
                        const double px = cos(2 * PI * (c->fluid->x[i] - q * P) / w - PI),
                                     pz = c->dim == 3 ? cos(2 * PI * (c->fluid->z[i] + 0.5 * P) / w - PI) : 1;
                        sy0 += y, cxs += px, czs += pz, cc += px * pz, n0++, nb += y < 0;
                    }
                    if (n0)
                        print_message("  drop %d: below 0.5 d: %d (%d below the face), mean height %.2f d, "
                                      "registry x %.2f z %.2f xz %.2f\n",
                                      q, n0, nb, sy0 / n0, cxs / n0, czs / n0, cc / n0);
                }
        }
    }
    assert_int_equal(pfsph_sim_removed(sim), 0);
    const char *name[2] = {cfg->cap ? "centroid" : "outline fit", cfg->cap ? "outline fit" : "centroid"};
    double mean[PFM_MAXDROP];
    for (int q = 0; q < nd; q++) {
        assert_true(cnt[0][q] > 0);
        for (int w = 0; w < 2; w++) {
            if (!cnt[w][q]) continue; /* 2D: no centroid angle */
            const double m = cnt[w][q] ? sum[w][q] / cnt[w][q] : NAN;
            const double sd = cnt[w][q] ? sqrt(fmax(0, sum2[w][q] / cnt[w][q] - m * m)) : NAN;
            print_message("target %5.1f deg%s: %s %6.1f deg (sd %.1f over %d samples, %.2f-%.2f s)\n", target[q],
                          ratio ? " (Eq. 21 of the ratio)" : "", name[w], m, sd, cnt[w][q], cfg->t_avg0, cfg->t_avg1);
            if (w == 0) {
                mean[q] = m;
                pfm_csv_row("contact_angles.csv", "dim,target_deg,measured_deg,sd_deg,samples", "%d,%g,%.2f,%.2f,%d",
                            cfg->dim, target[q], m, sd, cnt[0][q]);
            }
        }
    }
    for (int q = 0; q < nd; q++) assert_true(low[q] < 1.0);
    for (int q = 0; q < nd; q++) assert_true(fabs(mean[q] - target[q]) <= cfg->tol);
    pfsph_sim_destroy(sim);
}

int pfm_contact_knobs(double *target, double *ratio, int nd)
{
    const char *knob = getenv("PF_RATIO") ? getenv("PF_RATIO") : getenv("PF_ANG");
    if (!knob) return nd;
    nd = 0;
    for (char *p = (char *)knob; *p && nd < PFM_MAXDROP;) {
        ratio[nd] = strtod(p, &p);
        target[nd] = getenv("PF_RATIO") ? acos(2 * ratio[nd] - 1) * 180 / PI : ratio[nd];
        nd++;
        if (*p == ',') p++;
    }
    return nd;
}

void pfm_contact_angles(int dim, const double *targets, int nd)
{
    pfm_contact_drops(dim, targets, nd, dim == 2 ? 0.08 : 0.03, dim == 2 ? 0.7 : 0.26, 0);
}

void pfm_contact_drops(int dim, const double *targets, int nd, double half, double pitch, int cap)
{
    double target[PFM_MAXDROP], ratio[PFM_MAXDROP];
    memcpy(target, targets, (size_t)nd * sizeof *target);
    nd = pfm_contact_knobs(target, ratio, nd);
    pfm_contact cfg = {.dim = dim,
                       .pitch = tu_env_num("PF_PITCH", pitch),
                       .half = tu_env_num("PF_HALF", half),
                       .cap = (int)tu_env_num("PF_CAP", cap),
                       .top = dim == 2 ? 0.4 : 0.3,
                       .k = tu_env_num("PF_K", 1.7),
                       .seed = (int)tu_env_num("PF_SEED", 11),
                       .nu = tu_env("PF_NU", "0.001"),
                       .pw = tu_env("PF_PW", ""),
                       .dt_s = dim == 2 ? 0.05 : 0.02,
                       .tol = dim == 3 && getenv("PF_RATIO") ? 180 : 10};
    double t_end = tu_env_num("PF_T", dim == 2 ? 6.0 : 2.0);
#ifdef __SANITIZE_ADDRESS__
    /* 1 s: the 60-degree drop is still spreading. Averaged over 0.5-1 s, seeds 11 and 1-5
     * (Release, PF_T=1) read 72.9-76.2, 93.3-103.3 and 110.4-117.7 degrees: 16 degrees from
     * the target at most. The 30/150 drops and the 3D drops skip (tu_release_only). */
    if (dim == 3 || target[0] < 45) tu_release_only();
    t_end = 1.0;
    cfg.tol = 25;
#endif
    cfg.nsamples = (int)lround(t_end / cfg.dt_s);
    cfg.t_avg1 = t_end;
    if (dim == 2) { /* the second half of the samples */
        cfg.avg_after = cfg.nsamples / 2;
        cfg.t_avg0 = 0.5 * t_end;
    } else { /* those after PF_TAVG */
        cfg.t_avg0 = tu_env_num("PF_TAVG", 0.5 * t_end);
        while (cfg.dt_s * (cfg.avg_after + 1) <= cfg.t_avg0 + 1e-9) cfg.avg_after++;
    }
    pfm_contact_run(&cfg, target, getenv("PF_RATIO") ? ratio : NULL, nd);
}

/* ---- Laplace's law ---- */

#define SIGMA 4.0 /* N/m */
#define NB 10
#define D_SP 0.01 /* spacing [m] */

typedef struct drop {
    double Rs;
    pfsph_sim *sim;
    double Re, p, se;
    size_t m;
    int rc, removed;
    char msg[256];
    char log[1024];
} drop;

static void create_drop(const pfm_laplace *cfg, drop *dr)
{
    const double d = D_SP;
    const int D = cfg->dim;
    char json[2048], z[32], lo[32], hi[32], thermo[96] = "";
    const char *e = getenv("PF_THETA");
    if (e) snprintf(thermo, sizeof thermo, "\"thermostat\": {\"reduced_temperature\": %s},", e);
    e = getenv("PF_SEED");
    snprintf(json, sizeof json,
             "{\"dimension\": %d, \"seed\": %d, \"particle_radius\": %g, \"gravity\": %s,"
             " \"domain\": {\"min\": %s, \"max\": %s},"
             " \"solver\": {\"type\": \"%s\"%s}, \"time\": {\"dt_max\": %s},"
             " \"phases\": [{\"name\": \"water\", \"viscosity\": 0.001}],"
             " \"fluid\": [{\"shape\": \"sphere\", \"center\": %s, \"radius\": %g}],"
             " \"pairwise\": {\"k\": 1.7, %s \"coefficients\": [{\"phases\": [\"water\", \"water\"],"
             " \"sigma\": %g}]}}",
             D, e ? atoi(e) : 7, 0.5 * d, vec(z, sizeof z, D, 0, 0, 0), vec(lo, sizeof lo, D, -1, -1, -1),
             vec(hi, sizeof hi, D, 1, 1, 1), cfg->solver, cfg->solver_keys, cfg->dt_max, z, dr->Rs * d, thermo, SIGMA);
    dr->sim = tu_sim_from_json(json, "laplace.json");
    const size_t n = pfsph_sim_ctx(dr->sim)->fluid->n;
    /* the equivalent radius: the disc (ball) of the particles' volume */
    dr->Re = D == 2 ? sqrt((double)n * d * d / PI) : cbrt(3.0 * (double)n * d * d * d / (4.0 * PI));
}

/* Distance of particle i from the centre c. */
static double dist(int dim, const pfsph_particles *f, size_t i, const double *c)
{
    return dim == 2 ? hypot(f->x[i] - c[0], f->y[i] - c[1])
                    : hypot(hypot(f->x[i] - c[0], f->y[i] - c[1]), f->z[i] - c[2]);
}

/* Runs on one thread of the test's parallel loop: no cmocka assertion here (they jump); the
 * outcome goes into dr->rc / dr->msg and the report into dr->log. */
static void run_drop(const pfm_laplace *cfg, drop *dr)
{
    const int dim = cfg->dim;
    const double d = D_SP, t_end = cfg->t_end;
    pfsph_sim *sim = dr->sim;
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    const size_t n = f->n;
    pfsph_error err = {0};
    size_t cap = 1 << 12, m = 0;
    double prof[16] = {0}, rg = 0;
    long pcnt[16] = {0};
    pfsph_real *pm = malloc(n * sizeof *pm);
    double *smp = malloc(cap * sizeof *smp);
    dr->rc = !pm || !smp ? PFSPH_ENOMEM : pfsph_sim_advance(sim, cfg->t0, &err);
    while (dr->rc == PFSPH_OK && pfsph_sim_time(sim) < t_end - 1e-9) {
        /* whole steps (pfsph_sim_advance would shorten the last one to land on a time) */
        for (int q = 0; q < cfg->every && dr->rc == PFSPH_OK && pfsph_sim_time(sim) < t_end - 1e-9; q++)
            dr->rc = pfsph_sim_step(sim, t_end, &err);
        if (dr->rc == PFSPH_OK) dr->rc = pfsph_sim_mechanical_pressure(sim, pm);
        if (dr->rc != PFSPH_OK) break;
        double c[3] = {0, 0, 0}, sum = 0;
        int cnt = 0;
        for (size_t i = 0; i < n; i++) {
            c[0] += f->x[i], c[1] += f->y[i];
            if (dim == 3) c[2] += f->z[i];
        }
        for (int a = 0; a < dim; a++) c[a] /= (double)n;
        for (size_t i = 0; i < n; i++)
            if (dist(dim, f, i, c) < 0.5 * dr->Re) sum += pm[i], cnt++;
        if (cnt == 0) {
            snprintf(err.msg, sizeof err.msg, "no particle within R_e / 2 of the centroid at t = %g s",
                     pfsph_sim_time(sim));
            dr->rc = PFSPH_EUNSTABLE;
            break;
        }
        if (m == cap) {
            double *grown = realloc(smp, 2 * cap * sizeof *smp);
            if (!grown) {
                dr->rc = PFSPH_ENOMEM;
                break;
            }
            smp = grown, cap *= 2;
        }
        smp[m++] = sum / cnt;
        if (cfg->profile) { /* radial profile of the mechanical pressure, shells of 1 d; gyration radius */
            double g2 = 0;
            for (size_t i = 0; i < n; i++) {
                const double rr = dist(dim, f, i, c);
                g2 += rr * rr;
                const int k = (int)(rr / d);
                if (k < 16) prof[k] += pm[i], pcnt[k]++;
            }
            rg += sqrt(5.0 / 3.0 * g2 / (double)n);
        }
    }
    snprintf(dr->msg, sizeof dr->msg, "%s", err.msg);
    dr->m = m;
    dr->removed = (int)pfsph_sim_removed(sim);
    if (dr->rc == PFSPH_OK && m >= NB) {
        double bm[NB];
        tu_block_mean(smp, m, NB, &dr->p, &dr->se, bm);
        const double L = dim - 1; /* Laplace: dp = (dim - 1) sigma / R */
        int o = snprintf(dr->log, sizeof dr->log,
                         "R = %g d (%zu particles, R_e %.4f m): p_in = %.3f +- %.3f Pa over %zu samples; "
                         "%s / R_e = %.3f Pa (ratio %.3f +- %.3f); %llu steps\n",
                         dr->Rs, n, dr->Re, dr->p, dr->se, m, dim == 2 ? "sigma" : "2 sigma", L * SIGMA / dr->Re,
                         dr->p * dr->Re / (L * SIGMA), dr->se * dr->Re / (L * SIGMA),
                         (unsigned long long)pfsph_sim_steps(sim));
        if (cfg->profile) {
            o += snprintf(dr->log + o, sizeof dr->log - (size_t)o, "  blocks:");
            for (int b = 0; b < NB; b++) o += snprintf(dr->log + o, sizeof dr->log - (size_t)o, " %.1f", bm[b]);
            o += snprintf(dr->log + o, sizeof dr->log - (size_t)o,
                          "\n  R from gyration sqrt(5/3) Rg = %.3f d (R_e %.3f d); shells [Pa]:", rg / (double)m / d,
                          dr->Re / d);
            for (int k = 0; k < 16 && pcnt[k] && o < (int)sizeof dr->log; k++)
                o += snprintf(dr->log + o, sizeof dr->log - (size_t)o, " %d:%.1f", k, prof[k] / (double)pcnt[k]);
            if (o < (int)sizeof dr->log) snprintf(dr->log + o, sizeof dr->log - (size_t)o, "\n");
        }
    }
    free(pm);
    free(smp);
}

typedef struct drop_job {
    const pfm_laplace *cfg;
    drop *dr;
} drop_job;

static void run_job(void *arg, int i)
{
    drop_job *j = arg;
    run_drop(j->cfg, &j->dr[i]);
}

void pfm_laplace_run(const pfm_laplace *cfg, const double *radii, int nr)
{
    drop dr[PFM_MAXR];
    memset(dr, 0, sizeof dr);
    for (int i = 0; i < nr; i++) {
        dr[i].Rs = radii[i];
        create_drop(cfg, &dr[i]);
    }
    drop_job job = {cfg, dr};
    tu_parallel_largest_first(nr, radii, run_job, &job);
    for (int i = 0; i < nr; i++) {
        if (dr[i].rc != PFSPH_OK) print_message("R = %g d: %s\n", dr[i].Rs, dr[i].msg);
        assert_int_equal(dr[i].rc, PFSPH_OK);
        assert_int_equal(dr[i].removed, 0);
        assert_true(dr[i].m >= NB);
        print_message("%s", dr[i].log);
        pfsph_sim_destroy(dr[i].sim);
    }
    /* least squares p = a + s x, x = (dim - 1) / R_e */
    double x[PFM_MAXR], y[PFM_MAXR], Rmax = 0;
    for (int i = 0; i < nr; i++) x[i] = (double)(cfg->dim - 1) / dr[i].Re, y[i] = dr[i].p, Rmax = fmax(Rmax, dr[i].Re);
    const tu_line fit = tu_line_fit(nr, x, y);
    for (int i = 0; i < nr; i++)
        pfm_csv_row("laplace.csv", "dim,R_spacings,R_e_m,x_per_m,p_in_pa,p_err_pa,sigma_target",
                    "%d,%g,%.5f,%.4f,%.3f,%.3f,%g", cfg->dim, dr[i].Rs, dr[i].Re, x[i], dr[i].p, dr[i].se, SIGMA);
    print_message("fit: slope %.4f N/m = %.3f sigma, intercept %.3f Pa (bound %.3f), R^2 %.4f\n", fit.slope,
                  fit.slope / SIGMA, fit.icpt, 0.25 * SIGMA / Rmax, fit.r2);
    if (!cfg->checks) return;
    assert_true(fabs(fit.slope / SIGMA - 1) <= 0.15);
    assert_true(fabs(fit.icpt) <= 0.25 * SIGMA / Rmax);
    assert_true(fit.r2 >= 0.9);
}

/* ---- a 2D bubble's shape ---- */

/* Wendland C2 (2D), support H; only ratios of it are used */
static double bubble_wk(double r2, double H)
{
    double q = sqrt(r2) / H;
    if (q >= 1) return 0;
    double a = 1 - q;
    return a * a * a * a * (1 + 4 * q);
}

static double lerp0(double a, double b) { return a / (a - b); } /* where a + t (b - a) = 0 */

/* The bubble's outline: the 0.5 level of the Shepard colour field c = sum_gas W / sum W (support
 * 2 d) on a grid of spacing d / 2, traced by marching squares; the area is that of the cells'
 * sub-0.5 polygons summed exactly (each cell's polygon from the same interpolated crossings). */
void pfm_bubble_measure(const pfsph_ctx *c, int gas, pfm_bubble *s)
{
    const pfsph_particles *f = c->fluid;
    const double d = c->spacing, H = 2 * d, g = 0.5 * d;
    double sx = 0, sy = 0, sv = 0;
    double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
    int ng = 0;
    for (size_t i = 0; i < f->n; i++) {
        if (f->phase[i] != gas) continue;
        double x = f->x[i], y = f->y[i];
        sx += x;
        sy += y;
        sv += f->vy[i];
        ng++;
        if (x < x0) x0 = x;
        if (x > x1) x1 = x;
        if (y < y0) y0 = y;
        if (y > y1) y1 = y;
    }
    s->ngas = ng;
    s->cx = sx / ng;
    s->cy = sy / ng;
    s->vy = sv / ng;
    double mxx = 0, myy = 0, mxy = 0;
    for (size_t i = 0; i < f->n; i++) {
        if (f->phase[i] != gas) continue;
        double dx = f->x[i] - s->cx, dy = f->y[i] - s->cy;
        mxx += dx * dx;
        myy += dy * dy;
        mxy += dx * dy;
    }
    double tr = mxx + myy, det = mxx * myy - mxy * mxy, disc = sqrt(fmax(0, 0.25 * tr * tr - det));
    s->aspect = sqrt((0.5 * tr - disc) / (0.5 * tr + disc));
    s->hw = sqrt(myy / mxx);

    /* colour field on the grid around the gas, particles within H of it */
    x0 -= 2 * H;
    y0 -= 2 * H;
    x1 += 2 * H;
    y1 += 2 * H;
    const int nx = (int)ceil((x1 - x0) / g) + 1, ny = (int)ceil((y1 - y0) / g) + 1;
    double *cf = calloc((size_t)nx * ny, sizeof *cf), *wt = calloc((size_t)nx * ny, sizeof *wt);
    if (!cf || !wt) abort();
    for (size_t i = 0; i < f->n; i++) {
        double x = f->x[i], y = f->y[i];
        if (x < x0 - H || x > x1 + H || y < y0 - H || y > y1 + H) continue;
        int ia = (int)floor((x - H - x0) / g), ib = (int)ceil((x + H - x0) / g);
        int ja = (int)floor((y - H - y0) / g), jb = (int)ceil((y + H - y0) / g);
        for (int jj = ja < 0 ? 0 : ja; jj <= jb && jj < ny; jj++)
            for (int ii = ia < 0 ? 0 : ia; ii <= ib && ii < nx; ii++) {
                double dx = x0 + ii * g - x, dy = y0 + jj * g - y, w = bubble_wk(dx * dx + dy * dy, H);
                wt[jj * nx + ii] += w;
                if (f->phase[i] == gas) cf[jj * nx + ii] += w;
            }
    }
    for (int k = 0; k < nx * ny; k++) cf[k] = (wt[k] > 0 ? cf[k] / wt[k] : 0) - 0.5; /* > 0: gas */
    double P = 0, A = 0;
    for (int jj = 0; jj + 1 < ny; jj++)
        for (int ii = 0; ii + 1 < nx; ii++) {
            /* corners counter-clockwise: (0,0) (1,0) (1,1) (0,1) */
            const double v[4] = {cf[jj * nx + ii], cf[jj * nx + ii + 1], cf[(jj + 1) * nx + ii + 1],
                                 cf[(jj + 1) * nx + ii]};
            const double cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
            /* polygon of the gas part of the cell (walk the corners, insert edge crossings) */
            double px[8], py[8], ex[4], ey[4];
            int np = 0, ne = 0;
            for (int e = 0; e < 4; e++) {
                int a = e, b = (e + 1) & 3;
                if (v[a] > 0) {
                    px[np] = cx[a];
                    py[np++] = cy[a];
                }
                if ((v[a] > 0) != (v[b] > 0)) {
                    double t = lerp0(v[a], v[b]);
                    px[np] = cx[a] + t * (cx[b] - cx[a]);
                    py[np++] = cy[a] + t * (cy[b] - cy[a]);
                    ex[ne] = px[np - 1];
                    ey[ne++] = py[np - 1];
                }
            }
            for (int k = 0; k < np; k++) A += 0.5 * (px[k] * py[(k + 1) % np] - px[(k + 1) % np] * py[k]);
            /* contour segments: crossings in walk order pair up (0-1, 2-3); for a saddle this
             * joins the crossings of one corner region, either pairing has nearly the same length */
            for (int k = 0; k + 1 < ne; k += 2) P += hypot(ex[k + 1] - ex[k], ey[k + 1] - ey[k]);
        }
    free(cf);
    free(wt);
    s->perim = P * g;
    s->area = A * g * g;
    s->circ = 2 * sqrt(PI * s->area) / s->perim;
}
