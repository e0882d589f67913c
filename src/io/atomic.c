/* Atomic file output (temporary file in the same directory, fsync, rename) and whole-file reads,
 * used by every writer so a crash or a full disk never leaves a half-written frame behind; and
 * the start and the refusals shared by the frame readers. */
#include "io/io_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pfsph/io.h"

static char *dup_str(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

static void afile_release(pfsph__afile *a)
{
    free(a->path);
    free(a->tmp);
    a->path = a->tmp = NULL;
    a->f = NULL;
}

int pfsph__write_fault(const char *path)
{
    static _Atomic int hits;
    const char *spec = getenv("PFSPH_FAULT_WRITE");
    if (!spec || !*spec || !path) return 0;
    char text[256];
    snprintf(text, sizeof text, "%s", spec);
    char *colon = strrchr(text, ':');
    long nth = 1;
    if (colon) {
        nth = strtol(colon + 1, NULL, 10);
        *colon = 0;
    }
    if (!strstr(path, text) || ++hits < nth) return 0;
    errno = ENOSPC;
    return 1;
}

int pfsph__afile_open(pfsph__afile *a, const char *path, pfsph_error *err)
{
    memset(a, 0, sizeof *a);
    if (!path || !*path) return pfsph_fail(err, PFSPH_EIO, "empty output path");
    size_t n = strlen(path) + 32;
    a->path = dup_str(path);
    a->tmp = malloc(n);
    if (!a->path || !a->tmp) {
        afile_release(a);
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    }
    snprintf(a->tmp, n, "%s.tmp.%ld", path, (long)getpid());
    int fd = open(a->tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        int e = errno;
        afile_release(a);
        return pfsph_fail(err, PFSPH_EIO, "%s: cannot create temporary file: %s", path, strerror(e));
    }
    a->f = fdopen(fd, "wb");
    if (!a->f) {
        int e = errno;
        close(fd);
        unlink(a->tmp);
        afile_release(a);
        return pfsph_fail(err, PFSPH_EIO, "%s: %s", path, strerror(e));
    }
    return PFSPH_OK;
}

int pfsph__afile_write(pfsph__afile *a, const void *data, size_t len, pfsph_error *err)
{
    if (!a->f) return pfsph_fail(err, PFSPH_EIO, "%s: write after failure", a->path ? a->path : "?");
    if ((len && fwrite(data, 1, len, a->f) != len) || pfsph__write_fault(a->path)) {
        int e = errno;
        return pfsph_fail(err, PFSPH_EIO, "%s: write failed: %s", a->path, strerror(e ? e : EIO));
    }
    return PFSPH_OK;
}

void pfsph__afile_abort(pfsph__afile *a)
{
    if (a->f) fclose(a->f);
    if (a->tmp) unlink(a->tmp);
    afile_release(a);
}

/* Make the rename itself durable; failure here is not an error for the data. */
static void sync_parent_dir(const char *path)
{
    char *d = dup_str(path);
    if (!d) return;
    char *slash = strrchr(d, '/');
    const char *dir = ".";
    if (slash) {
        if (slash == d) slash[1] = 0;
        else *slash = 0;
        dir = d;
    }
    int fd = open(dir, O_RDONLY);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
    free(d);
}

int pfsph__afile_commit(pfsph__afile *a, pfsph_error *err) { return pfsph__afile_finish(a, 1, err); }

int pfsph__afile_finish(pfsph__afile *a, int durable, pfsph_error *err)
{
    if (!a->f) {
        pfsph__afile_abort(a);
        return pfsph_fail(err, PFSPH_EIO, "commit of a failed file");
    }
    const char *what = NULL;
    int e = 0;
    if (fflush(a->f) != 0 || pfsph__write_fault(a->path)) what = "write failed", e = errno;
    else if (durable && fsync(fileno(a->f)) != 0) what = "fsync failed", e = errno;
    int rc = fclose(a->f);
    a->f = NULL;
    if (!what && rc != 0) what = "close failed", e = errno;
    if (!what && rename(a->tmp, a->path) != 0) what = "rename failed", e = errno;
    if (what) {
        pfsph_fail(err, PFSPH_EIO, "%s: %s: %s", a->path, what, strerror(e ? e : EIO));
        pfsph__afile_abort(a);
        return PFSPH_EIO;
    }
    if (durable) sync_parent_dir(a->path);
    afile_release(a);
    return PFSPH_OK;
}

int pfsph__rename_durable(const char *src, const char *dest, pfsph_error *err)
{
    int fd = open(src, O_RDONLY);
    if (fd < 0) return pfsph_fail(err, PFSPH_EIO, "%s: %s", src, strerror(errno));
    int bad = fsync(fd) != 0;
    int e = errno;
    close(fd);
    if (bad) return pfsph_fail(err, PFSPH_EIO, "%s: fsync failed: %s", src, strerror(e));
    if (rename(src, dest) != 0)
        return pfsph_fail(err, PFSPH_EIO, "%s: cannot rename to %s: %s", src, dest, strerror(errno));
    sync_parent_dir(dest);
    return PFSPH_OK;
}

int pfsph_write_file_atomic(const char *path, const void *data, size_t len, pfsph_error *err)
{
    pfsph__afile a;
    int rc = pfsph__afile_open(&a, path, err);
    if (rc != PFSPH_OK) return rc;
    rc = pfsph__afile_write(&a, data, len, err);
    if (rc != PFSPH_OK) {
        pfsph__afile_abort(&a);
        return rc;
    }
    return pfsph__afile_commit(&a, err);
}

int pfsph__read_file(const char *path, unsigned char **data, size_t *len, pfsph_error *err)
{
    *data = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return pfsph_fail(err, PFSPH_EIO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(f);
        return pfsph_fail(err, PFSPH_EIO, "%s: not a regular file", path);
    }
    /* frames and checkpoints are read whole: a cap far above any this program writes keeps a
     * wrong file (a disk image named like a frame) from taking the machine's memory */
    if ((unsigned long long)st.st_size > PFSPH__READ_MAX_BYTES) {
        fclose(f);
        return pfsph_fail(err, PFSPH_EINPUT, "%s: %.3g GiB, larger than the %llu GiB pfsph reads; not one of its files",
                          path, (double)st.st_size / 1073741824.0, PFSPH__READ_MAX_BYTES >> 30);
    }
    size_t n = (size_t)st.st_size;
    unsigned char *buf = malloc(n + 1);
    if (!buf) {
        fclose(f);
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory for %zu bytes", path, n);
    }
    size_t got = fread(buf, 1, n, f);
    int bad = ferror(f);
    fclose(f);
    if (bad || got != n) {
        free(buf);
        return pfsph_fail(err, PFSPH_EIO, "%s: read failed", path);
    }
    buf[n] = 0;
    *data = buf;
    *len = n;
    return PFSPH_OK;
}

int pfsph__reader_open(const char *path, void *out, size_t out_size, unsigned char **buf, size_t *len, double *time,
                       pfsph_error *err)
{
    memset(out, 0, out_size);
    if (time) *time = 0;
    return pfsph__read_file(path, buf, len, err);
}

int pfsph__bad_input(pfsph_error *err, const char *path, const char *what, const char *fmt, ...)
{
    char m[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m, sizeof m, fmt, ap);
    va_end(ap);
    return pfsph_fail(err, PFSPH_EINPUT, "%s: invalid %s: %s", path, what, m);
}

int pfsph__enc_init(pfsph__enc *e, pfsph__afile *a, pfsph_error *err)
{
    memset(e, 0, sizeof *e);
    e->a = a;
    e->err = err;
    e->cap = 1u << 20;
    e->buf = malloc(e->cap);
    if (!e->buf) return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", a->path);
    return PFSPH_OK;
}

int pfsph__enc_open(pfsph__enc *e, pfsph__afile *a, const char *path, pfsph_error *err)
{
    int rc = pfsph__afile_open(a, path, err);
    if (rc != PFSPH_OK) return rc;
    rc = pfsph__enc_init(e, a, err);
    if (rc != PFSPH_OK) pfsph__afile_abort(a);
    return rc;
}

void pfsph__enc_printf(pfsph__enc *e, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    int len = vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (len < 0) return;
    if ((size_t)len >= sizeof line) len = (int)sizeof line - 1;
    pfsph__enc_put_text(e, line, (size_t)len);
}

int pfsph__enc_flush(pfsph__enc *e)
{
    if (e->failed) {
        e->len = 0;
        return PFSPH_EIO;
    }
    int rc = pfsph__afile_write(e->a, e->buf, e->len, e->err);
    e->len = 0;
    if (rc != PFSPH_OK) e->failed = 1;
    return rc;
}

int pfsph__enc_commit(pfsph__enc *e, pfsph__afile *af, pfsph_error *err)
{
    int rc = pfsph__enc_flush(e);
    pfsph__enc_free(e);
    if (rc != PFSPH_OK) {
        pfsph__afile_abort(af);
        return rc;
    }
    return pfsph__afile_commit(af, err);
}

void pfsph__enc_free(pfsph__enc *e)
{
    free(e->buf);
    e->buf = NULL;
}

size_t pfsph__type_size(int type)
{
    switch (type) {
    case PFSPH__T_I8:
    case PFSPH__T_U8: return 1;
    case PFSPH__T_I16:
    case PFSPH__T_U16: return 2;
    case PFSPH__T_I32:
    case PFSPH__T_U32:
    case PFSPH__T_F32: return 4;
    case PFSPH__T_I64:
    case PFSPH__T_U64:
    case PFSPH__T_F64: return 8;
    default: return 0;
    }
}

double pfsph__get_as_double(int type, const unsigned char *src)
{
    switch (type) {
    case PFSPH__T_I8: return (double)(int8_t)src[0];
    case PFSPH__T_U8: return (double)src[0];
    case PFSPH__T_I16: {
        int16_t v;
        pfsph__get_le(&v, src, 2);
        return v;
    }
    case PFSPH__T_U16: {
        uint16_t v;
        pfsph__get_le(&v, src, 2);
        return v;
    }
    case PFSPH__T_I32: {
        int32_t v;
        pfsph__get_le(&v, src, 4);
        return v;
    }
    case PFSPH__T_U32: {
        uint32_t v;
        pfsph__get_le(&v, src, 4);
        return v;
    }
    case PFSPH__T_I64: {
        int64_t v;
        pfsph__get_le(&v, src, 8);
        return (double)v;
    }
    case PFSPH__T_U64: {
        uint64_t v;
        pfsph__get_le(&v, src, 8);
        return (double)v;
    }
    case PFSPH__T_F32: {
        float v;
        pfsph__get_le(&v, src, 4);
        return v;
    }
    case PFSPH__T_F64: {
        double v;
        pfsph__get_le(&v, src, 8);
        return v;
    }
    default: return 0;
    }
}

int pfsph_mkdirs(const char *path, pfsph_error *err)
{
    char buf[PFSPH_PATH_LEN + 64];
    if (strlen(path) >= sizeof buf) return pfsph_fail(err, PFSPH_EIO, "%s: path too long", path);
    strcpy(buf, path);
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == 0) {
            char c = *p;
            *p = 0;
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return pfsph_fail(err, PFSPH_EIO, "%s: cannot create directory: %s", buf, strerror(errno));
            struct stat st;
            if (stat(buf, &st) != 0 || !S_ISDIR(st.st_mode))
                return pfsph_fail(err, PFSPH_EIO, "%s: exists and is not a directory", buf);
            *p = c;
            if (!c) break;
        }
    }
    return PFSPH_OK;
}
