/* Internal: Houdini's JSON geometry (.geo) and its binary JSON form (.bgeo), the formats Houdini
 * 12 and later read and write natively (docs/artists.md#houdini): a point cloud or a triangle mesh
 * with numeric point attributes, numeric and string primitive attributes. */
#ifndef PFSPH_IO_HGEO_H
#define PFSPH_IO_HGEO_H

#include <stddef.h>
#include <stdint.h>

#include "pfsph/types.h"

typedef struct pfsph__hattr {
    const char *name;
    int size;             /* tuple size: 1 or 3 */
    const float *f;       /* size * n values, or NULL */
    const int32_t *i;     /* n values (size 1), or NULL */
    const char *const *s; /* string attribute (size 1): nstrings strings, indexed by i */
    int nstrings;
    const char *typeinfo; /* "vector", "point", "normal" or NULL */
} pfsph__hattr;

typedef struct pfsph__hgeo {
    size_t npoints, ntris;
    const uint32_t *tri; /* 3 * ntris point indices, counter-clockwise from outside (pfsph) */
    int npattr, nprattr;
    const pfsph__hattr *pattr, *prattr; /* point ("P" first), primitive attributes */
} pfsph__hgeo;

/* Atomic. binary: bJSON (.bgeo, SideFX's UT_JSONDefines.h encoding, native byte order with the
 * magic that says which), else JSON text (.geo). Triangles are written in Houdini's winding
 * (clockwise seen from outside: the reverse of pfsph's), so that normals face out there. */
int pfsph__hgeo_write(const char *path, int binary, const pfsph__hgeo *g, pfsph_error *err);

#endif
