/* Checkpoint files and a run's checkpoints folder (docs/checkpoints.md, "Policy"): atomic
 * saves, loads that check the file name's frame, rotation of the newest few, and resume from
 * the newest valid one. The format is written by checkpoint_encode.c, read by
 * checkpoint_decode.c; the scene hash is src/scene/scene_hash.c. */
#include "pfsph/checkpoint.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/checkpoint_format.h"
#include "io/io_internal.h"
#include "pfsph/dist.h"
#include "pfsph/io.h"

static long name_frame(const char *name);

static int save(const char *path, const pfsph_sim *sim, int frame, int durable, size_t *bytes, pfsph_error *err)
{
    pfsph_dist *d = pfsph_sim_ctx(sim)->dist; /* under MPI every rank writes its part */
    if (d && d->save) return d->save(d, path, frame, durable, bytes, err);
    pfsph__afile a;
    int rc = pfsph__afile_open(&a, path, err);
    if (rc) return rc;
    size_t len = 0;
    if ((rc = pfsph__checkpoint_write(sim, frame, a.f, path, &len, err))) {
        pfsph__afile_abort(&a);
        return rc;
    }
    rc = pfsph__afile_finish(&a, durable, err);
    if (!rc && bytes) *bytes = len;
    return rc;
}

int pfsph_checkpoint_save(const char *path, const pfsph_sim *sim, int frame, size_t *bytes, pfsph_error *err)
{
    return save(path, sim, frame, 1, bytes, err);
}

int pfsph_checkpoint_stash(const char *path, const pfsph_sim *sim, int frame, pfsph_error *err)
{
    return save(path, sim, frame, 0, NULL, err);
}

int pfsph_checkpoint_keep(const char *stash, const char *dest, pfsph_error *err)
{
    return pfsph__rename_durable(stash, dest, err);
}

int pfsph_checkpoint_load(const char *path, pfsph_sim *sim, pfsph_checkpoint_info *info, pfsph_error *err)
{
    const char *base = strrchr(path, '/');
    pfsph_dist *d = pfsph_sim_ctx(sim)->dist; /* under MPI every rank reads a range */
    if (d && d->load) return d->load(d, path, name_frame(base ? base + 1 : path), info, err);
    unsigned char *data;
    size_t len;
    int rc = pfsph__read_file(path, &data, &len, err);
    if (rc) return rc;
    rc = pfsph__checkpoint_read(sim, data, len, path, name_frame(base ? base + 1 : path), info, err);
    free(data);
    return rc;
}

void pfsph_checkpoint_path(char *buf, size_t cap, const char *run_dir, int frame)
{
    snprintf(buf, cap, "%s/checkpoints/ckpt_%05d.bin", run_dir, frame);
}

/* Frame of a checkpoint file name "ckpt_<digits>.bin", or -1. */
static long name_frame(const char *name)
{
    if (strncmp(name, "ckpt_", 5) != 0) return -1;
    const char *p = name + 5;
    long v = 0;
    int digits = 0;
    while (*p >= '0' && *p <= '9') {
        if (v > 100000000) return -1;
        v = v * 10 + (*p++ - '0');
        digits++;
    }
    if (!digits || strcmp(p, ".bin") != 0) return -1;
    return v;
}

static int cmp_desc(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return x < y ? 1 : x > y ? -1 : 0;
}

/* Frames of the checkpoints in RUN/checkpoints, newest first (malloc'ed; *n entries). */
static int list_checkpoints(const char *run_dir, long **out, size_t *n, pfsph_error *err)
{
    char dir[PFSPH_PATH_LEN + 64];
    snprintf(dir, sizeof dir, "%s/checkpoints", run_dir);
    *out = NULL;
    *n = 0;
    DIR *d = opendir(dir);
    if (!d) {
        if (errno == ENOENT) return PFSPH_OK;
        return pfsph_fail(err, PFSPH_EIO, "%s: cannot list: %s", dir, strerror(errno));
    }
    size_t cap = 0;
    long *v = NULL;
    struct dirent *e;
    while ((e = readdir(d))) {
        long f = name_frame(e->d_name);
        if (f < 0) continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 16;
            long *q = realloc(v, cap * sizeof(long));
            if (!q) {
                free(v);
                closedir(d);
                return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            }
            v = q;
        }
        v[(*n)++] = f;
    }
    closedir(d);
    if (*n) qsort(v, *n, sizeof(long), cmp_desc);
    *out = v;
    return PFSPH_OK;
}

