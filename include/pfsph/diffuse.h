/* Diffuse material (Liu et al.): spray, foam and bubbles generated from flow entropy and
 * advected one-way through the fluid velocity field. */
#ifndef PFSPH_DIFFUSE_H
#define PFSPH_DIFFUSE_H

#include <stdbool.h>

#include "pfsph/types.h"

typedef struct pfsph_diffuse_params {
    bool enabled;
} pfsph_diffuse_params;

void pfsph_diffuse_defaults(pfsph_diffuse_params *p);

#endif
