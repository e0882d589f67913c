/* PNG previews of a run directory: particles splatted as shaded spheres with a depth buffer. */
#ifndef PFSPH_RENDER_H
#define PFSPH_RENDER_H

#include <stdbool.h>

#include "pfsph/types.h"

typedef struct pfsph_render_opts {
    int width, height;    /* 0: from the scene camera or 960x540 */
    const char *color_by; /* NULL: scene camera's, else "phase" */
    bool video;           /* also frames.mp4 via ffmpeg when present */
    int first, last;      /* frame range, last < 0 for all */
    bool quiet;           /* kept for callers; the library never prints (see progress) */
    bool all_walls;       /* 3D: keep the walls that face the camera (default: cut away) */
    bool no_legend;       /* no key: colour bar, legend of phases, bodies and diffuse kinds, scale bar */
    bool particles;       /* draw the fluid's and the bodies' particles even where
                            * frames/liquid_NNNNN.ply (a surface mesh, shaded as water) and
                            * frames/surfaces_NNNNN.ply (the bodies' meshes) exist */
    /* After each PNG: done of total frames, the file written (may be NULL); and a message
     * (the video written). Either may be NULL; both get `user`. */
    void (*progress)(int done, int total, const char *path, void *user);
    void (*message)(const char *msg, void *user);
    void *user;
} pfsph_render_opts;

/* Render every frame of RUN_DIR/frames into RUN_DIR/png/frame_NNNNN.png. Returns the number of
 * frames rendered through *count. */
/* The frames of one particle set in a run's frames/ directory: the numbers of
 * "<prefix>NNNNN.vtp" (preferred) or ".ply", sorted (the renderer and the viewer's replay). */
typedef struct pfsph_frame_list {
    int *num;
    char *ply; /* 1 where only a .ply exists for that number */
    int n, cap;
} pfsph_frame_list;

int pfsph_frame_list_read(const char *dir, const char *prefix, pfsph_frame_list *fl, pfsph_error *err);
void pfsph_frame_list_free(pfsph_frame_list *fl);
/* Index of the entry numbered f, or -1. */
int pfsph_frame_list_find(const pfsph_frame_list *fl, int f);

int pfsph_render_run(const char *run_dir, const pfsph_render_opts *o, int *count, pfsph_error *err);

/* The camera pfsph_render_run uses for a w x h image (the live viewer starts from it, so that
 * both show the same picture): 2D an orthographic view of the x-y plane, 3D the scene's camera
 * or the automatic front-right-above one framing the first frame's fluid and boundary. */
typedef struct pfsph_render_camera {
    bool ortho;
    double eye[3], right[3], up[3], fwd[3]; /* unit vectors, camera looks along fwd */
    double f;                               /* perspective: focal length in pixels; ortho: pixels per metre */
    double cx, cy;                          /* ortho: world x, y at the image centre */
    int w, h;
} pfsph_render_camera;

struct pfsph_scene;
struct pfsph_particles;
/* boundary may be NULL (no boundary frame). */
void pfsph_render_camera_for(const struct pfsph_scene *s, const struct pfsph_particles *fluid,
                             const struct pfsph_particles *boundary, int w, int h, pfsph_render_camera *out);

/* The cut-away of `pfsph render` (3D): the tank walls that face the camera are left out so
 * that what stands inside the tank shows, namely wall particles within 5 particle radii of a
 * face of the walls' bounding box on the eye's side, sideways or above, never the floor (the
 * face gravity points to). init: off in 2D, or when walls is NULL or empty. hides: whether the
 * wall particle at p is left out for a camera at eye (the live viewer asks as it orbits). */
typedef struct pfsph_cutaway {
    bool on;
    double lo[3], hi[3]; /* the walls' box [m] */
    double m;            /* depth of the cut [m] */
    int up;              /* the axis against gravity */
} pfsph_cutaway;
void pfsph_cutaway_init(pfsph_cutaway *cw, const struct pfsph_scene *s, const struct pfsph_particles *walls,
                        const struct pfsph_particles *fluid);
bool pfsph_cutaway_hides(const pfsph_cutaway *cw, const double eye[3], const double p[3]);

/* The colour walls of solid phase `phase` are drawn in (render and viewer): the phase's own
 * "color"; else light grey for the first solid phase and, when a scene has several solid phases
 * without colours (pf_wetting's five plates), a muted colour of its own for each of the others, so
 * that they can be told apart (and named in the viewer's legend). The grey turns a darker slate
 * when a fluid or gas phase is drawn in a grey like it (within 0.2 per channel: the bubble scenes'
 * near-white gas). Returns 1 when the colour is not the plain light grey (the phase belongs in a
 * legend). */
int pfsph_wall_color(const struct pfsph_scene *s, int phase, float out[3]);

/* Encode 8-bit RGB rows (top first) as a PNG and write it atomically. */
int pfsph_write_png_rgb(const char *path, const uint8_t *rgb, int w, int h, pfsph_error *err);

#endif
