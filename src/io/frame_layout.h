/* The byte layout of a particle frame (binary PLY, VTP with raw appended arrays): literal bytes
 * (headers, block sizes, the trailer) and per-particle regions of fixed size, so that a frame of
 * n particles can be written by one process in order (pfsph_write_ply/vtp) or by several, each
 * its slice of every region at a computed offset (src/mpi/frame_io.c). One copy of each format. */
#ifndef PFSPH_IO_FRAME_LAYOUT_H
#define PFSPH_IO_FRAME_LAYOUT_H

#include <stddef.h>
#include <stdint.h>

#include "pfsph/io.h"
#include "pfsph/particles.h"

#define PFSPH__LAYOUT_MAX_SEGS 40

/* A segment of the file: literal bytes (per 0) or a region of `per` bytes per particle. */
typedef struct pfsph__frame_seg {
    uint64_t off;        /* the file offset of its first byte */
    size_t per;          /* bytes per particle; 0: a literal */
    int kind;            /* a region's content (frame_layout.c) */
    size_t lit, lit_len; /* a literal: its bytes in text[lit, lit + lit_len) */
} pfsph__frame_seg;

typedef struct pfsph__frame_layout {
    uint64_t n;   /* particles in the whole frame */
    uint64_t len; /* bytes of the whole file */
    int nseg;
    pfsph__frame_seg seg[PFSPH__LAYOUT_MAX_SEGS];
    char *text; /* the literals' bytes (malloc'ed) */
    size_t text_len, text_cap;
    int failed; /* out of memory building it */
    pfsph_io_opts o;
} pfsph__frame_layout;

/* The layout of a PLY or VTP frame of n particles with the writer options o (o->surface_layer is
 * only tested for NULL here). PFSPH_ENOMEM, or PFSPH_OK; free with pfsph__frame_layout_free. */
int pfsph__ply_layout(pfsph__frame_layout *L, uint64_t n, const pfsph_io_opts *o);
int pfsph__vtp_layout(pfsph__frame_layout *L, uint64_t n, const pfsph_io_opts *o);
void pfsph__frame_layout_free(pfsph__frame_layout *L);

/* Region k's bytes of particles [lo, hi) of ps into out (L->seg[k].per * (hi - lo) bytes); the
 * particle at lo is the frame's particle `first` (the VTP cells name it); layer: the
 * surface_layer field indexed as ps (NULL when the layout has none). */
void pfsph__frame_encode(const pfsph__frame_layout *L, int k, const pfsph_particles *ps, const uint8_t *layer,
                         size_t lo, size_t hi, uint64_t first, unsigned char *out);

/* The whole file from one process, atomically (the serial writers). */
int pfsph__frame_write(const char *path, const pfsph__frame_layout *L, const pfsph_particles *ps, pfsph_error *err);

/* ParaView's index of a frame written in pieces ("<base>_0000.vtp" ... in the .pvtp's folder,
 * each a VTP of the same arrays), atomically. */
int pfsph__write_pvtp(const char *path, const pfsph_io_opts *o, const char *base, int npieces, pfsph_error *err);

#endif
