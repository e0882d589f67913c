/* Vectorised pair terms of the neighbour passes (pair_terms.c): per hit of a buffer, the
 * expressions the scalar passes evaluate, so that summing them in order gives the same bits. */
#ifndef PFSPH_PAIR_TERMS_H
#define PFSPH_PAIR_TERMS_H

#include "pfsph/kernel.h"

/* w[e] = pfsph_kernel_w(|x_ij|) from r2[e] = |x_ij|^2, e < n */
void pfsph__terms_w(const pfsph_kernel *k, int n, const pfsph_real *restrict r2, pfsph_real *restrict w);
/* dw[e] = pfsph_kernel_dw_r(|x_ij|) */
void pfsph__terms_dwr(const pfsph_kernel *k, int n, const pfsph_real *restrict r2, pfsph_real *restrict dw);

/* w[e] = W_k(|x_ij|) and, where not NULL, wk[e] = W_kk(|x_ij|) and dw[e] = dW_k/r, from one
 * square root of r2[e], e < n: pfsph__terms_w and pfsph__terms_dwr's values (the same bits). */
void pfsph__terms_w_dwr(const pfsph_kernel *kk, const pfsph_kernel *k, int n, const pfsph_real *restrict r2,
                        pfsph_real *restrict wk, pfsph_real *restrict w, pfsph_real *restrict dw);

/* Per listed target j = idx[q], q < n, of point (x, y, z): x_ij into cx, cy, cz, and W (into w)
 * and dW/r (into cw) of |x_ij| where |x_ij|^2 < h2, 0 beyond; with aux, both times aux[j]. The
 * expressions of pfsph__terms_w / _dwr (the same bits). n <= PFSPH_LIST_TERMS_MAX. */
#define PFSPH_LIST_TERMS_MAX 512
void pfsph__terms_list_wdw(const pfsph_kernel *k, pfsph_real h2, int n, const uint32_t *restrict idx,
                           const pfsph_real *restrict tx, const pfsph_real *restrict ty, const pfsph_real *restrict tz,
                           pfsph_real x, pfsph_real y, pfsph_real z, const pfsph_real *restrict aux,
                           pfsph_real *restrict cx, pfsph_real *restrict cy, pfsph_real *restrict cz,
                           pfsph_real *restrict cw, pfsph_real *restrict w);

/* particle i and the fluid arrays, for pfsph__terms_visc_pressure */
typedef struct pfsph_pair_in {
    pfsph_kernel k;
    const pfsph_real *vx, *vy, *vz, *nd, *p;
    const pfsph_real *nuj; /* per hit: the pair's nu (viscosity.h, pfsph__visc_pair_nu) */
    pfsph_real vxi, vyi, vzi, nui, pi, eps;
    pfsph_real ndi; /* delta_i: the Morris factor takes the pair's mean delta (viscosity.h) */
} pfsph_pair_in;

/* Per fluid hit e (index jj[e], x_ij, r2): dw[e] = dW/r, sv[e] the Morris viscosity factor
 * 2 nu_ij / (delta_i + delta_j) (v_ij . x_ij) / (r2 + eps) dW/r (viscosity.c), sp[e] the pressure factor
 * (p_i / delta_i^2 + p_j / delta_j^2) dW/r (pressure.c); the terms are sv x_ij, sp x_ij. */
void pfsph__terms_visc_pressure(const pfsph_pair_in *restrict in, int n, const uint32_t *restrict jj,
                                const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                                const pfsph_real *restrict dz, const pfsph_real *restrict r2, pfsph_real *restrict dw,
                                pfsph_real *restrict sv, pfsph_real *restrict sp);

/* Per listed fluid neighbour jj[e], e < n <= PFSPH_LIST_TERMS_MAX, of particle i at (xi, yi, zi)
 * (the targets x, y, z, their phase, and nu_row[phase] the pair's viscosity with i's phase,
 * pfsph__visc_pair_nu), with dw[e] its dW/r: x_ij into dx, dy, dz and sv[e] the Morris factor
 * of pfsph__terms_visc_pressure (in's vx, vy, vz, nd, vxi, vyi, vzi, eps; the same bits as
 * viscosity.c visc_pair). */
