/* PNG images: 8-bit RGB encoded with libpng into memory, then written through the atomic
 * writer (a reader never sees half a file). */
#include <png.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/io.h"
#include "pfsph/render.h"

typedef struct membuf {
    unsigned char *d;
    size_t n, cap;
    int failed;
} membuf;

static void png_mem_write(png_structp png, png_bytep data, png_size_t len)
{
    membuf *m = png_get_io_ptr(png);
    if (m->failed) return;
    if (m->n + len > m->cap) {
        size_t cap = m->cap ? m->cap : 65536;
        while (cap < m->n + len) cap *= 2;
        unsigned char *q = realloc(m->d, cap);
        if (!q) {
            m->failed = 1;
            return;
        }
        m->d = q;
        m->cap = cap;
    }
    memcpy(m->d + m->n, data, len);
    m->n += len;
}

static void png_mem_flush(png_structp png) { (void)png; }

/* Encode 8-bit RGB into m (no longjmp crosses live locals: all state is in m and rows). */
static int png_encode(const uint8_t *rgb, int w, int h, membuf *m)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    if (!png) return -1;
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        return -1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return -1;
    }
    png_set_write_fn(png, m, png_mem_write, png_mem_flush);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 4);
    png_write_info(png, info);
    for (int y = 0; y < h; y++) png_write_row(png, (png_const_bytep)(rgb + (size_t)3 * w * y));
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return m->failed ? -1 : 0;
}

int pfsph_write_png_rgb(const char *path, const uint8_t *rgb, int w, int h, pfsph_error *err)
{
    membuf m = {0};
    if (png_encode(rgb, w, h, &m) != 0) {
        free(m.d);
        return pfsph_fail(err, PFSPH_EIO, "%s: PNG encoding failed", path);
    }
    int rc = pfsph_write_file_atomic(path, m.d, m.n, err);
    free(m.d);
    return rc;
}
