/* The checkpoint file's layout shared by its writer (checkpoint_encode.c) and its reader
 * (checkpoint_decode.c); docs/checkpoints.md, "Format". */
#ifndef PFSPH_IO_CHECKPOINT_FORMAT_H
#define PFSPH_IO_CHECKPOINT_FORMAT_H

#include <stdint.h>
#include <stdio.h>

#include "pfsph/checkpoint.h"

#define PFSPH__CKPT_MAGIC "PFSPHCKP" /* its first 8 bytes */
/* magic, version, precision, scene hash, payload length, payload CRC32, header CRC32 */
enum { PFSPH__CKPT_HEADER = 40 };
/* Bytes per particle of a stored set: the real fields, phase and bubble bytes, the u32 id. */
#define PFSPH__CKPT_PER_PARTICLE (PFSPH_NFIELDS * sizeof(pfsph_real) + 2 + 4)

/* The checkpoint of sim at `frame` into f (open for writing at its start, seekable); *len its
 * size. `path` names f in messages. */
int pfsph__checkpoint_write(const pfsph_sim *sim, int frame, FILE *f, const char *path, size_t *len, pfsph_error *err);
/* ---- the payload in parts, for a writer that holds the fluid in slices (src/mpi/ckpt.c): the
 * head (the clock up to the fluid's count and next id) and the tail (the diffuse set, the bodies,
 * the emitters) come from these, the fluid's arrays between them from each slice; the layout is
 * this file's and checkpoint_encode.c's alone. ---- */
/* Takes n bytes; returns 0 or an errno value. */
typedef int (*pfsph__ckpt_sink)(void *user, const void *p, size_t n);
/* The fluid set's arrays in file order: the real fields, phase, bubble, id. */
#define PFSPH__CKPT_ARRAYS (PFSPH_NFIELDS + 3)
/* Array k of ps from element i0: *p its first element, returns its element size (the file
 * holds it little-endian). */
size_t pfsph__checkpoint_array(const pfsph_particles *ps, int k, size_t i0, const void **p);
/* The head's bytes and the payload's for a fluid of nfluid particles. */
void pfsph__checkpoint_sizes(const pfsph_sim *sim, uint64_t nfluid, size_t *head, size_t *payload);
/* The head for a fluid of nfluid particles, and the tail, into sink; *crc runs on over them
 * (zlib crc32); *len: the tail's bytes. 0 or the sink's errno. */
int pfsph__checkpoint_head(const pfsph_sim *sim, int frame, uint64_t nfluid, pfsph__ckpt_sink sink, void *user,
                           uint32_t *crc);
int pfsph__checkpoint_tail(const pfsph_sim *sim, pfsph__ckpt_sink sink, void *user, uint32_t *crc, size_t *len);
/* The 40-byte header for a payload of that length and CRC32. */
void pfsph__checkpoint_header(unsigned char *out, const pfsph_sim *sim, uint64_t payload, uint32_t pcrc);

/* Check and restore a checkpoint held in memory (pfsph_checkpoint_decode); expect_frame >= 0:
 * the frame its file name says, which it must hold. */
int pfsph__checkpoint_read(pfsph_sim *sim, const void *data, size_t len, const char *name, long expect_frame,
                           pfsph_checkpoint_info *info, pfsph_error *err);

/* A reader of ranges (src/mpi/ckpt.c): data holds the header, the head and the tail, the fluid's
 * arrays elided; the file is file_len bytes, crc the payload's CRC32 the caller combined, and
 * fluid this process's range of the fluid, read and checked (pfsph__checkpoint_check_set) by
 * the caller: it is what the restore takes. */
typedef struct pfsph__ckpt_elided {
    uint64_t file_len;
    uint32_t crc;
    const pfsph_particles *fluid;
} pfsph__ckpt_elided;
int pfsph__checkpoint_read_elided(pfsph_sim *sim, const void *data, size_t len, const char *name, long expect_frame,
                                  const pfsph__ckpt_elided *el, pfsph_checkpoint_info *info, pfsph_error *err);
/* A set's ids below its next id and its fields finite; i0: the index of ps's first particle in
 * the file's set (messages). */
int pfsph__checkpoint_check_set(const pfsph_particles *ps, size_t i0, const char *name, const char *what,
                                pfsph_error *err);

#endif
