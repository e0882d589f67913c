/* Building the bodies (pfsph_bodies_create, bodies.h): each body's mesh in its own frame, its
 * surface particles and their volumes, appended to the boundary set; the ODE side is
 * bodies_world.c. */
#include "pfsph/bodies.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/vec.h"
#include "physics/bodies_internal.h"
#include "physics/boundary.h"
#include "scene/shapes.h"

/* ------------------------------------------------------------------------------------------ */
/* Geometry of one body in its own frame. */

static int body_mesh(const pfsph_scene *s, body *bd, pfsph_error *err)
{
    const pfsph_body_def *d = &bd->def;
    int rc = PFSPH_OK;
    switch (d->shape) {
    case PFSPH_BODY_BOX: rc = pfsph_mesh_box(&bd->mesh, d->half); break;
    case PFSPH_BODY_SPHERE:
        rc = s->dim == 2 ? pfsph_mesh_cylinder(&bd->mesh, d->radius, 1.0, 2, 48)
                         : pfsph_mesh_sphere(&bd->mesh, d->radius, 32);
        break;
    case PFSPH_BODY_CYLINDER:
        rc = s->dim == 2 ? pfsph_mesh_cylinder(&bd->mesh, d->radius, 1.0, 2, 48)
                         : pfsph_mesh_cylinder(&bd->mesh, d->radius, d->height, d->axis, 48);
        break;
    case PFSPH_BODY_MESH: {
        if ((rc = pfsph_mesh_load_obj(&bd->mesh, d->mesh, err)) ||
            (rc = pfsph_mesh_validate_closed(&bd->mesh, d->mesh, err))) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            int bi = 0; /* the body's index, for its JSON path */
            while (bi < s->nbodies - 1 && strcmp(s->bodies[bi].name, d->name) != 0) bi++;
            return pfsph_fail(err, PFSPH_EINPUT, "%s: $.bodies[%d].file (body \"%s\"): %s", s->source, bi, d->name,
                              msg);
        }
        double vol, com[3], I[9];
        pfsph_mesh_transform(&bd->mesh, d->scale, NULL, NULL);
        pfsph_mesh_mass_properties(&bd->mesh, &vol, com, I);
        double t[3] = {-com[0], -com[1], -com[2]};
        pfsph_mesh_transform(&bd->mesh, 1.0, NULL, t);
        break;
    }
    }
    if (rc) return pfsph_fail(err, rc, "out of memory building body \"%s\"", d->name);
    return PFSPH_OK;
}

/* A mesh body once its file is read (the scene parser checks the other shapes): every extent
 * of its scaled bounding box at least the spacing, its density in range. */
static int mesh_body_check(const pfsph_scene *s, int i, const body *bd, double spacing, pfsph_error *err)
{
    const pfsph_body_def *d = &bd->def;
    for (int a = 0; a < 3; a++)
        if (!(bd->hi[a] - bd->lo[a] >= spacing))
            return pfsph_fail(err, PFSPH_EINPUT,
                              "%s: $.bodies[%d].scale (body \"%s\", %s): the scaled mesh is %g m across, less "
                              "than the particle spacing %g m: it would hold no particle the fluid can feel",
                              s->source, i, d->name, d->mesh, bd->hi[a] - bd->lo[a], spacing);
    double vol, com[3], I[9];
    char why[256];
    pfsph_mesh_mass_properties(&bd->mesh, &vol, com, I);
    if (pfsph__body_density_check(d->density, d->mass, vol, why, sizeof why))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: $.bodies[%d].%s (body \"%s\"): %s", s->source, i,
                          d->mass > 0 ? "mass" : "density", d->name, why);
    return PFSPH_OK;
}

/* Surface particles of a body in its own frame, d/2 inside the surface as for static solids
 * (their layer then continues the fluid's lattice, and the fluid's particle centres stop d/2
 * outside the surface: displaced volumes come out right). */
