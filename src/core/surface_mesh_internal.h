/* Shared by the surface reconstruction's files (surface_mesh.h; docs/surfaces.md): the block
 * layout, the kernels, the flat cell list and block hash (surface_grid.c), the kernels' build
 * (surface_kernels.c), the field on blocks (surface_field.c), the marching (surface_march.c),
 * the assembly and smoothing (surface_mesh.c) and the 2D contour (surface_contour.c). */
#ifndef PFSPH_SURFACE_MESH_INTERNAL_H
#define PFSPH_SURFACE_MESH_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "pfsph/surface_mesh.h"

/* A block: BS^3 cells, BN^3 nodes: 0 .. BS along each edge, the last layer being the next
 * block's first; BN = 8, so that a row of nodes is two 4-wide vectors. */
#define BS 7
#define BN (BS + 1)
#define BNODES (BN * BN * BN)
#define NEDGE (BNODES * 7) /* edges of a block: lower node x direction (1..7 as xyz bits) */
#define MAXTRI (BS * BS * BS * 12)
#define COORD_BITS 21
#define PI 3.14159265358979323846
#define NIDX(a, b, c) (((c)*BN + (b)) * BN + (a)) /* a node of a block */

/* A kernel as the field reads it, in grid cells: centre I + f (I the node at or below it, f in
 * [0, 1)), so that a node's offset from the centre is an exact small integer minus f whatever the
 * block and however far from the origin: every node's value is a function of its global index. */
typedef struct kern {
    int32_t I[3];
    float f[3];
    float g[6]; /* symmetric map cell offsets -> unit-kernel coordinates: xx xy xz yy yz zz */
    float amp;  /* d^3 |det G| sigma: the value at the centre over W(0) */
    float rad;  /* support radius [cells] */
} kern;

typedef struct block {
    int64_t key;
    int32_t b[3];
    float *f; /* BNODES node values */
    /* marching output: owned vertices (edges whose lower node lies in [0, BS)^3), ascending edge */
    uint32_t nv, nt;
    uint16_t *ve;  /* nv edge indices */
    double *vp;    /* 3 nv */
    float *vn;     /* 3 nv */
    uint32_t *tri; /* 3 nt: owned rank, or FOREIGN | neighbour offset bits << 12 | its edge */
} block;

#define FOREIGN 0x80000000u

/* The options with their defaults filled in; _checked also checks them (smoothing: the passes
 * count too), PFSPH_EINPUT. */
void pfsph__surface_resolve(const pfsph_surface_opts *in, pfsph_surface_opts *o);
int pfsph__surface_resolve_checked(const pfsph_surface_opts *in, bool smoothing, pfsph_surface_opts *o,
                                   pfsph_error *err);

static inline int64_t pack3(int64_t i, int64_t j, int64_t k)
{
    const int64_t bias = (int64_t)1 << (COORD_BITS - 1);
    return ((i + bias) << (2 * COORD_BITS)) | ((j + bias) << COORD_BITS) | (k + bias);
}

static inline void unpack3(int64_t key, int32_t b[3])
{
    const int64_t mask = ((int64_t)1 << COORD_BITS) - 1, bias = (int64_t)1 << (COORD_BITS - 1);
    b[0] = (int32_t)(((key >> (2 * COORD_BITS)) & mask) - bias);
    b[1] = (int32_t)(((key >> COORD_BITS) & mask) - bias);
    b[2] = (int32_t)((key & mask) - bias);
}

