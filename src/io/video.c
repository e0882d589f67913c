/* The video of a rendered run: ffmpeg, when on PATH, turns RUN_DIR/png/frame_NNNNN.png into
 * RUN_DIR/frames.mp4 (H.264, else MPEG-4), written under a temporary name and renamed. */
#include <errno.h>
#include <spawn.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "io/render_internal.h"

extern char **environ;

static bool on_path(const char *prog)
{
    const char *path = getenv("PATH");
    if (!path) return false;
    char buf[4096];
    while (*path) {
        size_t l = strcspn(path, ":");
        if (l && l + strlen(prog) + 2 < sizeof buf) {
            memcpy(buf, path, l);
            buf[l] = '/';
            strcpy(buf + l + 1, prog);
            if (access(buf, X_OK) == 0) return true;
        }
        path += l;
        if (*path == ':') path++;
    }
    return false;
}

static int run_wait(char *const argv[])
{
    pid_t pid;
    if (posix_spawnp(&pid, argv[0], NULL, NULL, argv, environ) != 0) return -1;
    int st;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int pfsph__render_video(const char *run_dir, int first, double fps, const pfsph_render_opts *o, pfsph_error *err)
{
    char pattern[PFSPH_PATH_LEN + 64], out[PFSPH_PATH_LEN + 64], tmp[PFSPH_PATH_LEN + 96];
    snprintf(pattern, sizeof pattern, "%s/png/frame_%%05d.png", run_dir);
    snprintf(out, sizeof out, "%s/frames.mp4", run_dir);
    /* ffmpeg picks the container from the extension, so the temporary name ends in .mp4. */
    snprintf(tmp, sizeof tmp, "%s/frames.tmp.%ld.mp4", run_dir, (long)getpid());
    if (!on_path("ffmpeg"))
        return pfsph_fail(err, PFSPH_EIO, "%s: ffmpeg not found on PATH; the PNG frames are in %s/png", out, run_dir);
    char rate[32], start[32];
    snprintf(rate, sizeof rate, "%g", fps > 0 ? fps : 25.0);
    snprintf(start, sizeof start, "%d", first);
    const char *codecs[2][4] = {{"-c:v", "libx264", "-crf", "20"}, {"-c:v", "mpeg4", "-q:v", "3"}};
    int st = -1;
    for (int c = 0; c < 2 && st != 0; c++) {
        char *argv[] = {"ffmpeg",
                        "-y",
                        "-loglevel",
                        "error",
                        "-framerate",
                        rate,
                        "-start_number",
                        start,
                        "-i",
                        pattern,
                        "-vf",
                        "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                        "-pix_fmt",
                        "yuv420p",
                        (char *)codecs[c][0],
                        (char *)codecs[c][1],
                        (char *)codecs[c][2],
                        (char *)codecs[c][3],
                        tmp,
                        NULL};
        st = run_wait(argv);
    }
    if (st != 0) {
        unlink(tmp);
        return pfsph_fail(err, PFSPH_EIO, "%s: ffmpeg failed (exit status %d)", out, st);
    }
    if (rename(tmp, out) != 0) {
        int e = errno;
        unlink(tmp);
        return pfsph_fail(err, PFSPH_EIO, "%s: rename failed: %s", out, strerror(e));
    }
    if (o->message) {
        char msg[PFSPH_PATH_LEN + 96];
        snprintf(msg, sizeof msg, "wrote %s", out);
        o->message(msg, o->user);
    }
    return PFSPH_OK;
}
