/* The table of pressure solvers, looked up by the scene's solver name. */
#include "physics/solver.h"

#include <math.h>
#include <string.h>

static const pfsph_solver_ops *const solvers[] = {&pfsph_solver_wcsph, &pfsph_solver_pcisph, &pfsph_solver_dfsph, NULL};

const pfsph_solver_ops *pfsph_solver_find(const char *name)
{
    for (int i = 0; name && solvers[i]; i++)
        if (!strcmp(solvers[i]->name, name)) return solvers[i];
    return NULL;
}

const pfsph_solver_ops *pfsph_solver_at(int i)
{
    return i >= 0 && i < (int)(sizeof solvers / sizeof *solvers) - 1 ? solvers[i] : NULL;
}

double pfsph__dt_force(double spacing, double a) { return a > 0 ? 0.25 * sqrt(spacing / a) : INFINITY; }
