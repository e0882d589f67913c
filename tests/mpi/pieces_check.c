/* pieces_check WHOLE.vtp FRAME.pvtp: the pieces a .pvtp names (output.pieces, docs/cluster.md),
 * each read with the project's VTP reader and concatenated in their order, are the particles of
 * the whole frame WHOLE.vtp (a serial run's), field by field, bit for bit. Exit 0, or 1 naming
 * the first difference. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/io.h"

static int fail(const char *what) { return fprintf(stderr, "pieces_check: %s\n", what), 1; }

int main(int argc, char **argv)
{
    if (argc != 3) return fail("usage: pieces_check WHOLE.vtp FRAME.pvtp");
    pfsph_error err;
    pfsph_particles whole;
    double t;
    if (pfsph_read_vtp(argv[1], &whole, &t, &err)) return fail(err.msg);
    FILE *f = fopen(argv[2], "rb");
    if (!f) return fail("cannot open the .pvtp");
    static char text[1 << 16];
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = 0;
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", argv[2]);
    char *slash = strrchr(dir, '/');
    if (slash) slash[1] = 0;
    else dir[0] = 0;
    size_t at = 0; /* particles of the whole frame matched so far */
    int pieces = 0;
    for (const char *p = text; (p = strstr(p, "<Piece Source=\"")); pieces++) {
        p += 15;
        const char *e = strchr(p, '"');
        if (!e) return fail("a Piece without its closing quote");
        char path[2048];
        snprintf(path, sizeof path, "%s%.*s", dir, (int)(e - p), p);
        pfsph_particles ps;
        if (pfsph_read_vtp(path, &ps, &t, &err)) return fail(err.msg);
        if (at + ps.n > whole.n) return fail("the pieces hold more particles than the whole frame");
        for (size_t i = 0; i < ps.n; i++, at++) {
            int bad = ps.phase[i] != whole.phase[at] || ps.id[i] != whole.id[at];
            for (int k = 0; k < PFSPH_NFIELDS; k++) bad |= memcmp(&ps.f[k][i], &whole.f[k][at], sizeof(pfsph_real));
            if (bad) {
                fprintf(stderr, "pieces_check: %s: particle %zu (%zu of the whole frame) differs\n", path, i, at);
                return 1;
            }
        }
        printf("%s: %zu particles\n", path, ps.n);
        pfsph_particles_free(&ps);
        p = e;
    }
    if (!pieces) return fail("the .pvtp names no piece");
    if (at != whole.n) return fail("the pieces hold fewer particles than the whole frame");
    printf("ok: %d pieces, %zu particles, equal to %s\n", pieces, at, argv[1]);
    pfsph_particles_free(&whole);
    return 0;
}
