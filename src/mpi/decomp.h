/* The domain decomposition over MPI ranks (docs/cluster.md): the process's pfsph_dist, the
 * stages it inserts into the step, the halo refresh, the serial-order sum; the frame gather in gather.c.
 * Program code: compiled only with -DPFSPH_MPI=ON, never part of the library. */
#ifndef PFSPH_MPI_DECOMP_H
#define PFSPH_MPI_DECOMP_H

#include <mpi.h>
#include <stdint.h>

#include "mpi/cost.h"
#include "mpi/cut.h"
#include "pfsph/dist.h"
#include "pfsph/sim.h"

/* Commands the root broadcasts to the other ranks, which follow them (src/mpi/mpi_cli.c). */
enum {
    PFSPH_MPI_CREATE = 1,
    PFSPH_MPI_STEP,
    PFSPH_MPI_FRAME,
    PFSPH_MPI_SAVE,
    PFSPH_MPI_LOAD,
    PFSPH_MPI_END,
    PFSPH_MPI_WRITE,
    PFSPH_MPI_GATHER
};

typedef struct pfsph_mpi_cmd {
    int cmd, rc;
    double t;
} pfsph_mpi_cmd;

/* One rank's figures, gathered by the root at every frame (summary.json). */
typedef struct pfsph_mpi_fig {
    uint64_t steps, owned, own_min, own_max, halo_particles, halo_calls, bytes_sent, migr_bytes, messages;
    uint64_t walls, walls_max, wall_trims, wall_fetches, wall_bytes; /* static walls held, their moves */
    uint64_t resident_max;                                           /* fluid (own + halo) + walls, most */
    uint64_t peak_rss_kb; /* getrusage: the rank's peak resident memory (the set-up included) */
    uint64_t rss_kb;      /* its resident memory at the frame */
    uint64_t diffuse;     /* diffuse particles it held at the frame (before the gather) */
    uint64_t ckpt_bytes;  /* bytes it wrote of the last checkpoint (src/mpi/ckpt.c) */
    uint64_t ckpt_read;   /* bytes it read of the checkpoint resumed from */
} pfsph_mpi_fig;

struct pfsph_decomp {
    pfsph_dist d; /* first: the hooks the step calls */
    MPI_Comm comm;
    int rank, size;
    pfsph_sim *sim;
    int root_all;                   /* the root holds every particle (the start) */
    int share;                      /* the next exchange shares the root's clock and state (a start, a resume) */
    uint64_t own_g0;                /* the global index of the local particle own_lo */
    uint64_t ckpt_bytes, ckpt_read; /* figures: bytes of the last checkpoint written, of the one read */
    int failed;                     /* a stage failed on some rank: the other ranks left their command loop */
    int framed;         /* a frame time passed without a gather: its fluid frames are written collectively */
    int gathered;       /* the root holds every particle for a frame, the others still their slices */
    size_t root_own_hi; /* the root's own particles [0, root_own_hi) before the frame gather */
    size_t ncells;
    size_t off;                             /* cells of key distance that a walk of the grid's reach can span */
    pfsph_cut C;                            /* the step's cut (src/mpi/cut.c); the four below point into it */
    int check_cut;                          /* PFSPH_MPI_CHECK_CUT=1: compare every cut with the dense one */
    uint32_t *key;                          /* per sent particle */
    uint32_t *cut;                          /* size + 1: rank q owns cells [cut[q], cut[q + 1]) */
    uint64_t *gofs;                         /* size + 1: rank q owns global indices [gofs[q], gofs[q + 1]) */
    uint64_t *lofs, *lend;                  /* size: rank q holds global indices [lofs[q], lend[q]) (with its halo) */
    int *scount, *sdispl, *rcount, *rdispl; /* size each, bytes */
    char *sbuf, *rbuf;
    size_t scap, rcap;
    /* figures for summary.json */
    uint64_t cuts_checked;      /* PFSPH_MPI_CHECK_CUT */
    uint64_t frames_collective; /* frame times whose fluid frames every rank wrote its slice of */
    uint64_t gathers;           /* gathers of the whole fluid to the root (frames, root checkpoints) */
    /* the static walls this rank keeps: cells [wlo[q], whi[q]) for rank q (the root: all) */
    int trim_walls;
    size_t wall_slack; /* percent of the need added each side when a window moves */
    size_t *wlo, *whi; /* size each */
    uint64_t walls_total, walls_max, wall_trims, wall_fetches, wall_bytes, resident_max;
    uint64_t steps, halo_calls, bytes_sent, messages, migr_bytes, halo_particles;
    size_t own_min, own_max; /* owned particles of this rank over the run */
    pfsph_mpi_fig *fig;      /* size; the root: every rank's, as of the last frame */
    /* per-rank scratch (size each, 2 size for cnt2 and rcnt2): the halo's offsets, the global
     * sum's read positions, the moves of a particle set */
    size_t *qa, *qb, *qc;
    int *cnt2, *rcnt2;
    uint64_t *scan_all; /* 8 size: every rank's counters of a scan (sets.c) */
    pfsph_cost cost;    /* this rank's measured cost, its particles' weight at the cut (cost.c) */
};

/* The decomposition of the world communicator (not yet attached to a simulation). */
int pfsph_decomp_init(pfsph_decomp *D, MPI_Comm comm);
/* The frame gather (src/mpi/gather.c): every rank's owned particles to the root, in the serial order. */
int pfsph_decomp_gather(pfsph_decomp *D, pfsph_error *err);
/* A frame time on every rank: the gather, or only the figures and the diffuse set where the
 * scene's fluid frames are written collectively (pfsph_mpi_frames_collective). */
int pfsph_decomp_frame(pfsph_decomp *D, pfsph_error *err);
/* src/mpi/frame_io.c: whether this scene's fluid frames can be written collectively; the
 * root's hook that has every rank write them (the others then call pfsph_mpi_frame_follow). */
int pfsph_mpi_frames_collective(const pfsph_decomp *D);
int pfsph_mpi_write_fluid(pfsph_dist *d, const char *dir, int frame, double time, pfsph_error *err);
int pfsph_mpi_frame_follow(pfsph_decomp *D, const pfsph_mpi_cmd *c, pfsph_error *err);
/* The hooks of src/mpi/sets.c: scan, any, allsum, migrate. */
void pfsph_decomp_set_hooks(pfsph_decomp *D);
/* The checkpoint hooks (src/mpi/ckpt.c): a file written and read by every rank with MPI-IO. */
void pfsph_decomp_ckpt_hooks(pfsph_decomp *D);
/* The collective write and read; the root gives the path (and the rest), the others NULL. */
int pfsph_decomp_save(pfsph_decomp *D, const char *path, int frame, int durable, size_t *bytes, pfsph_error *err);
int pfsph_decomp_load(pfsph_decomp *D, const char *path, long expect_frame, struct pfsph_checkpoint_info *info,
                      pfsph_error *err);
/* The lowest failing rank's status and message (err may be NULL) on every rank, PFSPH_OK when
 * none failed; unlike the agree hook it does not end the run (a rejected checkpoint is retried). */
int pfsph_decomp_first_failure(pfsph_decomp *D, int rc, pfsph_error *err);
/* Broadcast a command from the root. */
void pfsph_decomp_cmd(pfsph_decomp *D, pfsph_mpi_cmd *c);

#endif
