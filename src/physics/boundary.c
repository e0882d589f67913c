/* Akinci 2012 boundary volumes (the boundary terms of density, pressure and friction are
 * fused into those loops: density.c, pressure.c, viscosity.c). */
#include "physics/boundary.h"

void pfsph__boundary_volumes(pfsph_particles *b, const pfsph_grid *bg, const pfsph_kernel *k)
{
    const pfsph_real h2 = k->h * k->h;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < b->n; i++) {
        if (b->aux[i] > 0) continue; /* volume given (multi-layer walls) */
        pfsph_ranges r;
        pfsph_grid_ranges(bg, b->x[i], b->y[i], b->z[i], &r);
        double s = 0;
        for (int q = 0; q < r.n; q++)
            for (uint32_t j = r.b[q]; j < r.e[q]; j++) {
                pfsph_real dx = b->x[i] - b->x[j], dy = b->y[i] - b->y[j], dz = b->z[i] - b->z[j];
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 < h2) s += pfsph_kernel_w(k, pfsph_sqrt(r2));
            }
        b->aux[i] = (pfsph_real)(1.0 / s);
    }
}
