/* Kernel normalisation constants; the evaluation itself is inline in kernel.h. */
#include "pfsph/kernel.h"

#include <math.h>

void pfsph_kernel_init(pfsph_kernel *k, int dim, pfsph_real h)
{
    const double pi = 3.14159265358979323846;
    double hh = (double)h;
    double sigma = dim == 2 ? 40.0 / (7.0 * pi * hh * hh) : 8.0 / (pi * hh * hh * hh);
    k->dim = dim;
    k->h = h;
    k->inv_h = (pfsph_real)(1.0 / hh);
    k->sigma = (pfsph_real)sigma;
    k->gsigma = (pfsph_real)(sigma / hh);
}
