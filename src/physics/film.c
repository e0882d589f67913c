/* Bubbles in air: the film stage of PF Section 4.2.2 (surface detection per bubble, the even
 * film's volume fraction). src/pfsph/film.h, docs/film.md. */
#include "pfsph/film.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dist.h"
#include "pfsph/surface_detect.h"
#include "physics/stages.h"

struct pfsph_film {
    uint8_t *layer;
    size_t cap;
    int nb;
    long ns[PFSPH_MAX_BUBBLES];     /* surface particles per bubble, last update */
    double frac[PFSPH_MAX_BUBBLES]; /* their fraction */
    double volume[PFSPH_MAX_BUBBLES];
};

static int reserve(pfsph_film *fm, size_t n)
{
    if (n <= fm->cap) return PFSPH_OK;
    uint8_t *q = realloc(fm->layer, n ? n : 1);
    if (!q) return PFSPH_ENOMEM;
    fm->layer = q;
    fm->cap = n;
    return PFSPH_OK;
}

/* Layers and counts of the current state. */
static void detect(pfsph_film *fm, const pfsph_ctx *ctx)
{
    const pfsph_particles *f = ctx->fluid;
    /* one bubble at a time (group = bubble): two bubbles pressed together each keep their film
     * on the shared face, so their gases stay apart (docs/film.md). Walls cover: a bubble blown
     * from a tube has its film where it meets the air, not along the tube's inside, where the
     * gas touches the wall (docs/film.md, "Blowing a bubble") */
    pfsph_surface_opts o = {.radius = 0, .layers = 1, .group = f->bubble, .boundary = true, .reach = 0};
    pfsph_surface_detect(ctx, &o, fm->layer, NULL);
    for (int k = 0; k < fm->nb; k++) fm->ns[k] = 0;
    /* a distributed run: each rank counts the particles it owns, the counts summed over the
     * ranks (without the sum, tests/data/mpi/double_bubble_2d.json differs from the serial run at
     * its third frame). The layers need no refresh: the pair forces read the film of particles
     * within their reach of an owned one, whose detection walks (one grid reach) stay inside
     * what the rank holds (a walk's reach + 1 cells, src/mpi/decomp.c) */
    size_t lo, hi;
    pfsph__owned(ctx, &lo, &hi);
    for (size_t i = lo; i < hi; i++)
        if (f->bubble[i] && fm->layer[i] == 1) fm->ns[f->bubble[i] - 1]++;
    pfsph__count_sum(ctx, fm->ns, fm->nb);
}

int pfsph_film_create(pfsph_film **out, const pfsph_ctx *ctx, pfsph_film_params *fp, const char *source,
                      pfsph_error *err)
{
    *out = NULL;
    pfsph_film *fm = calloc(1, sizeof *fm);
    if (!fm || reserve(fm, ctx->fluid->n)) {
        free(fm);
        return pfsph_fail(err, PFSPH_ENOMEM, "film: out of memory");
    }
    fm->nb = fp->nbubbles;
    detect(fm, ctx);
    const double d = (double)ctx->spacing, V0 = (double)ctx->V0;
    for (int k = 0; k < fm->nb; k++) {
        if (fm->ns[k] == 0) {
            pfsph_film_destroy(fm);
            return pfsph_fail(err, PFSPH_EINPUT,
                              "%s: $.fluid[%d].bubble: the bubble holds no particle "
                              "(carved away by a later block, a solid or a body)",
                              source, fp->block[k]);
        }
        if (fp->thickness[k] > 0) /* a(0) = t / d: the film's area is N_s d^(dim-1) */
            fp->volume[k] = fp->thickness[k] * pow(d, ctx->dim - 1) * (double)fm->ns[k];
        const long ns = fm->ns[k];
        if (fp->volume[k] / ((double)ns * V0) > 1) {
            pfsph_film_destroy(fm);
            return pfsph_fail(err, PFSPH_EINPUT,
                              "%s: $.fluid[%d].bubble.liquid_volume: %g m^%d is more than its "
                              "%ld surface particles hold (%g m^%d, a film one particle thick); give at most that",
                              source, fp->block[k], fp->volume[k], ctx->dim, ns, (double)ns * V0, ctx->dim);
        }
        fm->volume[k] = fp->volume[k];
    }
    *out = fm;
    return PFSPH_OK;
}

void pfsph_film_destroy(pfsph_film *fm)
{
    if (!fm) return;
    free(fm->layer);
    free(fm);
}

int pfsph_film_update(pfsph_film *fm, const pfsph_ctx *ctx)
{
    pfsph_particles *f = ctx->fluid;
    const size_t n = f->n;
    if (reserve(fm, n)) return -1;
    detect(fm, ctx);
    int held = 0;
    for (int k = 0; k < fm->nb; k++) {
        /* the even film: V_L spread over the N_s surface particles of volume V0 each (a larger
         * surface, more surface particles, a thinner film) */
        double a = fm->ns[k] ? fm->volume[k] / ((double)fm->ns[k] * (double)ctx->V0) : 0;
        if (a > 1) a = 1, held++;
        fm->frac[k] = a;
    }
    const uint8_t *L = fm->layer;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) f->film[i] = f->bubble[i] && L[i] == 1 ? (pfsph_real)fm->frac[f->bubble[i] - 1] : 0;
    return held;
}

const uint8_t *pfsph_film_layers(const pfsph_film *fm) { return fm->layer; }
double pfsph_film_fraction(const pfsph_film *fm, int k) { return fm->frac[k]; }
long pfsph_film_surface_count(const pfsph_film *fm, int k) { return fm->ns[k]; }

/* bubbles in air: each bubble's surface layer and its film fraction (PF Section 4.2.2), on the
 * positions this step's forces see */
static int film_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    if (pfsph_film_update(st->film, st->ctx) < 0)
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory in the film stage");
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_film = {.name = "film",
                                          .slot = PFSPH_STAGE_FILM,
                                          .reads = PFSPH_D_POS | PFSPH_D_ORDER,
                                          .writes = PFSPH_D_FILM,
                                          .run = film_run};
