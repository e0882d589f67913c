/* Marching tetrahedra on the sparse blocks (surface_mesh_internal.h): a case table for the
 * cube built from the six Kuhn tetrahedra, and each block's triangles and owned vertices. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/surface_mesh_internal.h"

static const int KUHN[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

static void corner_xyz(int t, int p[3])
{
    p[0] = t & 1;
    p[1] = (t >> 1) & 1;
    p[2] = t >> 2;
}

/* a triangle on the tetrahedron edges e[k] = (corner, corner), oriented so that its normal points
 * away from corner `in` (inside), decided on the edges' midpoints in integers: the sign of the
 * real triangle for any interpolation parameters */
static void table_emit(mc_table *T, int cs, const int e[3][2], int in, int away, const int eid[8][8])
{
    long m[3][3];
    int pin[3];
    corner_xyz(in, pin);
    for (int k = 0; k < 3; k++) {
        int p[3], q[3];
        corner_xyz(e[k][0], p);
        corner_xyz(e[k][1], q);
        for (int u = 0; u < 3; u++) m[k][u] = p[u] + q[u];
    }
    long ab[3], ac[3], ai[3];
    for (int u = 0; u < 3; u++) {
        ab[u] = m[1][u] - m[0][u];
        ac[u] = m[2][u] - m[0][u];
        ai[u] = m[0][u] - 2L * pin[u];
    }
    long nx = ab[1] * ac[2] - ab[2] * ac[1], ny = ab[2] * ac[0] - ab[0] * ac[2], nz = ab[0] * ac[1] - ab[1] * ac[0];
    long s = nx * ai[0] + ny * ai[1] + nz * ai[2];
    if (!away) s = -s;
    int order[3] = {0, 1, 2};
    if (s < 0) {
        order[1] = 2;
        order[2] = 1;
    }
    uint8_t *t = T->tri[cs][T->ntri[cs]++];
    for (int k = 0; k < 3; k++) t[k] = (uint8_t)eid[e[order[k]][0]][e[order[k]][1]];
}

void pfsph__surface_mc_table(mc_table *T)
{
    memset(T, 0, sizeof *T);
    int eid[8][8], ne = 0;
    for (int s = 0; s < 8; s++)
        for (int q = 0; q < 8; q++) eid[s][q] = -1;
    for (int s = 0; s < 8; s++)
        for (int dir = 1; dir < 8; dir++)
            if (!(s & dir)) {
                T->es[ne] = (uint8_t)s;
                T->ed[ne] = (uint8_t)dir;
                eid[s][s | dir] = eid[s | dir][s] = ne++;
            }
    for (int cs = 1; cs < 255; cs++)
        for (int t = 0; t < 6; t++) {
            int v[4] = {0, 1 << KUHN[t][0], (1 << KUHN[t][0]) | (1 << KUHN[t][1]), 7};
            int ins[4], nin = 0, outs[4], nout = 0;
            for (int k = 0; k < 4; k++) {
                if (cs >> v[k] & 1) ins[nin++] = v[k];
                else outs[nout++] = v[k];
            }
            int e[3][2];
            if (nin == 1 || nin == 3) {
                int apex = nin == 1 ? ins[0] : outs[0];
                const int *others = nin == 1 ? outs : ins;
                for (int k = 0; k < 3; k++) {
                    e[k][0] = apex;
                    e[k][1] = others[k];
                }
                table_emit(T, cs, e, apex, nin == 1, eid);
            } else if (nin == 2) {
                /* quad (i0 o0) (i0 o1) (i1 o1) (i1 o0), two triangles */
                int q[4][2] = {{ins[0], outs[0]}, {ins[0], outs[1]}, {ins[1], outs[1]}, {ins[1], outs[0]}};
                int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
                for (int s = 0; s < 2; s++) {
                    for (int k = 0; k < 3; k++) {
                        e[k][0] = q[tri[s][k]][0];
                        e[k][1] = q[tri[s][k]][1];
                    }
                    table_emit(T, cs, e, ins[0], 1, eid);
                }
            }
        }
}

static void grad_at(const float *f, int a, int b, int c, double cellw, double g[3])
{
    /* central differences, one-sided on the block's faces */
    int i[3] = {a, b, c};
    for (int u = 0; u < 3; u++) {
        int lo[3] = {a, b, c}, hi[3] = {a, b, c};
        lo[u] = i[u] > 0 ? i[u] - 1 : 0;
        hi[u] = i[u] < BS ? i[u] + 1 : BS;
        g[u] = ((double)f[NIDX(hi[0], hi[1], hi[2])] - f[NIDX(lo[0], lo[1], lo[2])]) / ((hi[u] - lo[u]) * cellw);
    }
}

