/* The sparse cut (src/mpi/cut.c) gives the dense histogram's cut, offsets and removed count for
 * any key distribution: run under mpirun (label mpi). Keys spread, clustered in a few cells, all
 * in one cell, none at all, leaving the domain; grids from 1 cell to 1e6; coarse buckets from 1
 * (every cut refined, on the small grids) to more than the cells (one exact round); halo reaches from 0 to past the
 * grid; the count cut, and weighted cuts (each rank's particles their own weight, 1 to 4096, as
 * the cost cut gives them). The frames cannot show a wrong cut (any cut agreed by every rank gives
 * the same bytes), so this compares the cut itself, and checks a weighted cut against its
 * definition from a histogram made here: rank q's first cell is the first with q / size of the
 * weight before it; and that one weight on every rank gives the count cut. */
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

/* The weighted cut's definition, from a dense histogram of weights reduced here: cut[q] is the
 * first cell k whose weight before it, times size, reaches q times the total (0 < q < size). */
static int definition(const pfsph_cut *S, const uint32_t *key, size_t m, size_t nc, uint64_t wt, int size)
{
    uint64_t *h = calloc(nc, sizeof(uint64_t));
    if (!h) MPI_Abort(MPI_COMM_WORLD, 1);
    for (size_t i = 0; i < m; i++)
        if (key[i] != UINT32_MAX) h[key[i]] += wt;
    MPI_Allreduce(MPI_IN_PLACE, h, (int)nc, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    uint64_t tot = 0;
    for (size_t k = 0; k < nc; k++) tot += h[k];
    int ok = 1;
    if (tot) {
        for (int q = 1; q < size; q++) {
            uint64_t before = 0; /* the weight of cells [0, cut[q]) and of [0, cut[q] - 1) */
            for (size_t k = 0; k < S->cut[q]; k++) before += h[k];
            const uint64_t last = S->cut[q] ? h[S->cut[q] - 1] : 0;
            ok &= before * (uint64_t)size >= (uint64_t)q * tot;
            ok &= S->cut[q] == 0 || (before - last) * (uint64_t)size < (uint64_t)q * tot;
        }
    }
    free(h);
    return ok;
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
    int bad = 0, cases = 0, refined = 0, weighted = 0, defbad = 0;
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
                for (size_t o = 0; o < sizeof offs / sizeof offs[0]; o++)
                    for (int wk = 0; wk < 3; wk++) {
                        /* 0: the count cut; 1: one weight on every rank; 2: each rank its own. The
                         * dense histograms of the largest grid take most of the time: weighted there
                         * at one halo reach only, one weight everywhere on the small grids only */
                        if ((wk && nc > 100003 && o != 2) || (wk == 1 && nc > 4096)) continue;
                        const uint64_t c = (uint64_t)cases, r = (uint64_t)rank;
                        const uint64_t wt = wk == 0 ? 0 : wk == 1 ? 1 + c % 4096 : 1 + (r * 2654435761u + c) % 4096;
                        pfsph_cut S, E;
                        if (pfsph_cut_init(&S, size, buckets[b]) || pfsph_cut_init(&E, size, 1))
                            MPI_Abort(MPI_COMM_WORLD, 1);
                        int rc = pfsph_cut_compute(&S, MPI_COMM_WORLD, key, m, nc, offs[o], wt);
                        pfsph_cut_dense(&E, MPI_COMM_WORLD, key, m, nc, offs[o], wt);
                        int diff = rc || S.removed != E.removed || S.total != E.total || S.wtotal != E.wtotal;
                        for (int q = 0; q <= size; q++) diff |= S.cut[q] != E.cut[q] || S.gofs[q] != E.gofs[q];
                        for (int q = 0; q < size; q++) diff |= S.lofs[q] != E.lofs[q] || S.lend[q] != E.lend[q];
                        if (wk == 1) { /* the same weight everywhere: the count cut */
                            pfsph_cut U;
                            if (pfsph_cut_init(&U, size, 1)) MPI_Abort(MPI_COMM_WORLD, 1);
                            pfsph_cut_dense(&U, MPI_COMM_WORLD, key, m, nc, offs[o], 0);
                            for (int q = 0; q <= size; q++) diff |= U.cut[q] != S.cut[q];
                            pfsph_cut_free(&U);
                        }
                        if (wk == 2 && nc <= 100003) defbad += !definition(&S, key, m, nc, wt, size);
                        if (diff && rank == 0 && bad < 5) {
                            printf("FAIL: nc %zu kind %d buckets %llu off %zu weight kind %d:", nc, kind,
                                   (unsigned long long)buckets[b], offs[o], wk);
                            for (int q = 0; q <= size; q++) printf(" cut %u/%u", S.cut[q], E.cut[q]);
                            for (int q = 0; q < size; q++)
                                printf(" [%llu %llu]/[%llu %llu]", (unsigned long long)S.lofs[q],
                                       (unsigned long long)S.lend[q], (unsigned long long)E.lofs[q],
                                       (unsigned long long)E.lend[q]);
                            printf("\n");
                        }
                        bad += diff;
                        refined += S.rounds == 2;
                        weighted += S.weighted;
                        cases++;
                        pfsph_cut_free(&S);
                        pfsph_cut_free(&E);
                    }
            }
            free(key);
        }
    int all, alldef;
    MPI_Allreduce(&bad, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(&defbad, &alldef, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (rank == 0)
        printf("%d cases on %d ranks (%d refined in a second round, %d weighted): %d differ from the dense cut, %d "
               "weighted cuts from their definition\n",
               cases, size, refined, weighted, all, alldef);
    MPI_Finalize();
    return all || alldef || !refined || !weighted ? 1 : 0;
}
