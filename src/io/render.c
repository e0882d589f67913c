/* PNG previews of a run directory (pfsph/render.h): every particle is splatted as a shaded
 * sphere, z-buffered, supersampled 2x2, then written as a PNG; optionally an ffmpeg video. Where
 * a frame has meshes, the liquid's (liquid_NNNNN.ply) is rasterised and shaded as water and the
 * bodies' (surfaces_NNNNN.ply) as flat-shaded solids instead of their particles. This file: one
 * frame (splats binned into bands of rows, depth-tested in parallel, composited) and the loop
 * over the frames; the camera, the rasteriser, PNG and video are in render_*.c, png.c, video.c. */
#include "pfsph/render.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/colormap.h"
#include "io/render_internal.h"
#include "pfsph/io.h"
#include "pfsph/meshing.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"

#define BAND 16 /* rows per work item of the splatting loop */

typedef pfsph_frame_list frame_list;
typedef pfsph__splat splat;

/* ---- one frame ------------------------------------------------------------------------ */

typedef struct ctx {
    const pfsph_scene *sc;
    pfsph__rcam c;
    int ss; /* supersampling factor */
    int out_w, out_h;
    bool all_walls, no_legend;
    int color_by;
    double vref; /* speed colour scale: sqrt(2 g H) of the first frame's fluid, 0 if none */
    pfsph__image im;
    pfsph__splat_set sp;
    size_t *bidx; /* band lists */
    size_t *bstart;
    size_t bcap;
    uint8_t *rgb;
    float *mn; /* camera-space normals of mesh pixels (layer 0, ids PFSPH__MESH_ID and up) */
} ctx;

/* A mesh file of frame f (frames/<prefix>NNNNN.ply) into m; -1 when absent or unreadable, so
 * that a missing or broken mesh falls back to the particles. */
static int read_mesh(const char *fdir, const char *prefix, int f, pfsph_surface_mesh *m)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/%s%05d.ply", fdir, prefix, f);
    memset(m, 0, sizeof *m);
    if (access(path, R_OK) != 0) return -1;
    pfsph_error e;
    return pfsph_read_surface_ply(path, m, NULL, &e) == PFSPH_OK ? 0 : -1;
}

