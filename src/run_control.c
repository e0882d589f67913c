/* The run driver's edges (src/run.c): how a run stops on request, whether an asked-for end
 * lands on a frame, and whether statistics rows reached the disk (docs/robustness.md). */
#include "run_control.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/io_internal.h"
#include "pfsph/checkpoint.h"
#include "pfsph/io.h"

/* An end time asked for on the command line (--end) lands on a frame: the run stops at the
 * last frame at or before it, so 0.15 s at 50 fps stopped at 0.14 s while run.json said 0.15
 * (issue 33). A scene's own time.end keeps that rounding down (shipped scenes have 1.5 s at
 * 25 fps). */
int pfsph__run_end_on_frame(const pfsph_scene *s, double end, pfsph_error *err)
{
    const double x = end * s->fps, n = floor(x + 1e-9);
    if (x - n <= 1e-6) return PFSPH_OK;
    return pfsph_fail(err, PFSPH_EINPUT,
                      "end time %.9g s: not a whole number of frames at %g fps ($.time.fps of %s); the run "
                      "would stop at %.9g s: give %.9g or %.9g",
                      end, s->fps, s->source, n / s->fps, n / s->fps, (n + 1) / s->fps);
}

/* A stop asked for (Ctrl-C): the stash of the last finished frame becomes its checkpoint when
 * checkpoints are on and it is newer than the last one (a rename: no encoding on the way out),
 * and err says where the run stopped and how to go on. */
void pfsph__run_interrupted(const char *dir, const pfsph_scene *s, const pfsph_sim *sim, const char *stash,
                            int good_frame, int last_ckpt, pfsph_error *err)
{
    char cp[PFSPH_PATH_LEN + 64], path[PFSPH_PATH_LEN + 64];
    pfsph_error e;
    int kept = last_ckpt;
    if (stash && s->output.checkpoint_interval > 0 && good_frame > last_ckpt) {
        pfsph_checkpoint_path(cp, sizeof cp, dir, good_frame);
        snprintf(path, sizeof path, "%s/checkpoints", dir);
        if (pfsph_mkdirs(path, &e) == PFSPH_OK && pfsph_checkpoint_keep(stash, cp, &e) == PFSPH_OK) kept = good_frame;
    }
    if (s->output.checkpoint_interval > 0 && kept >= 0)
        pfsph_fail(err, PFSPH_EINTR,
                   "interrupted at t = %.6g s; the run continues from its checkpoint of frame %d (t = %.6g s) "
                   "with: pfsph run --resume %s",
                   pfsph_sim_time(sim), kept, kept / s->fps, dir);
    else
        pfsph_fail(err, PFSPH_EINTR,
                   "interrupted at t = %.6g s; no checkpoint to resume from (output.checkpoint_interval is 0): "
                   "run it again with --force",
                   pfsph_sim_time(sim));
}

/* The rows so far reached stats.csv or bodies.csv (flushed), else PFSPH_EIO naming the file:
 * a full disk must not cut the statistics silently. */
int pfsph__csv_flushed(FILE *f, const char *path, pfsph_error *err)
{
    int bad = fflush(f) != 0 || ferror(f) || pfsph__write_fault(path);
    int e = errno;
    return bad ? pfsph_fail(err, PFSPH_EIO, "%s: write failed: %s", path, strerror(e ? e : EIO)) : PFSPH_OK;
}
