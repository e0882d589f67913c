/* Line charts as PNG: diffuse particle counts over time (the paper's Fig. 14), read from a run's
 * stats.csv, and the validation pages' charts (pfsph_plot_lines). Self-contained: a tiny bitmap font, Bresenham lines, libpng, atomic rename. */
#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/io_internal.h"
#include "pfsph/io.h"

enum { W = 900, H = 540, ML = 80, MR = 30, MT = 40, MB = 60 };

typedef struct img {
    unsigned char *px; /* RGB */
} img;

static void put(img *im, int x, int y, const unsigned char c[3])
{
    if (x < 0 || y < 0 || x >= W || y >= H) return;
    memcpy(im->px + 3 * ((size_t)y * W + (size_t)x), c, 3);
}

static void line(img *im, int x0, int y0, int x1, int y1, const unsigned char c[3], int thick)
{
    int dx = abs(x1 - x0), sx = x0 < x1 ? 1 : -1, dy = -abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
    int e = dx + dy;
    for (;;) {
        for (int a = 0; a < thick; a++)
            for (int b = 0; b < thick; b++) put(im, x0 + a - thick / 2, y0 + b - thick / 2, c);
        if (x0 == x1 && y0 == y1) break;
        int e2 = 2 * e;
        if (e2 >= dy) e += dy, x0 += sx;
        if (e2 <= dx) e += dx, y0 += sy;
    }
}

/* 5x7 glyphs, one byte per row, bit 4 = leftmost column. */
static const struct {
    char c;
    unsigned char row[7];
} font[] = {
    {'0', {14, 17, 19, 21, 25, 17, 14}},
    {'1', {4, 12, 4, 4, 4, 4, 14}},
    {'2', {14, 17, 1, 2, 4, 8, 31}},
    {'3', {31, 2, 4, 2, 1, 17, 14}},
    {'4', {2, 6, 10, 18, 31, 2, 2}},
    {'5', {31, 16, 30, 1, 1, 17, 14}},
    {'6', {6, 8, 16, 30, 17, 17, 14}},
    {'7', {31, 1, 2, 4, 8, 8, 8}},
    {'8', {14, 17, 17, 14, 17, 17, 14}},
    {'9', {14, 17, 17, 15, 1, 2, 12}},
    {'.', {0, 0, 0, 0, 0, 12, 12}},
    {'-', {0, 0, 0, 31, 0, 0, 0}},
    {'+', {0, 4, 4, 31, 4, 4, 0}},
    {'[', {14, 8, 8, 8, 8, 8, 14}},
    {']', {14, 2, 2, 2, 2, 2, 14}},
    {'(', {2, 4, 8, 8, 8, 4, 2}},
    {')', {8, 4, 2, 2, 2, 4, 8}},
    {'a', {0, 0, 14, 1, 15, 17, 15}},
    {'b', {16, 16, 22, 25, 17, 17, 30}},
    {'c', {0, 0, 14, 16, 16, 17, 14}},
    {'d', {1, 1, 13, 19, 17, 17, 15}},
    {'e', {0, 0, 14, 17, 31, 16, 14}},
    {'f', {6, 9, 8, 28, 8, 8, 8}},
    {'g', {0, 15, 17, 17, 15, 1, 14}},
    {'i', {4, 0, 12, 4, 4, 4, 14}},
    {'k', {16, 16, 18, 20, 24, 20, 18}},
    {'l', {12, 4, 4, 4, 4, 4, 14}},
    {'m', {0, 0, 26, 21, 21, 17, 17}},
    {'n', {0, 0, 22, 25, 17, 17, 17}},
    {'o', {0, 0, 14, 17, 17, 17, 14}},
    {'p', {0, 0, 30, 17, 30, 16, 16}},
    {'r', {0, 0, 22, 25, 16, 16, 16}},
    {'s', {0, 0, 14, 16, 14, 1, 30}},
    {'t', {8, 8, 28, 8, 8, 9, 6}},
    {'u', {0, 0, 17, 17, 17, 19, 13}},
    {'w', {0, 0, 17, 17, 21, 21, 10}},
    {'y', {0, 0, 17, 17, 15, 1, 14}},
    {'M', {17, 27, 21, 21, 17, 17, 17}},
    {'N', {17, 25, 21, 19, 17, 17, 17}},
    {'D', {28, 18, 17, 17, 17, 18, 28}},
    {'F', {31, 16, 16, 30, 16, 16, 16}},
    {'S', {15, 16, 16, 14, 1, 1, 30}},
    /* for the line charts of pfsph_plot_lines */
    {'h', {16, 16, 22, 25, 17, 17, 17}},
    {'v', {0, 0, 17, 17, 17, 10, 4}},
    {'x', {0, 0, 17, 10, 4, 10, 17}},
    {'z', {0, 0, 31, 2, 4, 8, 31}},
    {'q', {0, 0, 13, 19, 15, 1, 1}},
    {'A', {14, 17, 17, 31, 17, 17, 17}},
    {'B', {30, 17, 17, 30, 17, 17, 30}},
    {'C', {14, 17, 16, 16, 16, 17, 14}},
    {'E', {31, 16, 16, 30, 16, 16, 31}},
    {'G', {14, 17, 16, 23, 17, 17, 15}},
    {'H', {17, 17, 17, 31, 17, 17, 17}},
    {'I', {14, 4, 4, 4, 4, 4, 14}},
    {'L', {16, 16, 16, 16, 16, 16, 31}},
    {'O', {14, 17, 17, 17, 17, 17, 14}},
    {'P', {30, 17, 17, 30, 16, 16, 16}},
    {'R', {30, 17, 17, 30, 20, 18, 17}},
    {'T', {31, 4, 4, 4, 4, 4, 4}},
    {'/', {1, 1, 2, 4, 8, 16, 16}},
    {'=', {0, 0, 31, 0, 31, 0, 0}},
    {',', {0, 0, 0, 0, 12, 4, 8}},
    {':', {0, 12, 12, 0, 12, 12, 0}},
    {'^', {4, 10, 17, 0, 0, 0, 0}},
};