/* triangles of one block; vertices only for the edges it owns (lower node in [0, BS)^3: each edge
 * has exactly one owner, the block that also holds the cell at its lower node, which the growth
 * always computes and keeps when the edge is crossed) */
int pfsph__surface_march_block(march_scratch *S, block *bl, const mc_table *T, float iso, double cellw)
{
    block_inside(bl->f, iso, S->in);
    uint32_t nloc = 0, nt = 0;
    for (int c = 0; c < BS; c++)
        for (int b = 0; b < BS; b++)
            for (int a = 0; a < BS; a++) {
                int cs = cell_case(S->in, a, b, c);
                if (cs == 0 || cs == 255) continue;
                for (int t = 0; t < T->ntri[cs]; t++)
                    for (int k = 0; k < 3; k++) {
                        int ce = T->tri[cs][t][k], s = T->es[ce];
                        int E = NIDX(a + (s & 1), b + (s >> 1 & 1), c + (s >> 2)) * 7 + T->ed[ce] - 1;
                        if (S->tab[E] < 0) S->tab[E] = (int32_t)nloc++;
                        S->tri[3 * (nt + (uint32_t)t) + (uint32_t)k] = (uint32_t)S->tab[E];
                    }
                nt += T->ntri[cs];
            }
    /* number the owned vertices in ascending edge order, refer to foreign ones by their owner */
    uint32_t nv = 0;
    uint16_t ve[NEDGE];
    for (int E = 0; E < NEDGE && nloc; E++) {
        if (S->tab[E] < 0) continue;
        int node = E / 7, dir = E % 7 + 1;
        int p[3] = {node % BN, node / BN % BN, node / (BN * BN)}, o = 0;
        for (int u = 0; u < 3; u++)
            if (p[u] == BS) {
                o |= 1 << u;
                p[u] = 0;
            }
        if (!o) {
            S->ren[S->tab[E]] = nv;
            ve[nv++] = (uint16_t)E;
        } else S->ren[S->tab[E]] = FOREIGN | (uint32_t)o << 12 | (uint32_t)(NIDX(p[0], p[1], p[2]) * 7 + dir - 1);
        S->tab[E] = -1;
    }
    bl->nv = nv;
    bl->nt = nt;
    bl->ve = malloc((nv ? nv : 1) * sizeof *bl->ve);
    bl->vp = malloc(3 * (nv ? nv : 1) * sizeof *bl->vp);
    bl->vn = malloc(3 * (nv ? nv : 1) * sizeof *bl->vn);
    bl->tri = malloc(3 * (nt ? nt : 1) * sizeof *bl->tri);
    if (!bl->ve || !bl->vp || !bl->vn || !bl->tri) return PFSPH_ENOMEM;
    memcpy(bl->ve, ve, nv * sizeof *ve);
    for (uint32_t i = 0; i < 3 * nt; i++) bl->tri[i] = S->ren[S->tri[i]];
    for (uint32_t i = 0; i < nv; i++) {
        int node = ve[i] / 7, dir = ve[i] % 7 + 1;
        int p[3] = {node % BN, node / BN % BN, node / (BN * BN)}, q[3];
        for (int u = 0; u < 3; u++) q[u] = p[u] + (dir >> u & 1);
        double fp = bl->f[NIDX(p[0], p[1], p[2])], fq = bl->f[NIDX(q[0], q[1], q[2])];
        double t = (iso - fp) / (fq - fp);
        if (t < 1e-3) t = 1e-3; /* no vertex on a node: no zero-area faces */
        if (t > 1 - 1e-3) t = 1 - 1e-3;
        double gp[3], gq[3], g[3], len = 0;
        grad_at(bl->f, p[0], p[1], p[2], cellw, gp);
        grad_at(bl->f, q[0], q[1], q[2], cellw, gq);
        for (int u = 0; u < 3; u++) {
            bl->vp[3 * i + u] = ((double)bl->b[u] * BS + p[u] + t * (q[u] - p[u])) * cellw;
            g[u] = -((1 - t) * gp[u] + t * gq[u]);
            len += g[u] * g[u];
        }
        len = len > 0 ? 1 / sqrt(len) : 0;
        for (int u = 0; u < 3; u++) bl->vn[3 * i + u] = (float)(g[u] * len);
    }
    return PFSPH_OK;
}