void pfsph__terms_visc_list(const pfsph_pair_in *restrict in, const pfsph_real *restrict x,
                            const pfsph_real *restrict y, const pfsph_real *restrict z, const uint8_t *restrict phase,
                            const pfsph_real *restrict nu_row, pfsph_real xi, pfsph_real yi, pfsph_real zi, int n,
                            const uint32_t *restrict jj, const pfsph_real *restrict dw, pfsph_real *restrict dx,
                            pfsph_real *restrict dy, pfsph_real *restrict dz, pfsph_real *restrict sv);

/* Per fluid hit e of the thermostat (thermostat.h): t[e] = pfsph__thermo_fluid(amp_ts[e], nu[e],
 * mi, mj[e], ndi, ndj[e], r2[e], dw[e], eps, sqrt(r2[e]), theta[e]), the noise force over r,
 * for hits with r2 > 0 (others: not finite). */
void pfsph__terms_thermo(double mi, double ndi, double eps, int n, const pfsph_real *restrict r2,
                         const pfsph_real *restrict dw, const double *restrict amp_ts, const double *restrict nu,
                         const double *restrict mj, const double *restrict ndj, const double *restrict theta,
                         double *restrict t);

/* sc[e] = cf[e] cos(U_R r) / r (0 where r2[e] = 0 or cf[e] = 0) and, with w, w[e] = 0 where
 * r2[e] = 0, as pfsph__terms_pair_sc computes them once it has gathered cf (the same bits). */
void pfsph__terms_pair_sc_cf(double U_R, int n, const double *restrict cf, const pfsph_real *restrict r2,
                             double *restrict sc, pfsph_real *restrict w);

/* theta[e] = pfsph_thermo_theta(key, idi, idj[e]) (the same bits), e < n. */
void pfsph__terms_theta(uint64_t key, uint32_t idi, int n, const uint32_t *restrict idj, double *restrict theta);

/* Four-lane sums of the pair pass (pairwise.c): hit e goes to lane e % 4 of each sum, lanes
 * are added at the end in a fixed order, so the result is the same bits on every CPU and
 * thread count (the association is fixed by the source, not by the vector width). */
typedef struct pfsph_pair_sums {
    double acc[3][4]; /* sum sc x_ij */
    double S[6][4];   /* sum sc x_ij x_ij^T (xx, xy, xz, yy, yz, zz) */
    double sw[4];     /* sum w */
    double sx[3][4];  /* sum w x_ij */
    double sxx[6][4]; /* sum w x_ij x_ij^T */
} pfsph_pair_sums;

/* Adds hits e < n (n a multiple of 4; padding entries have sc = w = 0) to the sums: sc[e] x_ij
 * always, S if vir, the w sums if filter. */
void pfsph__sums_pair(int n, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                      const pfsph_real *restrict dz, const double *restrict sc, const pfsph_real *restrict w,
                      int filter, int vir, pfsph_pair_sums *restrict P);

/* cos x for 0 <= x <= 2 pi in float arithmetic, absolute error below 2e-7 (test_hits): the
 * quadrant q = round(x / (pi/2)), x - q pi/2 in [-pi/4, pi/4] with pi/2 in two parts (q times the first exact), and the
 * Taylor series of cos and sin to the 8th and 9th power (truncation error < 3e-8 there).
 * Plain arithmetic and selects, so it vectorises and rounds alike in every clone of
 * pair_terms.c (compiled with -ffp-contract=off) and in scalar code compiled the same way. */
