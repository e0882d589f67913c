/* PNG previews of a run directory: particles splatted as shaded spheres with a depth buffer. */
#ifndef PFSPH_RENDER_H
#define PFSPH_RENDER_H

#include <stdbool.h>

#include "pfsph/types.h"

typedef struct pfsph_render_opts {
    int width, height;     /* 0: from the scene camera or 960x540 */
    const char *color_by;  /* NULL: scene camera's, else "phase" */
    bool video;            /* also frames.mp4 via ffmpeg when present */
    int first, last;       /* frame range, last < 0 for all */
    bool quiet;            /* kept for callers; the library never prints (see progress) */
    bool particles;        /* draw the fluid's particles even where frames/liquid_NNNNN.ply
                            * (a surface mesh, shaded as water) exists */
    /* After each PNG: done of total frames, the file written (may be NULL); and a message
     * (the video written). Either may be NULL; both get `user`. */
    void (*progress)(int done, int total, const char *path, void *user);
    void (*message)(const char *msg, void *user);
    void *user;
} pfsph_render_opts;

/* Render every frame of RUN_DIR/frames into RUN_DIR/png/frame_NNNNN.png. Returns the number of
 * frames rendered through *count. */
int pfsph_render_run(const char *run_dir, const pfsph_render_opts *o, int *count,
                     pfsph_error *err);

#endif
