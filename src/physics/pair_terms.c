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
/* AVX-512DQ adds the 64-bit multiply (vpmullq) that the thermostat's pair hash needs; integer
 * operations only, so the clones give the same bits */
#define PFSPH__CLONES_DQ __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define PFSPH__CLONES
#define PFSPH__CLONES_DQ
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
void pfsph__terms_w_dwr(const pfsph_kernel *kk, const pfsph_kernel *k, int n, const pfsph_real *restrict r2,
                        pfsph_real *restrict wk, pfsph_real *restrict w, pfsph_real *restrict dw)
{
    /* pfsph__terms_w with kk and k and pfsph__terms_dwr with k from one sqrt: the same bits */
    const pfsph_kernel KK = *kk, K = *k;
    if (wk && dw)
        for (int e = 0; e < n; e++) {
            const pfsph_real r = pfsph_sqrt(r2[e]);
            wk[e] = pfsph_kernel_w(&KK, r);
            w[e] = pfsph_kernel_w(&K, r);
            dw[e] = pfsph_kernel_dw_r(&K, r);
        }
    else if (wk)
        for (int e = 0; e < n; e++) {
            const pfsph_real r = pfsph_sqrt(r2[e]);
            wk[e] = pfsph_kernel_w(&KK, r);
            w[e] = pfsph_kernel_w(&K, r);
        }
    else if (dw)
        for (int e = 0; e < n; e++) {
            const pfsph_real r = pfsph_sqrt(r2[e]);
            w[e] = pfsph_kernel_w(&K, r);
            dw[e] = pfsph_kernel_dw_r(&K, r);
        }
    else
        for (int e = 0; e < n; e++) w[e] = pfsph_kernel_w(&K, pfsph_sqrt(r2[e]));
}

PFSPH__CLONES
void pfsph__terms_list_wdw(const pfsph_kernel *k, pfsph_real h2, int n, const uint32_t *restrict idx,
                           const pfsph_real *restrict tx, const pfsph_real *restrict ty, const pfsph_real *restrict tz,
                           pfsph_real x, pfsph_real y, pfsph_real z, const pfsph_real *restrict aux,
                           pfsph_real *restrict cx, pfsph_real *restrict cy, pfsph_real *restrict cz,
                           pfsph_real *restrict cw, pfsph_real *restrict w)
{
    /* pcisph_lists.c's gather of x_ij (scalar: the compiler does not vectorise the indexed
     * loads), then pfsph__terms_w and pfsph__terms_dwr from one sqrt with the mask beyond h in
     * one vector loop; with aux, the products aux_j w and aux_j dW/r the passes formed from the
     * masked terms (rounded once, as there) */
    pfsph_real r2[PFSPH_LIST_TERMS_MAX], a[PFSPH_LIST_TERMS_MAX];
    for (int q = 0; q < n; q++) {
        const int32_t j = (int32_t)idx[q]; /* signed: a vector gather where the clone has one */
        const pfsph_real dx = x - tx[j], dy = y - ty[j], dz = z - tz[j];
        cx[q] = dx;
        cy[q] = dy;
        cz[q] = dz;
        r2[q] = dx * dx + dy * dy + dz * dz;
    }
    const pfsph_kernel K = *k;
    if (aux) {
        for (int q = 0; q < n; q++) a[q] = aux[(int32_t)idx[q]];
        for (int q = 0; q < n; q++) {
            const pfsph_real r = pfsph_sqrt(r2[q]);
            const pfsph_real wq = r2[q] < h2 ? pfsph_kernel_w(&K, r) : 0;
            const pfsph_real dq = r2[q] < h2 ? pfsph_kernel_dw_r(&K, r) : 0;
            w[q] = a[q] * wq;
            cw[q] = a[q] * dq;
        }
    } else
        for (int q = 0; q < n; q++) {
            const pfsph_real r = pfsph_sqrt(r2[q]);
            w[q] = r2[q] < h2 ? pfsph_kernel_w(&K, r) : 0;
            cw[q] = r2[q] < h2 ? pfsph_kernel_dw_r(&K, r) : 0;
        }
}

