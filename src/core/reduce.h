/* Reductions with the same bits for any thread count. */
#ifndef PFSPH_REDUCE_H
#define PFSPH_REDUCE_H

#include <stddef.h>

#include "pfsph/types.h"

/* Deterministic sum (fixed blocks, serial combination): same bits for any thread count. */
double pfsph__sum(const pfsph_real *a, size_t n);

#endif
