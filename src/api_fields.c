/* The embedding API's particle fields (include/pfsph.h): named views of the particle sets'
 * arrays, in place, and the check after an embedder wrote fluid positions or velocities. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pfsph.h"
#include "pfsph/particles.h"
#include "pfsph/sim.h"

enum { REAL, PHASE, WALL, BUBBLE, ID };

/* One field of a set: a real slot of pfsph_particles (3 components: it and the next two), or
 * one of its integer arrays. */
typedef struct field_def {
    const char *name;
    int kind;       /* REAL or the integer array */
    int slot;       /* REAL: PFSPH_F_* of the first component */
    int components; /* 1 or 3 */
    const char *unit;
    int writable; /* fluid position and velocity (pfsph_sim_fields_written) */
} field_def;

/* name, kind, slot, components, unit, writable; "m^d": the volume's unit in d dimensions */
static const field_def FLUID[] = {
    {"position", REAL, PFSPH_F_X, 3, "m", 1},
    {"velocity", REAL, PFSPH_F_VX, 3, "m/s", 1},
    {"density", REAL, PFSPH_F_RHO, 1, "kg/m^3", 0},
    {"pressure", REAL, PFSPH_F_P, 1, "Pa", 0},
    {"phase", PHASE, 0, 1, "", 0},
    {"id", ID, 0, 1, "", 0},
    {"film", REAL, PFSPH_F_FILM, 1, "", 0},
    {"bubble", BUBBLE, 0, 1, "", 0},
    {NULL, 0, 0, 0, NULL, 0},
};
static const field_def BOUNDARY[] = {
    {"position", REAL, PFSPH_F_X, 3, "m", 0},
    {"velocity", REAL, PFSPH_F_VX, 3, "m/s", 0},
    {"volume", REAL, PFSPH_F_AUX, 1, "m^d", 0},
    {"phase", PHASE, 0, 1, "", 0},
    {"id", ID, 0, 1, "", 0},
    {"wall", WALL, 0, 1, "", 0},
    {NULL, 0, 0, 0, NULL, 0},
};
static const field_def DIFFUSE[] = {
    {"position", REAL, PFSPH_F_X, 3, "m", 0},
    {"velocity", REAL, PFSPH_F_VX, 3, "m/s", 0},
    {"lifetime", REAL, PFSPH_F_AUX, 1, "s", 0},
    {"type", PHASE, 0, 1, "", 0},
    {"id", ID, 0, 1, "", 0},
    {NULL, 0, 0, 0, NULL, 0},
};

static const struct {
    const char *name;
    const field_def *fields;
} SETS[] = {{"fluid", FLUID}, {"boundary", BOUNDARY}, {"diffuse", DIFFUSE}};
#define NSETS (int)(sizeof SETS / sizeof SETS[0])

static int set_index(const char *set)
{
    for (int k = 0; set && k < NSETS; k++)
        if (!strcmp(set, SETS[k].name)) return k;
    return -1;
}

static int bad_set(const char *set, pfsph_error *err)
{
    return pfsph_fail(err, PFSPH_EINPUT, "no particle set '%s'; the sets are fluid, boundary, diffuse",
                      set ? set : "(null)");
}

/* The set's particles: never NULL (an empty set for diffuse particles that are off). */
static const pfsph_particles *set_particles(const pfsph_sim *sim, int k)
{
    static const pfsph_particles none;
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    if (k == 0) return c->fluid;
    if (k == 1) return c->boundary;
    const pfsph_particles *d = pfsph_sim_diffuse(sim);
    return d ? d : &none;
}

const char *pfsph_field_name(const char *set, int i)
{
    int k = set_index(set);
    if (k < 0 || i < 0) return NULL;
    for (int j = 0; SETS[k].fields[j].name; j++)
        if (j == i) return SETS[k].fields[j].name;
    return NULL;
}

int pfsph_sim_count(const pfsph_sim *sim, const char *set, size_t *n, pfsph_error *err)
{
    int k = set_index(set);
    if (n) *n = 0;
    if (k < 0) return bad_set(set, err);
    if (n) *n = set_particles(sim, k)->n;
    return PFSPH_OK;
}

