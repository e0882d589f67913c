/* Fluid frames written collectively (docs/cluster.md, "Frames"): each rank's owned particles are
 * one contiguous slice of the serial order, and a PLY or VTP frame is literals and per-particle
 * regions of fixed size (src/io/frame_layout.h), so every rank writes its slice of each region at
 * a computed offset with MPI-IO into a temporary file, which the root renames into place. The
 * bytes are the serial writer's; the root never holds the whole fluid. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/frame_layout.h"
#include "io/io_internal.h"
#include "mpi/decomp.h"
#include "sim_internal.h"

/* particles per collective write (a buffer of at most 16384 x 96 bytes on each rank) */
#define WRITE_RUN ((uint64_t)16384)

int pfsph_mpi_frames_collective(const pfsph_decomp *D)
{
    const pfsph_sim *sim = D->sim;
    const pfsph_scene *s = &sim->scene;
    const char *g = getenv("PFSPH_MPI_GATHER_FRAMES"); /* the gather, as before (comparisons) */
    if (g && atoi(g) > 0) return 0;
    /* what the frame needs of the whole fluid on the root: the surface meshes (the mesher's
     * field reads every particle near a surface point; docs/cluster.md). The mechanical pressure
     * (pair forces) is computed by every rank on its slice, the kinetic temperature (stats.csv
     * with the thermostat) from its sums passed on rank to rank (src/mpi/gather.c). */
    return !s->output.surface.on;
}

/* The particles each rank owns: [gofs[q], gofs[q + 1]), the last rank also the emitters' new
 * particles after the sorted ones (to nglobal). */
static uint64_t owned_count(const pfsph_decomp *D, int q)
{
    const uint64_t e = q == D->size - 1 ? (uint64_t)D->d.nglobal : D->gofs[q + 1];
    return e - D->gofs[q];
}

/* One file: the root writes the literals, every rank its slice of each region, in rounds of
 * collective writes (the same number on every rank: the largest slice's). */
