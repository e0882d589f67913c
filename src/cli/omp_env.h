/* OpenMP's wait policy for programs (pfsph, bench, time_to_solution). libgomp's default spins
 * a waiting thread for about 300,000 iterations at every barrier: on a machine shared with
 * other work a thread that is not scheduled stalls its partner's spin, and a 2-thread run of
 * the 7k dam break took 142 s instead of 8.5 s (docs/benchmarks.md, "OpenMP wait policy").
 * A spin count of 1,000 keeps most of the spinning's gain on an idle machine and does not
 * collapse under load. libgomp reads its settings before main, so the program sets them and
 * starts itself again. */
#ifndef PFSPH_OMP_ENV_H
#define PFSPH_OMP_ENV_H

/* Call first in main. When the environment sets none of OMP_WAIT_POLICY, GOMP_SPINCOUNT (the
 * user's choice wins) and PFSPH_OMP_DEFAULTED (already done), sets GOMP_SPINCOUNT=1000 and
 * PFSPH_OMP_DEFAULTED=1 and executes /proc/self/exe with argv again. Returns only when it did
 * not (already set, or no /proc: the run goes on with libgomp's default). Linux. */
void pfsph_omp_wait_default(char **argv);

#endif
