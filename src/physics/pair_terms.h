/* Vectorised pair terms of the neighbour passes (pair_terms.c): per hit of a buffer, the
 * expressions the scalar passes evaluate, so that summing them in order gives the same bits. */
#ifndef PFSPH_PAIR_TERMS_H
#define PFSPH_PAIR_TERMS_H

#include "pfsph/kernel.h"

/* w[e] = pfsph_kernel_w(|x_ij|) from r2[e] = |x_ij|^2, e < n */
void pfsph__terms_w(const pfsph_kernel *k, int n, const pfsph_real *restrict r2, pfsph_real *restrict w);
/* dw[e] = pfsph_kernel_dw_r(|x_ij|) */
void pfsph__terms_dwr(const pfsph_kernel *k, int n, const pfsph_real *restrict r2, pfsph_real *restrict dw);

/* particle i and the fluid arrays, for pfsph__terms_visc_pressure */
typedef struct pfsph_pair_in {
    pfsph_kernel k;
    const pfsph_real *vx, *vy, *vz, *nd, *p;
    const pfsph_real *nuj; /* per hit: nu of j's phase */
    pfsph_real vxi, vyi, vzi, nui, pi, eps;
} pfsph_pair_in;

/* Per fluid hit e (index jj[e], x_ij, r2): dw[e] = dW/r, sv[e] the Morris viscosity factor
 * nu_ij / delta_j (v_ij . x_ij) / (r2 + eps) dW/r (viscosity.c), sp[e] the pressure factor
 * (p_i / delta_i^2 + p_j / delta_j^2) dW/r (pressure.c); the terms are sv x_ij, sp x_ij. */
void pfsph__terms_visc_pressure(const pfsph_pair_in *restrict in, int n, const uint32_t *restrict jj,
                                const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                                const pfsph_real *restrict dz, const pfsph_real *restrict r2,
                                pfsph_real *restrict dw, pfsph_real *restrict sv, pfsph_real *restrict sp);

/* Per fluid hit e of the thermostat (thermostat.h): t[e] = pfsph__thermo_fluid(amp_ts[e], nu[e],
 * mi, mj[e], ndi, ndj[e], r2[e], dw[e], eps, sqrt(r2[e]), theta[e]), the noise force over r,
 * for hits with r2 > 0 (others: not finite). */
void pfsph__terms_thermo(double mi, double ndi, double eps, int n, const pfsph_real *restrict r2,
                         const pfsph_real *restrict dw, const double *restrict amp_ts, const double *restrict nu,
                         const double *restrict mj, const double *restrict ndj, const double *restrict theta,
                         double *restrict t);

#endif