/* Text at (x, y) = top-left, scale s; returns the width drawn. */
static int text(img *im, int x, int y, const char *s, const unsigned char c[3], int sc)
{
    int x0 = x;
    for (; *s; s++, x += 6 * sc) {
        for (size_t g = 0; g < sizeof font / sizeof font[0]; g++) {
            if (font[g].c != *s) continue;
            for (int r = 0; r < 7; r++)
                for (int b = 0; b < 5; b++)
                    if (font[g].row[r] & (16 >> b))
                        for (int a = 0; a < sc; a++)
                            for (int q = 0; q < sc; q++) put(im, x + b * sc + a, y + r * sc + q, c);
        }
    }
    return x - x0;
}

/* A "nice" tick step (1, 2, 5 x 10^k) giving about n ticks over span. */
static double nice_step(double span, int n)
{
    double raw = span / n, p = pow(10, floor(log10(raw))), m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

/* Split a CSV line in place into at most max fields. */
static int split(char *s, char **f, int max)
{
    int n = 0;
    s[strcspn(s, "\r\n")] = 0;
    while (n < max) {
        f[n++] = s;
        char *c = strchr(s, ',');
        if (!c) break;
        *c = 0;
        s = c + 1;
    }
    return n;
}

static int write_png(const char *path, img *im, pfsph_error *err)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    FILE *fp = fopen(tmp, "wb");
    if (!fp) return pfsph_fail(err, PFSPH_EIO, "%s: %s", tmp, strerror(errno));
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        fclose(fp);
        remove(tmp);
        return pfsph_fail(err, PFSPH_EIO, "%s: PNG encoding failed", path);
    }
    png_init_io(png, fp);
    png_set_IHDR(png, info, W, H, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < H; y++) png_write_row(png, im->px + (size_t)y * W * 3);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    int bad = fflush(fp) != 0 || pfsph__write_fault(path) || fsync(fileno(fp)) != 0;
    bad |= fclose(fp) != 0;
    if (bad || rename(tmp, path) != 0) {
        int e = errno;
        remove(tmp);
        return pfsph_fail(err, PFSPH_EIO, "%s: %s", path, strerror(e));
    }
    return PFSPH_OK;
}