static int body_particles(const pfsph_scene *s, const body *bd, double d, pfsph_particles *ps, pfsph_error *err)
{
    const pfsph_body_def *bdef = &bd->def;
    if (bdef->shape != PFSPH_BODY_MESH) {
        pfsph_solid so;
        memset(&so, 0, sizeof so);
        so.layers = bdef->layers;
        so.phase = bdef->phase;
        so.axis = s->dim == 2 ? 2 : bdef->axis;
        so.radius = bdef->radius;
        so.height = bdef->height;
        so.shape = bdef->shape == PFSPH_BODY_BOX ? PFSPH_SHAPE_BOX
            : bdef->shape == PFSPH_BODY_SPHERE   ? PFSPH_SHAPE_SPHERE
                                                 : PFSPH_SHAPE_CYLINDER;
        for (int a = 0; a < 3; a++) {
            so.min[a] = -bdef->half[a];
            so.max[a] = bdef->half[a];
        }
        if (pfsph__sample_solid(s, &so, d, ps) < 0) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
        return PFSPH_OK;
    }
    double *pts = NULL;
    size_t n = 0;
    int rc = pfsph_mesh_sample_surface(&bd->mesh, d, &pts, &n, err);
    if (rc) return rc;
    /* move each sample d/2 inwards along the normal of its nearest triangle */
    const pfsph_mesh *m = &bd->mesh;
    for (size_t i = 0; i < n; i++) {
        double *p = pts + 3 * i, best = INFINITY, nb[3] = {0, 0, 0};
        for (size_t t = 0; t < m->ntris; t++) {
            const double *A = m->v + 3 * m->tri[3 * t], *B = m->v + 3 * m->tri[3 * t + 1],
                         *C = m->v + 3 * m->tri[3 * t + 2];
            double e1[3], e2[3], nn[3];
            vec3_sub(B, A, e1);
            vec3_sub(C, A, e2);
            vec3_cross(e1, e2, nn);
            double ln = vec3_norm(nn);
            if (!(ln > 0)) continue;
            for (int a = 0; a < 3; a++) nn[a] /= ln;
            /* distance to the plane, counted only if the projection falls in the triangle
             * (barycentric test); else the distance to the centroid stands in */
            double ap[3];
            vec3_sub(p, A, ap);
            double dist = vec3_dot(ap, nn);
            double q[3] = {p[0] - dist * nn[0], p[1] - dist * nn[1], p[2] - dist * nn[2]};
            double d00 = vec3_dot(e1, e1), d01 = vec3_dot(e1, e2), d11 = vec3_dot(e2, e2);
            double aq[3];
            vec3_sub(q, A, aq);
            double d20 = vec3_dot(aq, e1), d21 = vec3_dot(aq, e2);
            double den = d00 * d11 - d01 * d01;
            double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
            double tol = 1e-6;
            double dd;
            if (v >= -tol && w >= -tol && v + w <= 1 + tol) dd = fabs(dist);
            else {
                double c[3] = {(A[0] + B[0] + C[0]) / 3 - p[0], (A[1] + B[1] + C[1]) / 3 - p[1],
                               (A[2] + B[2] + C[2]) / 3 - p[2]};
                dd = vec3_norm(c);
            }
            if (dd < best) {
                best = dd;
                memcpy(nb, nn, sizeof nb);
            }
        }
        for (int l = 0; l < bdef->layers; l++) {
            const double o = (l + 0.5) * d;
            pfsph_real xr[3] = {(pfsph_real)(p[0] - o * nb[0]), (pfsph_real)(p[1] - o * nb[1]),
                                (pfsph_real)(p[2] - o * nb[2])};
            if (pfsph_particles_push(ps, xr, NULL, (uint8_t)bdef->phase) < 0) {
                free(pts);
                return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            }
        }
    }
    free(pts);
    return PFSPH_OK;
}

/* Akinci volumes over the body's own particles, so that a body's volumes do not depend on
 * what it touches at the start. */
