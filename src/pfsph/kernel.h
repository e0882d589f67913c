/* SPH smoothing kernels. Cubic spline (Monaghan 1992) with compact support radius h (W = 0 for
 * r >= h), in 2D and 3D. All functions are inline: they sit in the innermost neighbour loops. */
#ifndef PFSPH_KERNEL_H
#define PFSPH_KERNEL_H

#include "pfsph/types.h"

typedef struct pfsph_kernel {
    int dim;      /* 2 or 3 */
    pfsph_real h; /* support radius [m] */
    pfsph_real inv_h;
    pfsph_real sigma;  /* normalisation: 40/(7 pi h^2) in 2D, 8/(pi h^3) in 3D */
    pfsph_real gsigma; /* sigma / h, for the derivative */
} pfsph_kernel;

void pfsph_kernel_init(pfsph_kernel *k, int dim, pfsph_real h);

/* W(r); r >= 0. */
static inline pfsph_real pfsph_kernel_w(const pfsph_kernel *k, pfsph_real r)
{
    pfsph_real q = r * k->inv_h;
    if (q >= (pfsph_real)1) return 0;
    if (q <= (pfsph_real)0.5) {
        pfsph_real q2 = q * q;
        return k->sigma * ((pfsph_real)6 * (q2 * q - q2) + (pfsph_real)1);
    }
    pfsph_real t = (pfsph_real)1 - q;
    return k->sigma * (pfsph_real)2 * t * t * t;
}

/* dW/dr divided by r, so that grad W(x_ij) = pfsph_kernel_dw_r(r) * x_ij. Finite at r -> 0
 * is not needed (callers skip r = 0: the gradient of the self term is zero). */
static inline pfsph_real pfsph_kernel_dw_r(const pfsph_kernel *k, pfsph_real r)
{
    pfsph_real q = r * k->inv_h;
    if (q >= (pfsph_real)1 || r <= (pfsph_real)0) return 0;
    pfsph_real g;
    if (q <= (pfsph_real)0.5) g = (pfsph_real)6 * ((pfsph_real)3 * q * q - (pfsph_real)2 * q);
    else {
        pfsph_real t = (pfsph_real)1 - q;
        g = (pfsph_real)-6 * t * t;
    }
    return k->gsigma * g / r;
}

/* W(0), the self contribution. */
static inline pfsph_real pfsph_kernel_w0(const pfsph_kernel *k) { return k->sigma; }

#endif
