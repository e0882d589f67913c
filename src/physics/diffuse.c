/* Diffuse material (placeholder until the module lands). */
#include "pfsph/diffuse.h"

#include <string.h>

void pfsph_diffuse_defaults(pfsph_diffuse_params *p) { memset(p, 0, sizeof(*p)); }
