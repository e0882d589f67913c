/* The neighbours within h of one fluid particle for a solver pass (DFSPH, IISPH): from the
 * step's neighbour lists when they were built (core/nlist.h), else from a grid walk that finds
 * the same neighbours in the same order with the same kernel derivatives (the lists were filled
 * from the same hits with pfsph__terms_dwr, physics/density.c): a pass then adds the same terms
 * in the same order either way, the same bits, without the lists' ~300 B per particle in 3D
 * (docs/solvers.md, "Neighbour lists"). */
#ifndef PFSPH_NEIGHBOURS_H
#define PFSPH_NEIGHBOURS_H

#include "core/hits.h"
#include "core/nlist.h"
#include "physics/pair_terms.h"

/* The hits of H in order, with their kernel derivatives, as (J, DW) for BODY. */
#define PFSPH_NB_FLUSH_(k, H, J, DW, ...)                \
    do {                                                 \
        pfsph__terms_dwr((k), (H)->n, (H)->r2, (H)->t1); \
        for (int nb_e_ = 0; nb_e_ < (H)->n; nb_e_++) {   \
            const uint32_t J = (H)->j[nb_e_];            \
            const pfsph_real DW = (H)->t1[nb_e_];        \
            __VA_ARGS__                                  \
        }                                                \
    } while (0)

/* The same with X_ij as DX, DY, DZ (the hits' x - x_j) */
#define PFSPH_NB_FLUSH_X_(k, H, J, DW, DX, DY, DZ, ...)  \
    do {                                                 \
        pfsph__terms_dwr((k), (H)->n, (H)->r2, (H)->t1); \
        for (int nb_e_ = 0; nb_e_ < (H)->n; nb_e_++) {   \
            const uint32_t J = (H)->j[nb_e_];            \
            const pfsph_real DW = (H)->t1[nb_e_];        \
            const pfsph_real DX = (H)->dx[nb_e_];        \
            const pfsph_real DY = (H)->dy[nb_e_];        \
            const pfsph_real DZ = (H)->dz[nb_e_];        \
            __VA_ARGS__                                  \
        }                                                \
    } while (0)

/* Runs BODY (the statements after DW) for every neighbour of fluid particle i at (x, y, z),
 * with J its index in the target set and DW = pfsph_kernel_dw_r(k, |x_ij|): from list L when it
 * is not NULL, else by a walk of grid G over the targets (tx, ty, tz) with the hits function
 * `hits` and the caller's buffer H (one per thread), for |x_ij|^2 < h2 and j != skip (i for
 * the fluid, UINT32_MAX for the boundary). BODY may use `continue`; it sees no other loop
 * variable of this macro. */
#define PFSPH_FOR_NEIGHBOURS(L, G, hits, H, k, tx, ty, tz, i, x, y, z, h2, skip, J, DW, ...)                           \
    do {                                                                                                               \
        if (L) {                                                                                                       \
            for (uint32_t nb_e_ = (L)->start[i]; nb_e_ < (L)->start[(i) + 1]; nb_e_++) {                               \
                const uint32_t J = (L)->idx[nb_e_];                                                                    \
                const pfsph_real DW = (L)->dw[nb_e_];                                                                  \
                __VA_ARGS__                                                                                            \
            }                                                                                                          \
        } else {                                                                                                       \
            pfsph_ranges nb_r_;                                                                                        \
            pfsph_grid_ranges((G), (x), (y), (z), &nb_r_);                                                             \
            PFSPH_HITS_WALK(hits, H, nb_r_, tx, ty, tz, x, y, z, h2, skip, PFSPH_NB_FLUSH_(k, H, J, DW, __VA_ARGS__)); \
        }                                                                                                              \
    } while (0)

/* PFSPH_FOR_NEIGHBOURS's grid walk alone, its BODY also given DX, DY, DZ = x - tx[J] etc. as the
 * walk computed them (the bits of (x - tx[J]), so a pass needs no positions of its own). */
#define PFSPH_FOR_HITS(G, hits, H, k, tx, ty, tz, x, y, z, h2, skip, J, DW, DX, DY, DZ, ...) \
    do {                                                                                     \
        pfsph_ranges nb_r_;                                                                  \
        pfsph_grid_ranges((G), (x), (y), (z), &nb_r_);                                       \
        PFSPH_HITS_WALK(hits, H, nb_r_, tx, ty, tz, x, y, z, h2, skip,                       \
                        PFSPH_NB_FLUSH_X_(k, H, J, DW, DX, DY, DZ, __VA_ARGS__));            \
    } while (0)

#endif
