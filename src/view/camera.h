/* The viewer's camera: starts as the PNG renderer's (pfsph_render_camera_for), then orbits about
 * a target, pans and zooms; gives column-major view and projection matrices for OpenGL. */
#ifndef PFSPH_VIEW_CAMERA_H
#define PFSPH_VIEW_CAMERA_H

#include <stdbool.h>

#include "pfsph/render.h"

typedef struct pfsph_vcam {
    bool ortho;
    double eye[3], target[3], right[3], up[3], fwd[3];
    double world_up[3]; /* orbit axis */
    double f_per_h;     /* perspective: focal length / image height; ortho: pixels per metre / height */
    double cx, cy;      /* ortho: world x, y at the image centre */
} pfsph_vcam;

/* From the renderer's camera; `centre` is the point a perspective camera orbits about. */
void pfsph_vcam_init(pfsph_vcam *c, const pfsph_render_camera *rc, const double centre[3]);
/* Orbit by yaw about world_up and pitch about right [radians] (perspective only). */
void pfsph_vcam_orbit(pfsph_vcam *c, double yaw, double pitch);
/* Move by dx, dy pixels of an image h pixels high. */
void pfsph_vcam_pan(pfsph_vcam *c, double dx, double dy, int h);
/* Zoom in by factor s > 1 (out for s < 1). */
void pfsph_vcam_zoom(pfsph_vcam *c, double s);
/* Column-major 4x4 view and projection matrices for a w x h image; `depth` is the scene's
 * extent [m], for the near and far planes. */
void pfsph_vcam_matrices(const pfsph_vcam *c, int w, int h, double depth, float view[16], float proj[16]);
/* Pixels per metre at unit distance (perspective) or everywhere (ortho), for an image h high. */
double pfsph_vcam_focal(const pfsph_vcam *c, int h);

/* Pixel position (from the top left) and depth along the view axis of world point p; 0 when it
 * is behind the eye. Ortho: depth 0. */
int pfsph_vcam_project(const pfsph_vcam *c, int w, int h, const double p[3], double *sx, double *sy, double *depth);
/* The world point at pixel (sx, sy) and that depth (ortho: in the plane z = 0). */
void pfsph_vcam_unproject(const pfsph_vcam *c, int w, int h, double sx, double sy, double depth, double p[3]);

#endif
