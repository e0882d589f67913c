/* PCISPH's correction walks over neighbour lists built once per step (the interactive mode,
 * docs/interactive.md): the fluid and boundary neighbours within h at the step's positions, as
 * Solenthaler & Pajarola 2009 search them once per step, and the density and pressure of the
 * predicted positions summed over them. */
#ifndef PFSPH_PCISPH_LISTS_H
#define PFSPH_PCISPH_LISTS_H

#include "core/nlist.h"
#include "pfsph/ctx.h"

/* Lists l (fluid, j != i) and lb (boundary) of the fluid's neighbours within h at its current
 * positions, in one grid walk (two when a thread's region overflows). PFSPH_OK or
 * PFSPH_ENOMEM. */
int pfsph__pcisph_lists(const pfsph_ctx *ctx, pfsph_nlist *l, pfsph_nlist *lb);

/* pfsph__number_density at the predicted positions (x, y, z), over the listed pairs that are
 * still within h there (a pair entering h during the step is missed: its kernel is near 0). */
void pfsph__pcisph_density(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb, const pfsph_real *x,
                           const pfsph_real *y, const pfsph_real *z, pfsph_real *nd);

/* pfsph__pressure_accel over the same pairs. */
void pfsph__pcisph_pressure(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb, const pfsph_real *x,
                            const pfsph_real *y, const pfsph_real *z, const pfsph_real *nd, const pfsph_real *p,
                            pfsph_real *apx, pfsph_real *apy, pfsph_real *apz);

/* The pairs of one iteration at the predicted positions, kept from the density pass for the
 * pressure pass (same positions): per list entry x_ij (dx, dy, dz) and dW/r, 0 beyond h. The
 * pressure pass then streams them instead of gathering positions and evaluating the kernel
 * again (docs/interactive.md, "Profile"). */
typedef struct pfsph_pcisph_pairs {
    pfsph_real *dx, *dy, *dz, *dw;
    size_t cap;
} pfsph_pcisph_pairs;

/* Room for m entries: PFSPH_OK or PFSPH_ENOMEM (the arrays are then as before). */
int pfsph__pcisph_pairs_reserve(pfsph_pcisph_pairs *c, size_t m);
void pfsph__pcisph_pairs_free(pfsph_pcisph_pairs *c);

/* pfsph__pcisph_density summed in eight lanes (pair_terms.h: the last bits differ), filling cf and cb (room for l's and lb's entries); cb's dw
 * holds aux_j dW/r, the product the pressure pass forms for a wall particle j. */
void pfsph__pcisph_density_pairs(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb, const pfsph_real *x,
                                 const pfsph_real *y, const pfsph_real *z, pfsph_real *nd, pfsph_pcisph_pairs *cf,
                                 pfsph_pcisph_pairs *cb);

/* pfsph__pcisph_pressure at the positions cf and cb were filled at, summed in eight lanes; pn: scratch of
 * the fluid's count (p / delta^2 per particle). */
void pfsph__pcisph_pressure_pairs(const pfsph_ctx *ctx, const pfsph_nlist *l, const pfsph_nlist *lb,
                                  const pfsph_real *nd, const pfsph_real *p, const pfsph_pcisph_pairs *cf,
                                  const pfsph_pcisph_pairs *cb, pfsph_real *pn, pfsph_real *apx, pfsph_real *apy,
                                  pfsph_real *apz);

#endif