static int write_one(pfsph_decomp *D, const char *path, long pid, const pfsph__frame_layout *L,
                     const pfsph_particles *f, const uint8_t *layer, pfsph_error *err)
{
    char tmp[PFSPH_PATH_LEN + 96];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, pid);
    char msg[MPI_MAX_ERROR_STRING] = "";
    int len, e, bad = 0;
    size_t maxper = 1;
    for (int k = 0; k < L->nseg; k++)
        if (L->seg[k].per > maxper) maxper = L->seg[k].per;
    unsigned char *buf = malloc((size_t)WRITE_RUN * maxper);
    if (!buf) MPI_Abort(D->comm, 1); /* the others wait in the open */
    MPI_File fh;
    e = MPI_File_open(D->comm, tmp, MPI_MODE_WRONLY | MPI_MODE_CREATE, MPI_INFO_NULL, &fh);
    if (e != MPI_SUCCESS) MPI_Error_string(e, msg, &len), bad = 1;
    int any;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, D->comm);
    if (any) {
        free(buf);
        if (bad)
            pfsph_fail(err, PFSPH_EIO,
                       "%s: rank %d cannot create it: %s (a collective frame needs the run directory on a file "
                       "system every rank sees; PFSPH_MPI_GATHER_FRAMES=1 has rank 0 write it alone)",
                       tmp, D->rank, msg);
        /* a rank that opened it keeps the handle: a close is collective, and the run ends */
        return D->d.agree(&D->d, bad ? PFSPH_EIO : PFSPH_OK, err);
    }
    MPI_File_set_size(fh, 0); /* a leftover of the same name */
    MPI_Status st;
    if (D->rank == 0)
        for (int k = 0; k < L->nseg && !bad; k++)
            if (!L->seg[k].per) {
                e = MPI_File_write_at(fh, (MPI_Offset)L->seg[k].off, L->text + L->seg[k].lit, (int)L->seg[k].lit_len,
                                      MPI_BYTE, &st);
                if (e != MPI_SUCCESS) MPI_Error_string(e, msg, &len), bad = 1;
            }
    uint64_t rounds = 0;
    for (int q = 0; q < D->size; q++) {
        const uint64_t r = (owned_count(D, q) + WRITE_RUN - 1) / WRITE_RUN;
        if (r > rounds) rounds = r;
    }
    const uint64_t first = D->gofs[D->rank], mine = owned_count(D, D->rank);
    const size_t lo = D->d.own_lo;
    for (int k = 0; k < L->nseg; k++) {
        const size_t per = L->seg[k].per;
        if (!per) continue;
        for (uint64_t r = 0; r < rounds; r++) {
            const uint64_t a = r * WRITE_RUN < mine ? r * WRITE_RUN : mine;
            const uint64_t b = a + WRITE_RUN < mine ? a + WRITE_RUN : mine;
            pfsph__frame_encode(L, k, f, layer, lo + (size_t)a, lo + (size_t)b, first + a, buf);
            e = MPI_File_write_at_all(fh, (MPI_Offset)(L->seg[k].off + (first + a) * per), buf, (int)((b - a) * per),
                                      MPI_BYTE, &st);
            if (e != MPI_SUCCESS && !bad) MPI_Error_string(e, msg, &len), bad = 1;
        }
    }
    free(buf);
    e = MPI_File_sync(fh); /* durable before the rename */
    if (e != MPI_SUCCESS && !bad) MPI_Error_string(e, msg, &len), bad = 1;
    e = MPI_File_close(&fh);
    if (e != MPI_SUCCESS && !bad) MPI_Error_string(e, msg, &len), bad = 1;
    if (bad) pfsph_fail(err, PFSPH_EIO, "%s: rank %d: write failed: %s", path, D->rank, msg);
    /* every rank wrote its part before the root renames: else only the temporary goes */
    int rc = D->d.agree(&D->d, bad ? PFSPH_EIO : PFSPH_OK, err);
    if (!rc && D->rank == 0) {
        if (pfsph__write_fault(path)) /* the full-disk test hook */
            bad = 1, pfsph_fail(err, PFSPH_EIO, "%s: write failed: %s", path, strerror(ENOSPC));
        else if (pfsph__rename_durable(tmp, path, err)) bad = 1;
    }
    if (!rc) rc = D->d.agree(&D->d, bad ? PFSPH_EIO : PFSPH_OK, err);
    if (rc && D->rank == 0) unlink(tmp);
    return rc;
}

/* output.pieces: every rank writes its own particles as one VTP piece ("fluid_NNNNN_QQQQ.vtp",
 * Q its rank), then the root the .pvtp that names them, once every piece is in place. */
static int write_pieces(pfsph_decomp *D, const char *dir, int frame, const pfsph_particles *f, const pfsph_io_opts *o,
                        pfsph_error *err)
{
    const size_t lo = D->d.own_lo, n = (size_t)owned_count(D, D->rank);
    pfsph_particles v = *f; /* a view of the owned slice */
    for (int k = 0; k < PFSPH_NFIELDS; k++) v.f[k] = f->f[k] + lo;
    v.phase = f->phase + lo;
    v.wall = f->wall + lo;
    v.bubble = f->bubble + lo;
    v.id = f->id + lo;
    if (o->aux_name) v.aux = f->aux + lo;
    v.n = n;
    pfsph_io_opts po = *o;
    if (o->surface_layer) po.surface_layer = o->surface_layer + lo;
    char base[32], path[PFSPH_PATH_LEN + 96];
    snprintf(base, sizeof base, "fluid_%05d", frame);
    snprintf(path, sizeof path, "%s/frames/%s_%04d.vtp", dir, base, D->rank);
    int rc = pfsph_write_vtp(path, &v, &po, err);
    if ((rc = D->d.agree(&D->d, rc, err))) return rc;
    snprintf(path, sizeof path, "%s/frames/%s.pvtp", dir, base);
    if (D->rank == 0) rc = pfsph__write_pvtp(path, o, base, D->size, err);
    return D->d.agree(&D->d, rc, err);
}

