/* The frame files of a run directory (frames/<set>_NNNNN.vtp or .ply): which numbers exist,
 * and reading one; for `pfsph render` and the viewer's replay. */
#include <dirent.h>
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/render_internal.h"
#include "pfsph/io.h"

typedef pfsph_frame_list frame_list;

int pfsph_frame_list_read(const char *dir, const char *prefix, frame_list *fl, pfsph_error *err)
{
    memset(fl, 0, sizeof *fl);
    DIR *d = opendir(dir);
    if (!d) return pfsph_fail(err, PFSPH_EIO, "%s: cannot open: %s", dir, strerror(errno));
    size_t pl = strlen(prefix);
    struct dirent *de;
    int rc = PFSPH_OK;
    while ((de = readdir(d))) {
        const char *nm = de->d_name;
        if (strncmp(nm, prefix, pl) != 0) continue;
        const char *q = nm + pl;
        int digits = 0;
        long v = 0;
        while (q[digits] >= '0' && q[digits] <= '9' && digits < 9) v = v * 10 + (q[digits++] - '0');
        if (digits < 5) continue;
        bool vtp = strcmp(q + digits, ".vtp") == 0, ply = strcmp(q + digits, ".ply") == 0;
        if (!vtp && !ply) continue;
        int i;
        for (i = 0; i < fl->n; i++)
            if (fl->num[i] == (int)v) break;
        if (i < fl->n) {
            if (vtp) fl->ply[i] = 0;
            continue;
        }
        if (fl->n == fl->cap) {
            int cap = fl->cap ? 2 * fl->cap : 64;
            int *nn = realloc(fl->num, (size_t)cap * sizeof *nn);
            if (nn) fl->num = nn;
            char *np = realloc(fl->ply, (size_t)cap);
            if (np) fl->ply = np;
            if (!nn || !np) {
                rc = pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", dir);
                break;
            }
            fl->cap = cap;
        }
        fl->num[fl->n] = (int)v;
        fl->ply[fl->n] = ply;
        fl->n++;
    }
    closedir(d);
    /* Sort numbers and carry the ply flags along (small lists: insertion sort). */
    for (int i = 1; i < fl->n; i++)
        for (int j = i; j > 0 && fl->num[j - 1] > fl->num[j]; j--) {
            int t = fl->num[j];
            fl->num[j] = fl->num[j - 1];
            fl->num[j - 1] = t;
            char c = fl->ply[j];
            fl->ply[j] = fl->ply[j - 1];
            fl->ply[j - 1] = c;
        }
    return rc;
}

void pfsph_frame_list_free(frame_list *fl)
{
    free(fl->num);
    free(fl->ply);
    memset(fl, 0, sizeof *fl);
}

int pfsph__read_frame(const char *dir, const char *prefix, int num, bool ply, pfsph_particles *ps, double *time,
                      pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/%s%05d.%s", dir, prefix, num, ply ? "ply" : "vtp");
    return ply ? pfsph_read_ply(path, ps, time, err) : pfsph_read_vtp(path, ps, time, err);
}

int pfsph_frame_list_find(const frame_list *fl, int f)
{
    for (int i = 0; i < fl->n; i++)
        if (fl->num[i] == f) return i;
    return -1;
}
