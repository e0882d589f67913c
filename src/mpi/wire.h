/* A particle on the wire between ranks (src/mpi/): its record, packed and unpacked, and the
 * buffers that grow to hold a message. Shared by the decomposition and the other sets' moves. */
#ifndef PFSPH_MPI_WIRE_H
#define PFSPH_MPI_WIRE_H

#include <stdlib.h>
#include <string.h>

#include "pfsph/particles.h"

/* One particle on the wire: the persistent fields, the density of the step (frames), id, phase,
 * wall, bubble. A homogeneous cluster is assumed (the same byte order and pfsph_real). */
#define REC (((PFSPH_NFIELDS + 1) * sizeof(pfsph_real) + 7 + 7) & ~(size_t)7)

/* particles per message of the start's scatter and the frame gather (their buffers: 3 MB) */
#define GATHER_RUN ((size_t)65536)

static inline int grow(char **buf, size_t *cap, size_t n)
{
    if (n <= *cap) return PFSPH_OK;
    size_t c = n + n / 4 + 4096;
    char *p = realloc(*buf, c);
    if (!p) return PFSPH_ENOMEM;
    *buf = p;
    *cap = c;
    return PFSPH_OK;
}

static inline void pack(char *o, const pfsph_particles *f, const pfsph_real *nd, size_t i)
{
    for (int k = 0; k < PFSPH_NFIELDS; k++) memcpy(o + k * sizeof(pfsph_real), &f->f[k][i], sizeof(pfsph_real));
    pfsph_real v = nd ? nd[i] : 0;
    memcpy(o + PFSPH_NFIELDS * sizeof(pfsph_real), &v, sizeof v);
    char *t = o + (PFSPH_NFIELDS + 1) * sizeof(pfsph_real);
    memcpy(t, &f->id[i], 4);
    t[4] = (char)f->phase[i];
    t[5] = (char)f->wall[i];
    t[6] = (char)f->bubble[i];
}

static inline void unpack(const char *o, pfsph_particles *f, pfsph_real *nd, size_t i)
{
    for (int k = 0; k < PFSPH_NFIELDS; k++) memcpy(&f->f[k][i], o + k * sizeof(pfsph_real), sizeof(pfsph_real));
    if (nd) memcpy(&nd[i], o + PFSPH_NFIELDS * sizeof(pfsph_real), sizeof(pfsph_real));
    const char *t = o + (PFSPH_NFIELDS + 1) * sizeof(pfsph_real);
    memcpy(&f->id[i], t, 4);
    f->phase[i] = (uint8_t)t[4];
    f->wall[i] = (uint8_t)t[5];
    f->bubble[i] = (uint8_t)t[6];
}

#endif
