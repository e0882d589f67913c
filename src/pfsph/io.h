/* Frame files: VTK XML PolyData (.vtp, binary appended, ParaView) and binary little-endian PLY
 * (Blender), written atomically (temporary file in the same directory, then rename), and read
 * back (round-trip tests, the renderer). */
#ifndef PFSPH_IO_H
#define PFSPH_IO_H

#include <stdbool.h>

#include "pfsph/particles.h"

/* What to write besides positions, velocities, density, pressure, phase (always written, but see
 * `diffuse`). */
typedef struct pfsph_io_opts {
    int dim;                      /* 2 or 3: 2D files still carry z = 0 */
    bool write_id;                /* uint32 "id" */
    bool write_speed;             /* float "speed" = |v| */
    const char *aux_name;         /* name for the aux field, NULL to skip it (e.g. "volume", "lifetime") */
    double time;                  /* simulated time, stored as field data / comment */
    const uint8_t *surface_layer; /* per particle, "surface_layer" (UInt8 / uchar: 0 interior,
                           * 1 outermost layer, 2 the next one in); NULL to skip */
    bool write_film;              /* the film fraction of bubbles in air, "film" (docs/film.md) */
    bool diffuse;                 /* a diffuse set: the class is written as "type" (0 spray, 1 foam,
                           * 2 bubble), no density or pressure (readers put "type" in phase) */
} pfsph_io_opts;

int pfsph_write_vtp(const char *path, const pfsph_particles *ps, const pfsph_io_opts *o, pfsph_error *err);
int pfsph_write_ply(const char *path, const pfsph_particles *ps, const pfsph_io_opts *o, pfsph_error *err);
/* Read files written by the functions above into ps (initialised by the callee; free with
 * pfsph_particles_free). Fields absent from the file are zero. *time may be NULL. */
int pfsph_read_vtp(const char *path, pfsph_particles *ps, double *time, pfsph_error *err);
int pfsph_read_ply(const char *path, pfsph_particles *ps, double *time, pfsph_error *err);

/* Atomic whole-file write: data goes to "<path>.tmp.<pid>", fsync, rename. */
int pfsph_write_file_atomic(const char *path, const void *data, size_t len, pfsph_error *err);

/* Plot n_spray, n_foam, n_bubble (and their sum) over time from a stats CSV with a header line
 * naming the columns "time", "n_spray", "n_foam", "n_bubble", as a PNG like the paper's Fig. 14.
 * Written atomically. */
int pfsph_diffuse_plot(const char *stats_csv, const char *png_path, pfsph_error *err);

/* A line chart of ns series (y against x; NAN points are skipped) as a PNG, axes fitted to the
 * data, a legend of the series' names; for the validation pages (docs/validation_drop.md).
 * Written atomically. */
typedef struct pfsph_plot_series {
    const char *name;
    const double *x, *y;
    size_t n;
    int points; /* 1: dots, 0: a line */
} pfsph_plot_series;
int pfsph_plot_lines(const char *png_path, const char *title, const char *xlabel, const char *ylabel,
                     const pfsph_plot_series *s, int ns, pfsph_error *err);

/* mkdir -p; PFSPH_EIO with a message on failure. */
int pfsph_mkdirs(const char *path, pfsph_error *err);

#endif
