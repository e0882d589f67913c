/* Counters and sets other than the fluid across the ranks (docs/cluster.md): prefixes and
 * or-ed flags (emitters), exact sums (the bodies' forces), and the moves of a particle set that
 * keeps the serial order (diffuse particles). The hooks of pfsph_dist the library calls. */
#include <stdlib.h>
#include <string.h>

#include "mpi/decomp.h"
#include "mpi/wire.h"

static void scan(pfsph_dist *d, const uint64_t *v, int k, uint64_t *before, uint64_t *total)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    uint64_t mine[8], *all = D->scan_all;      /* 8 per rank */
    if (k > 8 || k < 1) MPI_Abort(D->comm, 1); /* a caller's bug */
    for (int j = 0; j < k && j < 8; j++) mine[j] = v[j];
    MPI_Allgather(mine, k, MPI_UINT64_T, all, k, MPI_UINT64_T, D->comm);
    for (int j = 0; j < k; j++) {
        uint64_t b = 0, t = 0;
        for (int q = 0; q < D->size; q++) {
            if (q < D->rank) b += all[q * k + j];
            t += all[q * k + j];
        }
        before[j] = b;
        total[j] = t;
    }
}

static void count(pfsph_dist *d, long *v, int k)
{
    MPI_Allreduce(MPI_IN_PLACE, v, k, MPI_LONG, MPI_SUM, ((pfsph_decomp *)d)->comm);
}

static void allsum(pfsph_dist *d, double *a, size_t n)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    for (size_t o = 0; o < n; o += (size_t)1 << 28) {
        const size_t k = n - o < (size_t)1 << 28 ? n - o : (size_t)1 << 28;
        MPI_Allreduce(MPI_IN_PLACE, a + o, (int)k, MPI_DOUBLE, MPI_SUM, D->comm);
    }
}

static void any(pfsph_dist *d, uint8_t *flags, size_t n)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    for (size_t o = 0; o < n; o += (size_t)1 << 30) {
        const size_t k = n - o < (size_t)1 << 30 ? n - o : (size_t)1 << 30;
        MPI_Allreduce(MPI_IN_PLACE, flags + o, (int)k, MPI_UINT8_T, MPI_BOR, D->comm);
    }
}

/* The rank whose cells [cut[q], cut[q + 1]) hold cell `key`. */
static int owner(const pfsph_decomp *D, uint32_t key)
{
    int a = 0, b = D->size - 1;
    while (a < b) {
        const int m = (a + b + 1) / 2;
        if (D->cut[m] <= key) a = m;
        else b = m - 1;
    }
    return a;
}

/* A set in the global order is [0, nold), a slice of its sorted part (rank order), then
 * [nold, n), new particles whose ids rise in the global order. Each rank sends each particle to
 * its destination, the first part before the new; a receiver takes the first parts in rank
 * order, then merges the new parts by id: the global order of what it holds. One Alltoallv. */
static void migrate(pfsph_dist *d, pfsph_particles *ps, size_t *nold, const uint32_t *key)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    const int P = D->size;
    int *cnt = D->cnt2, *rcnt = D->rcnt2;
    memset(cnt, 0, 2 * (size_t)P * sizeof(int));
    int *dest = malloc((ps->n ? ps->n : 1) * sizeof(int));
    if (!dest) MPI_Abort(D->comm, 1);
    for (size_t i = 0; i < ps->n; i++) {
        dest[i] = !key ? 0 : key[i] == UINT32_MAX ? D->rank : owner(D, key[i]);
        cnt[2 * dest[i] + (i >= *nold)]++;
    }
    MPI_Alltoall(cnt, 2, MPI_INT, rcnt, 2, MPI_INT, D->comm);
    size_t bytes = 0, rbytes = 0, rold = 0, rn = 0;
    for (int q = 0; q < P; q++) {
        D->scount[q] = (cnt[2 * q] + cnt[2 * q + 1]) * (int)REC;
        D->sdispl[q] = (int)bytes;
        D->rcount[q] = (rcnt[2 * q] + rcnt[2 * q + 1]) * (int)REC;
        D->rdispl[q] = (int)rbytes;
        bytes += (size_t)D->scount[q];
        rbytes += (size_t)D->rcount[q];
        rold += (size_t)rcnt[2 * q];
        rn += (size_t)(rcnt[2 * q] + rcnt[2 * q + 1]);
    }
    if (bytes > (size_t)INT32_MAX || rbytes > (size_t)INT32_MAX || grow(&D->sbuf, &D->scap, bytes) ||
        grow(&D->rbuf, &D->rcap, rbytes))
        MPI_Abort(D->comm, 1);
    size_t *at = D->qa;
    for (int q = 0; q < P; q++) at[q] = (size_t)D->sdispl[q];
    for (int part = 0; part < 2; part++) /* the first part, then the new */
        for (size_t i = part ? *nold : 0; i < (part ? ps->n : *nold); i++) {
            pack(D->sbuf + at[dest[i]], ps, NULL, i);
            at[dest[i]] += REC;
        }
    free(dest);
    MPI_Alltoallv(D->sbuf, D->scount, D->sdispl, MPI_BYTE, D->rbuf, D->rcount, D->rdispl, MPI_BYTE, D->comm);
    if (rn > ps->cap && pfsph_particles_reserve(ps, rn) != PFSPH_OK) MPI_Abort(D->comm, 1);
    size_t k = 0, *head = D->qb, *end = D->qc;
    for (int q = 0; q < P; q++)
        for (int j = 0; j < rcnt[2 * q]; j++) unpack(D->rbuf + D->rdispl[q] + (size_t)j * REC, ps, NULL, k++);
    for (int q = 0; q < P; q++) {
        head[q] = (size_t)D->rdispl[q] + (size_t)rcnt[2 * q] * REC;
        end[q] = (size_t)D->rdispl[q] + (size_t)D->rcount[q];
    }
    const size_t idat = (PFSPH_NFIELDS + 1) * sizeof(pfsph_real);
    while (k < rn) { /* merge the new parts by id (each rises) */
        int best = -1;
        uint32_t bid = 0;
        for (int q = 0; q < P; q++) {
            if (head[q] >= end[q]) continue;
            uint32_t id;
            memcpy(&id, D->rbuf + head[q] + idat, 4);
            if (best < 0 || id < bid) best = q, bid = id;
        }
        unpack(D->rbuf + head[best], ps, NULL, k++);
        head[best] += REC;
    }
    ps->n = rn;
    *nold = rold;
    for (int q = 0; q < P; q++)
        if (q != D->rank && D->scount[q]) {
            D->migr_bytes += (uint64_t)D->scount[q];
            D->messages++;
        }
}

void pfsph_decomp_set_hooks(pfsph_decomp *D)
{
    D->d.scan = scan;
    D->d.count = count;
    D->d.any = any;
    D->d.allsum = allsum;
    D->d.migrate = migrate;
}
