/* The per-pair terms of the neighbour passes over a buffer of hits (core/hits.h), written as
 * plain loops that the compiler vectorises, once per instruction set: target_clones makes an
 * AVX-512, an AVX2 and a baseline (x86-64-v2) version and the loader picks one for the CPU
 * (docs/architecture.md, dispatch). Each term is the expression of the scalar pass, lane by
 * lane, and the passes add the terms one after another in the hits' order, so the sums are
 * the same bits on every CPU. Compiled with -ffp-contract=off (an AVX-512 target allows FMA),
 * -fno-math-errno (sqrtf as an instruction) and -fno-trapping-math (both kernel branches
 * evaluated and selected), none of which changes a value. */
#include "physics/pair_terms.h"

#include "pfsph/thermostat.h"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(PFSPH_SANITIZED)
#define PFSPH__CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define PFSPH__CLONES
#endif

PFSPH__CLONES
void pfsph__terms_w(const pfsph_kernel *k, int n, const pfsph_real *restrict r2, pfsph_real *restrict w)
{
    const pfsph_kernel K = *k;
    for (int e = 0; e < n; e++) w[e] = pfsph_kernel_w(&K, pfsph_sqrt(r2[e]));
}

PFSPH__CLONES
void pfsph__terms_dwr(const pfsph_kernel *k, int n, const pfsph_real *restrict r2, pfsph_real *restrict dw)
{
    const pfsph_kernel K = *k;
    for (int e = 0; e < n; e++) dw[e] = pfsph_kernel_dw_r(&K, pfsph_sqrt(r2[e]));
}

PFSPH__CLONES
void pfsph__terms_visc_pressure(const pfsph_pair_in *restrict in, int n, const uint32_t *restrict jj,
                                const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                                const pfsph_real *restrict dz, const pfsph_real *restrict r2,
                                pfsph_real *restrict dw, pfsph_real *restrict sv, pfsph_real *restrict sp)
{
    const pfsph_kernel K = in->k;
    const pfsph_real *restrict vx = in->vx, *restrict vy = in->vy, *restrict vz = in->vz, *restrict nd = in->nd,
                               *restrict p = in->p, *restrict nuj = in->nuj;
    const pfsph_real vxi = in->vxi, vyi = in->vyi, vzi = in->vzi, nui = in->nui, pi = in->pi, eps = in->eps;
    for (int e = 0; e < n; e++) {
        const uint32_t j = jj[e];
        const pfsph_real dwr = pfsph_kernel_dw_r(&K, pfsph_sqrt(r2[e]));
        dw[e] = dwr;
        /* viscosity.c visc_pair: nu / delta_j (v_ij . x_ij) / (r2 + eps) dW/r */
        const pfsph_real nu = (pfsph_real)0.5 * (nui + nuj[e]);
        const pfsph_real vdx = (vxi - vx[j]) * dx[e] + (vyi - vy[j]) * dy[e] + (vzi - vz[j]) * dz[e];
        sv[e] = nu / nd[j] * vdx / (r2[e] + eps) * dwr;
        /* pressure.c: (p_i / delta_i^2 + p_j / delta_j^2) dW/r */
        sp[e] = (pi + p[j] / (nd[j] * nd[j])) * dwr;
    }
}

PFSPH__CLONES
void pfsph__terms_thermo(double mi, double ndi, double eps, int n, const pfsph_real *restrict r2,
                         const pfsph_real *restrict dw, const double *restrict amp_ts, const double *restrict nu,
                         const double *restrict mj, const double *restrict ndj, const double *restrict theta,
                         double *restrict t)
{
    for (int e = 0; e < n; e++) {
        const double r2d = (double)r2[e];
        t[e] = pfsph__thermo_fluid(amp_ts[e], nu[e], mi, mj[e], ndi, ndj[e], r2d, (double)dw[e], eps,
                                   __builtin_sqrt(r2d), theta[e]);
    }
}
