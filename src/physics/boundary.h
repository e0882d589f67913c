/* Akinci et al. 2012 boundary particles: the volume each one stands for. */
#ifndef PFSPH_BOUNDARY_H
#define PFSPH_BOUNDARY_H

#include "pfsph/grid.h"
#include "pfsph/kernel.h"
#include "pfsph/particles.h"

/* Akinci et al. 2012 boundary particle volume V_b = 1 / sum_k W_bk over boundary particles,
 * written into b->aux for the particles whose aux is not already positive. */
void pfsph__boundary_volumes(pfsph_particles *b, const pfsph_grid *bg, const pfsph_kernel *k);

#endif
