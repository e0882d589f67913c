/* The viewer's state and the interface between its files: viewer.c (the command: options,
 * setup, teardown), live.c (the simulation thread), replay.c (a run directory's frames),
 * frame.c (a frame's particles and meshes to draw), hud.c (the overlay), input.c (keys and
 * mouse) and window.c (the window's loop, screenshots). Program code, not the library. */
#ifndef PFSPH_VIEW_APP_H
#define PFSPH_VIEW_APP_H

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "pfsph/render.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "pfsph/surface_mesh.h"
#include "view/camera.h"
#include "view/draw.h"

/* What colours the fluid. */
enum { PFSPH_VBY_PHASE, PFSPH_VBY_SPEED, PFSPH_VBY_DENSITY, PFSPH_VBY_PRESSURE, PFSPH_VBY_COUNT };

/* The particle sets of one drawn frame (live: a snapshot of the simulation; replay: files). */
#define PFSPH_VMAX_BODIES 64
typedef struct pfsph_vframe {
    pfsph_particles fluid, walls, bodies, diffuse;
    int nb;                          /* rigid bodies (live), at most PFSPH_VMAX_BODIES */
    double bx[PFSPH_VMAX_BODIES][3]; /* their centres */
    bool draggable[PFSPH_VMAX_BODIES];
    double time;
    uint64_t steps;
    int number; /* replay: the frame number */
    /* replay: the frame's liquid surface (frames/liquid_NNNNN.ply) and the bodies' meshes
     * (frames/surfaces_NNNNN.ply), ntris 0 where absent; mesh_new: not yet sent to the GPU */
    pfsph_surface_mesh liquid, bmesh;
    bool mesh_new;
} pfsph_vframe;

/* Live mode: a change queued by the window for the simulation thread, applied between two
 * steps (live.c). */
enum { PFSPH_VCMD_GRAVITY, PFSPH_VCMD_COEF, PFSPH_VCMD_SIGMA, PFSPH_VCMD_ANGLE, PFSPH_VCMD_DRAG, PFSPH_VCMD_RELEASE };
typedef struct pfsph_vcmd {
    int kind, a, b;
    double v[3];
} pfsph_vcmd;
#define PFSPH_VMAX_CMDS 64

/* Live mode: the simulation on its worker thread and the triple buffer of its snapshots. */
typedef struct pfsph_vlive {
    pthread_t th;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    const pfsph_scene *scene0; /* as loaded: what reset goes back to */
    pfsph_sim *sim;
    int threads;
    pfsph_vframe fr[3]; /* triple buffer: the worker's, the newest ready, the drawn one */
    int iw, ir, idr;
    bool fresh; /* fr[ir] is newer than fr[idr] */
    bool quit, paused, step_once, reset, end_noted;
    pfsph_vcmd cmd[PFSPH_VMAX_CMDS];
    int ncmd;
    bool failed;
    char msg[1200];     /* the last error or refusal, for the overlay */
    double sps;         /* steps per second, over the last half second */
    double rtf;         /* real-time factor: simulated s per wall s, over the last half second */
    uint64_t published; /* snapshots published */
    /* queued changes: when the oldest was queued; applied so far, the step they act from, and
     * how long the last and the slowest waited for the step in progress [s] */
    double cmd_t0, lat_last, lat_max;
    uint64_t applied, applied_step;
} pfsph_vlive;

/* Live mode: the liquid's surface, rebuilt on a thread of its own (vsurf.c). */
#define PFSPH_VSURF_LEVELS 4
typedef struct pfsph_vsurf {
    pthread_t th;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    bool started, quit;
    bool sync; /* a screenshot: every drawn frame's mesh, no limit on the rebuild rate */
    int dim;
    double spacing, budget; /* particle spacing [m]; the time a rebuild may take [s] (1/30) */
    /* the job: the liquid's positions and phases of the snapshot handed over */
    double *x;
    uint8_t *ph;
    size_t n, cap;
    bool job;
    double job_time, posted_time;
    double post_wall, next_post; /* wall time of the last hand-over; the next one not before */
    uint64_t posted_steps;
    /* the meshes: the worker's, the newest finished; their simulated times and cells (/ d) */
    pfsph_surface_mesh mesh[2];
    double mesh_time[2], mesh_cell[2];
    int iw, ir;
    bool fresh;
    /* the cost: level (index of the cell), the last and the smoothed rebuild times [s] */
    int level, over, under;
    double cell, last_s, avg_s;
    uint64_t nbuilt, rate_n0;
    double rate, rate_t0; /* rebuilds per second, over the last half second */
    bool gave_up, failed; /* too slow at the coarsest cell (retried at retry_at) / an error */
    double retry_at;
    char msg[300];
} pfsph_vsurf;

/* Replay mode: the frames of a run directory. */
typedef struct pfsph_vreplay {
    char fdir[PFSPH_PATH_LEN + 16];
    pfsph_frame_list fluid, bnd, dif, bod;
    int cur;        /* index into fluid */
    int loaded_bnd; /* frame number of the boundary file in memory, -1 none */
    bool playing;
    double next_t; /* wall time of the next frame while playing */
} pfsph_vreplay;

/* The command's options (viewer.c). */
typedef struct pfsph_vopts {
    const char *input;
    int w, h;
    const char *color_by;
    int frame;
    int threads;
    bool paused, no_overlay, particles, all_walls;
    const char *screenshot, *dump;
    bool hide_walls, hide_bodies, hide_diffuse;
    int frames;
    double surface_budget; /* ms, 0: default */
    const char *press;     /* keys pressed, one per drawn frame after the first (tests, demos) */
    int samples;           /* 0: automatic */
    double bench;
    double max_fps; /* most frames drawn per second in a window (0: no limit; default 60) */
} pfsph_vopts;