int pfsph_diffuse_plot(const char *stats_csv, const char *png_path, pfsph_error *err)
{
    static const char *const want[4] = {"time", "n_spray", "n_foam", "n_bubble"};
    FILE *fp = fopen(stats_csv, "r");
    if (!fp) return pfsph_fail(err, PFSPH_EIO, "%s: %s", stats_csv, strerror(errno));
    char buf[8192];
    char *f[256];
    int col[4] = {-1, -1, -1, -1};
    if (!fgets(buf, sizeof buf, fp)) {
        fclose(fp);
        return pfsph_fail(err, PFSPH_EINPUT, "%s: empty file", stats_csv);
    }
    int nf = split(buf, f, 256);
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < nf; i++)
            if (strcmp(f[i], want[k]) == 0) col[k] = i;
    for (int k = 0; k < 4; k++)
        if (col[k] < 0) {
            fclose(fp);
            return pfsph_fail(err, PFSPH_EINPUT, "%s: no column \"%s\" in the header", stats_csv, want[k]);
        }
    size_t n = 0, cap = 0;
    double *v = NULL; /* n rows x 4 */
    long lineno = 1;
    while (fgets(buf, sizeof buf, fp)) {
        lineno++;
        if (buf[0] == '\n' || buf[0] == '\r' || buf[0] == 0) continue;
        nf = split(buf, f, 256);
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            double *q = realloc(v, cap * 4 * sizeof(double));
            if (!q) {
                free(v);
                fclose(fp);
                return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            }
            v = q;
        }
        for (int k = 0; k < 4; k++) {
            char *end = NULL;
            double x = col[k] < nf ? strtod(f[col[k]], &end) : NAN;
            if (col[k] >= nf || end == f[col[k]] || !isfinite(x)) {
                free(v);
                fclose(fp);
                return pfsph_fail(err, PFSPH_EINPUT, "%s:%ld: bad value in column \"%s\"", stats_csv, lineno, want[k]);
            }
            v[4 * n + k] = x;
        }
        n++;
    }
    fclose(fp);

    double t0 = n ? v[0] : 0, t1 = n ? v[4 * (n - 1)] : 1, ymax = 1;
    for (size_t i = 0; i < n; i++) {
        if (v[4 * i] < t0) t0 = v[4 * i];
        if (v[4 * i] > t1) t1 = v[4 * i];
        double tot = v[4 * i + 1] + v[4 * i + 2] + v[4 * i + 3];
        if (tot > ymax) ymax = tot;
    }
    if (t1 <= t0) t1 = t0 + 1;
    double ystep = nice_step(ymax, 5), tstep = nice_step(t1 - t0, 8);
    ymax = ceil(ymax / ystep) * ystep;

    img im = {malloc((size_t)W * H * 3)};
    if (!im.px) {
        free(v);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    }
    memset(im.px, 255, (size_t)W * H * 3);
    const unsigned char black[3] = {0, 0, 0}, grey[3] = {225, 225, 225};
    const unsigned char colors[4][3] = {{40, 100, 220}, {30, 160, 60}, {220, 60, 40}, {90, 90, 90}};
    const int pw = W - ML - MR, ph = H - MT - MB;
#define PX(t) (ML + (int)lround(((t)-t0) / (t1 - t0) * pw))
#define PY(c) (MT + ph - (int)lround((c) / ymax * ph))
    char lab[64];
    for (double y = 0; y <= ymax * (1 + 1e-9); y += ystep) {
        line(&im, ML, PY(y), ML + pw, PY(y), grey, 1);
        snprintf(lab, sizeof lab, "%.0f", y);
        text(&im, ML - 8 - 6 * (int)strlen(lab), PY(y) - 3, lab, black, 1);
    }
    for (double t = ceil(t0 / tstep) * tstep; t <= t1 * (1 + 1e-9); t += tstep) {
        line(&im, PX(t), MT, PX(t), MT + ph, grey, 1);
        snprintf(lab, sizeof lab, "%g", fabs(t) < 1e-12 ? 0.0 : t);
        text(&im, PX(t) - 3 * (int)strlen(lab), MT + ph + 8, lab, black, 1);
    }
    line(&im, ML, MT, ML, MT + ph, black, 1);
    line(&im, ML, MT + ph, ML + pw, MT + ph, black, 1);
    text(&im, ML + pw / 2 - 24, H - 24, "time [s]", black, 1);
    text(&im, 8, MT - 28, "Diffuse particles", black, 2);
    static const char *const names[4] = {"spray", "foam", "bubble", "total"};
    int lx = ML + 16;
    for (int k = 0; k < 4; k++) {
        line(&im, lx, MT + 14, lx + 20, MT + 14, colors[k], 3);
        lx += 26 + text(&im, lx + 26, MT + 11, names[k], black, 1) + 16;
    }
    for (int k = 3; k >= 0; k--)
        for (size_t i = 1; i < n; i++) {
            double a = k < 3 ? v[4 * (i - 1) + 1 + k] : v[4 * (i - 1) + 1] + v[4 * (i - 1) + 2] + v[4 * (i - 1) + 3];
            double b = k < 3 ? v[4 * i + 1 + k] : v[4 * i + 1] + v[4 * i + 2] + v[4 * i + 3];
            line(&im, PX(v[4 * (i - 1)]), PY(a), PX(v[4 * i]), PY(b), colors[k], 2);
        }
