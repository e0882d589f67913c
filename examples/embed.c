/* Embedding pfsph: build a scene (its own small 2D dam break, or the JSON file given as the
 * first argument), step it to a time (the second argument, else the scene's end or 0.25 s for
 * its own), nudge the fluid once on the way, and print a few particles. Uses include/pfsph.h
 * only. Build against an installed pfsph:
 *   cc embed.c $(pkg-config --cflags --libs --static pfsph) -o embed */
#include <pfsph.h>
#include <stdio.h>
#include <stdlib.h>

static const char *SCENE =
    "{\n"
    "  \"name\": \"embedded column\",\n"
    "  \"dimension\": 2,\n"
    "  \"particle_radius\": 0.01,\n"
    "  \"gravity\": [0, -9.81],\n"
    "  \"domain\": {\"min\": [-0.05, -0.05], \"max\": [0.65, 0.6]},\n"
    "  \"solver\": {\"type\": \"pcisph\"},\n"
    "  \"time\": {\"end\": 0.25, \"fps\": 20, \"dt_max\": 0.004},\n"
    "  \"phases\": [\n"
    "    {\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3},\n"
    "    {\"name\": \"wall\", \"kind\": \"solid\"}\n"
    "  ],\n"
    "  \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0], \"max\": [0.2, 0.3], \"phase\": \"water\"}],\n"
    "  \"solids\": [{\"shape\": \"container\", \"min\": [0, 0], \"max\": [0.6, 0.5],\n"
    "              \"open_top\": true, \"phase\": \"wall\"}]\n"
    "}\n";

/* Value i of component k of a real field (position, velocity, density, ...). */
static double real_at(const pfsph_field *f, int k, size_t i)
{
    const char *p = (const char *)f->data[k] + i * f->stride;
    return f->type == PFSPH_FLOAT64 ? *(const double *)p : *(const float *)p;
}

static int fail(const char *what, int rc, const pfsph_error *err)
{
    fprintf(stderr, "embed: %s: %s (%s)\n", what, err->msg, pfsph_strerror(rc));
    return rc == PFSPH_EINPUT ? 2 : rc == PFSPH_EUNSTABLE ? 3 : 1;
}

int main(int argc, char **argv)
{
    pfsph_error err = {0};
    if (pfsph_real_type() != PFSPH_REAL_TYPE) {
        fprintf(stderr, "embed: compiled for another precision than the library's\n");
        return 1;
    }
    pfsph_scene *scene = NULL;
    int rc =
        argc > 1 ? pfsph_scene_new_file(&scene, argv[1], &err) : pfsph_scene_new_json(&scene, SCENE, "<embed.c>", &err);
    if (rc) return fail("scene", rc, &err);
    double t_end = argc > 2 ? atof(argv[2]) : pfsph_scene_end_time(scene);
    pfsph_sim *sim = NULL;
    rc = pfsph_sim_new(&sim, scene, &err);
    pfsph_scene_free(scene); /* the simulation keeps its own copy */
    if (rc) return fail("simulation", rc, &err);
    printf("pfsph %s, %s precision, %d threads: %dD scene \"%s\" to t = %g s\n", pfsph_version(),
           PFSPH_REAL_TYPE == PFSPH_FLOAT64 ? "double" : "single", pfsph_threads(0), pfsph_sim_dim(sim),
           pfsph_scene_name(pfsph_sim_scene(sim)), t_end);

    /* halfway, a user's own forcing: the fluid gets 0.1 m/s more towards +x, written in place
     * between steps, then announced so that the next time step follows the new speeds */
    rc = pfsph_sim_advance(sim, 0.5 * t_end, &err);
    pfsph_field v;
    if (!rc) rc = pfsph_sim_field_write(sim, "fluid", "velocity", &v, &err);
    for (size_t i = 0; !rc && i < v.count; i++) {
        pfsph_real *vx = (pfsph_real *)((char *)v.data[0] + i * v.stride);
        *vx += (pfsph_real)0.1;
    }
    if (!rc) rc = pfsph_sim_fields_written(sim, &err);
    if (!rc) rc = pfsph_sim_advance(sim, t_end, &err);
    if (rc) {
        pfsph_sim_free(sim);
        return fail("step", rc, &err);
    }

    pfsph_stats st;
    pfsph_sim_stats_get(sim, &st);
    printf("t = %.4f s after %llu steps (dt %.3g s): %zu fluid, %zu boundary particles, vmax %.3f m/s\n", st.time,
           (unsigned long long)st.steps, st.dt, st.n_fluid, st.n_boundary, st.vmax);

    /* the particles with ids 0..4 (the sort reorders them every step: find them by id) */
    pfsph_field x, id, rho;
    if ((rc = pfsph_sim_field(sim, "fluid", "position", &x, &err)) ||
        (rc = pfsph_sim_field(sim, "fluid", "velocity", &v, &err)) ||
        (rc = pfsph_sim_field(sim, "fluid", "density", &rho, &err)) ||
        (rc = pfsph_sim_field(sim, "fluid", "id", &id, &err))) {
        pfsph_sim_free(sim);
        return fail("fields", rc, &err);
    }
    printf("%4s %10s %10s %10s %10s %10s\n", "id", "x [m]", "y [m]", "vx [m/s]", "vy [m/s]", "rho");
    const uint32_t *ids = id.data[0];
    for (uint32_t want = 0; want < 5; want++)
        for (size_t i = 0; i < id.count; i++)
            if (ids[i] == want)
                printf("%4u %10.5f %10.5f %10.5f %10.5f %10.3f\n", (unsigned)want, real_at(&x, 0, i), real_at(&x, 1, i),
                       real_at(&v, 0, i), real_at(&v, 1, i), real_at(&rho, 0, i));
    pfsph_sim_free(sim);
    return 0;
}
