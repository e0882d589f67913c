/* Houdini geometry: `pfsph export RUN_DIR --houdini` (JSON geometry, binary or text: houdini.c)
 * and the classic ASCII .geo format SideFX documents ("PGEOMETRY V5"), points only, with P, v,
 * density, pressure, phase and id as point attributes, with a reader for round trips. */
#ifndef PFSPH_HOUDINI_H
#define PFSPH_HOUDINI_H

#include "pfsph/particles.h"

/* Atomic. Positions and values are written with %.9g (floats round-trip exactly). */
int pfsph_write_houdini_geo(const char *path, const pfsph_particles *ps, double time, pfsph_error *err);

/* Read a file written above (the attribute list may be in any order; unknown attributes are
 * skipped) into ps (initialised here). PFSPH_EINPUT naming the file and line on anything else. */
int pfsph_read_houdini_geo(const char *path, pfsph_particles *ps, double *time, pfsph_error *err);

/* Houdini's JSON geometry: binary (.bgeo, the default) or text (.geo); or the classic ASCII
 * format above (fluid frames only, as before issue 33). */
enum { PFSPH_HOUDINI_BGEO = 0, PFSPH_HOUDINI_JSON, PFSPH_HOUDINI_CLASSIC };

typedef struct pfsph_houdini_report {
    int frames, diffuse, liquid, bodies; /* files written per set */
    int solids;                          /* solids in RUN/solids.<ext> (0: none written) */
    int no_ids;                          /* some particle frames had no ids (no `id` attribute) */
} pfsph_houdini_report;

/* Every frame of RUN_DIR: frames/fluid_NNNNN.<ext> (points ordered by id, P v id pscale density
 * pressure phase), diffuse_NNNNN (P v id pscale type lifetime), liquid_NNNNN (triangles: P N v,
 * primitive phase), bodies_NNNNN (the body surfaces: P, primitive body and name) and once
 * RUN/solids.<ext> (primitive solid, phase, name); ext bgeo or geo. docs/artists.md#houdini. */
int pfsph_export_houdini(const char *dir, int format, pfsph_houdini_report *rep, pfsph_error *err);

#endif
