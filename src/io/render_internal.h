/* Internal interface of `pfsph render` (pfsph/render.h) between its files: the camera
 * (render_camera.c), the rasteriser and its shading (render_raster.c), one frame and the
 * driver (render.c), the frame files (frame_list.c), PNG (png.c) and the video (video.c). */
#ifndef PFSPH_IO_RENDER_INTERNAL_H
#define PFSPH_IO_RENDER_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "pfsph/particles.h"
#include "pfsph/render.h"
#include "pfsph/scene.h"
#include "pfsph/surface_mesh.h"
#include "pfsph/types.h"

/* Small 3-vectors of the camera and of the meshes' normals. */
static inline double pfsph__rdot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void pfsph__rcross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static inline void pfsph__rnorm3(double a[3])
{
    double l = sqrt(pfsph__rdot3(a, a));
    if (l > 0)
        for (int k = 0; k < 3; k++) a[k] /= l;
}

/* ---- camera (render_camera.c) ---------------------------------------------------------- */

typedef struct pfsph__rcam {
    bool ortho;
    double eye[3], right[3], up[3], fwd[3];
    double f;      /* perspective: focal length in pixels; ortho: pixels per metre */
    double cx, cy; /* ortho: world x, y at the image centre */
    double dist;   /* perspective: the eye's distance to the target [m] (the scale bar's depth) */
    int w, h;      /* supersampled image size */
} pfsph__rcam;

/* Frame the scene for an image of c->w x c->h pixels: 2D an orthographic view of the x-y
 * plane, 3D the scene's camera or the automatic one, fitted to the fluid and the boundary
 * (NULL: none) of one frame. */
void pfsph__rcam_frame(pfsph__rcam *c, const pfsph_scene *s, const pfsph_particles *fluid,
                       const pfsph_particles *boundary);

/* ---- splats (render_raster.c) ---------------------------------------------------------- */

typedef struct pfsph__splat {
    float sx, sy, r; /* screen centre and radius, supersampled pixels */
    float depth, rw; /* depth of the centre, sphere radius in depth units */
    float col[3];
    float relief;  /* 0..1: how much shading; discs of a pixel or two are drawn flat */
    uint8_t layer; /* 0 fluid/diffuse, 1 boundary */
} pfsph__splat;

/* Supersampled layers (0 fluid and diffuse, 1 boundary): nearest depth and the splat that
 * owns the sample; shading is deferred to the composite pass, once per sample. */
typedef struct pfsph__image {
    int w, h;
    float *z[2];
    uint32_t *id[2];
} pfsph__image;

typedef struct pfsph__splat_set {
    pfsph__splat *s;
    size_t n, cap;
} pfsph__splat_set;

/* Screen position, radius and depth of a sphere at p of radius rad into s; false when it is
 * behind or too close to the eye (render_camera.c). */
bool pfsph__rcam_project(const pfsph__rcam *c, const double p[3], double rad, pfsph__splat *s);

/* What colours the fluid (the scene camera's color_by). */
enum { PFSPH__COLOR_PHASE, PFSPH__COLOR_SPEED, PFSPH__COLOR_DENSITY, PFSPH__COLOR_PRESSURE };

/* Append the splats of a particle set: kind 0 fluid (coloured by `by`, speed up to vref when
 * > 0; the colour range into range when not NULL), 1 boundary (cw: the cut-away), 2 diffuse,
 * 3 bodies; ssf: the supersampling factor. PFSPH_ENOMEM when out of memory. */
int pfsph__splat_add_set(pfsph__splat_set *ss, const pfsph__rcam *c, const pfsph_particles *ps, double rad, int layer,
                         int kind, const pfsph_scene *sc, int by, double vref, int ssf, const pfsph_cutaway *cw,
                         double range[2]);
/* Depth-test every splat of idx[0..nidx) overlapping rows [y0, y1) into its layer. */
void pfsph__splat_band(pfsph__image *im, const pfsph__splat *sp, const size_t *idx, size_t nidx, int y0, int y1);
/* Colour of splat s at supersampled pixel (px, py); flat: the walls' flat look (3D). */
void pfsph__shade_splat(const pfsph__splat *s, int px, int py, bool flat, float out[3]);
/* The background of row y of h. */
void pfsph__background(int y, int h, double out[3]);

/* ---- meshes (render_raster.c) ----------------------------------------------------------- */

/* Layer-0 id of a pixel of the liquid's mesh. */
#define PFSPH__MESH_ID UINT32_MAX
/* Layer-0 ids at or above PFSPH__BODY_ID0 are pixels of a body's mesh (body = id -
 * PFSPH__BODY_ID0); PFSPH__MESH_ID the liquid's. Splats never come near: their count is checked
 * against UINT32_MAX - 512. */
#define PFSPH__BODY_ID0 (UINT32_MAX - 257u)

/* Depth-test a mesh's triangles into layer 0 of im, their camera-space normals into mn (3 per
 * pixel): bodies with each face's own normal, the liquid with its smooth vertex normals. */
void pfsph__raster_mesh(const pfsph__rcam *c, pfsph__image *im, float *mn, const pfsph_surface_mesh *m, bool bodies);
/* The liquid's pixel of normal n as water; a body's pixel in colour col as a solid. */
void pfsph__shade_water(const float n[3], float out[3]);
void pfsph__shade_solid(const float n[3], const float col[3], float out[3]);
/* The colour of body b of the bodies' surface file: its phase's, as its particles are drawn. */
void pfsph__body_color(const pfsph_scene *sc, int b, float col[3]);

/* ---- caption and key (render_key.c) ------------------------------------------------------ */

/* The caption in the built-in 5x7 font (digits, "framets=.- "), scale sc, into 8-bit RGB rows. */
void pfsph__draw_text(uint8_t *rgb, int w, int h, int x0, int y0, int sc, const char *txt);

/* What a preview's key shows (pfsph__draw_key); tsc: the caption's text scale. */
typedef struct pfsph__key {
    const pfsph_scene *sc;
    const pfsph__rcam *cam; /* the supersampled camera; ss its factor */
    int ss, tsc;
    int color_by;                           /* PFSPH__COLOR_*: a colour bar unless phase or the liquid is a mesh */
    double range[2];                        /* the colour bar's range */
    bool fluid_phases;                      /* the fluid's particles are drawn in their phases' colours */
    bool liquid_mesh;                       /* the liquid is drawn as a water surface */
    const pfsph_particles *walls, *diffuse; /* NULL: none drawn */
    bool bodies;                            /* the scene's bodies are drawn */
} pfsph__key;

/* The key of a preview: the colour bar of the fluid's field with its name and unit (right), a
 * legend of what is drawn in a colour of its own, with names: fluid phases, the water surface,
 * walls, bodies, spray/foam/bubbles (top left), and a scale bar (bottom right). */
void pfsph__draw_key(uint8_t *rgb, int w, int h, const pfsph__key *k);

/* ---- files (frame_list.c, video.c) -------------------------------------------------------- */

/* Particles of frame num of a set (dir/<prefix>NNNNN.vtp, or .ply when ply). */
int pfsph__read_frame(const char *dir, const char *prefix, int num, bool ply, pfsph_particles *ps, double *time,
                      pfsph_error *err);
/* RUN_DIR/frames.mp4 from RUN_DIR/png/frame_NNNNN.png, numbered from first, with ffmpeg. */
int pfsph__render_video(const char *run_dir, int first, double fps, const pfsph_render_opts *o, pfsph_error *err);

#endif
