/* Replay mode (app.h): the frames of a run directory, read with the VTP/PLY readers and the
 * surface mesh reader. */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "pfsph/io.h"
#include "pfsph/meshing.h"
#include "view/app.h"

static int read_set(const char *dir, const char *prefix, int num, bool ply, pfsph_particles *ps, double *t,
                    pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/%s%05d.%s", dir, prefix, num, ply ? "ply" : "vtp");
    pfsph_particles_free(ps);
    return ply ? pfsph_read_ply(path, ps, t, err) : pfsph_read_vtp(path, ps, t, err);
}

/* Load fluid frame index k (and the boundary, bodies and diffuse files of its number). */
int pfsph_vreplay_load(pfsph_vreplay *R, int k, pfsph_vframe *f, pfsph_error *err)
{
    int num = R->fluid.num[k];
    int rc = read_set(R->fdir, "fluid_", num, R->fluid.ply[k], &f->fluid, &f->time, err);
    if (rc) return rc;
    int bi = -1;
    for (int i = 0; i < R->bnd.n; i++)
        if (R->bnd.num[i] <= num) bi = i;
    if (bi >= 0 && R->bnd.num[bi] != R->loaded_bnd) {
        if ((rc = read_set(R->fdir, "boundary_", R->bnd.num[bi], R->bnd.ply[bi], &f->walls, NULL, err))) return rc;
        R->loaded_bnd = R->bnd.num[bi];
    }
    int ri = pfsph_frame_list_find(&R->bod, num), di = pfsph_frame_list_find(&R->dif, num);
    f->bodies.n = f->diffuse.n = 0;
    if (ri >= 0 && (rc = read_set(R->fdir, "bodies_", num, R->bod.ply[ri], &f->bodies, NULL, err))) return rc;
    if (di >= 0 && (rc = read_set(R->fdir, "diffuse_", num, R->dif.ply[di], &f->diffuse, NULL, err))) return rc;
    /* the meshes through the io layer's reader; a liquid without normals cannot be shaded as
     * water, so it counts as absent (as in `pfsph render`) */
    pfsph_surface_mesh_free(&f->liquid);
    pfsph_surface_mesh_free(&f->bmesh);
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/liquid_%05d.ply", R->fdir, num);
    if (access(path, F_OK) == 0) {
        if ((rc = pfsph_read_surface_ply(path, &f->liquid, NULL, err))) return rc;
        if (!f->liquid.n) pfsph_surface_mesh_free(&f->liquid);
    }
    snprintf(path, sizeof path, "%s/surfaces_%05d.ply", R->fdir, num);
    if (access(path, F_OK) == 0 && (rc = pfsph_read_surface_ply(path, &f->bmesh, NULL, err))) return rc;
    f->mesh_new = true;
    f->number = num;
    R->cur = k;
    return PFSPH_OK;
}

void pfsph_vreplay_goto(pfsph_vapp *A, int k)
{
    if (k < 0) k = 0;
    if (k >= A->R.fluid.n) k = A->R.fluid.n - 1;
    if (k == A->R.cur) return;
    pfsph_error err = {0};
    if (pfsph_vreplay_load(&A->R, k, &A->rf, &err)) fprintf(stderr, "pfsph: %s\n", err.msg);
    A->dirty = true;
}
