/* What every stage shares: the timing slots' names, the blow-up report and the largest speed. */
#include "core/stage.h"

#include <math.h>
#include <stdio.h>

const char *const pfsph_stage_names[PFSPH_NSTAGES] = {"grid",      "density", "forces", "pairwise", "pressure",
                                                      "integrate", "diffuse", "bodies", "film",     "output"};

int pfsph__blowup(pfsph_blowup *b, size_t i, const char *what, double value)
{
    b->particle = i;
    snprintf(b->what, sizeof b->what, "%s %.6g", what, value);
    return PFSPH_EUNSTABLE;
}

double pfsph__max_speed(const pfsph_particles *f, size_t *worst)
{
    double vmax = 0;
    size_t wi = 0;
    int bad = 0;
#pragma omp parallel
    {
        double lv = 0;
        size_t li = 0;
        int lbad = 0;
#pragma omp for schedule(static) nowait
        for (size_t i = 0; i < f->n; i++) {
            double v2 = (double)f->vx[i] * f->vx[i] + (double)f->vy[i] * f->vy[i] + (double)f->vz[i] * f->vz[i];
            if (!isfinite(v2) || !isfinite(f->x[i] + f->y[i] + f->z[i])) {
                if (!lbad || i < li) li = i;
                lbad = 1;
            } else if (!lbad && (v2 > lv || (v2 == lv && i < li))) {
                lv = v2;
                li = i;
            }
        }
#pragma omp critical
        {
            if (lbad && (!bad || li < wi)) {
                bad = 1;
                wi = li;
            } else if (!bad && !lbad && (lv > vmax || (lv == vmax && li < wi))) {
                vmax = lv;
                wi = li;
            }
        }
    }
    *worst = wi;
    return bad ? NAN : sqrt(vmax);
}
