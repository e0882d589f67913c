/* Internal helpers shared by the frame writers, readers and the renderer: atomic file output
 * streams, whole-file reads and little-endian encoding. */
#ifndef PFSPH_IO_INTERNAL_H
#define PFSPH_IO_INTERNAL_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/types.h"

/* An output file being written atomically: data goes to "<path>.tmp.<pid>"; commit fsyncs and
 * renames it over path, abort removes it. The old file at path is never touched before the
 * rename, so a failed write leaves it intact. */
typedef struct pfsph__afile {
    FILE *f;
    char *path; /* owned copies */
    char *tmp;
} pfsph__afile;

int pfsph__afile_open(pfsph__afile *a, const char *path, pfsph_error *err);
/* Buffered write; on failure the error names the path. */
int pfsph__afile_write(pfsph__afile *a, const void *data, size_t len, pfsph_error *err);
/* Flush, fsync, close, rename. Aborts (removes the temporary file) on any failure. */
int pfsph__afile_commit(pfsph__afile *a, pfsph_error *err);
/* As pfsph__afile_commit; durable 0 skips the fsyncs: the file survives this process, not a
 * power cut (a scratch copy). */
int pfsph__afile_finish(pfsph__afile *a, int durable, pfsph_error *err);
/* fsync src, rename it to dest and make the rename durable. */
int pfsph__rename_durable(const char *src, const char *dest, pfsph_error *err);
/* Close and remove the temporary file; safe to call twice. */
void pfsph__afile_abort(pfsph__afile *a);

/* Read a whole file into a malloc'ed buffer with one extra NUL byte after the data. */
int pfsph__read_file(const char *path, unsigned char **data, size_t *len, pfsph_error *err);

/* Scalar type codes of the on-disk formats. */
enum pfsph__type {
    PFSPH__T_NONE = 0,
    PFSPH__T_I8,
    PFSPH__T_U8,
    PFSPH__T_I16,
    PFSPH__T_U16,
    PFSPH__T_I32,
    PFSPH__T_U32,
    PFSPH__T_I64,
    PFSPH__T_U64,
    PFSPH__T_F32,
    PFSPH__T_F64
};
size_t pfsph__type_size(int type);
/* A PLY scalar type name ("float", "uint8", ...) as its code; PFSPH__T_NONE if unknown. */
int pfsph__ply_type(const char *s);
/* The next line of a PLY header at *pos (CR-LF tolerated), copied into line[cap]: 0, or 1 when
 * no end_header comes within the header limit, 2 when the line does not fit. Shared by the
 * particle and the surface readers. */
int pfsph__ply_header_line(const unsigned char *buf, size_t len, size_t *pos, char *line, size_t cap);
/* "comment time T" sets *time (when time is not NULL); other comments are ignored. */
void pfsph__ply_comment_time(const char *line, double *time);
/* Decode one little-endian value of the given type as a double (exact for every type we write:
 * float, double, uint8, uint32). */
double pfsph__get_as_double(int type, const unsigned char *src);

static inline int pfsph__host_le(void)
{
    const uint16_t one = 1;
    unsigned char c;
    memcpy(&c, &one, 1);
    return c == 1;
}

/* Copy size bytes from src to dst, reversing them on a big-endian host (files are LE). */
static inline void pfsph__put_le(unsigned char *dst, const void *src, size_t size)
{
    memcpy(dst, src, size);
    if (!pfsph__host_le())
        for (size_t i = 0; i < size / 2; i++) {
            unsigned char t = dst[i];
            dst[i] = dst[size - 1 - i];
            dst[size - 1 - i] = t;
        }
}

static inline void pfsph__get_le(void *dst, const unsigned char *src, size_t size) { pfsph__put_le(dst, src, size); }

/* A small write buffer in front of an atomic file, so values can be emitted one at a time. */
typedef struct pfsph__enc {
    pfsph__afile *a;
    unsigned char *buf;
    size_t cap, len;
    int failed;
    pfsph_error *err;
} pfsph__enc;

int pfsph__enc_init(pfsph__enc *e, pfsph__afile *a, pfsph_error *err);
/* Open the atomic file and the buffer in front of it; on failure nothing is left behind. */
int pfsph__enc_open(pfsph__enc *e, pfsph__afile *a, const char *path, pfsph_error *err);
/* printf-style header text (at most 1 KiB per call). */
void pfsph__enc_printf(pfsph__enc *e, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
int pfsph__enc_flush(pfsph__enc *e);
void pfsph__enc_free(pfsph__enc *e);

static inline void pfsph__enc_put(pfsph__enc *e, const void *v, size_t size)
{
    if (e->len + size > e->cap && pfsph__enc_flush(e) != PFSPH_OK) return;
    pfsph__put_le(e->buf + e->len, v, size);
    e->len += size;
}

/* Raw bytes (header text), no byte swapping; len must be below the buffer size (1 MiB). */
static inline void pfsph__enc_put_text(pfsph__enc *e, const char *s, size_t len)
{
    if (e->len + len > e->cap && pfsph__enc_flush(e) != PFSPH_OK) return;
    memcpy(e->buf + e->len, s, len);
    e->len += len;
}

/* Strict decimal unsigned integer (no sign, no spaces, no overflow): 0 or -1. */
int pfsph__parse_u64(const char *s, uint64_t *v);

/* Validates an aux field name for the frame writers (names the path in the error). */
int pfsph__check_aux_name(const char *path, const char *name, pfsph_error *err);

#endif