static int render_frame(ctx *x, const pfsph_particles *fluid, const pfsph_particles *bnd, const pfsph_particles *bod,
                        const pfsph_particles *dif, const pfsph_surface_mesh *liq, const pfsph_surface_mesh *bmesh,
                        int frame, double time, const char *png_path, pfsph_error *err)
{
    const pfsph_scene *sc = x->sc;
    const double r = sc->particle_radius > 0 ? sc->particle_radius : 0.01;
    x->sp.n = 0;
    int rc = PFSPH_OK;
    /* 2D: the boundary is drawn behind the fluid (depth bias) and slightly smaller. */
    const bool d2 = sc->dim == 2;
    /* 2D fluid discs are drawn a little larger than the particle so that a block of fluid
     * reads as a surface rather than a lattice with holes (spacing is 2r). */
    const int ssf = x->ss;
    pfsph_cutaway cw;
    pfsph_cutaway_init(&cw, sc, x->all_walls ? NULL : bnd, fluid);
    double range[2] = {0, 1};
    if (bnd &&
        (rc = pfsph__splat_add_set(&x->sp, &x->c, bnd, d2 ? 0.9 * r : r, 1, 1, sc, PFSPH__COLOR_PHASE, 0, ssf, &cw,
                                   NULL)))
        goto oom;
    const bool mesh = liq && liq->ntris && !d2; /* the liquid's surface instead of its particles */
    if (!mesh &&
        (rc = pfsph__splat_add_set(&x->sp, &x->c, fluid, d2 ? 1.3 * r : r, 0, 0, sc, x->color_by, x->vref, ssf, NULL,
                                   range)))
        goto oom;
    if (dif &&
        (rc = pfsph__splat_add_set(&x->sp, &x->c, dif, 0.4 * r, 0, 2, sc, PFSPH__COLOR_PHASE, 0, ssf, NULL, NULL)))
        goto oom;
    /* rigid bodies are drawn solid in their phase's colour, not as translucent walls */
    const bool bmeshes = bmesh && bmesh->ntris && !d2; /* the bodies' surfaces instead of their particles */
    if (bod && !bmeshes &&
        (rc = pfsph__splat_add_set(&x->sp, &x->c, bod, r, 0, 3, sc, PFSPH__COLOR_PHASE, 0, ssf, NULL, NULL)))
        goto oom;

    if (x->sp.n > UINT32_MAX - 512) return pfsph_fail(err, PFSPH_EINPUT, "%s: too many particles", png_path);
    /* Bin splats into bands of rows: a splat goes to every band it overlaps. */
    const int W = x->c.w, H = x->c.h, nb = (H + BAND - 1) / BAND;
    size_t *cnt = calloc((size_t)nb + 1, sizeof *cnt);
    if (!cnt) goto oom;
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            size_t acc = 0;
            for (int b = 0; b <= nb; b++) {
                size_t t = cnt[b];
                cnt[b] = acc;
                acc += t;
            }
            total = acc;
            if (total > x->bcap) {
                size_t *q = realloc(x->bidx, (total ? total : 1) * sizeof *q);
                if (!q) {
                    free(cnt);
                    goto oom;
                }
                x->bidx = q;
                x->bcap = total;
            }
            memcpy(x->bstart, cnt, ((size_t)nb + 1) * sizeof *cnt);
        }
        for (size_t i = 0; i < x->sp.n; i++) {
            const splat *s = &x->sp.s[i];
            float rr = s->r < 0.6f ? 0.6f : s->r;
            if (s->sx + rr < 0 || s->sx - rr > W || s->sy + rr < 0 || s->sy - rr > H) continue;
            int b0 = (int)floorf((s->sy - rr) / BAND), b1 = (int)floorf((s->sy + rr) / BAND);
            if (b0 < 0) b0 = 0;
            if (b1 > nb - 1) b1 = nb - 1;
            for (int b = b0; b <= b1; b++) {
                if (pass == 0) cnt[b]++;
                else x->bidx[cnt[b]++] = i;
            }
        }
    }
    free(cnt);

    const size_t npix = (size_t)W * H;
    for (int l = 0; l < 2; l++) {
        for (size_t i = 0; i < npix; i++) x->im.z[l][i] = FLT_MAX;
    }
    if (d2) /* push the boundary layer behind every fluid particle */
        for (size_t i = 0; i < x->sp.n; i++)
            if (x->sp.s[i].layer == 1) x->sp.s[i].depth += (float)(4 * r);
#pragma omp parallel for schedule(dynamic, 1)
    for (int b = 0; b < nb; b++) {
        int y0 = b * BAND, y1 = y0 + BAND < H ? y0 + BAND : H;
        pfsph__splat_band(&x->im, x->sp.s, x->bidx + x->bstart[b], x->bstart[b + 1] - x->bstart[b], y0, y1);
    }
    if (mesh || bmeshes) {
        if (!x->mn && !(x->mn = malloc(3 * npix * sizeof *x->mn))) goto oom;
        if (mesh) pfsph__raster_mesh(&x->c, &x->im, x->mn, liq, false);
        if (bmeshes) pfsph__raster_mesh(&x->c, &x->im, x->mn, bmesh, true);
    }

    /* Composite and downsample: boundary walls in front of fluid are translucent in 3D. */
    const int ss = x->ss, ow = x->out_w, oh = x->out_h;
    const double a_front = d2 ? 1.0 : 0.28, a_back = d2 ? 1.0 : 0.85;