static inline int32_t floordiv(int32_t a, int32_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

static inline int i64_cmp(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : (x > y);
}

/* ---- a flat sorted cell list: points ordered by cell (x, y, z lexicographic, z fastest), in
 * ascending index within a cell, so that a column of cells (i, j, k0..k1) is one contiguous
 * range. Dense (a start per cell of the bounding box, one counting sort) when the box holds at
 * most a few cells per point; otherwise sparse (radix-sorted keys, binary search per column). */
typedef struct grid {
    int32_t lo[3];
    int64_t ext[3];
    int dense;
    size_t nu;
    uint32_t *idx;    /* n point indices in cell order */
    uint32_t *start;  /* dense: cells + 1 */
    int64_t *ukey;    /* sparse: nu keys */
    uint32_t *ustart; /* nu + 1: the non-empty cells' ranges in idx */
    int32_t *ucell;   /* 3 nu: their coordinates */
} grid;

void pfsph__surface_grid_free(grid *g);
/* the cell list of n points whose cells are cell[3 i .. 3 i + 2]; PFSPH_ENOMEM */
int pfsph__surface_grid_build(grid *g, const int32_t *cell, size_t n);
/* the range in idx of the column of cells (i, j, k0..k1); b == e when empty */
void pfsph__surface_grid_col(const grid *g, int64_t i, int64_t j, int64_t k0, int64_t k1, uint32_t *b, uint32_t *e);

/* ---- sparse blocks: open-addressing hash of block keys (growth only; surface_grid.c) ---- */
typedef struct bmap {
    int64_t *keys;
    int32_t *val;
    size_t cap, n;
} bmap;

/* the value stored for key, or -1 */
int pfsph__surface_bmap_find(const bmap *m, int64_t key);
/* a new key (not present); PFSPH_ENOMEM */
int pfsph__surface_bmap_put(bmap *m, int64_t key, int32_t v);

/* Kernels of n points: centres, anisotropy, in grid cells of cellw. surf[i] (may be NULL) gets
 * 1 for particles near the surface (few neighbours, offset centre of mass or flattened
 * neighbourhood). *rad_max: the largest support radius [cells]. drop_scale > 0: the amplitude
 * factor of isolated particles' kn kernels (pfsph__surface_drop_scale). */
int pfsph__surface_kernels(const double *x, size_t n, const pfsph_surface_opts *o, double drop_scale, kern *K,
                           uint8_t *surf, float *rad_max);
/* The amplitude factor at which one lone kn kernel's field crosses `iso` at the radius
 * o->droplet d, when that is smaller than the kn kernel's blob; 0 when no bound applies. */
double pfsph__surface_drop_scale(const pfsph_surface_opts *o, double iso);
#define PFSPH__ISOLATED 5 /* fewer particles than this within the PCA radius (itself included) */

/* node values of a block: the rows (b, c) set in `rows` (bit b + 8 c), the others 0 */
void pfsph__surface_block_field(block *bl, const kern *K, const grid *kg, int R, uint64_t rows);
/* the neighbour blocks that a block's crossed rim cells call for (bit (ox + 1) + 3 (oy + 1) +
 * 9 (oz + 1)); *any: some cell of the block is crossed */
uint32_t pfsph__surface_block_needs(const float *f, float iso, int *any);

/* the corner case of each cell (bit t for corner (t & 1, t >> 1 & 1, t >> 2) inside) */
static inline int cell_case(const uint8_t *in, int a, int b, int c)
{
    const uint8_t *p = in + NIDX(a, b, c);
    return p[0] | p[1] << 1 | p[BN] << 2 | p[BN + 1] << 3 | p[BN * BN] << 4 | p[BN * BN + 1] << 5 |
        p[BN * BN + BN] << 6 | p[BN * BN + BN + 1] << 7;
}

static inline void block_inside(const float *f, float iso, uint8_t *in)
{
    for (int i = 0; i < BNODES; i++) in[i] = f[i] > iso;
}

/* ---- marching tetrahedra (surface_march.c): a case table for the cube, built from the six Kuhn
 * tetrahedra */
typedef struct mc_table {
    uint8_t ntri[256];
    uint8_t tri[256][12][3]; /* cube edges 0..18 */
    uint8_t es[19], ed[19];  /* cube edge: lower corner (xyz bits), direction (xyz bits, 1..7) */
} mc_table;

/* per-thread scratch of the marching: the edge table (local vertex number or -1) and buffers */
typedef struct march_scratch {
    int32_t tab[NEDGE];
    uint32_t ren[NEDGE]; /* local number -> owned rank or foreign reference */
    uint32_t tri[3 * MAXTRI];
    uint8_t in[BNODES];
} march_scratch;

/* the case table of the six-tetrahedra split */
void pfsph__surface_mc_table(mc_table *T);
/* triangles of one block and its owned vertices (S->tab all -1 on entry and on return) */
int pfsph__surface_march_block(march_scratch *S, block *bl, const mc_table *T, float iso, double cellw);

#endif
