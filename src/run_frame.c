/* A frame's files as pfsph_run writes them (src/run.c): the particle sets (fluid, boundary at
 * frame 0, diffuse, bodies and their surfaces), the static solids' meshes at frame 0, the liquid
 * surfaces and the .pvd collections; under MPI the fluid frames through the decomposition. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/frame_layout.h"
#include "io/io_internal.h"
#include "pfsph/bodies.h"
#include "pfsph/dist.h"
#include "pfsph/io.h"
#include "pfsph/meshing.h"
#include "pfsph/run.h"
#include "pfsph/sim.h"
#include "pfsph/solid_mesh.h"
#include "pfsph/surface_io.h"

/* layer: the fluid's surface layers (NULL for other sets); film: bubbles' film fractions */
static int write_set_ex(const pfsph_scene *s, const char *dir, const char *name, int frame, const pfsph_particles *ps,
                        const char *aux, double time, const uint8_t *layer, bool film, pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    pfsph_io_opts o = {.dim = s->dim,
                       .write_id = (s->output.fields & PFSPH_OUT_ID) != 0,
                       .write_speed = (s->output.fields & PFSPH_OUT_SPEED) != 0,
                       .aux_name = aux,
                       .time = time,
                       .surface_layer = layer,
                       .write_film = film,
                       .diffuse = !strcmp(name, "diffuse")};
    int rc;
    if (s->output.vtp && s->output.pieces && !strcmp(name, "fluid")) { /* one piece (docs/cluster.md) */
        char base[32];
        snprintf(base, sizeof base, "%s_%05d", name, frame);
        snprintf(path, sizeof path, "%s/frames/%s_0000.vtp", dir, base);
        if ((rc = pfsph_write_vtp(path, ps, &o, err))) return rc;
        snprintf(path, sizeof path, "%s/frames/%s.pvtp", dir, base);
        if ((rc = pfsph__write_pvtp(path, &o, base, 1, err))) return rc;
    } else if (s->output.vtp) {
        snprintf(path, sizeof path, "%s/frames/%s_%05d.vtp", dir, name, frame);
        if ((rc = pfsph_write_vtp(path, ps, &o, err))) return rc;
    }
    if (s->output.ply) {
        snprintf(path, sizeof path, "%s/frames/%s_%05d.ply", dir, name, frame);
        if ((rc = pfsph_write_ply(path, ps, &o, err))) return rc;
    }
    return PFSPH_OK;
}

static int write_set(const pfsph_scene *s, const char *dir, const char *name, int frame, const pfsph_particles *ps,
                     const char *aux, double time, pfsph_error *err)
{
    return write_set_ex(s, dir, name, frame, ps, aux, time, NULL, false, err);
}

/* The boundary particles with ids >= first (bodies) or below it (static solids) as one set. */
static int write_boundary_part(const pfsph_scene *s, const char *dir, const char *name, int frame,
                               const pfsph_particles *b, uint32_t first, bool bodies, double t, pfsph_error *err)
{
    pfsph_particles ps;
    if (pfsph_particles_init(&ps, b->n ? b->n : 1)) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    for (size_t j = 0; j < b->n; j++) {
        if ((b->id[j] >= first) != bodies) continue;
        for (int k = 0; k < PFSPH_NFIELDS; k++) ps.f[k][ps.n] = b->f[k][j];
        ps.phase[ps.n] = b->phase[j];
        ps.id[ps.n] = b->id[j];
        ps.n++;
    }
    int rc = write_set(s, dir, name, frame, &ps, "volume", t, err);
    pfsph_particles_free(&ps);
    return rc;
}

/* Bodies of a frame: their particles ("bodies_NNNNN", like the other sets) and their
 * surfaces ("surfaces_NNNNN", triangle meshes with each body's pose). */