#undef PX
#undef PY
    free(v);
    int rc = write_png(png_path, &im, err);
    free(im.px);
    return rc;
}

int pfsph_plot_lines(const char *png_path, const char *title, const char *xlabel, const char *ylabel,
                     const pfsph_plot_series *s, int ns, pfsph_error *err)
{
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int k = 0; k < ns; k++)
        for (size_t i = 0; i < s[k].n; i++) {
            if (!isfinite(s[k].x[i]) || !isfinite(s[k].y[i])) continue;
            x0 = fmin(x0, s[k].x[i]), x1 = fmax(x1, s[k].x[i]);
            y0 = fmin(y0, s[k].y[i]), y1 = fmax(y1, s[k].y[i]);
        }
    if (!(x1 > x0)) x0 = 0, x1 = 1;
    if (!(y1 > y0)) y0 = 0, y1 = 1;
    const double ystep = nice_step(y1 - y0, 6), xstep = nice_step(x1 - x0, 8);
    y0 = floor(y0 / ystep) * ystep, y1 = ceil(y1 / ystep) * ystep;
    img im = {malloc((size_t)W * H * 3)};
    if (!im.px) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    memset(im.px, 255, (size_t)W * H * 3);
    const unsigned char black[3] = {0, 0, 0}, grey[3] = {225, 225, 225};
    const unsigned char colors[6][3] = {{40, 100, 220}, {220, 60, 40}, {30, 160, 60},
                                        {90, 90, 90},   {200, 140, 0}, {150, 60, 180}};
    const int pw = W - ML - MR, ph = H - MT - MB;
#define PX(t) (ML + (int)lround(((t)-x0) / (x1 - x0) * pw))
#define PY(c) (MT + ph - (int)lround(((c)-y0) / (y1 - y0) * ph))
    char lab[64];
    for (double y = y0; y <= y1 + 1e-9 * ystep; y += ystep) {
        line(&im, ML, PY(y), ML + pw, PY(y), grey, 1);
        snprintf(lab, sizeof lab, "%g", fabs(y) < 1e-9 * ystep ? 0.0 : y);
        text(&im, ML - 8 - 6 * (int)strlen(lab), PY(y) - 3, lab, black, 1);
    }
    for (double t = ceil(x0 / xstep) * xstep; t <= x1 * (1 + 1e-9); t += xstep) {
        line(&im, PX(t), MT, PX(t), MT + ph, grey, 1);
        snprintf(lab, sizeof lab, "%g", fabs(t) < 1e-9 * xstep ? 0.0 : t);
        text(&im, PX(t) - 3 * (int)strlen(lab), MT + ph + 8, lab, black, 1);
    }
    line(&im, ML, MT, ML, MT + ph, black, 1);
    line(&im, ML, MT + ph, ML + pw, MT + ph, black, 1);
    text(&im, ML + pw / 2 - 3 * (int)strlen(xlabel), H - 24, xlabel, black, 1);
    text(&im, 8, MT - 12, ylabel, black, 1);
    text(&im, 8, 6, title, black, 2);
    int lx = ML + 16, ly = MT + 14;
    for (int k = 0; k < ns; k++) {
        const unsigned char *c = colors[k % 6];
        if (s[k].points) line(&im, lx + 10, ly, lx + 10, ly, c, 5);
        else line(&im, lx, ly, lx + 20, ly, c, 3);
        lx += 26 + text(&im, lx + 26, ly - 3, s[k].name, black, 1) + 16;
        if (lx > W - 200) lx = ML + 16, ly += 14;
    }
    for (int k = 0; k < ns; k++) {
        const unsigned char *c = colors[k % 6];
        for (size_t i = 0; i < s[k].n; i++) {
            if (!isfinite(s[k].x[i]) || !isfinite(s[k].y[i])) continue;
            if (s[k].points) line(&im, PX(s[k].x[i]), PY(s[k].y[i]), PX(s[k].x[i]), PY(s[k].y[i]), c, 5);
            else if (i > 0 && isfinite(s[k].x[i - 1]) && isfinite(s[k].y[i - 1]))
                line(&im, PX(s[k].x[i - 1]), PY(s[k].y[i - 1]), PX(s[k].x[i]), PY(s[k].y[i]), c, 2);
        }
    }
#undef PX
#undef PY
    int rc = write_png(png_path, &im, err);
    free(im.px);
    return rc;
}
