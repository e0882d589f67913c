/* Reductions with the same bits for any thread count. */
#ifndef PFSPH_REDUCE_H
#define PFSPH_REDUCE_H

#include <stddef.h>

#include "pfsph/types.h"

/* Deterministic sum (fixed blocks, serial combination): same bits for any thread count. A pass
 * that sums as it goes gets the same bits with a double per block of PFSPH_SUM_BLOCK values,
 * each summed from 0 in order, then the blocks' sums added to 0 in order; a distributed run
 * reproduces that order (src/mpi/decomp.c). */
enum { PFSPH_SUM_BLOCK = 4096 };
double pfsph__sum(const pfsph_real *a, size_t n);

#endif
