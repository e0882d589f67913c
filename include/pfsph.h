/* pfsph, a particle fluid simulator (SPH), as a library: the one header an embedding program
 * includes. Scenes are the JSON of docs/scene-format.md; particle fields are read in place
 * (no copies) through pfsph_sim_field. Ownership, pointer lifetimes and threads:
 * docs/embedding.md. Link: pkg-config --cflags --libs --static pfsph, or CMake's
 * find_package(pfsph) and the target pfsph::pfsph. */
#ifndef PFSPH_H
#define PFSPH_H

#include <stddef.h>
#include <stdint.h>

#include "pfsph/config.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- status codes ----
 * Every function that can fail returns one of these (0 or negative). The library never exits,
 * aborts or re-executes the process: a program maps the codes to its exit statuses. One list,
 * for the enum and pfsph_strerror: X(name, value, description). */
#define PFSPH_ERRNO_MAP(X)                                           \
    X(OK, 0, "success")                                              \
    X(EINPUT, -2, "invalid input (scene, file content or argument)") \
    X(EUNSTABLE, -3, "the simulation became unstable")               \
    X(EINTR, -4, "interrupted (a stop was asked for)")               \
    X(EIO, -5, "file system error")                                  \
    X(ENOMEM, -12, "out of memory")

enum {
#define PFSPH_ERRNO_ENUM_(name, value, text) PFSPH_##name = value,
    PFSPH_ERRNO_MAP(PFSPH_ERRNO_ENUM_)
#undef PFSPH_ERRNO_ENUM_
};

/* The description of a status code ("unknown error" for others); a static string. */
const char *pfsph_strerror(int code);

/* What went wrong, filled by the function that fails (msg always zero-terminated):
 * "<file>: <JSON path>: <reason>" for scene errors, as the pfsph program prints them. Every
 * function taking a pfsph_error * accepts NULL. */
typedef struct pfsph_error {
    int code;
    char msg[1024];
} pfsph_error;

/* ---- version and precision ---- */

/* PFSPH_VERSION of the library linked (the header's is in pfsph/config.h). */
const char *pfsph_version(void);

/* Types of field values (pfsph_field.type). */
enum { PFSPH_FLOAT32 = 1, PFSPH_FLOAT64 = 2, PFSPH_UINT8 = 3, PFSPH_UINT32 = 4 };

/* Real-valued particle data: float, or double in a PFSPH_DOUBLE build (pfsph/config.h says
 * which; the library checks itself at run time with pfsph_real_type). */
#ifdef PFSPH_DOUBLE
typedef double pfsph_real;
#define PFSPH_REAL_TYPE PFSPH_FLOAT64
#else
typedef float pfsph_real;
#define PFSPH_REAL_TYPE PFSPH_FLOAT32
#endif
/* The library's PFSPH_REAL_TYPE: equal to the header's unless the two were mixed. */
int pfsph_real_type(void);

/* ---- threads ----
 * Steps run OpenMP parallel regions. With n > 0, sets the number of threads of the regions
 * the calling thread starts (omp_set_num_threads); returns the count they get. The scene's
 * "threads" key is read by the pfsph program only. */
int pfsph_threads(int n);

/* ---- scenes ---- */

typedef struct pfsph_scene pfsph_scene; /* opaque */

/* Read a scene file (JSON) and validate it; relative paths in it (meshes) are resolved
 * against its directory. *out is NULL on error. Free with pfsph_scene_free. */
int pfsph_scene_new_file(pfsph_scene **out, const char *path, pfsph_error *err);
/* The same from JSON text; source names it in messages and resolves relative paths against its
 * directory (NULL: "<scene>", and paths relative to the working directory). */
int pfsph_scene_new_json(pfsph_scene **out, const char *json, const char *source, pfsph_error *err);
void pfsph_scene_free(pfsph_scene *s); /* NULL is a no-op */
/* The built-in default scene (a small 3D dam break), as JSON text; a static string. */
const char *pfsph_scene_default_json(void);
int pfsph_scene_dim(const pfsph_scene *s);         /* 2 or 3 */
double pfsph_scene_end_time(const pfsph_scene *s); /* "time.end" [s] */
double pfsph_scene_fps(const pfsph_scene *s);      /* frames per second of output */
const char *pfsph_scene_name(const pfsph_scene *s);

/* ---- simulations ---- */

typedef struct pfsph_sim pfsph_sim; /* opaque */

/* Build the particles of a scene (copied: the scene may be freed at once) and prepare them as
 * `pfsph run` does before its first frame: sorted, densities and pressures set, so fields
 * read before the first step carry real values. Free with pfsph_sim_free. */
int pfsph_sim_new(pfsph_sim **out, const pfsph_scene *scene, pfsph_error *err);
void pfsph_sim_free(pfsph_sim *sim); /* NULL is a no-op */
/* Advance by one time step, never past t_limit [s] (a step shortens to land on it; pass a
 * large value for none). PFSPH_EUNSTABLE names the particle and the stage that blew up. */
int pfsph_sim_step(pfsph_sim *sim, double t_limit, pfsph_error *err);
/* Advance to exactly time t [s] (steps land on it). `pfsph run` advances frame by frame,
 * to k / fps: the same calls give the same particles as its frames. */
int pfsph_sim_advance(pfsph_sim *sim, double t, pfsph_error *err);
double pfsph_sim_time(const pfsph_sim *sim);    /* simulated time [s] */
uint64_t pfsph_sim_steps(const pfsph_sim *sim); /* steps taken */
double pfsph_sim_dt(const pfsph_sim *sim);      /* the last step's time step [s] (0 before one) */
int pfsph_sim_dim(const pfsph_sim *sim);        /* 2 or 3 */
/* The scene as the simulation runs it (a view owned by sim; pair-force targets resolved). */
const pfsph_scene *pfsph_sim_scene(const pfsph_sim *sim);