static int body_volumes(const pfsph_particles *src, int dim, double h, pfsph_real *vol)
{
    pfsph_particles ps;
    pfsph_grid g;
    int rc = pfsph_particles_init(&ps, src->n ? src->n : 1);
    if (rc) return rc;
    pfsph_real lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < src->n; i++) {
        for (int k = 0; k < PFSPH_NFIELDS; k++) ps.f[k][i] = src->f[k][i];
        ps.aux[i] = -1;
        ps.id[i] = (uint32_t)i;
        const pfsph_real p[3] = {src->x[i], src->y[i], src->z[i]};
        for (int a = 0; a < dim; a++) {
            if (i == 0 || p[a] < lo[a]) lo[a] = p[a];
            if (i == 0 || p[a] > hi[a]) hi[a] = p[a];
        }
    }
    ps.n = src->n;
    for (int a = 0; a < dim; a++) {
        lo[a] -= (pfsph_real)(2 * h);
        hi[a] += (pfsph_real)(2 * h);
    }
    if ((rc = pfsph_grid_init(&g, dim, lo, hi, (pfsph_real)h))) {
        pfsph_particles_free(&ps);
        return rc;
    }
    pfsph_kernel k;
    pfsph_kernel_init(&k, dim, (pfsph_real)h);
    if (!(rc = pfsph_grid_sort(&g, &ps, NULL))) {
        pfsph__boundary_volumes(&ps, &g, &k);
        for (size_t i = 0; i < ps.n; i++) vol[ps.id[i]] = ps.aux[i];
    }
    pfsph_grid_free(&g);
    pfsph_particles_free(&ps);
    return rc;
}

/* ------------------------------------------------------------------------------------------ */

