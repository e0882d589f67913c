/* Pairwise interaction forces (Yang et al., PF-SPH, Sections 3-4): cosine pair force over an
 * enlarged radius k*h (Eqs. 3, 5, 6), anisotropic filtering (Eqs. 7-12), coefficients from
 * surface tension and contact angle targets (Eqs. 13-21). */
#ifndef PFSPH_PAIRWISE_H
#define PFSPH_PAIRWISE_H

#include <stdbool.h>

#include "pfsph/types.h"

typedef struct pfsph_pairwise_params {
    bool enabled;
    double k;         /* radius enlargement, default (80/30)^(1/3) (Eq. 5) */
    bool filter;      /* anisotropic filter on (Eq. 12) */
    double eta;       /* Eq. 11, default 0.2 */
    double eps_min;   /* Eq. 8 clamp on normalised eigenvalues, default 0.5 */
    /* Coefficient matrix c[a][b] over scene phases (solids included), symmetric, >= 0. */
    double c[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* Targets as written in the scene; resolved into c by pfsph_pairwise_resolve. */
    bool sigma_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    double sigma[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];   /* N/m (2D: N) */
    bool angle_set[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    double angle_deg[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
} pfsph_pairwise_params;

void pfsph_pairwise_defaults(pfsph_pairwise_params *p);

#endif
