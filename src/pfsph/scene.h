/* A scene: everything a JSON scene file describes, validated, in SI units. The loader
 * (scene.c) fills it; pfsph_sim_create turns it into particles. Documented key by key in
 * docs/scene-format.md. */
#ifndef PFSPH_SCENE_H
#define PFSPH_SCENE_H

#include <stdbool.h>
#include <stdio.h>

#include "pfsph/types.h"
#include "pfsph/params.h"

/* Fluid blocks: a fixed array, as the scene is a plain value that is copied (pfsph_sim keeps
 * its own) and never freed; 1024 of them take 150 kB. */
#define PFSPH_MAX_BLOCKS 1024
#define PFSPH_MAX_SOLIDS 64
#define PFSPH_MAX_BODIES 32
#define PFSPH_MAX_KEYFRAMES 16

enum pfsph_shape {
    PFSPH_SHAPE_BOX = 0,
    PFSPH_SHAPE_SPHERE,    /* a disc in 2D */
    PFSPH_SHAPE_CYLINDER,  /* axis along `axis`; a box-like slab... in 2D a disc */
    PFSPH_SHAPE_CONTAINER, /* hollow box: walls on all sides, optionally open at the top */
    PFSPH_SHAPE_PLANE,     /* finite plane patch inside the domain */
};

/* WCSPH with several densities: each phase's own rest density scales its Tait pressure
 * (Solenthaler & Pajarola 2008), or the densest fluid's scales all of them (Colagrossi &
 * Landrini 2003: equal stiffness, a light phase gets a sqrt(rho_max / rho) faster sound speed
 * and the time step shrinks by that factor; needed at density ratios of about 100 and more). */
enum pfsph_pressure_scale { PFSPH_PRESSURE_PHASE = 0, PFSPH_PRESSURE_COMMON };

/* The regime (docs/interactive.md): "physical" steps as the accuracy limits say; "interactive"
 * takes steps of the order of a 1/30 s frame where the pair-force model stays stable. */
enum pfsph_mode { PFSPH_MODE_PHYSICAL = 0, PFSPH_MODE_INTERACTIVE };

/* A region of fluid particles. */
typedef struct pfsph_block {
    int shape;             /* BOX or SPHERE (or CYLINDER) */
    int phase;             /* index into scene phases */
    double min[3], max[3]; /* BOX */
    double center[3];      /* SPHERE, CYLINDER */
    double radius;         /* SPHERE, CYLINDER */
    double height;         /* CYLINDER, along axis */
    int axis;              /* CYLINDER: 0 x, 1 y, 2 z */
    double velocity[3];    /* initial velocity, m/s */
    double jitter;         /* random lattice displacement, fraction of the spacing (0: none) */
    int bubble;            /* -1, or the bubble (index into the scene's film params) it is */
} pfsph_block;

/* Tangential friction of a solid on the fluid (Akinci 2012 wall viscosity) or none. */
enum pfsph_slip { PFSPH_NO_SLIP = 0, PFSPH_FREE_SLIP = 1 };

/* A static solid sampled with boundary particles. */
typedef struct pfsph_solid {
    int shape;
    int phase;             /* a phase of kind SOLID (its own pair coefficients) */
    double min[3], max[3]; /* BOX, CONTAINER */
    double center[3];      /* SPHERE, CYLINDER; a point on PLANE */
    double normal[3];      /* PLANE, unit */
    double radius;         /* SPHERE, CYLINDER */
    double height;         /* CYLINDER */
    int axis;              /* CYLINDER */
    int layers;            /* boundary particle layers, >= 1 */
    bool open_top;         /* CONTAINER */
    int slip;              /* enum pfsph_slip: wall friction or none */
    bool own_viscosity;    /* NO_SLIP: friction with `viscosity`, not the fluid's own */
    double viscosity;      /* kinematic [m^2/s], when own_viscosity */
} pfsph_solid;

/* A rigid body (docs/bodies.md): dynamic (moved by fluid forces, gravity and contacts) or
 * kinematic (moved by keyframes). Geometry is given in body coordinates about `position`. */
enum pfsph_body_shape { PFSPH_BODY_BOX = 0, PFSPH_BODY_SPHERE, PFSPH_BODY_CYLINDER, PFSPH_BODY_MESH };

typedef struct pfsph_keyframe {
    double t;           /* s */
    double position[3]; /* m */
    double rotation[3]; /* degrees about x, then y, then z (fixed axes) */
} pfsph_keyframe;