static int write_bodies(const pfsph_scene *s, const char *dir, int frame, const pfsph_particles *b,
                        const pfsph_bodies *B, double t, pfsph_error *err)
{
    const int nb = pfsph_bodies_count(B);
    int rc = write_boundary_part(s, dir, "bodies", frame, b, pfsph_bodies_first_id(B), true, t, err);
    if (rc) return rc;
    pfsph_mesh *m = calloc((size_t)nb, sizeof *m);
    pfsph_body_pose *pose = calloc((size_t)nb, sizeof *pose);
    if (!m || !pose) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    for (int i = 0; i < nb && !rc; i++) {
        pfsph_body_state st;
        pfsph_bodies_get_state(B, i, &st);
        pose[i].name = pfsph_bodies_name(B, i);
        memcpy(pose[i].x, st.x, sizeof st.x);
        memcpy(pose[i].q, st.q, sizeof st.q);
        if (pfsph_bodies_world_mesh(B, i, &m[i])) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    }
    char path[PFSPH_PATH_LEN + 64];
    if (!rc && s->output.vtp) {
        snprintf(path, sizeof path, "%s/frames/surfaces_%05d.vtp", dir, frame);
        rc = pfsph_write_surfaces_vtp(path, m, nb, pose, t, err);
    }
    if (!rc && s->output.ply) {
        snprintf(path, sizeof path, "%s/frames/surfaces_%05d.ply", dir, frame);
        rc = pfsph_write_surfaces_ply(path, m, nb, pose, t, err);
    }
    for (int i = 0; m && i < nb; i++) pfsph_mesh_free(&m[i]);
    free(m);
    free(pose);
    return rc;
}

/* Liquid surface meshes (output.surface) and the .pvd collections, after a frame's sets. */
static int write_frame_extras(const pfsph_scene *s, const char *dir, int frame, const pfsph_particles *fluid, double t,
                              pfsph_error *err)
{
    int rc = PFSPH_OK;
    if (s->output.surface.on) rc = pfsph_mesh_frame(s, dir, frame, fluid, t, NULL, err);
    if (!rc && (s->output.vtp || (s->output.surface.on && s->output.surface.vtp)))
        rc = pfsph_write_pvd_collections(dir, s->output.frame_interval / s->fps, err);
    return rc;
}

int pfsph__run_frame_files(const pfsph_scene *s, const char *dir, int frame, pfsph_sim *sim, pfsph_error *err)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    double t = pfsph_sim_time(sim);
    int rc = PFSPH_OK;
    /* a distributed run whose root does not hold the fluid: every rank writes its slice of the
     * fluid frames (src/mpi/frame_io.c, with the same fields) */
    if ((s->output.vtp || s->output.ply) && c->dist && !c->dist->fluid_whole) {
        rc = c->dist->write_fluid(c->dist, dir, frame, t, err);
    } else if (s->output.vtp || s->output.ply) {
        /* Without particle files ("formats": [], a benchmark or a meshes-only run) the frame-derived
         * fields have no reader: skipping them saved 6.5 s a frame at 493k */
        /* the outer two layers of surface particles (docs/film.md) and, with pair forces, the
         * mechanical pressure (Laplace's law holds for that one): the output stages' fields */
        if ((rc = pfsph_sim_output(sim, err))) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            return pfsph_fail(err, rc, "frame %d: %s", frame, msg);
        }
        const uint8_t *layer = pfsph_sim_output_surface_layer(sim);
        const pfsph_real *mech = pfsph_sim_output_mechanical_pressure(sim);
        const bool film = s->film.nbubbles > 0;
        if (mech) {
            pfsph_particles fl = *c->fluid;
            fl.aux = (pfsph_real *)mech; /* read only: the writer reads aux as the extra field */
            rc = write_set_ex(s, dir, "fluid", frame, &fl, "mechanical_pressure", t, layer, film, err);
        } else {
            rc = write_set_ex(s, dir, "fluid", frame, c->fluid, NULL, t, layer, film, err);
        }
    }
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    if (!rc && frame == 0 && c->boundary->n && s->output.write_boundary) {
        if (!B) rc = write_set(s, dir, "boundary", frame, c->boundary, "volume", t, err);
        else /* the static part; body particles go to bodies_NNNNN every frame */
            rc = write_boundary_part(s, dir, "boundary", frame, c->boundary, pfsph_bodies_first_id(B), false, t, err);
    }
    if (!rc && frame == 0) { /* the static solids as meshes, once (docs/artists.md#static-solids) */
        int nsolid;
        rc = pfsph_write_solids(s, dir, &nsolid, err);
    }
    const pfsph_particles *d = pfsph_sim_diffuse(sim);
    if (!rc && d) rc = write_set(s, dir, "diffuse", frame, d, "lifetime", t, err);
    if (!rc && B) rc = write_bodies(s, dir, frame, c->boundary, B, t, err);
    if (!rc) rc = write_frame_extras(s, dir, frame, c->fluid, t, err);
    return rc;
}
