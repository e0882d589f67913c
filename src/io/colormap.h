/* The colours of `pfsph render` (src/io/render_raster.c, render.c) that the live viewer
 * (src/view/) shares, so that both colour a frame alike: the colour map of a field (viridis),
 * the fixed scale of speed, the colours of diffuse particles. Inline: the viewer is part of the
 * program, not of the library, and needs no library-internal symbol for it. */
#ifndef PFSPH_IO_COLORMAP_H
#define PFSPH_IO_COLORMAP_H

#include <float.h>
#include <math.h>

#include "pfsph/particles.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"

/* Spray, foam, bubble (a diffuse particle's type): white, cream, light blue. Foam was a light
 * grey (0.80, 0.82, 0.85), which read as the walls' grey (0.78, 0.78, 0.80) in previews (issue
 * 33): cream differs from the walls, the spray and the bubbles by 0.35 or more in a channel. */
static const float PFSPH__DIFFUSE_COL[3][3] = {{0.98f, 0.98f, 0.98f}, {0.96f, 0.84f, 0.45f}, {0.55f, 0.78f, 0.98f}};

/* Viridis, sampled at five stops and interpolated linearly; t is clamped to 0..1 (NaN: 0). */
static inline void pfsph__viridis(double t, float out[3])
{
    static const float st[5][3] = {{0.267f, 0.005f, 0.329f},
                                   {0.229f, 0.322f, 0.546f},
                                   {0.128f, 0.567f, 0.551f},
                                   {0.369f, 0.789f, 0.383f},
                                   {0.993f, 0.906f, 0.144f}};
    if (!(t > 0)) t = 0;
    if (t > 1) t = 1;
    double u = t * 4;
    int i = (int)u;
    if (i > 3) i = 3;
    double f = u - i;
    for (int k = 0; k < 3; k++) out[k] = (float)((1 - f) * st[i][k] + f * st[i + 1][k]);
}

/* A fixed colour scale for speed over the whole run (per-frame ranges flicker): the free-fall
 * speed sqrt(2 g H) over the fluid's height H in the first frame, the largest speed a
 * gravity-driven flow such as a dam break reaches, or what emitted fluid reaches when more.
 * 0 (per-frame range) without gravity or fluid. */
static inline double pfsph__speed_scale(const pfsph_scene *sc, const pfsph_particles *fluid)
{
    double g2 = 0, ve = pfsph_scene_emitter_speed(sc);
    for (int k = 0; k < 3; k++) g2 += sc->gravity[k] * sc->gravity[k];
    if (!(g2 > 0) || fluid->n == 0) return ve;
    double g = sqrt(g2), lo = DBL_MAX, hi = -DBL_MAX;
    for (size_t i = 0; i < fluid->n; i++) {
        double h = -(fluid->x[i] * sc->gravity[0] + fluid->y[i] * sc->gravity[1] +
                     (sc->dim == 3 ? fluid->z[i] * sc->gravity[2] : 0.0)) /
            g;
        if (!isfinite(h)) continue;
        if (h < lo) lo = h;
        if (h > hi) hi = h;
    }
    return fmax(ve, hi > lo ? sqrt(2 * g * (hi - lo)) : 0);
}

#endif