typedef struct pfsph_body_def {
    char name[PFSPH_NAME_LEN];
    int shape;                               /* enum pfsph_body_shape */
    int phase;                               /* a solid phase: pair coefficients and colour */
    double half[3];                          /* BOX half extents */
    double radius, height;                   /* SPHERE, CYLINDER */
    int axis;                                /* CYLINDER, body coordinates */
    char mesh[PFSPH_PATH_LEN];               /* MESH: OBJ path, resolved against the scene's directory */
    double scale;                            /* MESH: vertex scale */
    double position[3];                      /* m: centre of mass (a mesh is moved so that its own lies here) */
    double rotation[3];                      /* degrees, as in pfsph_keyframe */
    double velocity[3], angular_velocity[3]; /* m/s, rad/s */
    double density;                          /* kg/m^3 (per unit depth in 2D); 0: from mass */
    double mass;                             /* kg; 0: from density */
    double inertia[3];                       /* principal moments about the centre of mass in body axes [kg m^2];
                            * 0: from the shape (2D: inertia[2] only, per metre of depth) */
    double friction;                         /* Coulomb coefficient of contacts */
    double restitution;                      /* of contacts, 0..1 */
    int layers;                              /* particle layers inside the surface (2: V0 volumes, 1: Akinci's) */
    bool kinematic;
    int nkeys;
    pfsph_keyframe keys[PFSPH_MAX_KEYFRAMES];
} pfsph_body_def;

/* A body's density (mass > 0: mass / volume, else density) within the range of rigid bodies
 * (0.1..1e5 kg/m^3): 0; else 1 with the reason in msg. The scene parser checks bodies of
 * known volume, pfsph_bodies_create mesh bodies once their volume is known. */
int pfsph__body_density_check(double density, double mass, double volume, char *msg, size_t cap);

/* output.surface: liquid surface meshes while running (docs/surfaces.md) */
typedef struct pfsph_surface_output {
    bool on;
    bool ply, obj, vtp; /* formats */
    bool vdb;           /* an OpenVDB level set per frame (3D; src/pfsph/vdb.h) */
    unsigned vdb_grids; /* its grids, PFSPH_VDB_* (0: surface and velocity) */
    bool isotropic;     /* spherical kernels instead of Yu & Turk's anisotropic ones */
    int smoothing;      /* Taubin passes */
    double cell;        /* marching-cubes cell / spacing (0: default 0.5) */
    double droplet;     /* blob radius of isolated particles / spacing (0: 0.62, their own volume;
                         * -1: unbounded, as before issue 33); pfsph_surface_opts.droplet */
} pfsph_surface_output;

typedef struct pfsph_output {
    char dir[PFSPH_PATH_LEN]; /* run directory */
    bool vtp, ply;            /* formats */
    bool write_boundary;      /* also write the boundary set */
    unsigned fields;          /* bitmask of extra fields, see PFSPH_OUT_* */
    int frame_interval;       /* write every n-th frame (1 = every frame) */
    int checkpoint_interval;  /* checkpoint every n-th frame (0 = never); docs/checkpoints.md */
    bool pieces;              /* the fluid's VTP frames as ParaView pieces (.pvtp), one per MPI rank */
    bool surface_layer;       /* the fluid frames' surface_layer field (docs/film.md): a peel of
                               * the surface each frame, 20 min at frame 0 of 1.9e8 particles */
    pfsph_surface_output surface;
} pfsph_output;

enum { PFSPH_OUT_ID = 1u << 0, PFSPH_OUT_SPEED = 1u << 1 };

typedef struct pfsph_camera {
    bool set;
    double eye[3], target[3], up[3];
    double fov_deg;
    int width, height;
    char color_by[PFSPH_NAME_LEN]; /* "phase" or a field name: "speed", "density", "pressure" */
} pfsph_camera;

