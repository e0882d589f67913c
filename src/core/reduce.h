/* Reductions with the same bits for any thread count. */
#ifndef PFSPH_REDUCE_H
#define PFSPH_REDUCE_H

#include <stddef.h>

#include "pfsph/types.h"

/* The blocks of pfsph__sum (a distributed run reproduces its order: src/mpi/decomp.c). */
enum { PFSPH_SUM_BLOCK = 4096 };

/* Deterministic sum (fixed blocks, serial combination): same bits for any thread count. */
double pfsph__sum(const pfsph_real *a, size_t n);

#endif