static inline float pfsph__cos_pair(float x)
{
    const float q = __builtin_floorf(x * 0.636619772f + 0.5f);
    const float y = (x - q * 1.5703125f) - q * 4.83826795e-4f;
    const float y2 = y * y;
    const float c = 1.0f + y2 * (-0.5f + y2 * (4.16666667e-2f + y2 * (-1.38888889e-3f + y2 * 2.48015873e-5f)));
    const float s =
        y + y * y2 * (-1.66666667e-1f + y2 * (8.33333333e-3f + y2 * (-1.98412698e-4f + y2 * 2.75573192e-6f)));
    const float v = q == 1.0f || q == 3.0f ? s : c;
    return q == 1.0f || q == 2.0f ? -v : v;
}

/* For the pair forces (pairwise.c): per hit e with r2[e] > 0, cr[e] = cos(U_R r) / r with
 * r = sqrt((double) r2[e]) (the cosine of Eq. 5 over r: times c m_j x_ij it is the pair
 * acceleration); entries with r2[e] = 0 are not finite and must be skipped. */
void pfsph__terms_pair_cos(double U_R, int n, const pfsph_real *restrict r2, double *restrict cr);

/* The same times the pair's coefficient, for one coefficient per phase of j: sc[e] = cf[e] cr[e]
 * with cf[e] = coef[phase[jj[e]]] (cf: scratch of n entries) where r2[e] > 0 and cf[e] is not 0,
 * else 0; w (if not NULL): w[e] set to 0 where r2[e] = 0 (r = 0 has no direction and is not in
 * Eq. 7's sum). */
void pfsph__terms_pair_sc(double U_R, const double *restrict coef, const uint8_t *restrict phase, int n,
                          const uint32_t *restrict jj, const pfsph_real *restrict r2, double *restrict cf,
                          double *restrict sc, pfsph_real *restrict w);

/* The interactive mode's sums in eight lanes (pcisph_lists.c, viscosity.c's list walk): entry q
 * of n goes to lane q % 8 and the lanes are added in a fixed tree, so the bits are the same on
 * every CPU and thread count, but not those of a sum in the entries' order (the physical mode
 * never calls these). pfsph__lanes_sum: the sum of w; pfsph__lanes_sx: out = sum s x_ij;
 * pfsph__lanes_pressure: out = sum (pi + pn[idx[q]]) cw[q] x_ij (the pressure pass's terms).
 * The arrays but idx and pn must have 7 readable entries past n (their values do not matter). */
pfsph_real pfsph__lanes_sum(int n, const pfsph_real *restrict w);
void pfsph__lanes_sx(int n, const pfsph_real *restrict s, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                     const pfsph_real *restrict dz, pfsph_real out[3]);
void pfsph__lanes_pressure(int n, const uint32_t *restrict idx, const pfsph_real *restrict pn, pfsph_real pi,
                           const pfsph_real *restrict cw, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                           const pfsph_real *restrict dz, pfsph_real out[3]);

/* The interactive mode's pair pass in the particles' precision (pairwise.c, the list walk):
 * sc as pfsph__terms_pair_sc computes it, in pfsph_real, with coef in pfsph_real; and the pair
 * sums of pfsph__sums_pair (no virial) in eight lanes of pfsph_real, n a multiple of 8 (padding
 * entries zero), lanes added by pfsph__lanes8 in a fixed tree: the same bits on every CPU and
 * thread count, not those of the physical mode's double sums. */
typedef struct pfsph_pair_sums_r {
    pfsph_real acc[3][8];
    pfsph_real sw[8];
    pfsph_real sx[3][8];
    pfsph_real sxx[6][8];
} pfsph_pair_sums_r;
void pfsph__terms_pair_sc_r(pfsph_real U_R, const pfsph_real *restrict coef, const uint8_t *restrict phase, int n,
                            const uint32_t *restrict jj, const pfsph_real *restrict r2, pfsph_real *restrict cf,
                            pfsph_real *restrict sc, pfsph_real *restrict w);
void pfsph__sums_pair_r(int n, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                        const pfsph_real *restrict dz, const pfsph_real *restrict sc, const pfsph_real *restrict w,
                        int filter, pfsph_pair_sums_r *restrict P);
static inline pfsph_real pfsph__lanes8(const pfsph_real l[8])
{
    return ((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]));
}

#endif
