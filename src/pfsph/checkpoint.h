/* Checkpoints: the whole state of a simulation in one compact binary file, written atomically,
 * with a format version, the hash of the scene it belongs to and a CRC32, so that a run can be
 * resumed and continue bit for bit as if it had never stopped. Format, policy and guarantees:
 * docs/checkpoints.md. */
#ifndef PFSPH_CHECKPOINT_H
#define PFSPH_CHECKPOINT_H

#include "pfsph/scene.h"
#include "pfsph/sim.h"

/* 4: the scene hash of src/scene/scene_hash.c (the payload is version 3's) */
#define PFSPH_CHECKPOINT_VERSION 4u
/* Checkpoints kept in RUN/checkpoints (older ones are deleted after a new one is written). */
#define PFSPH_CHECKPOINT_KEEP 2

/* 64-bit hash of every scene value that shapes the simulated state: every member of the scene
 * (src/scene/scene_hash.c's tables, which the build checks against the structs) except output
 * settings, the end time, the thread count, the camera, the scene's name and source, phase
 * colours and the values the simulation derives (resolved pair coefficients): a run may be
 * resumed with another end time or output directory. The same for a scene as parsed and as
 * pfsph_sim_scene holds it. */
uint64_t pfsph_scene_hash(const pfsph_scene *s);

/* What a checkpoint says about itself. */
typedef struct pfsph_checkpoint_info {
    int frame;   /* output frame (in frames of 1/fps) the state was saved at */
    int threads; /* OpenMP threads of the run that wrote it (bit-identical resume needs the same) */
    double time; /* simulated time [s] */
    uint64_t step;
} pfsph_checkpoint_info;

/* Serialise the state of sim, reached at output frame `frame`, into a malloc'ed buffer. */
int pfsph_checkpoint_encode(const pfsph_sim *sim, int frame, void **data, size_t *len, pfsph_error *err);
/* Check and restore a buffer produced by pfsph_checkpoint_encode into sim (info may be NULL), which must have been
 * created from the same scene (hash compared). `name` names the source in messages. The buffer
 * is fully checked (length, magic, version, precision, CRC32, scene hash, counts, the frame
 * against PFSPH_MAX_FRAMES and the time against frame / fps, finite values) before sim is
 * touched. Returns PFSPH_OK, PFSPH_EINPUT (corrupt, truncated, other scene) or PFSPH_ENOMEM. */
int pfsph_checkpoint_decode(pfsph_sim *sim, const void *data, size_t len, const char *name, pfsph_checkpoint_info *info,
                            pfsph_error *err);

/* Write a checkpoint file atomically (temporary file, fsync, rename); *bytes (may be NULL)
 * receives its size. */
int pfsph_checkpoint_save(const char *path, const pfsph_sim *sim, int frame, size_t *bytes, pfsph_error *err);
/* As pfsph_checkpoint_save without the fsyncs: a scratch copy that this process may need again
 * (the last good frame that pfsph_run keeps for a blow-up). Like every checkpoint file it is
 * written from the simulation's arrays through a small buffer, with no copy of the state in
 * memory. */
int pfsph_checkpoint_stash(const char *path, const pfsph_sim *sim, int frame, pfsph_error *err);
/* Make a stashed checkpoint durable under dest (fsync, rename). */
int pfsph_checkpoint_keep(const char *stash, const char *dest, pfsph_error *err);
/* Read and restore a checkpoint file; messages name the file. A file named ckpt_NNNNN.bin must
 * hold frame NNNNN. */
int pfsph_checkpoint_load(const char *path, pfsph_sim *sim, pfsph_checkpoint_info *info, pfsph_error *err);

/* RUN/checkpoints/ckpt_NNNNN.bin for a frame. */
void pfsph_checkpoint_path(char *buf, size_t cap, const char *run_dir, int frame);
/* Save RUN/checkpoints/ckpt_<frame>.bin (creating the folder) and delete all but the newest
 * `keep` checkpoints there. */
int pfsph_checkpoint_write_run(const char *run_dir, const pfsph_sim *sim, int frame, int keep, size_t *bytes,
                               pfsph_error *err);

/* Delete every checkpoint of RUN/checkpoints (a fresh run into an old run directory). */
int pfsph_checkpoint_clear(const char *run_dir, pfsph_error *err);

/* Messages about skipped checkpoints (the library never prints). */
typedef void (*pfsph_message_fn)(const char *msg, void *user);

/* Restore the newest valid checkpoint of RUN/checkpoints into sim; a corrupt, truncated or
 * foreign one is reported through warn (may be NULL) and the next older one tried. info->frame
 * receives the frame of the checkpoint used, or -1 (and PFSPH_OK, sim untouched) when the
 * folder holds no checkpoint at all. PFSPH_EINPUT when there are some but none is usable. */
int pfsph_checkpoint_resume(const char *run_dir, pfsph_sim *sim, pfsph_checkpoint_info *info, pfsph_message_fn warn,
                            void *user, pfsph_error *err);

#endif