typedef struct pfsph_scene {
    char source[PFSPH_PATH_LEN]; /* file it was read from ("<embedded>" for the default) */
    char name[PFSPH_NAME_LEN];
    int dim;                             /* 2 or 3 */
    double particle_radius;              /* m; spacing = 2 r */
    double support_factor;               /* h = support_factor * spacing, default 2 */
    double gravity[3];                   /* m/s^2 */
    double domain_min[3], domain_max[3]; /* particles leaving it are removed */
    /* the pressure solver: its name in the registry (src/physics/solver.h) and its own keys'
     * values, in the order of its row's keys */
    char solver[PFSPH_NAME_LEN];
    double solver_settings[PFSPH_SOLVER_MAX_KEYS];
    int mode; /* enum pfsph_mode */
    /* time stepping */
    double cfl;            /* dt <= cfl * spacing / vmax */
    double dt_min, dt_max; /* s */
    double end_time;       /* s */
    double fps;            /* frames per second of output */
    uint64_t seed;
    int threads; /* 0: OpenMP default */
    /* WCSPH */
    double sound_speed; /* m/s; 0 = automatic (10 x estimated max speed) */
    double gamma;       /* Tait exponent, default 7 */
    int pressure_scale; /* enum pfsph_pressure_scale: the Tait pressure's rho0 */
    /* phases */
    int nphases;
    pfsph_phase phases[PFSPH_MAX_PHASES];
    int nblocks;
    pfsph_block blocks[PFSPH_MAX_BLOCKS];
    int nsolids;
    pfsph_solid solids[PFSPH_MAX_SOLIDS];
    int nbodies;
    pfsph_body_def bodies[PFSPH_MAX_BODIES];
    int nemitters; /* nozzles that add fluid while running (docs/emitters.md) */
    pfsph_emitter_params emitters[PFSPH_MAX_EMITTERS];
    pfsph_pairwise_params pairwise; /* see pairwise.h */
    pfsph_diffuse_params diffuse;   /* see diffuse.h */
    pfsph_film_params film;         /* bubbles in air (film.h) */
    pfsph_output output;
    pfsph_camera camera;
} pfsph_scene;

/* Fill s with the defaults of every key (docs/scene-format.md). */
void pfsph_scene_defaults(pfsph_scene *s);

/* Parse and validate a scene from JSON text. `source` names the file in messages. On error
 * returns PFSPH_EINPUT and err->msg reads "<source>: <json path>: <reason>". */
int pfsph_scene_parse(pfsph_scene *s, const char *json, const char *source, pfsph_error *err);

/* Read a file and parse it (pfsph_scene_read_text, then pfsph_scene_parse). */
int pfsph_scene_load(pfsph_scene *s, const char *path, pfsph_error *err);
/* The whole scene file as a C string (*text, free()): at most PFSPH_SCENE_MAX_BYTES, no NUL
 * byte, a regular file or a pipe; PFSPH_EINPUT naming the file otherwise (a directory, a frame
 * file, /dev/zero), PFSPH_EIO when it cannot be opened or read. The one reader of scene files:
 * the library and the pfsph program (docs/robustness.md). */
#define PFSPH_SCENE_MAX_BYTES ((size_t)16 << 20)
int pfsph_scene_read_text(const char *path, char **text, pfsph_error *err);

/* The embedded default scene (a small 3D dam break against an obstacle), as JSON text. */
const char *pfsph_scene_default_json(void);

/* The solver's name as the scene writes it ("wcsph", "pcisph", ...). */
const char *pfsph_scene_solver_name(const pfsph_scene *s);
/* Choose the solver called name with its default settings; PFSPH_EINPUT if there is none. */
int pfsph_scene_set_solver(pfsph_scene *s, const char *name);
/* The value of the solver's own key (e.g. "tolerance"), or NAN if its solver has no such key. */
double pfsph_scene_solver_setting(const pfsph_scene *s, const char *key);

/* Index of the phase called name, or -1. */
int pfsph_scene_phase_index(const pfsph_scene *s, const char *name);

/* Smallest and largest rest density of the fluid and gas phases; returns 0 when there is none. */
int pfsph_scene_density_range(const pfsph_scene *s, double *lo, double *hi);

/* ---- pair-force targets (scene_pairwise.c) ---- */

/* Radius the pair forces need: k*h if enabled, else 0. The core sizes grid cells to
 * max(h, this). */
pfsph_real pfsph_pairwise_radius(const pfsph_scene *s, pfsph_real h);

/* Turn sigma and contact-angle targets into c[a][b] (Eqs. 13-16, 21) for particles at the given
 * spacing [m] and SPH support h [m]; fills s->pairwise.resolved/radius/lambda. Idempotent.
 * Returns PFSPH_EINPUT with a message for impossible targets (a cross surface tension larger
 * than the cohesions allow, a contact angle on a fluid without cohesion, ...). */
int pfsph_pairwise_resolve(pfsph_scene *s, pfsph_real spacing, pfsph_real h, pfsph_error *err);

/* Print the coefficient matrix, each target with the coefficient it produced, and the surface
 * tensions and contact angles the final matrix predicts (for `pfsph check`). */
void pfsph_pairwise_report(const pfsph_scene *s, FILE *out);

/* The longest simulated time of a run [s]: $.time.end and `--end` alike. */
#define PFSPH_MAX_END 1e6
/* The most frames (of 1/fps) one run holds: an end time x fps above it is refused (scene and
 * pfsph_run), and so is a checkpoint whose frame is above it. */
#define PFSPH_MAX_FRAMES 100000000

#endif