PFSPH__CLONES
void pfsph__terms_visc_pressure(const pfsph_pair_in *restrict in, int n, const uint32_t *restrict jj,
                                const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                                const pfsph_real *restrict dz, const pfsph_real *restrict r2, pfsph_real *restrict dw,
                                pfsph_real *restrict sv, pfsph_real *restrict sp)
{
    const pfsph_kernel K = in->k;
    const pfsph_real *restrict vx = in->vx, *restrict vy = in->vy, *restrict vz = in->vz, *restrict nd = in->nd,
                               *restrict p = in->p, *restrict nuj = in->nuj;
    const pfsph_real vxi = in->vxi, vyi = in->vyi, vzi = in->vzi, pi = in->pi, eps = in->eps, ndi = in->ndi;
    for (int e = 0; e < n; e++) {
        const uint32_t j = jj[e];
        const pfsph_real dwr = pfsph_kernel_dw_r(&K, pfsph_sqrt(r2[e]));
        dw[e] = dwr;
        /* viscosity.c visc_pair: 2 nu_ij / (delta_i + delta_j) (v_ij . x_ij) / (r2 + eps) dW/r */
        const pfsph_real nu = nuj[e];
        const pfsph_real vdx = (vxi - vx[j]) * dx[e] + (vyi - vy[j]) * dy[e] + (vzi - vz[j]) * dz[e];
        sv[e] = 2 * nu / (ndi + nd[j]) * vdx / (r2[e] + eps) * dwr;
        /* pressure.c: (p_i / delta_i^2 + p_j / delta_j^2) dW/r */
        sp[e] = (pi + p[j] / (nd[j] * nd[j])) * dwr;
    }
}