/* Figures of the last step. */
typedef struct pfsph_stats {
    double time, dt; /* [s] */
    uint64_t steps;  /* taken so far */
    size_t n_fluid;  /* live particles per set */
    size_t n_boundary;
    size_t n_diffuse;       /* all types; 0 without diffuse particles */
    size_t n_removed;       /* fluid particles removed so far (they left the domain) */
    double vmax;            /* largest fluid speed [m/s] */
    double density_err_avg; /* mean relative compression of the fluid */
    double density_err_max;
    double ekin;        /* kinetic energy of the fluid [J] */
    int iterations;     /* pressure iterations of the last step (PCISPH, DFSPH) */
    int div_iterations; /* DFSPH divergence-solve iterations of the last step */
} pfsph_stats;
void pfsph_sim_stats_get(const pfsph_sim *sim, pfsph_stats *out);

/* ---- particle fields ----
 * Particle sets: "fluid", "boundary" (solids and rigid bodies), "diffuse" (spray, foam,
 * bubbles; empty unless the scene turns them on). Fields (pfsph_field_name lists them):
 *   fluid:    position, velocity [m, m/s; 3 components], density [kg/m^3], pressure [Pa],
 *             phase (uint8: index in the scene's phases), id (uint32), film (liquid fraction
 *             of a bubble's film particle, 0 elsewhere), bubble (uint8: 0 or bubble + 1)
 *   boundary: position, velocity, volume [m^dim], phase, id, wall (uint8: wall model)
 *   diffuse:  position, velocity, lifetime [s], type (uint8: 0 spray, 1 foam, 2 bubble), id
 * Storage is structure-of-arrays: a field of 3 components (x, y, z; z is 0 in 2D) is three
 * arrays, data[0..2]; one of 1 component is data[0]. Element i of component k is at
 * (char *)data[k] + i * stride. Values are in the simulation's own order, which the grid sort
 * changes every step: match particles across steps by id.
 * Lifetime: the pointers and count are valid until the next call that changes sim
 * (pfsph_sim_step, pfsph_sim_advance, pfsph_sim_free); take them again after it. */
typedef struct pfsph_field {
    void *data[3];    /* one array per component; NULL past `components` and when count is 0 */
    size_t count;     /* particles */
    size_t stride;    /* bytes from one particle to the next within data[k] */
    size_t itemsize;  /* bytes of one value */
    int components;   /* 1 or 3 */
    int type;         /* PFSPH_FLOAT32, PFSPH_FLOAT64, PFSPH_UINT8, PFSPH_UINT32 */
    int writable;     /* 1 when obtained with pfsph_sim_field_write */
    const char *unit; /* SI unit ("m", "m/s", "kg/m^3", "Pa", "m^3", "s"; "" for none) */
} pfsph_field;

/* Read access. PFSPH_EINPUT (message naming the set or field and the valid ones) for an
 * unknown set or field name; out is then zeroed. */
int pfsph_sim_field(const pfsph_sim *sim, const char *set, const char *name, pfsph_field *out, pfsph_error *err);
/* The i-th field name of a set (i from 0), NULL past the last or for an unknown set. */
const char *pfsph_field_name(const char *set, int i);
/* Live particles of a set; PFSPH_EINPUT for an unknown set. */
int pfsph_sim_count(const pfsph_sim *sim, const char *set, size_t *n, pfsph_error *err);

/* Write access between steps (a user's own forcing): the fluid's "position" and "velocity"
 * only (PFSPH_EINPUT for anything else). Write through out->data, then call
 * pfsph_sim_fields_written before the next step: it checks the values and makes the next time
 * step follow the new speeds. The next step's grid sort sees the new positions (fluid moved
 * out of the scene's domain is removed there, as fluid that flows out). */
int pfsph_sim_field_write(pfsph_sim *sim, const char *set, const char *name, pfsph_field *out, pfsph_error *err);
/* PFSPH_EINPUT (naming the particle's index and id) for a non-finite position or velocity, or
 * a non-zero z in 2D; the values stay as written, to be corrected before stepping. */
int pfsph_sim_fields_written(pfsph_sim *sim, pfsph_error *err);

/* ---- output ---- */

/* Write the particles as they are now as frame `frame` of the run directory dir, with the
 * frame writer of `pfsph run` (so the files equal the program's for the same state):
 * dir/frames/<set>_NNNNN.{vtp,ply} in the scene's "output" formats and fields (boundary
 * particles at frame 0 only, as the program does; diffuse, bodies and liquid surfaces when the
 * scene has them) and the .pvd collections; dir and dir/frames are made if missing. frame < 0:
 * the frame of the simulated time, floor(t * fps) / output.frame_interval. Does not change the
 * particles; writes no stats.csv or summary.json. PFSPH_EINPUT for a path too long, PFSPH_EIO. */
int pfsph_sim_write_frame(pfsph_sim *sim, const char *dir, int frame, pfsph_error *err);

/* ---- rigid bodies ---- */

int pfsph_sim_body_count(const pfsph_sim *sim);
const char *pfsph_sim_body_name(const pfsph_sim *sim, int i); /* NULL for a bad index */
/* Pose and velocity of body i: centre of mass x [m], unit quaternion q (w, x, y, z), linear
 * velocity v [m/s], angular velocity w [rad/s], world frame. Any pointer may be NULL.
 * PFSPH_EINPUT for a bad index. */
int pfsph_sim_body_state(const pfsph_sim *sim, int i, double x[3], double q[4], double v[3], double w[3]);

#ifdef __cplusplus
}
#endif

#endif
