/* The embedding API (include/pfsph.h): status texts, version, scenes, the simulation's life and
 * clock, bodies. A thin layer over the library's own modules; particle fields: api_fields.c. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph.h"
#include "pfsph/bodies.h"
#include "pfsph/io.h"
#include "pfsph/run.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"

const char *pfsph_strerror(int code)
{
    switch (code) {
#define PFSPH_ERRNO_TEXT_(name, value, text) \
    case PFSPH_##name: return text;
        PFSPH_ERRNO_MAP(PFSPH_ERRNO_TEXT_)
#undef PFSPH_ERRNO_TEXT_
    }
    return "unknown error";
}

const char *pfsph_version(void) { return PFSPH_VERSION; }
int pfsph_real_type(void) { return PFSPH_REAL_TYPE; }

int pfsph_threads(int n)
{
    if (n > 0) omp_set_num_threads(n);
    return omp_get_max_threads();
}

/* ---- scenes: heap copies of the value the loader fills ---- */

static int scene_alloc(pfsph_scene **out, pfsph_scene **s, pfsph_error *err)
{
    if (!out) return pfsph_fail(err, PFSPH_EINPUT, "no place for the scene (out is NULL)");
    *out = NULL;
    *s = malloc(sizeof **s);
    return *s ? PFSPH_OK : pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
}

int pfsph_scene_new_file(pfsph_scene **out, const char *path, pfsph_error *err)
{
    pfsph_scene *s;
    int rc = scene_alloc(out, &s, err);
    if (rc) return rc;
    if ((rc = pfsph_scene_load(s, path, err))) {
        free(s);
        return rc;
    }
    *out = s;
    return PFSPH_OK;
}

int pfsph_scene_new_json(pfsph_scene **out, const char *json, const char *source, pfsph_error *err)
{
    pfsph_scene *s;
    int rc = scene_alloc(out, &s, err);
    if (rc) return rc;
    if ((rc = pfsph_scene_parse(s, json, source, err))) {
        free(s);
        return rc;
    }
    *out = s;
    return PFSPH_OK;
}

void pfsph_scene_free(pfsph_scene *s) { free(s); }
int pfsph_scene_dim(const pfsph_scene *s) { return s->dim; }
double pfsph_scene_end_time(const pfsph_scene *s) { return s->end_time; }
double pfsph_scene_fps(const pfsph_scene *s) { return s->fps; }
const char *pfsph_scene_name(const pfsph_scene *s) { return s->name; }

/* ---- simulations ---- */

int pfsph_sim_new(pfsph_sim **out, const pfsph_scene *scene, pfsph_error *err)
{
    if (!out) return pfsph_fail(err, PFSPH_EINPUT, "no place for the simulation (out is NULL)");
    *out = NULL;
    if (!scene) return pfsph_fail(err, PFSPH_EINPUT, "no scene (NULL)");
    int rc = pfsph_sim_create(out, scene, err);
    if (rc) return rc;
    /* as `pfsph run` does before its frame 0, so that its frames and an embedder's advance
     * to k / fps see the same particles */
    pfsph_sim_prime_output(*out);
    return PFSPH_OK;
}

void pfsph_sim_free(pfsph_sim *sim) { pfsph_sim_destroy(sim); }
double pfsph_sim_dt(const pfsph_sim *sim) { return pfsph_sim_stats(sim)->dt; }
int pfsph_sim_dim(const pfsph_sim *sim) { return pfsph_sim_ctx(sim)->dim; }

void pfsph_sim_stats_get(const pfsph_sim *sim, pfsph_stats *out)
{
    const pfsph_step_stats *st = pfsph_sim_stats(sim);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *d = pfsph_sim_diffuse(sim);
    *out = (pfsph_stats){.time = pfsph_sim_time(sim),
                         .dt = st->dt,
                         .steps = pfsph_sim_steps(sim),
                         .n_fluid = c->fluid->n,
                         .n_boundary = c->boundary->n,
                         .n_diffuse = d ? d->n : 0,
                         .n_removed = pfsph_sim_removed(sim),
                         .vmax = st->vmax,
                         .density_err_avg = st->density_err_avg,
                         .density_err_max = st->density_err_max,
                         .ekin = st->ekin,
                         .iterations = st->iterations,
                         .div_iterations = st->div_iterations};
}

/* ---- output: the run's own frame writer (run.c) ---- */

int pfsph_sim_write_frame(pfsph_sim *sim, const char *dir, int frame, pfsph_error *err)
{
    if (!sim || !dir || !dir[0]) return pfsph_fail(err, PFSPH_EINPUT, "write frame: no simulation or directory");
    /* the writer's paths are dir/frames/<set>_NNNNN.ext in PFSPH_PATH_LEN + 64 bytes */
    if (strlen(dir) >= PFSPH_PATH_LEN)
        return pfsph_fail(err, PFSPH_EINPUT, "write frame: directory name longer than %d bytes", PFSPH_PATH_LEN - 1);
    const pfsph_scene *s = pfsph_sim_scene(sim);
    if (frame < 0) {
        double k = floor(pfsph_sim_time(sim) * s->fps + 1e-9);
        if (!(k <= PFSPH_MAX_FRAMES)) return pfsph_fail(err, PFSPH_EINPUT, "write frame: t * fps = %g frames", k);
        frame = (int)k / s->output.frame_interval;
    }
    char path[PFSPH_PATH_LEN + 16];
    snprintf(path, sizeof path, "%s/frames", dir);
    int rc = pfsph_mkdirs(path, err);
    return rc ? rc : pfsph__run_write_frame(sim, dir, frame, err);
}

/* ---- rigid bodies ---- */

int pfsph_sim_body_count(const pfsph_sim *sim)
{
    const pfsph_bodies *b = pfsph_sim_bodies(sim);
    return b ? pfsph_bodies_count(b) : 0;
}

const char *pfsph_sim_body_name(const pfsph_sim *sim, int i)
{
    if (i < 0 || i >= pfsph_sim_body_count(sim)) return NULL;
    return pfsph_bodies_name(pfsph_sim_bodies(sim), i);
}

int pfsph_sim_body_state(const pfsph_sim *sim, int i, double x[3], double q[4], double v[3], double w[3])
{
    if (i < 0 || i >= pfsph_sim_body_count(sim)) return PFSPH_EINPUT;
    pfsph_body_state st;
    pfsph_bodies_get_state(pfsph_sim_bodies(sim), i, &st);
    for (int a = 0; a < 3; a++) {
        if (x) x[a] = st.x[a];
        if (v) v[a] = st.v[a];
        if (w) w[a] = st.w[a];
    }
    for (int a = 0; q && a < 4; a++) q[a] = st.q[a];
    return PFSPH_OK;
}
