/* The sparse cut (src/mpi/cut.c) gives the dense histogram's cut, offsets and removed count for
 * any key distribution: run under mpirun (label mpi). Keys spread, clustered in a few cells, all
 * in one cell, none at all, leaving the domain; grids from 1 cell to 1e6; coarse buckets from 1
 * (every cut refined, on the small grids) to more than the cells (one exact round); halo reaches from 0 to past the
 * grid. The frames cannot show a wrong cut (any cut agreed by every rank gives the same bytes),
 * so this compares the cut itself. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpi/cut.h"

static uint64_t rng = 88172645463325252ull;
static uint64_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

int main(int argc, char **argv)
{
    MPI_Init(&argc, &argv);
    int rank, size;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    const size_t ncs[] = {1, 7, 100, 4096, 100003, 1000003};
    const uint64_t buckets[] = {1, 3, 64, 1000, 1u << 17};
    const size_t offs[] = {0, 1, 57, 5000};
    int bad = 0, cases = 0, refined = 0;
    for (size_t a = 0; a < sizeof ncs / sizeof ncs[0]; a++)
        for (int kind = 0; kind < 5; kind++) {
            const size_t nc = ncs[a];
            /* each rank its own count and keys: the same generator, skipped by rank */
            size_t m = kind == 4 ? 0 : (size_t)(next() % 20000);
            uint32_t *key = malloc((m ? m : 1) * sizeof(uint32_t));
            uint64_t centre = next() % nc;
            for (int r = 0; r <= rank; r++)
                for (size_t i = 0; i < m; i++) {
                    uint64_t u = next();
                    uint32_t k;
                    if (kind == 0) k = (uint32_t)(u % nc);                                      /* spread */
                    else if (kind == 1) k = (uint32_t)((centre + (u % 7) * (nc / 7 + 1)) % nc); /* 7 cells */
                    else if (kind == 2) k = (uint32_t)centre;                                   /* one cell */
                    else k = (uint32_t)((centre + u % 50) % nc);                                /* a cluster */
                    if (u % 97 == 0) k = UINT32_MAX;                                            /* left the domain */
                    key[i] = k;
                }
            for (size_t b = 0; b < sizeof buckets / sizeof buckets[0]; b++) {
                if (nc / buckets[b] > 5000) continue; /* round 2 counts windows of 2 nc / buckets cells */
                for (size_t o = 0; o < sizeof offs / sizeof offs[0]; o++) {
                    pfsph_cut S, E;
                    if (pfsph_cut_init(&S, size, buckets[b]) || pfsph_cut_init(&E, size, 1))
                        MPI_Abort(MPI_COMM_WORLD, 1);
                    int rc = pfsph_cut_compute(&S, MPI_COMM_WORLD, key, m, nc, offs[o]);
                    pfsph_cut_dense(&E, MPI_COMM_WORLD, key, m, nc, offs[o]);
                    int diff = rc || S.removed != E.removed || S.total != E.total;
                    for (int q = 0; q <= size; q++) diff |= S.cut[q] != E.cut[q] || S.gofs[q] != E.gofs[q];
                    for (int q = 0; q < size; q++) diff |= S.lofs[q] != E.lofs[q] || S.lend[q] != E.lend[q];
                    if (diff && rank == 0 && bad < 5) {
                        printf("FAIL: nc %zu kind %d buckets %llu off %zu:", nc, kind, (unsigned long long)buckets[b],
                               offs[o]);
                        for (int q = 0; q <= size; q++) printf(" cut %u/%u", S.cut[q], E.cut[q]);
                        for (int q = 0; q < size; q++)
                            printf(" [%llu %llu]/[%llu %llu]", (unsigned long long)S.lofs[q],
                                   (unsigned long long)S.lend[q], (unsigned long long)E.lofs[q],
                                   (unsigned long long)E.lend[q]);
                        printf("\n");
                    }
                    bad += diff;
                    refined += S.rounds == 2;
                    cases++;
                    pfsph_cut_free(&S);
                    pfsph_cut_free(&E);
                }
            }
            free(key);
        }
    int all;
    MPI_Allreduce(&bad, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (rank == 0)
        printf("%d cases on %d ranks (%d refined in a second round): %d differ from the dense cut\n", cases, size,
               refined, all);
    MPI_Finalize();
    return all || !refined ? 1 : 0;
}
