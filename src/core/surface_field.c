/* The volume-fraction field on the sparse blocks (surface_mesh_internal.h): kernels splatted
 * into rows of nodes, so that a node's value has the same bits in every block that holds it. */
#include <math.h>
#include <string.h>

#include "core/surface_mesh_internal.h"

/* one kernel into the block whose first node is O (global node index): rows of BN nodes along x.
 * A node's offset from the centre is (global index - I) - f, exact integers converted, and its
 * unit-kernel coordinates are formed in a fixed order, so its term has the same bits in every
 * block that holds it. The ellipsoid q^2 = r^T M r < 1 (M = G G) is rasterised: per z slice the
 * rows that meet it (each row then evaluated whole, two 4-wide vectors). The ranges are those of a
 * slightly larger ellipsoid (1.0001, plus 1e-3 cell), so that whatever is skipped has q^2 >= 1
 * beyond any rounding and would add exactly nothing: a node gets the same terms in every block. */
#define GROW 1.0001f
#define MARGIN 1e-3f
static void splat(float *restrict fv, const kern *k, const int32_t O[3], const int8_t rlo[BN], const int8_t rhi[BN])
{
    const float *g = k->g, rad = k->rad * GROW + MARGIN; /* bounds: a superset of the support */
    float cen[3];
    for (int u = 0; u < 3; u++) cen[u] = (float)(k->I[u] - O[u]) + k->f[u];
    if (cen[0] + rad < 0 || cen[0] - rad > BS || cen[1] + rad < 0 || cen[1] - rad > BS) return;
    float za = ceilf(cen[2] - rad), zb = floorf(cen[2] + rad);
    if (zb < 0 || za > BS) return;
    const int c0 = za < 0 ? 0 : (int)za, c1 = zb > BS ? BS : (int)zb;
    /* M = G G (G symmetric), and the Schur complements that give a slice's row range */
    const float m00 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2], m01 = g[0] * g[1] + g[1] * g[3] + g[2] * g[4],
                m02 = g[0] * g[2] + g[1] * g[4] + g[2] * g[5], m11 = g[1] * g[1] + g[3] * g[3] + g[4] * g[4],
                m12 = g[1] * g[2] + g[3] * g[4] + g[4] * g[5], m22 = g[2] * g[2] + g[4] * g[4] + g[5] * g[5];
    const float i00 = 1.0f / m00, sa = m11 - m01 * m01 * i00, sb = m12 - m01 * m02 * i00, sc = m22 - m02 * m02 * i00,
                isa = 1.0f / sa, amp = k->amp;
    const int32_t ux0 = O[0] - k->I[0], vy0 = O[1] - k->I[1];
    float us[BN];
    for (int a = 0; a < BN; a++) us[a] = (float)(ux0 + a) - k->f[0];
    for (int c = c0; c <= c1; c++) {
        if (rlo[c] > rhi[c]) continue; /* no row of this slice wanted */
        const float w = (float)(O[2] + c - k->I[2]) - k->f[2];
        /* rows: sa v^2 + 2 sb w v + sc w^2 < GROW, v = (y - I) - f */
        const float B = sb * w, disc = B * B - sa * (sc * w * w - GROW);
        if (disc < 0) continue;
        const float sq = sqrtf(disc), ylo = cen[1] + (-B - sq) * isa - MARGIN, yhi = cen[1] + (-B + sq) * isa + MARGIN;
        const int b0 = ylo < rlo[c] ? rlo[c] : (int)ceilf(ylo), b1 = yhi > rhi[c] ? rhi[c] : (int)floorf(yhi);
        const float wr0 = g[2] * w, wr1 = g[4] * w, wr2 = g[5] * w;
        for (int b = b0; b <= b1; b++) {
            const float v = (float)(vy0 + b) - k->f[1];
            const float rt0 = g[1] * v + wr0, rt1 = g[3] * v + wr1, rt2 = g[4] * v + wr2;
            float *restrict row = fv + NIDX(0, b, c);
#pragma omp simd
            for (int a = 0; a < BN; a++) {
                const float u = us[a];
                const float t0 = g[0] * u + rt0, t1 = g[1] * u + rt1, t2 = g[2] * u + rt2;
                const float q2 = t0 * t0 + t1 * t1 + t2 * t2;
                const float q = sqrtf(q2), t = 1.0f - q;
                const float outer = 2.0f * t * t * t, inner = 6.0f * q * q * (q - 1.0f) + 1.0f;
                const float val = q <= 0.5f ? inner : outer;
                row[a] += q2 < 1.0f ? amp * val : 0.0f;
            }
        }
    }
}

/* node values of a block (the rows (b, c) set in `rows`, bit b + 8 c; the others 0): the kernels
 * whose centres lie in the block cells within R, visited in
 * ascending cell then index order; a node shared with another block sees its kernels in the same
 * order there (both visit the same global order), so it gets the same sum, bit for bit */
void pfsph__surface_block_field(block *bl, const kern *K, const grid *kg, int R, uint64_t rows)
{
    memset(bl->f, 0, BNODES * sizeof *bl->f);
    int8_t rlo[BN], rhi[BN]; /* the rows wanted in a slice form one range (own rows, then faces) */
    for (int c = 0; c < BN; c++) {
        unsigned m = (unsigned)(rows >> (BN * c)) & 0xffu;
        rlo[c] = BN;
        rhi[c] = -1;
        for (int b = 0; b < BN; b++)
            if (m >> b & 1) {
                if (rlo[c] == BN) rlo[c] = (int8_t)b;
                rhi[c] = (int8_t)b;
            }
    }
    const int32_t O[3] = {bl->b[0] * BS, bl->b[1] * BS, bl->b[2] * BS};
    for (int64_t a = (int64_t)bl->b[0] - R; a <= (int64_t)bl->b[0] + R; a++)
        for (int64_t b = (int64_t)bl->b[1] - R; b <= (int64_t)bl->b[1] + R; b++) {
            uint32_t s, e;
            pfsph__surface_grid_col(kg, a, b, (int64_t)bl->b[2] - R, (int64_t)bl->b[2] + R, &s, &e);
            for (uint32_t q = s; q < e; q++) splat(bl->f, K + kg->idx[q], O, rlo, rhi);
        }
}

/* the blocks that a block's rim cells crossed by the surface call for: bit (ox + 1) + 3 (oy + 1)
 * + 9 (oz + 1) for the neighbour at offset (ox, oy, oz); *any: some cell of the block is crossed */
uint32_t pfsph__surface_block_needs(const float *f, float iso, int *any)
{
    uint8_t in[BNODES];
    block_inside(f, iso, in);
    uint32_t need = 0;
    *any = 0;
    for (int c = 0; c < BS; c++)
        for (int b = 0; b < BS; b++)
            for (int a = 0; a < BS; a++) {
                int cs = cell_case(in, a, b, c);
                if (cs == 0 || cs == 255) continue;
                *any = 1;
                int lo[3] = {a == 0 ? -1 : 0, b == 0 ? -1 : 0, c == 0 ? -1 : 0},
                    hi[3] = {a == BS - 1 ? 1 : 0, b == BS - 1 ? 1 : 0, c == BS - 1 ? 1 : 0};
                for (int z = lo[2]; z <= hi[2]; z++)
                    for (int y = lo[1]; y <= hi[1]; y++)
                        for (int xx = lo[0]; xx <= hi[0]; xx++) need |= 1u << ((xx + 1) + 3 * (y + 1) + 9 * (z + 1));
            }
    return need & ~(1u << 13); /* not itself */
}
