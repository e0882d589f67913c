/* Internal to the run driver (src/run.c, src/run_control.c): stopping, end times, CSV rows. */
#ifndef PFSPH_RUN_CONTROL_H
#define PFSPH_RUN_CONTROL_H

#include <stdio.h>

#include "pfsph/scene.h"
#include "pfsph/sim.h"

/* PFSPH_OK when end (an --end) is a whole number of frames at the scene's fps, else
 * PFSPH_EINPUT offering the frame times on either side. */
int pfsph__run_end_on_frame(const pfsph_scene *s, double end, pfsph_error *err);
/* After a stop was asked for: the stash (NULL: none) of good_frame becomes its checkpoint when
 * checkpoints are on and it is newer than last_ckpt (-1: none); err (PFSPH_EINTR) says where
 * the run stopped and how to resume. */
void pfsph__run_interrupted(const char *dir, const pfsph_scene *s, const pfsph_sim *sim, const char *stash,
                            int good_frame, int last_ckpt, pfsph_error *err);
/* The rows written so far to f reached path (flushed), else PFSPH_EIO naming it. */
int pfsph__csv_flushed(FILE *f, const char *path, pfsph_error *err);

#endif
