/* OpenGL 3.3 core drawing for the viewer: particles as instanced point sprites (screen-facing
 * quads shaded as spheres in the fragment shader, with true sphere depth), two layers composited
 * as the PNG renderer does (fluid, bodies and diffuse in one, walls in the other: translucent
 * walls in 3D), triangle meshes in vertex buffers (a replayed run's liquid, shaded as water,
 * and rigid bodies), and a 2D overlay of text and coloured quads in pixels. */
#ifndef PFSPH_VIEW_DRAW_H
#define PFSPH_VIEW_DRAW_H

#include <stddef.h>
#include <stdint.h>

/* One particle to draw: centre [m], radius [m], colour 0..1. */
typedef struct pfsph_vsprite {
    float x, y, z, r;
    float cr, cg, cb, pad;
} pfsph_vsprite;

typedef struct pfsph_vdraw pfsph_vdraw;

/* Needs a current OpenGL 3.3 core context. NULL on failure, with a message in msg. */
pfsph_vdraw *pfsph_vdraw_create(char *msg, size_t cap);
void pfsph_vdraw_destroy(pfsph_vdraw *d);

/* Samples per pixel along each axis: 2 (default, as the PNG renderer) or 1. */
void pfsph_vdraw_set_samples(pfsph_vdraw *d, int ss);
/* Whether the current context renders in software (Mesa llvmpipe, softpipe). */
int pfsph_vdraw_software(void);

/* Start a frame of w x h pixels with these column-major matrices; f: pixels per metre at unit
 * distance (perspective) or everywhere (ortho), for the shading level of small discs; walls3d:
 * translucent, flat-shaded walls (3D) rather than walls behind the fluid (2D). */
void pfsph_vdraw_begin(pfsph_vdraw *d, int w, int h, const float view[16], const float proj[16], int ortho, double f,
                       int walls3d);
/* Draw n sprites into layer 0 (fluid, bodies, diffuse) or 1 (walls: one call a frame, or none
 * for no walls; the same sprites as the last frame's, with the same camera, re-use the layer
 * as it was drawn: static walls cost nothing while the camera stands still). */
void pfsph_vdraw_sprites(pfsph_vdraw *d, int layer, const pfsph_vsprite *s, size_t n);
/* A triangle mesh held by the GPU (one vertex buffer, and an index buffer when indexed). */
typedef struct pfsph_vmesh pfsph_vmesh;
/* Vertices of 9 floats: position [m], unit normal, colour 0..1. idx (ni entries, 3 per
 * triangle) may be NULL: then every three vertices are a triangle (faces with their own
 * normals). Replaces what the mesh held. NULL from create when out of memory. */
pfsph_vmesh *pfsph_vmesh_create(void);
void pfsph_vmesh_upload(pfsph_vmesh *m, const float *vert, size_t nv, const uint32_t *idx, size_t ni);
void pfsph_vmesh_destroy(pfsph_vmesh *m);
/* Draw a mesh into layer 0: water = 1 shades it as `pfsph render` shades the liquid (a blue
 * body, Lambert light, a highlight and Fresnel towards the sky; the colours are ignored),
 * water = 0 as a solid in its vertex colours with the particles' light. */
void pfsph_vdraw_mesh(pfsph_vdraw *d, const pfsph_vmesh *m, int water);
/* Composite the layers over the background into the frame. */
void pfsph_vdraw_composite(pfsph_vdraw *d);
/* Overlay, in pixels from the top left: a filled rectangle, text (3x5 font scaled by sc; letters
 * are drawn upper case: io/font.h), and the colour bar of io/colormap.h. */
void pfsph_vdraw_rect(pfsph_vdraw *d, float x, float y, float w, float h, const float rgba[4]);
float pfsph_vdraw_text(pfsph_vdraw *d, float x, float y, float sc, const char *s, const float rgba[4]);
void pfsph_vdraw_colorbar(pfsph_vdraw *d, float x, float y, float w, float h);
/* Draw the overlay queued since begin. */
void pfsph_vdraw_overlay(pfsph_vdraw *d);
/* Copy the frame to the window's framebuffer (fb_w x fb_h). */
void pfsph_vdraw_present(pfsph_vdraw *d, int fb_w, int fb_h);
/* Read the frame as 8-bit RGB rows, top first (w * h * 3 bytes). */
void pfsph_vdraw_read(pfsph_vdraw *d, uint8_t *rgb);

#endif