int pfsph_checkpoint_write_run(const char *run_dir, const pfsph_sim *sim, int frame, int keep, size_t *bytes,
                               pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/checkpoints", run_dir);
    int rc = pfsph_mkdirs(path, err);
    if (rc) return rc;
    pfsph_checkpoint_path(path, sizeof path, run_dir, frame);
    if ((rc = pfsph_checkpoint_save(path, sim, frame, bytes, err))) return rc;
    long *frames;
    size_t n;
    if (list_checkpoints(run_dir, &frames, &n, err) != PFSPH_OK) return PFSPH_OK; /* saved; pruning is best effort */
    /* Keep the one just written and the keep - 1 newest older ones. Newer ones are stale: a
     * resume starts from the newest valid checkpoint, so any newer one was rejected. */
    size_t kept = 1;
    for (size_t i = 0; i < n; i++) {
        if (frames[i] == frame) continue;
        if (frames[i] < frame && kept < (size_t)(keep > 1 ? keep : 1)) {
            kept++;
            continue;
        }
        pfsph_checkpoint_path(path, sizeof path, run_dir, (int)frames[i]);
        unlink(path);
    }
    free(frames);
    return PFSPH_OK;
}

int pfsph_checkpoint_clear(const char *run_dir, pfsph_error *err)
{
    long *frames;
    size_t n;
    int rc = list_checkpoints(run_dir, &frames, &n, err);
    if (rc) return rc;
    char path[PFSPH_PATH_LEN + 64];
    for (size_t i = 0; i < n; i++) {
        pfsph_checkpoint_path(path, sizeof path, run_dir, (int)frames[i]);
        if (unlink(path) != 0 && errno != ENOENT) {
            rc = pfsph_fail(err, PFSPH_EIO, "%s: cannot remove: %s", path, strerror(errno));
            break;
        }
    }
    free(frames);
    return rc;
}

/* Remove temporaries "ckpt_*.bin.tmp.*" left by a writer that was killed (best effort). */
static void remove_temporaries(const char *run_dir)
{
    char dir[PFSPH_PATH_LEN + 64], path[2 * PFSPH_PATH_LEN];
    snprintf(dir, sizeof dir, "%s/checkpoints", run_dir);
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strncmp(e->d_name, "ckpt_", 5) == 0 && strstr(e->d_name, ".bin.tmp.")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    closedir(d);
}

int pfsph_checkpoint_resume(const char *run_dir, pfsph_sim *sim, pfsph_checkpoint_info *info, pfsph_message_fn warn,
                            void *user, pfsph_error *err)
{
    long *frames;
    size_t n;
    remove_temporaries(run_dir);
    int rc = list_checkpoints(run_dir, &frames, &n, err);
    if (rc) return rc;
    if (n == 0) {
        memset(info, 0, sizeof(*info));
        info->frame = -1;
        return PFSPH_OK;
    }
    char path[PFSPH_PATH_LEN + 64];
    for (size_t i = 0; i < n; i++) {
        pfsph_checkpoint_path(path, sizeof path, run_dir, (int)frames[i]);
        pfsph_error e = {0};
        rc = pfsph_checkpoint_load(path, sim, info, &e);
        if (rc == PFSPH_OK) {
            free(frames);
            return PFSPH_OK;
        }
        if (rc == PFSPH_ENOMEM) {
            free(frames);
            *err = e;
            return rc;
        }
        if (warn) {
            char msg[sizeof e.msg + 64];
            snprintf(msg, sizeof msg, "%s; %s", e.msg,
                     i + 1 < n ? "trying the previous checkpoint" : "no older checkpoint left");
            warn(msg, user);
        }
    }
    free(frames);
    snprintf(path, sizeof path, "%s/checkpoints", run_dir);
    return pfsph_fail(err, PFSPH_EINPUT, "%s: no valid checkpoint to resume from (all were rejected, see above)", path);
}
