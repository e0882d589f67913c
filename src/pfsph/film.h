/* Bubbles in air as two-phase particles (PF Section 4.2.2, Eq. 24, Figs. 9-11): a bubble is a
 * droplet of a gas phase whose outermost layer of particles (surface detection, one bubble at
 * a time) each carry the same liquid volume fraction a of a film phase, the "even film" of the
 * paper; its interior particles are pure gas. The fraction follows the number of surface
 * particles, a = V_L / (N_s V0), so that the film's liquid volume V_L stays what the scene
 * gave while the enclosed gas keeps its volume through the pressure solve. The pair force of
 * two such particles uses Eq. 24. Choices where the paper is silent: docs/film.md. */
#ifndef PFSPH_FILM_H
#define PFSPH_FILM_H

#include <stdbool.h>
#include <stdint.h>

#include "pfsph/ctx.h"

/* Eq. 24, generalised to particles of any phases: particle i of phase pi holds the fraction a
 * of its film phase film[pi] (a = 0 for every particle that is not a bubble's film), j of pj
 * the fraction b of film[pj]:
 *   c~ = a b c[fi][fj] + a (1 - b) c[fi][pj] + (1 - a) b c[pi][fj] + (1 - a)(1 - b) c[pi][pj].
 * With one film phase alpha and one gas beta it is the paper's
 *   a b c_aa + (a (1 - b) + (1 - a) b) c_ab + (1 - a)(1 - b) c_bb;
 * with a = b = 0 it is c[pi][pj]: solids and ordinary fluids use the same matrix. Symmetric
 * in (i, j) when c is. apart: i and j belong to two different bubbles; their gases are kept
 * apart by the films between them, so the gas-gas term is left out (docs/film.md: without
 * this two touching bubbles of one gas coalesce into one drop within 0.25 s). */
static inline double pfsph_film_pair_c(const double (*c)[PFSPH_MAX_PHASES], const int *film, int pi, double a, int pj,
                                       double b, bool apart)
{
    const int fi = a > 0 && film[pi] >= 0 ? film[pi] : pi;
    const int fj = b > 0 && film[pj] >= 0 ? film[pj] : pj;
    return a * b * c[fi][fj] + a * (1 - b) * c[fi][pj] + (1 - a) * b * c[pi][fj] +
        (apart ? 0.0 : (1 - a) * (1 - b) * c[pi][pj]); /* Eq. 24 */
}

typedef struct pfsph_film pfsph_film;

/* The film state for ctx's bubbles (ctx->film->nbubbles > 0; fluid->bubble set; ctx->grid
 * sorted for the fluid). Resolves each bubble's liquid volume given as a thickness t into
 * fp->volume = t d^(dim-1) N_s(0) (the film's area at the start is its surface-particle count
 * times d^(dim-1), so a(0) = t / d), and checks that a volume given directly makes a(0) <= 1;
 * on failure err names the block, the key and the value. */
int pfsph_film_create(pfsph_film **out, const pfsph_ctx *ctx, pfsph_film_params *fp, const char *source,
                      pfsph_error *err);
void pfsph_film_destroy(pfsph_film *fm); /* NULL is a no-op */

/* The stage (after the grid sort and the shift, before the density): detects each bubble's
 * outer layer and writes fluid->film: a_k = V_L,k / (N_s,k V0) on bubble k's surface particles,
 * 0 elsewhere. A fraction above 1 (a film thicker than a particle) is held at 1 and that
 * bubble's liquid is no longer conserved; returns how many bubbles were held this step. The
 * detection's neighbour radius is min(2 d, h), walked with the grid's h queries. Allocates
 * only when the fluid count grew. */
int pfsph_film_update(pfsph_film *fm, const pfsph_ctx *ctx);

/* The last update's surface layers (1 on a bubble's film, 0 elsewhere), fluid order, and the
 * fraction of bubble k and its surface-particle count. */
const uint8_t *pfsph_film_layers(const pfsph_film *fm);
double pfsph_film_fraction(const pfsph_film *fm, int k);
long pfsph_film_surface_count(const pfsph_film *fm, int k);

#endif
