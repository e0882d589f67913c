/* The process-wide decomposition pointer (pfsph/dist.h): NULL unless the program runs under MPI. */
#include "pfsph/dist.h"

pfsph_dist *pfsph__dist_process = NULL;