#pragma omp parallel for schedule(static)
    for (int oy = 0; oy < oh; oy++) {
        for (int ox = 0; ox < ow; ox++) {
            double acc[3] = {0, 0, 0};
            for (int sy = 0; sy < ss; sy++) {
                int py = oy * ss + sy;
                double bg[3];
                pfsph__background(py, H, bg);
                for (int sx = 0; sx < ss; sx++) {
                    const int px = ox * ss + sx;
                    const size_t o = (size_t)py * W + (size_t)px;
                    double c[3];
                    float sc3[3];
                    bool hf = x->im.z[0][o] < FLT_MAX, hb = x->im.z[1][o] < FLT_MAX;
                    if (hf && x->im.id[0][o] == PFSPH__MESH_ID) {
                        pfsph__shade_water(x->mn + 3 * o, sc3);
                        for (int k = 0; k < 3; k++) c[k] = sc3[k];
                    } else if (hf && x->im.id[0][o] >= PFSPH__BODY_ID0) {
                        float bc[3];
                        pfsph__body_color(sc, (int)(x->im.id[0][o] - PFSPH__BODY_ID0), bc);
                        pfsph__shade_solid(x->mn + 3 * o, bc, sc3);
                        for (int k = 0; k < 3; k++) c[k] = sc3[k];
                    } else if (hf) {
                        pfsph__shade_splat(&x->sp.s[x->im.id[0][o]], px, py, false, sc3);
                        for (int k = 0; k < 3; k++) c[k] = sc3[k];
                    } else {
                        for (int k = 0; k < 3; k++) c[k] = bg[k];
                    }
                    if (hb) {
                        double a = !hf ? a_back : (x->im.z[1][o] < x->im.z[0][o] ? a_front : 0);
                        pfsph__shade_splat(&x->sp.s[x->im.id[1][o]], px, py, !d2, sc3);
                        for (int k = 0; k < 3; k++) c[k] = (1 - a) * c[k] + a * sc3[k];
                    }
                    for (int k = 0; k < 3; k++) acc[k] += c[k];
                }
            }
            for (int k = 0; k < 3; k++)
                x->rgb[3 * ((size_t)oy * ow + ox) + k] = (uint8_t)lrint(fmin(1.0, acc[k] / (ss * ss)) * 255.0);
        }
    }
    char cap[96];
    snprintf(cap, sizeof cap, "frame %d  t=%.3f s", frame, time);
    int tsc = oh >= 400 ? 2 : 1;
    pfsph__draw_text(x->rgb, ow, oh, 6 * tsc, oh - 9 * tsc - 4, tsc, cap);
    if (!x->no_legend) {
        pfsph__key key = {.sc = sc,
                          .cam = &x->c,
                          .ss = ss,
                          .tsc = tsc,
                          .color_by = x->color_by,
                          .range = {range[0], range[1]},
                          .fluid_phases = x->color_by == PFSPH__COLOR_PHASE && !mesh,
                          .liquid_mesh = mesh,
                          .walls = bnd,
                          .bodies = (bod && bod->n) || bmeshes,
                          .diffuse = dif};
        pfsph__draw_key(x->rgb, ow, oh, &key);
    }

    return pfsph_write_png_rgb(png_path, x->rgb, ow, oh, err);
oom:
    return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", png_path);
}

/* ---- driver --------------------------------------------------------------------------- */

static int color_code(const char *s)
{
    if (!s || !*s || strcmp(s, "phase") == 0) return PFSPH__COLOR_PHASE;
    if (strcmp(s, "speed") == 0) return PFSPH__COLOR_SPEED;
    if (strcmp(s, "density") == 0) return PFSPH__COLOR_DENSITY;
    if (strcmp(s, "pressure") == 0) return PFSPH__COLOR_PRESSURE;
    return -1;
}

/* Index of the newest entry with number <= f, or -1. */
static int newest_le(const frame_list *fl, int f)
{
    int best = -1;
    for (int i = 0; i < fl->n; i++)
        if (fl->num[i] <= f) best = i;
    return best;
}

