/* The decomposition's global sum (src/mpi/decomp.c) gives the bits of the serial pfsph__sum for
 * any cut: run under mpirun (label mpi). Frames and stats.csv print too few digits to see a sum
 * added in another order, so this checks the sum itself: arrays of mixed magnitudes (where the
 * order of additions shows in the last bits), lengths around the 4096-value blocks, cuts inside
 * blocks, on block edges and empty ranks. A sum of per-rank partials fails it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/reduce.h"
#include "mpi/decomp.h"

static uint64_t rng = 88172645463325252ull;
static double next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    pfsph_decomp D;
    if (pfsph_decomp_init(&D, MPI_COMM_WORLD)) {
        fprintf(stderr, "init failed\n");
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    const size_t lens[] = {1, 100, 4095, 4096, 4097, 8192 + 3, 3 * 4096, 50001};
    int bad = 0, cases = 0, differs_naive = 0;
    for (size_t li = 0; li < sizeof lens / sizeof lens[0]; li++) {
        const size_t N = lens[li];
        pfsph_real *a = malloc(N * sizeof(pfsph_real));
        for (size_t i = 0; i < N; i++) /* magnitudes over 8 decades: rounding shows the order */
            a[i] = (pfsph_real)(next() * pow(10.0, 8.0 * next() - 4.0));
        const double want = pfsph__sum(a, N);
        for (int cutkind = 0; cutkind < 4; cutkind++) {
            /* the same cut on every rank (the same generator state) */
            D.gofs[0] = 0;
            for (int q = 1; q < D.size; q++) {
                uint64_t g;
                if (cutkind == 0) g = (uint64_t)N * (uint64_t)q / (uint64_t)D.size;                      /* even */
                else if (cutkind == 1) g = (uint64_t)(next() * (double)N);                               /* anywhere */
                else if (cutkind == 2) g = ((uint64_t)N * (uint64_t)q / (uint64_t)D.size) / 4096 * 4096; /* edges */
                else g = q == 1 ? 0 : (uint64_t)N; /* empty ranks */
                D.gofs[q] = g < D.gofs[q - 1] ? D.gofs[q - 1] : g;
            }
            D.gofs[D.size] = N;
            D.d.nglobal = N;
            const uint64_t G = D.gofs[D.rank], m = D.gofs[D.rank + 1] - G;
            D.d.own_lo = 0;
            D.d.own_hi = (size_t)m;
            const double got = D.d.sum(&D.d, a + G);
            double part = 0, naive = 0; /* what a sum of per-rank partials would give */
            for (uint64_t i = 0; i < m; i++) part += (double)a[G + i];
            MPI_Allreduce(&part, &naive, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
            differs_naive += memcmp(&naive, &want, sizeof want) != 0;
            cases++;
            if (memcmp(&got, &want, sizeof want)) {
                bad++;
                if (D.rank == 0)
                    fprintf(stderr, "N %zu cut %d: got %.17g, the serial sum %.17g\n", N, cutkind, got, want);
            }
        }
        free(a);
    }
    if (D.rank == 0)
        printf("%d cases on %d ranks: %d differ from the serial sum (a sum of per-rank partials differs in %d)\n",
               cases, D.size, bad, differs_naive);
    MPI_Finalize();
    return bad ? 1 : 0;
}
