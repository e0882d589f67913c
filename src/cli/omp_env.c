/* OpenMP's wait policy for programs (omp_env.h): part of the program, never of the library. */
#include "cli/omp_env.h"

#include <stdlib.h>
#include <unistd.h>

void pfsph_omp_wait_default(char **argv)
{
    if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT") || getenv("PFSPH_OMP_DEFAULTED")) return;
    if (setenv("PFSPH_OMP_DEFAULTED", "1", 1) || setenv("GOMP_SPINCOUNT", "1000", 1)) return;
    execv("/proc/self/exe", argv);
    unsetenv("GOMP_SPINCOUNT"); /* not started again: say nothing false to child processes */
}
