/* The checkpoint file's layout shared by its writer (checkpoint_encode.c) and its reader
 * (checkpoint_decode.c); docs/checkpoints.md, "Format". */
#ifndef PFSPH_IO_CHECKPOINT_FORMAT_H
#define PFSPH_IO_CHECKPOINT_FORMAT_H

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
/* Check and restore a checkpoint held in memory (pfsph_checkpoint_decode); expect_frame >= 0:
 * the frame its file name says, which it must hold. */
int pfsph__checkpoint_read(pfsph_sim *sim, const void *data, size_t len, const char *name, long expect_frame,
                           pfsph_checkpoint_info *info, pfsph_error *err);

#endif