int pfsph_render_run(const char *run_dir, const pfsph_render_opts *o, int *count, pfsph_error *err)
{
    pfsph_render_opts def = {.last = -1};
    if (!o) o = &def;
    if (count) *count = 0;
    char path[PFSPH_PATH_LEN + 64], fdir[PFSPH_PATH_LEN + 16], pdir[PFSPH_PATH_LEN + 16];
    if (strlen(run_dir) >= PFSPH_PATH_LEN)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: run directory path too long", run_dir);
    snprintf(path, sizeof path, "%s/scene.json", run_dir);
    snprintf(fdir, sizeof fdir, "%s/frames", run_dir);
    snprintf(pdir, sizeof pdir, "%s/png", run_dir);

    pfsph_scene *sc = malloc(sizeof *sc);
    if (!sc) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    int rc = pfsph_scene_load(sc, path, err);
    if (rc != PFSPH_OK) {
        free(sc);
        return rc;
    }
    ctx x;
    memset(&x, 0, sizeof x);
    x.sc = sc;
    frame_list fl = {0}, bl = {0}, dl = {0}, rl = {0};
    pfsph_particles fluid = {0}, bnd = {0}, dif = {0}, both = {0};
    int bnd_loaded = -1, rendered = 0;

    const char *cby = o->color_by ? o->color_by : sc->camera.color_by;
    x.color_by = color_code(cby);
    x.all_walls = o->all_walls;
    x.no_legend = o->no_legend;
    if (x.color_by < 0) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "color_by '%s': expected phase, speed, density or pressure", cby);
        goto out;
    }
    x.out_w = o->width > 0 ? o->width : (sc->camera.width > 0 ? sc->camera.width : 960);
    x.out_h = o->height > 0 ? o->height : (sc->camera.height > 0 ? sc->camera.height : 540);
    if (x.out_w < 8 || x.out_h < 8 || x.out_w > 16384 || x.out_h > 16384) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "image size %dx%d: expected 8..16384 per side", x.out_w, x.out_h);
        goto out;
    }
    x.ss = (double)x.out_w * x.out_h <= 4096.0 * 2160.0 ? 2 : 1;
    x.c.w = x.out_w * x.ss;
    x.c.h = x.out_h * x.ss;

    if ((rc = pfsph_frame_list_read(fdir, "fluid_", &fl, err))) goto out;
    if ((rc = pfsph_frame_list_read(fdir, "boundary_", &bl, err))) goto out;
    if ((rc = pfsph_frame_list_read(fdir, "diffuse_", &dl, err))) goto out;
    if ((rc = pfsph_frame_list_read(fdir, "bodies_", &rl, err))) goto out;
    if (fl.n == 0) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: no fluid_NNNNN.vtp or .ply frames", fdir);
        goto out;
    }
    if (mkdir(pdir, 0755) != 0 && errno != EEXIST) {
        rc = pfsph_fail(err, PFSPH_EIO, "%s: cannot create: %s", pdir, strerror(errno));
        goto out;
    }

    const size_t npix = (size_t)x.c.w * x.c.h;
    for (int l = 0; l < 2; l++) {
        x.im.z[l] = malloc(npix * sizeof(float));
        x.im.id[l] = malloc(npix * sizeof(uint32_t));
    }
    x.im.w = x.c.w;
    x.im.h = x.c.h;
    x.rgb = malloc((size_t)x.out_w * x.out_h * 3);
    x.bstart = malloc(((size_t)(x.c.h + BAND - 1) / BAND + 1) * sizeof(size_t));
    if (!x.im.z[0] || !x.im.z[1] || !x.im.id[0] || !x.im.id[1] || !x.rgb || !x.bstart) {
        rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory for a %dx%d image", x.c.w, x.c.h);
        goto out;
    }

    /* The camera is fixed for the whole run, from the first frame rendered. */
    int i0 = -1;
    for (int i = 0; i < fl.n; i++)
        if (fl.num[i] >= o->first && (o->last < 0 || fl.num[i] <= o->last)) {
            i0 = i;
            break;
        }
    if (i0 < 0) {
        rc = pfsph_fail(err, PFSPH_EINPUT, "%s: no frames in the range %d..%d", fdir, o->first, o->last);
        goto out;
    }
    int first_num = fl.num[i0];
    int total = 0;
    for (int i = i0; i < fl.n && (o->last < 0 || fl.num[i] <= o->last); i++) total++;
    for (int i = i0; i < fl.n; i++) {
        int f = fl.num[i];
        if (o->last >= 0 && f > o->last) break;
        double t = 0;
        pfsph_particles_free(&fluid);
        if ((rc = pfsph__read_frame(fdir, "fluid_", f, fl.ply[i], &fluid, &t, err))) goto out;
        int bi = newest_le(&bl, f);
        if (bi >= 0 && bl.num[bi] != bnd_loaded) {
            pfsph_particles_free(&bnd);
            if ((rc = pfsph__read_frame(fdir, "boundary_", bl.num[bi], bl.ply[bi], &bnd, NULL, err))) goto out;
            bnd_loaded = bl.num[bi];
        }
        /* rigid bodies move: their particles of this frame */
        int ri = pfsph_frame_list_find(&rl, f);
        pfsph_particles_free(&both);
        if (ri >= 0 && (rc = pfsph__read_frame(fdir, "bodies_", f, rl.ply[ri], &both, NULL, err))) goto out;
        int di = pfsph_frame_list_find(&dl, f);
        pfsph_particles_free(&dif);
        if (di >= 0 && (rc = pfsph__read_frame(fdir, "diffuse_", f, dl.ply[di], &dif, NULL, err))) goto out;
        if (i == i0) {
            pfsph__rcam_frame(&x.c, sc, &fluid, bi >= 0 ? &bnd : NULL);
            x.vref = pfsph__speed_scale(sc, &fluid);
        }
        pfsph_surface_mesh liq, bm;
        /* the liquid needs its normals (smooth shading); a file without them counts as absent */
        int have_liq = o->particles ? -1 : read_mesh(fdir, "liquid_", f, &liq);
        if (have_liq == 0 && !liq.n) {
            pfsph_surface_mesh_free(&liq);
            have_liq = -1;
        }
        int have_bm = o->particles ? -1 : read_mesh(fdir, "surfaces_", f, &bm);
        snprintf(path, sizeof path, "%s/frame_%05d.png", pdir, f);
        rc = render_frame(&x, &fluid, bi >= 0 ? &bnd : NULL, ri >= 0 ? &both : NULL, di >= 0 ? &dif : NULL,
                          have_liq == 0 ? &liq : NULL, have_bm == 0 ? &bm : NULL, f, t, path, err);
        if (have_liq == 0) pfsph_surface_mesh_free(&liq);
        if (have_bm == 0) pfsph_surface_mesh_free(&bm);
        if (rc != PFSPH_OK) goto out;
        rendered++;
        if (o->progress) o->progress(rendered, total, path, o->user);
    }
    if (o->video) rc = pfsph__render_video(run_dir, first_num, sc->fps, o, err);

out:
    if (count) *count = rendered;
    pfsph_particles_free(&fluid);
    pfsph_particles_free(&bnd);
    pfsph_particles_free(&dif);
    pfsph_particles_free(&both);
    pfsph_frame_list_free(&fl);
    pfsph_frame_list_free(&bl);
    pfsph_frame_list_free(&dl);
    pfsph_frame_list_free(&rl);
    for (int l = 0; l < 2; l++) {
        free(x.im.z[l]);
        free(x.im.id[l]);
    }
    free(x.sp.s);
    free(x.bidx);
    free(x.bstart);
    free(x.rgb);
    free(x.mn);
    free(sc);
    return rc;
}