/* The whole viewer: options, scene, the source of the frames, camera, GL state and input. */
typedef struct pfsph_vapp {
    pfsph_vopts o;
    pfsph_scene *scene; /* live: as loaded; replay: RUN_DIR/scene.json */
    bool is_live;
    pfsph_vlive L;
    pfsph_vsurf S;                /* live, 3D: the liquid's surface */
    pfsph_surface_mesh live_mesh; /* live: the surface drawn (from S) */
    double live_mesh_time, live_mesh_cell;
    bool live_mesh_new;
    pfsph_vreplay R;
    pfsph_vframe rf; /* replay: the frame shown */
    const pfsph_vframe *shown;
    pfsph_vcam cam, cam0;
    double depth; /* scene extent, for the clip planes */
    double vref;  /* speed colour scale */
    int by;
    bool show_walls, show_bodies, show_diffuse, show_help;
    bool show_surface;                  /* meshes (replay: where the run has them; live: the liquid's surface
                                           where it keeps up) or particles (M toggles) */
    bool cut_walls;                     /* 3D: the walls facing the camera cut away (X toggles) */
    pfsph_vmesh *gl_liquid, *gl_bodies; /* the shown frame's meshes on the GPU */
    pfsph_vmesh *gl_gas;                /* live: the gases' surfaces (bubbles), in their phase colours */
    float *mv;                          /* vertex staging for the uploads */
    size_t mv_cap;
    int pair_a, pair_b; /* selected phase pair (live) */
    bool gravity_off;
    double g_saved[3];
    GLFWwindow *win;
    pfsph_vdraw *draw;
    pfsph_vsprite *spr;
    size_t spr_cap;
    bool dirty;     /* redraw needed */
    bool save_next; /* S pressed: write the next frame drawn */
    int saved;      /* screenshots written with S */
    double mx, my;  /* cursor, framebuffer pixels */
    bool drag_l, drag_r, slider_drag;
    int grab; /* body dragged with ctrl + left button, -1 none */
    double grab_depth;
    double fps; /* frames drawn per second, over the last half second */
    int fb_w, fb_h;
} pfsph_vapp;

/* The field names of the PFSPH_VBY_* codes, as --color-by takes them. */
extern const char *const pfsph_vby_name[PFSPH_VBY_COUNT];

/* ---- frame.c ---------------------------------------------------------------------------- */
void pfsph_vframe_free(pfsph_vframe *f);
/* Whether live mode draws its reconstructed surface now (on, a mesh there, not given up). */
bool pfsph_vframe_live_surface(pfsph_vapp *A);
/* Draw A->shown (and the overlay unless --no-overlay) into the frame. */
void pfsph_vframe_draw(pfsph_vapp *A);

/* ---- live.c ------------------------------------------------------------------------------ */
/* Snapshot of the simulation into f; PFSPH_ENOMEM when out of memory. */
int pfsph_vlive_publish_into(pfsph_vlive *L, pfsph_vframe *f);
/* The simulation thread (arg: the pfsph_vlive). */
void *pfsph_vlive_main(void *arg);
/* Queue a change for the simulation thread. */
void pfsph_vlive_post(pfsph_vlive *L, const pfsph_vcmd *q);
/* Wait (up to 120 s) for a snapshot newer than the one drawn. */
void pfsph_vlive_wait_fresh(pfsph_vlive *L);

/* ---- vsurf.c ------------------------------------------------------------------------------ */
/* Whether phase ph is drawn as a surface (fluids and gases). */
bool pfsph_vsurf_meshes_phase(const pfsph_scene *sc, int ph);
/* Start / stop the surface thread (start: 0, or -1 when it cannot). */
int pfsph_vsurf_start(pfsph_vsurf *S, const pfsph_scene *sc);
void pfsph_vsurf_stop(pfsph_vsurf *S);
/* Hand f's liquid to the thread when it is idle and f is newer than the last handed over. */
bool pfsph_vsurf_post(pfsph_vsurf *S, const pfsph_scene *sc, const pfsph_vframe *f);
/* Wait for the job handed over to finish. */
void pfsph_vsurf_wait(pfsph_vsurf *S);
/* Swap the newest finished mesh into *out (with its simulated time and cell / d); false: none new. */
bool pfsph_vsurf_take(pfsph_vsurf *S, pfsph_surface_mesh *out, double *time, double *cell);

/* ---- replay.c ----------------------------------------------------------------------------- */
/* Load fluid frame index k into f (and the boundary, bodies, diffuse and mesh files of its number). */
int pfsph_vreplay_load(pfsph_vreplay *R, int k, pfsph_vframe *f, pfsph_error *err);
/* Show frame index k (clamped); a file that cannot be read is reported on stderr. */
void pfsph_vreplay_goto(pfsph_vapp *A, int k);

/* ---- hud.c -------------------------------------------------------------------------------- */
/* Queue the overlay: counts and clock, the selected pair, messages, legend (the fluid's colour
 * range lo..hi), slider, help. */
void pfsph_vhud_draw(pfsph_vapp *A, double lo, double hi);

/* ---- input.c ------------------------------------------------------------------------------ */
/* Select the next phase pair that can act (not two solids). */
void pfsph_vinput_next_pair(pfsph_vapp *A);
/* A key pressed (GLFW_KEY_*): what the window's key callback does, also for --press. */
void pfsph_vinput_key(pfsph_vapp *A, int key);
/* Key, mouse button, cursor and scroll callbacks for the window (its user pointer: A). */
void pfsph_vinput_attach(GLFWwindow *w);

/* ---- window.c ----------------------------------------------------------------------------- */
/* Open the window (hidden for --screenshot), draw until closed or done; the exit status. */
int pfsph_vwindow_run(pfsph_vapp *A);

#endif
