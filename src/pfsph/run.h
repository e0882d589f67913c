/* Running a scene into a run directory: frames, statistics, summary. The library reports
 * progress through a callback and never prints. */
#ifndef PFSPH_RUN_H
#define PFSPH_RUN_H

#include <signal.h>
#include <stdbool.h>

#include "pfsph/checkpoint.h"
#include "pfsph/scene.h"

typedef struct pfsph_progress {
    int frame, nframes; /* frames done / total */
    double time, end_time;
    uint64_t steps;
    double wall_s; /* seconds since the run started */
    double steps_per_s;
    size_t n_fluid;
    double time0; /* simulated time this run started from (a resume's checkpoint) */
    bool partial; /* an update within a frame (steps; at most 4 a second), not a frame done */
} pfsph_progress;

typedef void (*pfsph_progress_fn)(const pfsph_progress *p, void *user);

typedef struct pfsph_run_opts {
    const char *out_dir;    /* NULL: scene->output.dir */
    double end_time;        /* < 0: scene->end_time */
    const char *scene_text; /* the scene file's text, saved as RUN/scene.json (NULL: none) */
    pfsph_progress_fn progress;
    void *user;
    /* Continue the run in out_dir from its newest valid checkpoint (docs/checkpoints.md):
     * frames after it are rewritten, stats.csv rows after it dropped, then rows appended. The
     * scene must be the one of the checkpoint (scene hash). */
    bool resume;
    pfsph_message_fn message; /* warnings (a checkpoint skipped); may be NULL; gets `user` */
    /* A fresh run into a directory that is not empty: remove pfsph's files there (frames,
     * checkpoints, PNGs, scene.json, stats and summary; nothing else) and run. Without it such
     * a run is refused (PFSPH_EINPUT). */
    bool force;
    /* Set nonzero (from a signal handler) to stop the run at its next step: it ends with
     * PFSPH_EINTR, keeps the last finished frame's state as a checkpoint when checkpoints are on
     * (a rename of the stash, no encoding) and says in err how to resume. NULL: never. */
    const volatile sig_atomic_t *stop;
} pfsph_run_opts;

/* Run the scene, writing a checkpoint every scene->output.checkpoint_interval frames into
 * RUN/checkpoints. The run holds an exclusive flock on RUN/.pfsph.lock throughout; a second
 * run into the same directory is refused (PFSPH_EINPUT, naming the holder's pid). A fresh run
 * refuses a non-empty directory unless opts->force; it records its end time in RUN/run.json,
 * which a resume without an end time uses. A resume removes temporaries left by a killed
 * writer and the frame files after its checkpoint. Returns PFSPH_OK, PFSPH_EINPUT (bad end
 * time, a directory that cannot be made, written or locked, not empty), PFSPH_EIO (writing
 * output), PFSPH_EUNSTABLE (blow-up; frames written so far are kept) or PFSPH_ENOMEM. */
int pfsph_run(const pfsph_scene *s, const pfsph_run_opts *o, pfsph_error *err);

/* One frame as pfsph_run writes it (its own writer), into dir/frames, which must exist: for the
 * embedding API's pfsph_sim_write_frame. */
int pfsph__run_write_frame(pfsph_sim *sim, const char *dir, int frame, pfsph_error *err);
/* The same with the scene given (src/run_frame.c; the driver passes its own). */
int pfsph__run_frame_files(const pfsph_scene *s, const char *dir, int frame, pfsph_sim *sim, pfsph_error *err);

#endif
