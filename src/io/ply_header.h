/* The header of a binary little-endian PLY file, one parser for both PLY readers: the particle
 * frames (ply.c: one vertex element) and the surface meshes (meshing.c: vertices, then faces
 * with a list of vertex indices). The reader says which elements it takes, in which order; the
 * lists it reads and the properties it needs it judges itself, from what this returns. */
#ifndef PFSPH_IO_PLY_HEADER_H
#define PFSPH_IO_PLY_HEADER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "pfsph/types.h"

#define PFSPH__PLY_MAX_PROPS 32 /* per element */
#define PFSPH__PLY_MAX_ELEMS 2

typedef struct pfsph__ply_prop {
    bool list;      /* "property list COUNT ITEM NAME" */
    int type;       /* a scalar's type; a list's item type (PFSPH__T_NONE when unknown) */
    int count_type; /* a list's count type (PFSPH__T_NONE when unknown) */
    size_t offset;  /* a scalar's: bytes before it among the element's scalars */
    size_t line;    /* its header line, for messages */
    char name[80];
} pfsph__ply_prop;

typedef struct pfsph__ply_element {
    uint64_t count;
    size_t line; /* header line of "element" */
    int nprops;  /* lists included */
    size_t rec;  /* bytes of the element's scalars */
    pfsph__ply_prop prop[PFSPH__PLY_MAX_PROPS];
} pfsph__ply_element;

typedef struct pfsph__ply_header {
    int nelems; /* elements found: the first nelems of spec->elems */
    pfsph__ply_element elem[PFSPH__PLY_MAX_ELEMS];
    size_t data; /* offset of the first byte after end_header */
} pfsph__ply_header;

/* A PLY scalar type name ("float", "uint8", ...) as its code; PFSPH__T_NONE if unknown. */
int pfsph__ply_type(const char *s);

/* What a reader takes: its kind of file for messages ("PLY file"), the elements in the order
 * they must come (a file may stop early; NULL ends the list), whether list properties are
 * allowed (the reader judges them; else refused) and whether property names must be unique
 * within an element. */
typedef struct pfsph__ply_spec {
    const char *what;
    const char *elems[PFSPH__PLY_MAX_ELEMS + 1];
    bool lists, unique;
} pfsph__ply_spec;

/* Read the header at the start of buf[0..len): the "ply" magic, "format binary_little_endian
 * 1.0", comments ("comment time T" sets *time when time is not NULL), the elements of spec, each
 * followed by its properties, and end_header within 64 KiB, in lines of at most 255 characters
 * (CR-LF tolerated). A file that breaks this is refused with "<path>: invalid <what>: <reason>"
 * (PFSPH_EINPUT), the reason naming the header line. */
int pfsph__ply_header_read(const unsigned char *buf, size_t len, const char *path, const pfsph__ply_spec *spec,
                           pfsph__ply_header *h, double *time, pfsph_error *err);

#endif