PFSPH__CLONES
void pfsph__terms_visc_list(const pfsph_pair_in *restrict in, const pfsph_real *restrict x,
                            const pfsph_real *restrict y, const pfsph_real *restrict z, const uint8_t *restrict phase,
                            const pfsph_real *restrict nu_row, pfsph_real xi, pfsph_real yi, pfsph_real zi, int n,
                            const uint32_t *restrict jj, const pfsph_real *restrict dw, pfsph_real *restrict dx,
                            pfsph_real *restrict dy, pfsph_real *restrict dz, pfsph_real *restrict sv)
{
    /* the gather apart (scalar), then viscosity.c visc_pair's factor in a vector loop */
    pfsph_real r2[PFSPH_LIST_TERMS_MAX], nuj[PFSPH_LIST_TERMS_MAX];
    for (int e = 0; e < n; e++) {
        const int32_t j = (int32_t)jj[e]; /* signed: a vector gather where the clone has one */
        const pfsph_real ex = xi - x[j], ey = yi - y[j], ez = zi - z[j];
        dx[e] = ex;
        dy[e] = ey;
        dz[e] = ez;
        r2[e] = ex * ex + ey * ey + ez * ez;
        nuj[e] = nu_row[phase[j]];
    }
    const pfsph_real *restrict vx = in->vx, *restrict vy = in->vy, *restrict vz = in->vz, *restrict nd = in->nd;
    const pfsph_real vxi = in->vxi, vyi = in->vyi, vzi = in->vzi, eps = in->eps, ndi = in->ndi;
    for (int e = 0; e < n; e++) {
        const int32_t j = (int32_t)jj[e];
        const pfsph_real nu = nuj[e];
        const pfsph_real vdx = (vxi - vx[j]) * dx[e] + (vyi - vy[j]) * dy[e] + (vzi - vz[j]) * dz[e];
        sv[e] = 2 * nu / (ndi + nd[j]) * vdx / (r2[e] + eps) * dw[e];
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
void pfsph__terms_pair_sc(double U_R, const double *restrict coef, const uint8_t *restrict phase, int n,
                          const uint32_t *restrict jj, const pfsph_real *restrict r2, double *restrict cf,
                          double *restrict sc, pfsph_real *restrict w)
{
    /* the gather apart, so that the arithmetic loop vectorises */
    for (int e = 0; e < n; e++) cf[e] = coef[phase[jj[e]]];
    for (int e = 0; e < n; e++) {
        const double r = __builtin_sqrt((double)r2[e]);
        const double cr = (double)pfsph__cos_pair((float)(U_R * r)) / r;
        sc[e] = r2[e] > 0 && cf[e] != 0.0 ? cf[e] * cr : 0.0;
    }
    if (w)
        for (int e = 0; e < n; e++) w[e] = r2[e] > 0 ? w[e] : 0;
}

PFSPH__CLONES
void pfsph__terms_pair_sc_cf(double U_R, int n, const double *restrict cf, const pfsph_real *restrict r2,
                             double *restrict sc, pfsph_real *restrict w)
{
    /* pfsph__terms_pair_sc's arithmetic loop with the coefficients given */
    for (int e = 0; e < n; e++) {
        const double r = __builtin_sqrt((double)r2[e]);
        const double cr = (double)pfsph__cos_pair((float)(U_R * r)) / r;
        sc[e] = r2[e] > 0 && cf[e] != 0.0 ? cf[e] * cr : 0.0;
    }
    if (w)
        for (int e = 0; e < n; e++) w[e] = r2[e] > 0 ? w[e] : 0;
}

PFSPH__CLONES_DQ
void pfsph__terms_theta(uint64_t key, uint32_t idi, int n, const uint32_t *restrict idj, double *restrict theta)
{
    /* pfsph_thermo_theta, lane by lane: 64-bit multiplies (emulated from 32-bit ones where the
     * CPU lacks them) and the exact 53-bit integer to double conversion of pfsph__u53_double */
    for (int e = 0; e < n; e++) {
        const uint64_t lo = idi < idj[e] ? idi : idj[e], hi = idi < idj[e] ? idj[e] : idi;
        const uint64_t z = pfsph__mix64(key ^ pfsph__mix64((lo << 32) | hi));
        theta[e] = 1.7320508075688772 * (pfsph__u53_double(z >> 11) * (2.0 / 9007199254740992.0) - 1.0);
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

/* Four doubles as one value: the lanes of the pair sums. GNU C vector extensions (gcc, clang)
 * keep the lanes apart lane by lane, so each lane is the scalar expression in the scalar order;
 * the compiler's own vectoriser built these vectors from scalars and shuffles (perf). */
typedef double pf__v4d __attribute__((vector_size(32)));

/* loads and stores as macros: a function returning a vector outside the clones' targets would
 * change the ABI (-Wpsabi) */
#define LD4D(v, p) __builtin_memcpy(&(v), (p), sizeof(pf__v4d))
#define ST4D(p, v) __builtin_memcpy((p), &(v), sizeof(pf__v4d))
#ifdef PFSPH_DOUBLE
#define LD4R(v, p) LD4D(v, p)
#else
typedef float pf__v4f __attribute__((vector_size(16)));
/* four floats as doubles (exact) */
#define LD4R(v, p)                                  \
    do {                                            \
        pf__v4f f_;                                 \
        __builtin_memcpy(&f_, (p), sizeof f_);      \
        (v) = __builtin_convertvector(f_, pf__v4d); \
    } while (0)
#endif

PFSPH__CLONES
void pfsph__sums_pair(int n, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                      const pfsph_real *restrict dz, const double *restrict sc, const pfsph_real *restrict w,
                      int filter, int vir, pfsph_pair_sums *restrict P)
{
    /* lane l of each vector is hit e + l: acc[a][l] += sc x, in e's order (pair_terms.h) */
    pf__v4d a0, a1, a2;
    LD4D(a0, P->acc[0]);
    LD4D(a1, P->acc[1]);
    LD4D(a2, P->acc[2]);
    if (vir) {
        pf__v4d S0, S1, S2, S3, S4, S5;
        LD4D(S0, P->S[0]);
        LD4D(S1, P->S[1]);
        LD4D(S2, P->S[2]);
        LD4D(S3, P->S[3]);
        LD4D(S4, P->S[4]);
        LD4D(S5, P->S[5]);
        for (int e = 0; e < n; e += 4) {
            pf__v4d x, y, z, s;
            LD4R(x, dx + e);
            LD4R(y, dy + e);
            LD4R(z, dz + e);
            LD4D(s, sc + e);
            a0 += s * x;
            a1 += s * y;
            a2 += s * z;
            S0 += s * x * x;
            S1 += s * x * y;
            S2 += s * x * z;
            S3 += s * y * y;
            S4 += s * y * z;
            S5 += s * z * z;
        }
        ST4D(P->S[0], S0), ST4D(P->S[1], S1), ST4D(P->S[2], S2);
        ST4D(P->S[3], S3), ST4D(P->S[4], S4), ST4D(P->S[5], S5);
    } else {
        for (int e = 0; e < n; e += 4) {
            pf__v4d x, y, z, s;
            LD4R(x, dx + e);
            LD4R(y, dy + e);
            LD4R(z, dz + e);
            LD4D(s, sc + e);
            a0 += s * x;
            a1 += s * y;
            a2 += s * z;
        }
    }
    ST4D(P->acc[0], a0), ST4D(P->acc[1], a1), ST4D(P->acc[2], a2);
    if (filter) {
        pf__v4d sw, x0, x1, x2;
        LD4D(sw, P->sw);
        LD4D(x0, P->sx[0]);
        LD4D(x1, P->sx[1]);
        LD4D(x2, P->sx[2]);
        pf__v4d q0, q1, q2, q3, q4, q5;
        LD4D(q0, P->sxx[0]);
        LD4D(q1, P->sxx[1]);
        LD4D(q2, P->sxx[2]);
        LD4D(q3, P->sxx[3]);
        LD4D(q4, P->sxx[4]);
        LD4D(q5, P->sxx[5]);
        for (int e = 0; e < n; e += 4) {
            pf__v4d x, y, z, v;
            LD4R(x, dx + e);
            LD4R(y, dy + e);
            LD4R(z, dz + e);
            LD4R(v, w + e);
            sw += v;
            x0 += v * x;
            x1 += v * y;
            x2 += v * z;
            q0 += v * x * x;
            q1 += v * x * y;
            q2 += v * x * z;
            q3 += v * y * y;
            q4 += v * y * z;
            q5 += v * z * z;
        }
        ST4D(P->sw, sw), ST4D(P->sx[0], x0), ST4D(P->sx[1], x1), ST4D(P->sx[2], x2);
        ST4D(P->sxx[0], q0), ST4D(P->sxx[1], q1), ST4D(P->sxx[2], q2);
        ST4D(P->sxx[3], q3), ST4D(P->sxx[4], q4), ST4D(P->sxx[5], q5);
    }
}

/* The interactive mode's eight-lane sums (pair_terms.h): entry q of n goes to lane q % 8, the
 * lanes are added in a fixed tree, so every clone and thread count gives the same bits (the
 * association is the source's, not the vector width's). GCC's vector type (plain arrays of
 * accumulators were not kept in registers); the last, partial vector is read whole and its
 * lanes past n masked to 0 (x + 0 = x; whatever those entries hold, even not finite), so the
 * inputs need 7 readable entries past n. */
#define PF__LANES 8
typedef pfsph_real pf__v8r __attribute__((vector_size(PF__LANES * sizeof(pfsph_real))));
#ifdef PFSPH_DOUBLE
typedef int64_t pf__v8m __attribute__((vector_size(PF__LANES * sizeof(pfsph_real))));
#else
typedef int32_t pf__v8m __attribute__((vector_size(PF__LANES * sizeof(pfsph_real))));
#endif
#define LD8(v, p) __builtin_memcpy(&(v), (p), sizeof(pf__v8r))
/* lanes 0..7 of l added in a fixed tree; v with its lanes >= r set to 0 (macros: a function
 * taking or returning a vector changes the ABI in the baseline clone) */
#define LANES8(l) ((((l)[0] + (l)[1]) + ((l)[2] + (l)[3])) + (((l)[4] + (l)[5]) + ((l)[6] + (l)[7])))
#define MASK8(v, r) ((pf__v8r)((pf__v8m)(v) & ((pf__v8m){0, 1, 2, 3, 4, 5, 6, 7} < (r))))

PFSPH__CLONES
pfsph_real pfsph__lanes_sum(int n, const pfsph_real *restrict w)
{
    pf__v8r a = {0};
    int e = 0;
    for (; e + PF__LANES <= n; e += PF__LANES) {
        pf__v8r v;
        LD8(v, w + e);
        a += v;
    }
    if (e < n) {
        pf__v8r v;
        LD8(v, w + e);
        a += MASK8(v, n - e);
    }
    return LANES8(a);
}

PFSPH__CLONES
void pfsph__lanes_sx(int n, const pfsph_real *restrict s, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                     const pfsph_real *restrict dz, pfsph_real out[3])
{
    pf__v8r ax = {0}, ay = {0}, az = {0};
    for (int e = 0; e < n; e += PF__LANES) {
        pf__v8r v, x, y, z;
        LD8(v, s + e);
        LD8(x, dx + e);
        LD8(y, dy + e);
        LD8(z, dz + e);
        if (n - e < PF__LANES) {
            v = MASK8(v, n - e);
            x = MASK8(x, n - e);
            y = MASK8(y, n - e);
            z = MASK8(z, n - e);
        }
        ax += v * x;
        ay += v * y;
        az += v * z;
    }
    out[0] = LANES8(ax);
    out[1] = LANES8(ay);
    out[2] = LANES8(az);
}

PFSPH__CLONES
void pfsph__lanes_pressure(int n, const uint32_t *restrict idx, const pfsph_real *restrict pn, pfsph_real pi,
                           const pfsph_real *restrict cw, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                           const pfsph_real *restrict dz, pfsph_real out[3])
{
    /* the gather lane by lane: a loop's vector gather with its remainder cost more at ~35
     * entries a particle (callgrind) */
    pf__v8r ax = {0}, ay = {0}, az = {0};
    for (int e = 0; e < n; e += PF__LANES) {
        const uint32_t *q = idx + e;
        pf__v8r g;
        if (n - e >= PF__LANES)
            g = (pf__v8r){pn[q[0]], pn[q[1]], pn[q[2]], pn[q[3]], pn[q[4]], pn[q[5]], pn[q[6]], pn[q[7]]};
        else
            for (int l = 0; l < PF__LANES; l++) g[l] = l < n - e ? pn[q[l]] : 0;
        pf__v8r w, x, y, z;
        LD8(w, cw + e);
        LD8(x, dx + e);
        LD8(y, dy + e);
        LD8(z, dz + e);
        if (n - e < PF__LANES) {
            w = MASK8(w, n - e);
            x = MASK8(x, n - e);
            y = MASK8(y, n - e);
            z = MASK8(z, n - e);
        }
        const pf__v8r s = (pi + g) * w;
        ax += s * x;
        ay += s * y;
        az += s * z;
    }
    out[0] = LANES8(ax);
    out[1] = LANES8(ay);
    out[2] = LANES8(az);
}

PFSPH__CLONES
void pfsph__terms_pair_sc_r(pfsph_real U_R, const pfsph_real *restrict coef, const uint8_t *restrict phase, int n,
                            const uint32_t *restrict jj, const pfsph_real *restrict r2, pfsph_real *restrict cf,
                            pfsph_real *restrict sc, pfsph_real *restrict w)
{
    for (int e = 0; e < n; e++) cf[e] = coef[phase[jj[e]]];
    for (int e = 0; e < n; e++) {
        const pfsph_real r = pfsph_sqrt(r2[e]);
        const pfsph_real cr = (pfsph_real)pfsph__cos_pair((float)(U_R * r)) / r;
        sc[e] = r2[e] > 0 && cf[e] != 0 ? cf[e] * cr : 0;
    }
    if (w)
        for (int e = 0; e < n; e++) w[e] = r2[e] > 0 ? w[e] : 0;
}

PFSPH__CLONES
void pfsph__sums_pair_r(int n, const pfsph_real *restrict dx, const pfsph_real *restrict dy,
                        const pfsph_real *restrict dz, const pfsph_real *restrict sc, const pfsph_real *restrict w,
                        int filter, pfsph_pair_sums_r *restrict P)
{
    /* lane l of each vector is hit e + l (n a multiple of 8) */
    pf__v8r a0, a1, a2;
    LD8(a0, P->acc[0]);
    LD8(a1, P->acc[1]);
    LD8(a2, P->acc[2]);
    for (int e = 0; e < n; e += PF__LANES) {
        pf__v8r x, y, z, s;
        LD8(x, dx + e);
        LD8(y, dy + e);
        LD8(z, dz + e);
        LD8(s, sc + e);
        a0 += s * x;
        a1 += s * y;
        a2 += s * z;
    }
    __builtin_memcpy(P->acc[0], &a0, sizeof a0);
    __builtin_memcpy(P->acc[1], &a1, sizeof a1);
    __builtin_memcpy(P->acc[2], &a2, sizeof a2);
    if (!filter) return;
    pf__v8r sw, x0, x1, x2, q0, q1, q2, q3, q4, q5;
    LD8(sw, P->sw);
    LD8(x0, P->sx[0]);
    LD8(x1, P->sx[1]);
    LD8(x2, P->sx[2]);
    LD8(q0, P->sxx[0]);
    LD8(q1, P->sxx[1]);
    LD8(q2, P->sxx[2]);
    LD8(q3, P->sxx[3]);
    LD8(q4, P->sxx[4]);
    LD8(q5, P->sxx[5]);
    for (int e = 0; e < n; e += PF__LANES) {
        pf__v8r x, y, z, v;
        LD8(x, dx + e);
        LD8(y, dy + e);
        LD8(z, dz + e);
        LD8(v, w + e);
        sw += v;
        x0 += v * x;
        x1 += v * y;
        x2 += v * z;
        q0 += v * x * x;
        q1 += v * x * y;
        q2 += v * x * z;
        q3 += v * y * y;
        q4 += v * y * z;
        q5 += v * z * z;
    }
    __builtin_memcpy(P->sw, &sw, sizeof sw);
    __builtin_memcpy(P->sx[0], &x0, sizeof x0);
    __builtin_memcpy(P->sx[1], &x1, sizeof x1);
    __builtin_memcpy(P->sx[2], &x2, sizeof x2);
    __builtin_memcpy(P->sxx[0], &q0, sizeof q0);
    __builtin_memcpy(P->sxx[1], &q1, sizeof q1);
    __builtin_memcpy(P->sxx[2], &q2, sizeof q2);
    __builtin_memcpy(P->sxx[3], &q3, sizeof q3);
    __builtin_memcpy(P->sxx[4], &q4, sizeof q4);
    __builtin_memcpy(P->sxx[5], &q5, sizeof q5);
}
