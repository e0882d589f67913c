/* Houdini geometry: the ASCII .geo format SideFX documents ("PGEOMETRY V5", Houdini's own and
 * still read by current Houdini), points only, with P, v, density, pressure, phase and id as point
 * attributes; `pfsph export RUN_DIR --houdini`; and a reader of what we write for round trips. */
#ifndef PFSPH_HOUDINI_H
#define PFSPH_HOUDINI_H

#include "pfsph/particles.h"

/* Atomic. Positions and values are written with %.9g (floats round-trip exactly). */
int pfsph_write_houdini_geo(const char *path, const pfsph_particles *ps, double time, pfsph_error *err);

/* Read a file written above (the attribute list may be in any order; unknown attributes are
 * skipped) into ps (initialised here). PFSPH_EINPUT naming the file and line on anything else. */
int pfsph_read_houdini_geo(const char *path, pfsph_particles *ps, double *time, pfsph_error *err);

/* Every fluid frame of RUN_DIR (frames/fluid_NNNNN.vtp or .ply) to frames/fluid_NNNNN.geo;
 * *frames gets the count. */
int pfsph_export_houdini(const char *dir, int *frames, pfsph_error *err);

#endif
