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
/* The test hook for a full disk (docs/robustness.md): with PFSPH_FAULT_WRITE="TEXT" or
 * "TEXT:N" in the environment, the N-th (default the first) and every later checked write to
 * a file whose path contains TEXT fails as on a full disk: returns 1 and sets errno to ENOSPC.
 * 0 otherwise (always, without the variable). Every writer calls it where it checks a write. */
int pfsph__write_fault(const char *path);

/* Read a whole file into a malloc'ed buffer with one extra NUL byte after the data: a regular
 * file of at most PFSPH__READ_MAX_BYTES (PFSPH_EINPUT otherwise, naming it). Frames read back by
 * render, mesh, export and view, and checkpoints, come through here (docs/robustness.md). */
#define PFSPH__READ_MAX_BYTES (8ull << 30)
int pfsph__read_file(const char *path, unsigned char **data, size_t *len, pfsph_error *err);

/* The start of every frame reader (PLY, VTP, surface PLY): out (out_size bytes) cleared, so
 * that a refused file leaves it empty; *time 0 until the file says otherwise (time may be NULL);
 * the whole file into *buf as pfsph__read_file does. The caller frees *buf. */
int pfsph__reader_open(const char *path, void *out, size_t out_size, unsigned char **buf, size_t *len, double *time,
                       pfsph_error *err);
/* A malformed input file: fails with "<path>: invalid <what>: <reason>" (PFSPH_EINPUT), the
 * reason printf-formatted (at most 511 characters); the reason names the line or the array. */
int pfsph__bad_input(pfsph_error *err, const char *path, const char *what, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* In a reader holding `rc`, `err` and `path`, with a `done:` label that cleans up: refuse the
 * file as pfsph__bad_input does and go to done. */
#define PFSPH__BAD(what, ...)                                \
    do {                                                     \
        rc = pfsph__bad_input(err, path, what, __VA_ARGS__); \
        goto done;                                           \
    } while (0)

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
/* The end of a writer: flush and free the buffer, then commit the file (pfsph__afile_commit),
 * or remove it when anything failed. */
int pfsph__enc_commit(pfsph__enc *e, pfsph__afile *af, pfsph_error *err);
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