/* Every rank: the frame's derived fields for its particles, then each fluid format. */
static int write_frames(pfsph_decomp *D, const char *dir, int frame, double time, long pid, pfsph_error *err)
{
    pfsph_sim *sim = D->sim;
    const pfsph_scene *s = &sim->scene;
    pfsph_particles *f = sim->ctx.fluid;
    /* the integrator moved the owned particles only: the surface layers' walks read the halo */
    pfsph_real *const pos[3] = {f->x, f->y, f->z};
    D->d.halo(&D->d, pos, 3);
    D->frames_collective++;
    int rc = pfsph_sim_output(sim, err); /* the surface layers: src/core/surface_detect.c refreshes its halo */
    if ((rc = D->d.agree(&D->d, rc, err))) return rc;
    /* with pair forces the mechanical pressure as the extra field, as the serial frame has it
     * (src/run_frame.c); each rank computed it for its own particles */
    const pfsph_real *mech = pfsph_sim_output_mechanical_pressure(sim);
    pfsph_particles fl = *f;
    if (mech) fl.aux = (pfsph_real *)mech; /* read only: the writers read aux as the extra field */
    pfsph_io_opts o = {.dim = s->dim,
                       .write_id = (s->output.fields & PFSPH_OUT_ID) != 0,
                       .write_speed = (s->output.fields & PFSPH_OUT_SPEED) != 0,
                       .aux_name = mech ? "mechanical_pressure" : NULL,
                       .time = time,
                       .surface_layer = pfsph_sim_output_surface_layer(sim),
                       .write_film = s->film.nbubbles > 0,
                       .diffuse = false};
    char path[PFSPH_PATH_LEN + 64];
    for (int fmt = 0; fmt < 2 && !rc; fmt++) { /* the serial writer's order: VTP, then PLY */
        if (!(fmt ? s->output.ply : s->output.vtp)) continue;
        if (!fmt && s->output.pieces) {
            rc = write_pieces(D, dir, frame, &fl, &o, err);
            continue;
        }
        snprintf(path, sizeof path, "%s/frames/fluid_%05d.%s", dir, frame, fmt ? "ply" : "vtp");
        pfsph__frame_layout L;
        int lr = fmt ? pfsph__ply_layout(&L, D->d.nglobal, &o) : pfsph__vtp_layout(&L, D->d.nglobal, &o);
        if (lr) MPI_Abort(D->comm, 1); /* a few KiB of header: the others wait in the write */
        rc = write_one(D, path, pid, &L, &fl, o.surface_layer, err);
        pfsph__frame_layout_free(&L);
    }
    return rc;
}

/* What the root sends with the command: the frame, the time, its pid (the temporary's name) and
 * the run directory as an absolute path (the ranks' working directories may differ). */
typedef struct write_msg {
    int frame;
    long pid;
    double time;
    char dir[PFSPH_PATH_LEN + 8];
} write_msg;

int pfsph_mpi_write_fluid(pfsph_dist *d, const char *dir, int frame, double time, pfsph_error *err)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    write_msg m;
    memset(&m, 0, sizeof m);
    m.frame = frame;
    m.pid = (long)getpid();
    m.time = time;
    char *abs = realpath(dir, NULL);
    snprintf(m.dir, sizeof m.dir, "%s", abs ? abs : dir);
    free(abs);
    pfsph_mpi_cmd c = {PFSPH_MPI_WRITE, frame, time};
    pfsph_decomp_cmd(D, &c);
    MPI_Bcast(&m, sizeof m, MPI_BYTE, 0, D->comm);
    return write_frames(D, m.dir, m.frame, m.time, m.pid, err);
}

int pfsph_mpi_frame_follow(pfsph_decomp *D, const pfsph_mpi_cmd *c, pfsph_error *err)
{
    (void)c;
    write_msg m;
    MPI_Bcast(&m, sizeof m, MPI_BYTE, 0, D->comm);
    return write_frames(D, m.dir, m.frame, m.time, m.pid, err);
}
