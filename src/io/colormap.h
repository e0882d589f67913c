/* The colour map of a field (viridis), shared by `pfsph render` (src/io/render_raster.c) and the
 * live viewer (src/view/), so that both colour a field alike. Inline: the viewer is part of the
 * program, not of the library, and needs no library-internal symbol for it. */
#ifndef PFSPH_IO_COLORMAP_H
#define PFSPH_IO_COLORMAP_H

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

#endif
