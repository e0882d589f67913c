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
void pfsph__terms_pair_cos(double U_R, int n, const pfsph_real *restrict r2, double *restrict cr)
{
    for (int e = 0; e < n; e++) {
        const double r = __builtin_sqrt((double)r2[e]);
        cr[e] = (double)pfsph__cos_pair((float)(U_R * r)) / r;
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

PFSPH__CLONES
void pfsph__sums_pair(int n, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                      const pfsph_real *restrict dz, const double *restrict sc, const pfsph_real *restrict w,
                      int filter, int vir, pfsph_pair_sums *restrict P)
{
    pfsph_pair_sums L = *P;
    for (int e = 0; e < n; e += 4)
        for (int l = 0; l < 4; l++) {
            const double x = (double)dx[e + l], y = (double)dy[e + l], z = (double)dz[e + l], s = sc[e + l];
            L.acc[0][l] += s * x;
            L.acc[1][l] += s * y;
            L.acc[2][l] += s * z;
        }
    if (vir)
        for (int e = 0; e < n; e += 4)
            for (int l = 0; l < 4; l++) {
                const double x = (double)dx[e + l], y = (double)dy[e + l], z = (double)dz[e + l], s = sc[e + l];
                L.S[0][l] += s * x * x;
                L.S[1][l] += s * x * y;
                L.S[2][l] += s * x * z;
                L.S[3][l] += s * y * y;
                L.S[4][l] += s * y * z;
                L.S[5][l] += s * z * z;
            }
    if (filter)
        for (int e = 0; e < n; e += 4)
            for (int l = 0; l < 4; l++) {
                const double x = (double)dx[e + l], y = (double)dy[e + l], z = (double)dz[e + l], v = (double)w[e + l];
                L.sw[l] += v;
                L.sx[0][l] += v * x;
                L.sx[1][l] += v * y;
                L.sx[2][l] += v * z;
                L.sxx[0][l] += v * x * x;
                L.sxx[1][l] += v * x * y;
                L.sxx[2][l] += v * x * z;
                L.sxx[3][l] += v * y * y;
                L.sxx[4][l] += v * y * z;
                L.sxx[5][l] += v * z * z;
            }
    *P = L;
}
