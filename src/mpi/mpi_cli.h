/* The program under mpirun (docs/cluster.md): rank 0 runs the serial driver (src/run.c) on a
 * distributed simulation, the other ranks follow its commands. Without -DPFSPH_MPI=ON these are
 * the serial program's no-ops, and no MPI header is included. */
#ifndef PFSPH_MPI_CLI_H
#define PFSPH_MPI_CLI_H

#include "pfsph/scene.h"

#ifdef PFSPH_MPI
/* MPI_Init (finalized at exit). */
void pfsph_mpi_start(int *argc, char ***argv);
int pfsph_mpi_rank(void);
int pfsph_mpi_size(void);
/* Rank 0: what MPI cannot run yet, refused (exit status 2 for the caller); PFSPH_OK otherwise. */
int pfsph_mpi_check_scene(const pfsph_scene *s, pfsph_error *err);
/* Rank 0: the outcome of loading the scene (an exit status) and its text, for every rank;
 * returns status. With more than one rank, the run is distributed from here on. */
int pfsph_mpi_share_scene(int status, const char *text, const char *source);
/* The other ranks: wait for the scene, then follow rank 0's commands; returns the exit status
 * (exit_code maps a library status to it). */
int pfsph_mpi_follow(int threads, int (*exit_code)(int));
/* Rank 0, the run over with status rc: the others stop (with the same status). */
void pfsph_mpi_end(int rc);
#else
static inline void pfsph_mpi_start(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
}
static inline int pfsph_mpi_rank(void) { return 0; }
static inline int pfsph_mpi_size(void) { return 1; }
static inline int pfsph_mpi_check_scene(const pfsph_scene *s, pfsph_error *err)
{
    (void)s;
    (void)err;
    return 0;
}
static inline int pfsph_mpi_share_scene(int status, const char *text, const char *source)
{
    (void)text;
    (void)source;
    return status;
}
static inline int pfsph_mpi_follow(int threads, int (*exit_code)(int))
{
    (void)threads;
    (void)exit_code;
    return 0;
}
static inline void pfsph_mpi_end(int rc) { (void)rc; }
#endif

#endif