static int get_field(const pfsph_sim *sim, const char *set, const char *name, int write, pfsph_field *out,
                     pfsph_error *err)
{
    if (out) memset(out, 0, sizeof *out);
    int k = set_index(set);
    if (k < 0) return bad_set(set, err);
    const field_def *f = SETS[k].fields;
    while (f->name && !(name && !strcmp(name, f->name))) f++;
    if (!f->name) {
        char list[256];
        size_t len = 0;
        list[0] = 0;
        for (const field_def *g = SETS[k].fields; g->name; g++)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", g == SETS[k].fields ? "" : ", ", g->name);
        return pfsph_fail(err, PFSPH_EINPUT, "%s: no field '%s'; its fields are %s", set, name ? name : "(null)", list);
    }
    if (write && !f->writable)
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s %s: not writable; an embedder writes the fluid's position and velocity only", set, name);
    if (!out) return pfsph_fail(err, PFSPH_EINPUT, "%s %s: no place for the field (out is NULL)", set, name);
    const pfsph_particles *ps = set_particles(sim, k);
    out->count = ps->n;
    out->components = f->components;
    out->writable = write;
    out->unit = f->unit;
    if (!strcmp(f->unit, "m^d")) out->unit = pfsph_sim_ctx(sim)->dim == 2 ? "m^2" : "m^3";
    if (f->kind == REAL) {
        out->type = PFSPH_REAL_TYPE;
        out->itemsize = sizeof(pfsph_real);
        for (int a = 0; a < f->components && ps->n; a++) out->data[a] = ps->f[f->slot + a];
    } else if (f->kind == ID) {
        out->type = PFSPH_UINT32;
        out->itemsize = sizeof(uint32_t);
        if (ps->n) out->data[0] = ps->id;
    } else {
        out->type = PFSPH_UINT8;
        out->itemsize = sizeof(uint8_t);
        if (ps->n) out->data[0] = f->kind == PHASE ? ps->phase : f->kind == WALL ? ps->wall : ps->bubble;
    }
    out->stride = out->itemsize; /* the sets' arrays are dense */
    return PFSPH_OK;
}

int pfsph_sim_field(const pfsph_sim *sim, const char *set, const char *name, pfsph_field *out, pfsph_error *err)
{
    return get_field(sim, set, name, 0, out, err);
}

int pfsph_sim_field_write(pfsph_sim *sim, const char *set, const char *name, pfsph_field *out, pfsph_error *err)
{
    return get_field(sim, set, name, 1, out, err);
}

int pfsph_sim_fields_written(pfsph_sim *sim, pfsph_error *err)
{
    const pfsph_particles *f = pfsph_sim_ctx(sim)->fluid;
    const int dim = pfsph_sim_ctx(sim)->dim;
    /* the grid sort bins positions and the time step follows speeds: both must be numbers (a
     * NaN would be binned nowhere) */
    for (size_t i = 0; i < f->n; i++) {
        if (!isfinite(f->x[i]) || !isfinite(f->y[i]) || !isfinite(f->z[i]) || !isfinite(f->vx[i]) ||
            !isfinite(f->vy[i]) || !isfinite(f->vz[i]))
            return pfsph_fail(err, PFSPH_EINPUT,
                              "fluid particle %zu (id %u): position (%g, %g, %g) m or velocity (%g, %g, %g) m/s "
                              "is not finite",
                              i, (unsigned)f->id[i], (double)f->x[i], (double)f->y[i], (double)f->z[i],
                              (double)f->vx[i], (double)f->vy[i], (double)f->vz[i]);
        if (dim == 2 && (f->z[i] != 0 || f->vz[i] != 0))
            return pfsph_fail(err, PFSPH_EINPUT,
                              "fluid particle %zu (id %u): z = %g m, vz = %g m/s in a 2D scene: they stay 0", i,
                              (unsigned)f->id[i], (double)f->z[i], (double)f->vz[i]);
    }
    pfsph_sim_velocities_written(sim);
    return PFSPH_OK;
}