int pfsph_bodies_create(pfsph_bodies **out, const pfsph_scene *s, double spacing, pfsph_particles *boundary,
                        pfsph_error *err)
{
    *out = NULL;
    pfsph_bodies *B = calloc(1, sizeof *B);
    if (!B) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    B->dim = s->dim;
    B->spacing = spacing;
    B->nb = s->nbodies;
    B->first_id = boundary->next_id;
    int rc = PFSPH_OK;
    B->b = calloc((size_t)(B->nb ? B->nb : 1), sizeof(body));
    if (!B->b) {
        free(B);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    }
    if ((rc = pfsph__bodies_world_create(B, s, spacing))) {
        pfsph_bodies_destroy(B);
        return pfsph_fail(err, rc, "out of memory");
    }

    const double h = s->support_factor * spacing;
    pfsph_particles tmp;
    if ((rc = pfsph_particles_init(&tmp, 1024))) {
        pfsph_bodies_destroy(B);
        return pfsph_fail(err, rc, "out of memory");
    }
    for (int i = 0; i < B->nb; i++) {
        body *bd = &B->b[i];
        bd->def = s->bodies[i];
        if ((rc = body_mesh(s, bd, err))) goto fail;
        pfsph_mesh_bounds(&bd->mesh, bd->lo, bd->hi); /* body_mesh validated it */
        if (bd->def.shape == PFSPH_BODY_MESH && (rc = mesh_body_check(s, i, bd, spacing, err))) goto fail;
        tmp.n = 0;
        if ((rc = body_particles(s, bd, spacing, &tmp, err))) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            if (rc == PFSPH_EINPUT) /* the mesh's sampling: name the file and the key */
                pfsph_fail(err, rc, "%s: $.bodies[%d].%s (body \"%s\"%s%s): %s", s->source, i,
                           bd->def.shape == PFSPH_BODY_MESH ? "scale" : "shape", bd->def.name,
                           bd->def.shape == PFSPH_BODY_MESH ? ", " : "",
                           bd->def.shape == PFSPH_BODY_MESH ? bd->def.mesh : "", msg);
            goto fail;
        }
        if (tmp.n == 0) {
            rc = pfsph_fail(err, PFSPH_EINPUT,
                            "%s: $.bodies[%d]: body \"%s\" is too small for the particle spacing %g m", s->source, i,
                            bd->def.name, spacing);
            goto fail;
        }
        pfsph_real *vol = malloc(tmp.n * sizeof *vol);
        double *loc = realloc(B->local, 3 * (B->np + tmp.n) * sizeof(double));
        uint16_t *own = realloc(B->owner, (B->np + tmp.n) * sizeof(uint16_t));
        if (loc) B->local = loc;
        if (own) B->owner = own;
        /* Volumes as for static walls (docs/solids): two or more layers continue the fluid's
         * lattice (V0); one layer stands for a half-space (Akinci), over the body alone. With
         * one layer a floating box rode 0.22 d too high (submerged fraction 0.454 for 0.5). */
        if (vol && bd->def.layers > 1)
            for (size_t j = 0; j < tmp.n; j++)
                vol[j] = (pfsph_real)(s->dim == 2 ? spacing * spacing : spacing * spacing * spacing);
        if (!vol || !loc || !own || (bd->def.layers == 1 && (rc = body_volumes(&tmp, s->dim, h, vol)))) {
            free(vol);
            rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
            goto fail;
        }
        bd->first = B->np;
        bd->n = (uint32_t)tmp.n;
        for (size_t j = 0; j < tmp.n; j++) {
            B->local[3 * (B->np + j)] = tmp.x[j];
            B->local[3 * (B->np + j) + 1] = tmp.y[j];
            B->local[3 * (B->np + j) + 2] = tmp.z[j];
            B->owner[B->np + j] = (uint16_t)i;
            pfsph_real z[3] = {0, 0, 0};
            long k = pfsph_particles_push(boundary, z, NULL, (uint8_t)bd->def.phase);
            if (k < 0) {
                free(vol);
                rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
                goto fail;
            }
            boundary->aux[k] = vol[j];
            boundary->rho[k] = (pfsph_real)s->phases[bd->def.phase].rest_density;
        }
        free(vol);
        B->np += (uint32_t)tmp.n;

        if (pfsph__bodies_world_add(B, bd, s->dim)) {
            rc = pfsph_fail(err, PFSPH_EINPUT,
                            "%s: $.bodies[%d] (body \"%s\"): its mass %g kg and moments of inertia are not "
                            "those of a rigid body (zero, negative or not finite); check \"mass\", \"density\" "
                            "and \"inertia\"",
                            s->source, i, bd->def.name, bd->mass);
            goto fail;
        }
    }
    pfsph_particles_free(&tmp);
    B->fp = calloc(3 * (size_t)(B->np ? B->np : 1), sizeof(double));
    if (!B->fp) {
        pfsph_bodies_destroy(B);
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    }
    for (int i = 0; i < B->nb; i++) pfsph__bodies_canonical_quat(B->b[i].id);
    pfsph__bodies_place_all(B, boundary);
    /* Bodies that overlap at the start were pushed apart by their contacts at 0.5 m/s each:
     * refuse them, naming both (issue 15 item 15). Body particles sit d/2 inside their own
     * surface, so bodies that only touch are not caught. */
    for (size_t j = 0; j < boundary->n; j++) {
        if (boundary->id[j] < B->first_id) continue;
        const int i = B->owner[boundary->id[j] - B->first_id];
        const double p[3] = {boundary->x[j], boundary->y[j], boundary->z[j]};
        for (int k = 0; k < B->nb; k++) {
            /* keyframed bodies are not moved by contacts: two of them may overlap (the egg's
             * halves of scenes/bodies_cracked_egg.json meet along the crack) */
            bool skip = k == i || (B->b[i].def.kinematic && B->b[k].def.kinematic);
            double dist = skip ? 1 : pfsph_bodies_distance(B, k, p);
            if (dist < 0) {
                int lo = i < k ? i : k, hi = i < k ? k : i;
                rc = pfsph_fail(err, PFSPH_EINPUT,
                                "%s: $.bodies[%d] (\"%s\") and $.bodies[%d] (\"%s\") overlap at the start (a "
                                "surface particle of \"%s\" at %.4g %.4g %.4g lies inside \"%s\"); move them "
                                "apart: overlapping bodies are pushed apart by their contacts",
                                s->source, lo, B->b[lo].def.name, hi, B->b[hi].def.name, B->b[i].def.name, p[0], p[1],
                                p[2], B->b[k].def.name);
                pfsph_bodies_destroy(B);
                return rc;
            }
        }
    }
    *out = B;
    return PFSPH_OK;
fail:
    pfsph_particles_free(&tmp);
    pfsph_bodies_destroy(B);
    return rc;
}
