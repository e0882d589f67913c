/* The pfsph program: run, check, render, bench. Parses the command line, prints progress and
 * errors, maps library status codes to exit statuses (2 bad input, 3 unstable, 1 other). */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/omp_env.h"
#include "pfsph/bodies.h"
#include "pfsph/emitter.h"
#include "pfsph/houdini.h"
#include "pfsph/meshing.h"
#include "pfsph/pairwise.h"
#include "pfsph/render.h"
#include "pfsph/run.h"
#include "mpi/mpi_cli.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "pfsph/vdb.h"
#include "physics/solver.h"
#ifdef PFSPH_HAVE_VIEWER
#include "view/view.h"
#endif

static const char *USAGE =
    "usage: pfsph run [SCENE] [-o DIR] [--force] [--threads N] [--end T] [--render] [--quiet]\n"
    "       pfsph run --resume RUN_DIR [--threads N] [--end T] [--render] [--quiet]\n"
    "       pfsph check SCENE\n"
    "       pfsph render RUN_DIR [--video] [--color-by phase|speed|density|pressure]\n"
    "                            [--size WxH] [--particles] [--all-walls] [--no-legend]\n"
    "       pfsph mesh RUN_DIR [--formats ply,obj,vtp,vdb] [--smooth N] [--isotropic] [--droplet R]\n"
    "                  [--threads N]\n"
    "       pfsph export RUN_DIR --houdini [--ascii | --classic]\n"
    "       pfsph view [SCENE | RUN_DIR] [--screenshot FILE --frames N] [...]\n"
    "       pfsph --version\n"
    "       pfsph help [COMMAND]    (or pfsph COMMAND --help)\n";

static const char *HELP =
    "pfsph: a particle fluid simulator (SPH) for scenes described in JSON.\n"
    "\n"
    "commands:\n"
    "  run      simulate a scene into a run directory (frames, stats.csv, summary.json)\n"
    "  check    validate a scene: particle counts, memory estimate, coefficients\n"
    "  render   PNG previews (and an mp4) of a run directory's frames\n"
    "  export   Houdini geometry (.geo) of a run directory's fluid frames\n"
    "  mesh     liquid surface meshes (PLY, OBJ, VTP) of a run directory's fluid frames (2D: outlines)\n"
    "  view     a window: a scene simulated live, or a run directory replayed\n"
    "  help     this text, or a command's: pfsph help run\n"
    "  --version  the version, precision and OpenMP thread count\n"
    "\n"
    "Exit status: 0 done, 2 bad input (scene, options, run directory), 3 the simulation blew\n"
    "up, 1 anything else (a full disk, out of memory). Scene keys: docs/scene-format.md.\n";

static const char *HELP_RUN =
    "usage: pfsph run [SCENE] [-o DIR] [--force] [--threads N] [--end T] [--render] [--quiet]\n"
    "       pfsph run --resume RUN_DIR [--threads N] [--end T] [--render] [--quiet]\n"
    "\n"
    "Simulate SCENE (a JSON file) into its run directory: frames/, stats.csv, summary.json,\n"
    "scene.json, run.json, checkpoints/. Without SCENE, the embedded default scene (a small 3D\n"
    "dam break) runs into ./pfsph_default_run and is rendered.\n"
    "\n"
    "  -o, --output DIR  run directory (default: the scene's output.directory)\n"
    "  --force           the run directory is not empty: remove pfsph's files there first\n"
    "                    (frames, checkpoints, PNGs, stats; nothing else) instead of refusing\n"
    "  --resume RUN_DIR  continue a stopped run from its newest valid checkpoint, with\n"
    "                    RUN_DIR/scene.json, to the end it was started with (RUN_DIR/run.json)\n"
    "  --threads N       OpenMP threads, 1..1024; 0 = the default (the scene's \"threads\", else\n"
    "                    OpenMP's)\n"
    "  --end T           simulated end time [s], overrides the scene's time.end (and, with\n"
    "                    --resume, the run's own end)\n"
    "  --render          render PNG previews after the run (as `pfsph render`)\n"
    "  --quiet           no progress, no messages but errors\n"
    "  -h, --help        this text\n"
    "\n"
    "A run holds a lock on its directory: a second run into it is refused (exit status 2).\n"
    "Built with -DPFSPH_MPI=ON, `mpirun -np N pfsph run ...` spreads the run over N ranks, with\n"
    "the same frames as one process (docs/cluster.md).\n"
    "Exit status: 0 finished, 2 bad input, 3 unstable (the last good state is kept as a\n"
    "checkpoint), 1 other errors.\n";

static const char *HELP_CHECK =
    "usage: pfsph check SCENE\n"
    "\n"
    "Validate SCENE without running it: every key (unknown keys, ranges, JSON paths in the\n"
    "messages), the particle counts, the memory estimate against 80% of this machine's memory,\n"
    "mesh files of bodies, density ratios, resolved pairwise coefficients. The verdict\n"
    "(\"SCENE: valid ...\") is printed last. Exit status 0 valid, 2 not.\n"
    "\n"
    "  -h, --help  this text\n";

static const char *HELP_RENDER =
    "usage: pfsph render RUN_DIR [--video] [--color-by phase|speed|density|pressure] [--size WxH]\n"
    "                            [--particles] [--all-walls] [--no-legend]\n"
    "\n"
    "Render the frames of RUN_DIR/frames into RUN_DIR/png/frame_NNNNN.png with the scene's\n"
    "camera (RUN_DIR/scene.json).\n"
    "\n"
    "  --video                 also RUN_DIR/frames.mp4 (needs ffmpeg on the PATH)\n"
    "  --particles             particles even where meshes exist: the liquid's (frames/liquid_*.ply,\n"
    "                          `pfsph mesh`), otherwise drawn as a water surface, and the rigid\n"
    "                          bodies' (frames/surfaces_*.ply), otherwise drawn as solids\n"
    "  --all-walls             3D: keep the tank walls facing the camera (cut away by default,\n"
    "                          so that what stands in the tank shows; never where no fluid\n"
    "                          lies below the walls' top, such as drops on plates)\n"
    "  --no-legend             no key: colour bar (field, unit), legend of the colours\n"
    "                          (phases, walls, bodies, spray/foam/bubbles), scale bar\n"
    "  --color-by FIELD        phase, speed, density or pressure (default: the scene camera's)\n"
    "  --size WxH              image size in pixels, 16..16384 each (default: the camera's)\n"
    "  -h, --help              this text\n";

static const char *HELP_MESH =
    "usage: pfsph mesh RUN_DIR [--formats ply,obj,vtp,vdb] [--smooth N] [--isotropic] [--droplet R]\n"
    "                  [--threads N]\n"
    "\n"
    "Reconstruct the liquid surface of every fluid frame of RUN_DIR (a finished or stopped\n"
    "run) into RUN_DIR/frames/liquid_NNNNN.{ply,obj,vtp,vdb}, one closed mesh per fluid phase with\n"
    "the phase per face, and rewrite the .pvd collections. Anisotropic kernels (Yu & Turk 2013);\n"
    "docs/surfaces.md. Settings default to the scene's output.surface.\n"
    "\n"
    "  --formats LIST  comma-separated: ply, obj, vtp, vdb (an OpenVDB level set: its grids are\n"
    "                  the scene's vdb_grids; default: the scene's formats, else ply,vtp)\n"
    "  --smooth N      Taubin smoothing passes of the mesh, 0..100 (default 0)\n"
    "  --isotropic     spherical kernels instead of anisotropic ones\n"
    "  --droplet R     blob radius of isolated particles in spacings (default 0.62: their own\n"
    "                  volume; -1: unbounded, the meshes before issue 33)\n"
    "  --threads N     OpenMP threads (the meshes are the same bytes for any count)\n"
    "  -h, --help      this text\n"
    "\n"
    "A 2D run gets the liquid's outline as VTP polylines (liquid_NNNNN.vtp) instead; PLY or OBJ\n"
    "for a 2D run is refused (exit status 2).\n";

static const char *HELP_EXPORT =
    "usage: pfsph export RUN_DIR --houdini [--ascii | --classic]\n"
    "\n"
    "Write RUN_DIR's frames as Houdini geometry (binary JSON .bgeo, which Houdini 12 and later\n"
    "read natively): frames/fluid_NNNNN (points ordered by id: P v id pscale density pressure\n"
    "phase), diffuse_NNNNN (P v id pscale type lifetime), liquid_NNNNN (the liquid mesh: P N v,\n"
    "primitive phase), bodies_NNNNN (body surfaces: primitive body, name) and RUN_DIR/solids\n"
    "(the static solids' triangles). Ids need frames with ids (output.fields [\"id\"]).\n"
    "docs/artists.md#houdini.\n"
    "\n"
    "  --houdini   the format\n"
    "  --ascii     JSON text (.geo) instead of binary\n"
    "  --classic   the classic ASCII .geo (PGEOMETRY V5), fluid points only\n"
    "  -h, --help  this text\n";

static int is_help(const char *a) { return !strcmp(a, "--help") || !strcmp(a, "-h"); }

/* The signal that asked a run to stop (SIGINT, SIGTERM), 0 for none: the run stops at its next
 * step, keeps a checkpoint and the program exits with 128 + the signal, the shell's status for a
 * process killed by it. A second signal ends the program at once (the default action). */
static volatile sig_atomic_t g_stop;

static void on_stop_signal(int sig)
{
    g_stop = sig;
    signal(sig, SIG_DFL);
}

static int exit_code(int rc)
{
    switch (rc) {
    case PFSPH_OK: return 0;
    case PFSPH_EINTR: return 128 + (g_stop ? (int)g_stop : SIGINT);
    case PFSPH_EINPUT: return 2;
    case PFSPH_EUNSTABLE: return 3;
    default: return 1;
    }
}

static int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "pfsph: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n%s", USAGE);
    return 2;
}

/* Messages carry what the input said (keys, names, file names): a control byte or a byte
 * that is not part of valid UTF-8 is written as \xNN, so random input cannot drive the
 * terminal. */
static void put_escaped(FILE *f, const char *s)
{
    const unsigned char *p = (const unsigned char *)s;
    while (*p) {
        int len = *p < 0x80 ? 1 : (*p & 0xe0) == 0xc0 ? 2 : (*p & 0xf0) == 0xe0 ? 3 : (*p & 0xf8) == 0xf0 ? 4 : 0;
        int ok = len > 0 && !(len == 1 && (*p < 0x20 || *p == 0x7f) && *p != '\n' && *p != '\t');
        for (int k = 1; ok && k < len; k++) ok = (p[k] & 0xc0) == 0x80;
        if (ok && len == 2 && *p < 0xc2) ok = 0; /* overlong */
        if (!ok) {
            fprintf(f, "\\x%02x", *p++);
            continue;
        }
        fwrite(p, 1, (size_t)len, f);
        p += len;
    }
}

/* "pfsph: <prefix><msg>" on stderr, escaped. */
static void print_error(const char *prefix, const char *msg)
{
    fputs("pfsph: ", stderr);
    if (prefix) fputs(prefix, stderr);
    put_escaped(stderr, msg);
    fputc('\n', stderr);
}

/* Loads SCENE (or the default when path is NULL); prints the error. */
static int load_scene(const char *path, pfsph_scene *s, char **text)
{
    pfsph_error err = {0};
    int rc;
    if (!path) {
        *text = strdup(pfsph_scene_default_json());
        rc = pfsph_scene_parse(s, *text, "<default scene>", &err);
    } else {
        /* the library's reader, with its 16 MiB cap (/dev/zero grew to 1 GB: issue 33) */
        rc = pfsph_scene_read_text(path, text, &err);
        if (rc) {
            print_error(NULL, err.msg);
            return rc == PFSPH_ENOMEM ? 1 : 2; /* a scene that cannot be read is bad input */
        }
        rc = pfsph_scene_parse(s, *text, path, &err);
    }
    if (rc) {
        print_error(NULL, err.msg);
        return exit_code(rc);
    }
    return 0;
}

static long physical_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? pages * size : 0;
}

static int check_memory(const pfsph_scene *s, int verbose)
{
    size_t nf = 0, nb = 0, bytes = 0;
    pfsph_error err = {0};
    int rc = pfsph_scene_estimate(s, &nf, &nb, &bytes, &err);
    if (rc) {
        print_error(NULL, err.msg);
        return exit_code(rc);
    }
    long mem = physical_memory();
    size_t ne = 0;
    if (s->nemitters && (rc = pfsph_scene_emitted_max(s, s->end_time, &ne, &err))) { /* estimate checked it */
        print_error(NULL, err.msg);
        return exit_code(rc);
    }
    if (verbose) {
        if (ne)
            printf("particles: %zu fluid at the start, up to %zu with the emitters' by t = %g s, %zu boundary\n", nf,
                   nf + ne, s->end_time, nb);
        else printf("particles: %zu fluid, %zu boundary\n", nf, nb);
        printf("memory estimate: %.1f MiB (%.0f bytes per fluid particle)%s\n", (double)bytes / 1048576.0,
               nf + ne ? (double)bytes / (double)(nf + ne) : 0.0, ne ? ", for the most fluid" : "");
        const pfsph_solver_ops *ops = pfsph_solver_find(pfsph_scene_solver_name(s));
        if (ops && ops->neighbour_lists) /* $.solver.neighbour_lists */
            printf("neighbour lists: %s\n",
                   pfsph__sim_lists(s, (double)(nf + ne))
                       ? "yes"
                       : "no (grid walks: the same results, less memory, slower solver)");
    }
    if (mem > 0 && (double)bytes > 0.8 * (double)mem) {
        fprintf(stderr,
                "pfsph: %s: the scene needs about %.1f GiB, more than 80%% of this machine's %.1f GiB; "
                "enlarge particle_radius or shrink the fluid\n",
                s->source, (double)bytes / 1073741824.0, (double)mem / 1073741824.0);
        return 2;
    }
    return 0;
}

typedef struct progress_state {
    int tty, quiet;
    double last_line; /* wall_s of the last line written without a terminal */
} progress_state;

static void show_progress(const pfsph_progress *p, void *user)
{
    progress_state *ps = user;
    if (ps->quiet) return;
    /* by simulated time (steps move it within a frame), from where this run started */
    double span = p->end_time - p->time0;
    double frac = span > 0 ? (p->time - p->time0) / span : 1;
    if (frac < 0) frac = 0;
    if (frac > 1) frac = 1;
    double eta = frac > 0 ? p->wall_s * (1 - frac) / frac : 0;
    if (ps->tty) {
        char bar[31];
        int filled = (int)(frac * 30);
        for (int i = 0; i < 30; i++) bar[i] = i < filled ? '#' : '.';
        bar[30] = 0;
        fprintf(stderr, "\r[%s] frame %d/%d  t=%.4g/%.4g s  %.0f steps/s  ", bar, p->frame, p->nframes, p->time,
                p->end_time, p->steps_per_s);
        if (frac > 0) fprintf(stderr, "ETA %02d:%02d", (int)eta / 60, (int)eta % 60);
        else fprintf(stderr, "ETA --:--");
        fputs("\033[K", stderr); /* the rest of a longer earlier line goes (it left "ETA 00:00 0") */
        if (!p->partial && p->frame == p->nframes) fputc('\n', stderr);
    } else {
        /* a log: a line per frame, and within long frames one every 10 s */
        if (p->partial && p->wall_s - ps->last_line < 10) return;
        ps->last_line = p->wall_s;
        fprintf(stderr, "%s %d/%d t=%.4f s steps=%llu %.0f steps/s fluid=%zu eta=%.0f s\n",
                p->partial ? "in frame" : "frame", p->partial ? p->frame + 1 : p->frame, p->nframes, p->time,
                (unsigned long long)p->steps, p->steps_per_s, p->n_fluid, eta);
    }
    fflush(stderr);
}

/* Render progress: on a terminal one line rewritten in place, otherwise nothing per frame (the
 * command ends with a one-line summary). */
static void show_render_progress(int done, int total, const char *path, void *user)
{
    progress_state *ps = user;
    if (ps->quiet || !ps->tty) return;
    fprintf(stderr, "\rrender: frame %d/%d  %s\033[K", done, total, path ? path : "");
    if (done == total) fputc('\n', stderr);
    fflush(stderr);
}

static void show_render_message(const char *msg, void *user)
{
    progress_state *ps = user;
    if (!ps->quiet) fprintf(stderr, "render: %s\n", msg);
}

static void show_message(const char *msg, void *user)
{
    /* the set-up's progress (src/run.c, setup_note) is news, not a warning */
    if (!strncmp(msg, "set-up: ", 8)) {
        const progress_state *ps = user;
        if (!ps || !ps->quiet) fprintf(stderr, "pfsph: %s\n", msg);
        return;
    }
    fprintf(stderr, "pfsph: warning: %s\n", msg);
}

static int cmd_run(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL, *resume = NULL;
    double end = -1;
    int threads = 0, render = 0, quiet = 0, force = 0;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (is_help(a)) {
            fputs(HELP_RUN, stdout);
            return 0;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (++i >= argc) return usage_error("%s needs a directory", a);
            out = argv[i];
        } else if (!strcmp(a, "--threads")) {
            char *e;
            if (++i >= argc) return usage_error("%s needs a number", a);
            threads = (int)strtol(argv[i], &e, 10);
            if (*e || e == argv[i] || threads < 0 || threads > 1024)
                return usage_error("--threads: '%s' is not a thread count 1..1024 (0: the default)", argv[i]);
        } else if (!strcmp(a, "--end")) {
            char *e;
            if (++i >= argc) return usage_error("%s needs a time in seconds", a);
            end = strtod(argv[i], &e);
            if (*e || e == argv[i] || !(end >= 0) || !isfinite(end))
                return usage_error("--end: '%s' is not a finite time >= 0", argv[i]);
            if (end > PFSPH_MAX_END)
                return usage_error("--end: '%s' is more than 1e6 s, the range of $.time.end", argv[i]);
        } else if (!strcmp(a, "--resume")) {
            if (++i >= argc) return usage_error("%s needs a run directory", a);
            resume = argv[i];
        } else if (!strcmp(a, "--render")) {
            render = 1;
        } else if (!strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "--force")) {
            force = 1;
        } else if (a[0] == '-') {
            return usage_error("unknown option '%s'", a);
        } else if (!scene_path) {
            scene_path = a;
        } else {
            return usage_error("unexpected argument '%s'", a);
        }
    }
    /* under mpirun the other ranks follow rank 0, which reads the scene and writes the run */
    if (pfsph_mpi_size() > 1 && pfsph_mpi_rank() > 0) return pfsph_mpi_follow(threads, exit_code);
    char resume_scene[4096];
    if (resume) {
        if (scene_path) return usage_error("--resume takes the scene from RUN_DIR/scene.json, not '%s'", scene_path);
        if (out) return usage_error("--resume writes into RUN_DIR; drop '%s'", out);
        if (force) return usage_error("%s", "--force is for a fresh run; --resume continues the run in RUN_DIR");
        if ((size_t)snprintf(resume_scene, sizeof resume_scene, "%s/scene.json", resume) >= sizeof resume_scene)
            return usage_error("--resume: path too long: '%s'", resume);
        scene_path = resume_scene;
        out = resume;
    }
    static pfsph_scene s;
    char *text = NULL;
    int rc = load_scene(scene_path, &s, &text);
    if (!rc && end >= 0 && floor(end * s.fps + 1e-9) > PFSPH_MAX_FRAMES) {
        fprintf(stderr,
                "pfsph: --end %g: at %g fps ($.time.fps of %s) that makes %.3g frames, more than the %d "
                "one run holds\n",
                end, s.fps, s.source, end * s.fps, PFSPH_MAX_FRAMES);
        rc = 2;
    }
    if (!rc) rc = check_memory(&s, 0);
    pfsph_error merr = {0};
    if (!rc && pfsph_mpi_check_scene(&s, &merr)) {
        print_error(NULL, merr.msg);
        rc = 2;
    }
    rc = pfsph_mpi_share_scene(rc, text, rc ? "" : s.source); /* one rank refuses, every rank exits */
    if (rc) {
        free(text);
        return rc;
    }
    const int mpi = pfsph_mpi_size() > 1;
    if (!scene_path) render = 1;
    if (!scene_path && !out) force = 1; /* the embedded demo into its own directory: rerunnable */
    if (threads > 0) omp_set_num_threads(threads);
    else if (s.threads > 0) omp_set_num_threads(s.threads);
    progress_state ps = {isatty(2), quiet, -1e9};
    pfsph_run_opts o = {.out_dir = out,
                        .end_time = end,
                        .scene_text = text,
                        .progress = show_progress,
                        .user = &ps,
                        .resume = resume != NULL,
                        .message = show_message,
                        .force = force,
                        .stop = mpi ? NULL : &g_stop}; /* under MPI a signal ends every rank */
    const char *dir = out ? out : s.output.dir;
    if (!quiet)
        fprintf(stderr, "pfsph %s: %s -> %s (%d threads)%s\n", PFSPH_VERSION, s.source, dir, omp_get_max_threads(),
                resume ? ", resuming" : "");
    pfsph_error err = {0};
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    struct sigaction old_int, old_term; /* a signal ignored at the start (nohup, a background job) stays so */
    sigaction(SIGINT, NULL, &old_int);
    sigaction(SIGTERM, NULL, &old_term);
    if (old_int.sa_handler != SIG_IGN && !mpi) sigaction(SIGINT, &sa, NULL);
    if (old_term.sa_handler != SIG_IGN && !mpi) sigaction(SIGTERM, &sa, NULL);
    rc = pfsph_run(&s, &o, &err);
    pfsph_mpi_end(rc);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    free(text);
    if (rc) {
        if (ps.tty && !quiet) fputc('\n', stderr);
        print_error(NULL, err.msg);
        return exit_code(rc);
    }
    if (render) {
        pfsph_render_opts ro = {0};
        ro.last = -1;
        ro.quiet = quiet;
        ro.progress = show_render_progress;
        ro.message = show_render_message;
        ro.user = &ps;
        int count = 0;
        rc = pfsph_render_run(dir, &ro, &count, &err);
        if (rc) {
            print_error("render: ", err.msg);
            return exit_code(rc);
        }
        if (!quiet) fprintf(stderr, "rendered %d frames into %s/png\n", count, dir);
    }
    if (!quiet) fprintf(stderr, "done: %s\n", dir);
    return 0;
}

static int cmd_check(int argc, char **argv)
{
    for (int i = 0; i < argc; i++)
        if (is_help(argv[i])) {
            fputs(HELP_CHECK, stdout);
            return 0;
        }
    if (argc != 1) return usage_error("%s", "check takes exactly one scene file");
    if (argv[0][0] == '-') return usage_error("unknown option '%s'", argv[0]);
    static pfsph_scene s;
    char *text = NULL;
    int rc = load_scene(argv[0], &s, &text);
    free(text);
    if (rc) return rc;
    rc = check_memory(&s, 1);
    if (rc) return rc;
    double rho_lo, rho_hi;
    if (pfsph_scene_density_range(&s, &rho_lo, &rho_hi) && rho_lo > 0 && rho_hi > rho_lo) {
        double ratio = rho_hi / rho_lo;
        printf("density ratio %.4g between fluid phases", ratio);
        const pfsph_solver_ops *ops = pfsph_solver_find(s.solver);
        char buf[256];
        const char *advice = ops && ops->ratio_advice
            ? ops->ratio_advice(ratio, s.pressure_scale == PFSPH_PRESSURE_COMMON, buf, sizeof buf)
            : NULL;
        if (advice) printf(": %s\n", advice);
        else printf("\n");
    }
    if (s.nbodies) {
        /* check_memory has read and checked the mesh files already */
        pfsph_error err = {0};
        pfsph_particles tmp;
        pfsph_bodies *B = NULL;
        if (pfsph_particles_init(&tmp, 1024) == PFSPH_OK &&
            pfsph_bodies_create(&B, &s, 2 * s.particle_radius, &tmp, &err) == PFSPH_OK) {
            static const char *const shapes[] = {"box", "sphere", "cylinder", "mesh"};
            printf("bodies: %d, %zu particles\n", s.nbodies, tmp.n);
            for (int i = 0; i < s.nbodies; i++)
                printf("  %s: %s, %s, mass %.4g kg%s\n", s.bodies[i].name, shapes[s.bodies[i].shape],
                       s.bodies[i].kinematic ? "kinematic" : "dynamic", pfsph_bodies_mass(B, i),
                       s.dim == 2 ? " per metre of depth" : "");
        }
        pfsph_bodies_destroy(B);
        pfsph_particles_free(&tmp);
    }
    if (s.nemitters) {
        pfsph_error err = {0};
        pfsph_emitter_info info[PFSPH_MAX_EMITTERS];
        if (pfsph_scene_emitters_info(&s, info, &err) == PFSPH_OK) {
            static const char *const shapes[] = {"disc", "rectangle", "segment"};
            printf("emitters: %d\n", s.nemitters);
            for (int i = 0; i < s.nemitters; i++) {
                const pfsph_emitter_params *e = &s.emitters[i];
                double m = info[i].rate * s.phases[e->phase].rest_density;
                printf("  [%d] %s of %zu sites, phase \"%s\", %.4g m/s, %.4g m^%d/s (%.4g kg/s%s, %.4g layers/s), "
                       "from %g s to ",
                       i, shapes[e->shape], info[i].sites, s.phases[e->phase].name, info[i].speed, info[i].rate, s.dim,
                       m, s.dim == 2 ? " per metre" : "", info[i].layer_rate, e->start);
                if (isfinite(e->stop)) printf("%g s\n", e->stop);
                else printf("the end\n");
            }
        }
    }
    if (s.pairwise.enabled) {
        pfsph_error err = {0};
        double d = 2 * s.particle_radius;
        rc = pfsph_pairwise_resolve(&s, (pfsph_real)d, (pfsph_real)(s.support_factor * d), &err);
        if (rc) {
            print_error(NULL, err.msg);
            return exit_code(rc);
        }
        pfsph_pairwise_report(&s, stdout);
    }
    if (s.film.nbubbles > 0) {
        /* bubbles in air: the film's start needs the surface detection, so build the simulation
         * (a liquid_volume too large for the bubble's surface is reported here, exit 2) */
        pfsph_error err = {0};
        pfsph_sim *sim = NULL;
        rc = pfsph_sim_create(&sim, &s, &err);
        if (rc) {
            print_error(NULL, err.msg);
            return exit_code(rc);
        }
        const pfsph_scene *ss = pfsph_sim_scene(sim);
        const pfsph_ctx *c = pfsph_sim_ctx(sim);
        printf("bubbles in air (docs/film.md): %d\n", ss->film.nbubbles);
        for (int k = 0; k < ss->film.nbubbles; k++) {
            long ns = 0, nall = 0;
            for (size_t i = 0; i < c->fluid->n; i++)
                if (c->fluid->bubble[i] == k + 1) nall++, ns += c->fluid->film[i] > 0;
            const int g = ss->film.gas[k];
            printf("  $.fluid[%d]: gas \"%s\", film \"%s\", %ld particles, %ld on the surface, film fraction %.4g, "
                   "liquid volume %.4g m^%d\n",
                   ss->film.block[k], ss->phases[g].name, ss->phases[ss->film.film[g]].name, nall, ns,
                   ns ? ss->film.volume[k] / ((double)ns * (double)c->V0) : 0.0, ss->film.volume[k], ss->dim);
        }
        pfsph_sim_destroy(sim);
    }
    /* the verdict last, once every check has passed */
    printf("%s: valid %dD scene, solver %s, %d phases, %d fluid blocks, %d solids", s.source, s.dim,
           pfsph_scene_solver_name(&s), s.nphases, s.nblocks, s.nsolids);
    if (s.nemitters) printf(", %d emitter%s", s.nemitters, s.nemitters > 1 ? "s" : "");
    printf("\n");
    return 0;
}

static int cmd_render(int argc, char **argv)
{
    const char *dir = NULL;
    pfsph_render_opts o = {0};
    o.last = -1;
    progress_state ps = {isatty(2), 0, -1e9};
    o.progress = show_render_progress;
    o.message = show_render_message;
    o.user = &ps;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (is_help(a)) {
            fputs(HELP_RENDER, stdout);
            return 0;
        } else if (!strcmp(a, "--video")) o.video = true;
        else if (!strcmp(a, "--particles")) o.particles = true;
        else if (!strcmp(a, "--all-walls")) o.all_walls = true;
        else if (!strcmp(a, "--no-legend")) o.no_legend = true;
        else if (!strcmp(a, "--color-by")) {
            if (++i >= argc) return usage_error("%s needs a field", a);
            o.color_by = argv[i];
        } else if (!strcmp(a, "--size")) {
            if (++i >= argc || sscanf(argv[i], "%dx%d", &o.width, &o.height) != 2 || o.width < 16 || o.height < 16 ||
                o.width > 16384 || o.height > 16384)
                return usage_error("--size: '%s' is not WxH (16..16384)", i < argc ? argv[i] : "");
        } else if (a[0] == '-') return usage_error("unknown option '%s'", a);
        else if (!dir) dir = a;
        else return usage_error("unexpected argument '%s'", a);
    }
    if (!dir) return usage_error("%s", "render needs a run directory");
    pfsph_error err = {0};
    int count = 0;
    int rc = pfsph_render_run(dir, &o, &count, &err);
    if (rc) {
        print_error(NULL, err.msg);
        return exit_code(rc);
    }
    printf("rendered %d frames into %s/png\n", count, dir);
    return 0;
}

static int cmd_export(int argc, char **argv)
{
    const char *dir = NULL;
    bool houdini = false;
    int format = PFSPH_HOUDINI_BGEO;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (is_help(a)) {
            fputs(HELP_EXPORT, stdout);
            return 0;
        } else if (!strcmp(a, "--houdini")) houdini = true;
        else if (!strcmp(a, "--ascii")) format = PFSPH_HOUDINI_JSON;
        else if (!strcmp(a, "--classic")) format = PFSPH_HOUDINI_CLASSIC;
        else if (a[0] == '-') return usage_error("unknown option '%s'", a);
        else if (!dir) dir = a;
        else return usage_error("unexpected argument '%s'", a);
    }
    if (!dir) return usage_error("%s", "export needs a run directory");
    if (!houdini) return usage_error("%s", "export needs a format: --houdini");
    pfsph_error err = {0};
    pfsph_houdini_report r;
    int rc = pfsph_export_houdini(dir, format, &r, &err);
    if (rc) {
        print_error(NULL, err.msg);
        return exit_code(rc);
    }
    const char *ext = format == PFSPH_HOUDINI_BGEO ? "bgeo" : "geo";
    printf("exported %d frames into %s/frames/fluid_NNNNN.%s", r.frames, dir, ext);
    if (r.diffuse) printf(", %d diffuse_NNNNN", r.diffuse);
    if (r.liquid) printf(", %d liquid_NNNNN", r.liquid);
    if (r.bodies) printf(", %d bodies_NNNNN", r.bodies);
    if (r.solids) printf(", %d solids in %s/solids.%s", r.solids, dir, ext);
    printf("\n");
    if (r.no_ids)
        fprintf(stderr,
                "pfsph: note: the frames carry no particle ids, so the points have no `id` and keep the "
                "frames' order, which changes from frame to frame; run with \"output\": {\"fields\": "
                "[\"id\"]} for stable ids (docs/artists.md#houdini)\n");
    return 0;
}

static int cmd_mesh(int argc, char **argv)
{
    const char *dir = NULL;
    pfsph_surface_output so = {.on = true};
    bool set = false;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (is_help(a)) {
            fputs(HELP_MESH, stdout);
            return 0;
        } else if (!strcmp(a, "--formats")) {
            if (++i >= argc) return usage_error("%s needs a list", a);
            so.ply = strstr(argv[i], "ply") != NULL;
            so.obj = strstr(argv[i], "obj") != NULL;
            so.vtp = strstr(argv[i], "vtp") != NULL;
            so.vdb = strstr(argv[i], "vdb") != NULL;
            char tmp[256];
            snprintf(tmp, sizeof tmp, "%s", argv[i]);
            for (char *t = strtok(tmp, ","); t; t = strtok(NULL, ","))
                if (strcmp(t, "ply") && strcmp(t, "obj") && strcmp(t, "vtp") && strcmp(t, "vdb"))
                    return usage_error("--formats: unknown format '%s' (ply, obj, vtp, vdb)", t);
            if (so.vdb && !pfsph_vdb_available())
                return usage_error("%s",
                                   "--formats vdb: this build of pfsph has no OpenVDB (Debian: libopenvdb-dev, "
                                   "then rebuild; docs/artists.md#openvdb-level-sets-houdini-blender)");
            set = true;
        } else if (!strcmp(a, "--smooth")) {
            char *end = NULL;
            long v = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : -1;
            if (i + 1 >= argc || *end || v < 0 || v > 100)
                return usage_error("--smooth: '%s' is not 0..100", i + 1 < argc ? argv[i + 1] : "");
            so.smoothing = (int)v;
            i++;
            set = true;
        } else if (!strcmp(a, "--droplet")) {
            char *end = NULL;
            double v = i + 1 < argc ? strtod(argv[i + 1], &end) : -2;
            if (i + 1 >= argc || *end || !(v == -1 || (v >= 0 && v <= 2)))
                return usage_error("--droplet: '%s' is not -1 or 0..2", i + 1 < argc ? argv[i + 1] : "");
            so.droplet = v;
            i++;
            set = true;
        } else if (!strcmp(a, "--isotropic")) so.isotropic = set = true;
        else if (!strcmp(a, "--threads")) {
            char *end = NULL;
            long v = i + 1 < argc ? strtol(argv[i + 1], &end, 10) : -1;
            if (i + 1 >= argc || *end || v < 1 || v > 1024)
                return usage_error("--threads: '%s' is not 1..1024", i + 1 < argc ? argv[i + 1] : "");
            omp_set_num_threads((int)v);
            i++;
        } else if (a[0] == '-') return usage_error("unknown option '%s'", a);
        else if (!dir) dir = a;
        else return usage_error("unexpected argument '%s'", a);
    }
    if (!dir) return usage_error("%s", "mesh needs a run directory");
    pfsph_error err = {0};
    int count = 0;
    int rc = pfsph_mesh_run(dir, set ? &so : NULL, &count, &err);
    if (rc) {
        print_error(NULL, err.msg);
        return exit_code(rc);
    }
    printf("meshed %d frames into %s/frames/liquid_NNNNN.*\n", count, dir);
    return 0;
}

/* `pfsph view` (src/view/) exists only in builds that found GLFW and libepoxy. */
static int cmd_view(int argc, char **argv)
{
#ifdef PFSPH_HAVE_VIEWER
    return pfsph_view_main(argc, argv);
#else
    (void)argc;
    (void)argv;
    fprintf(stderr,
            "pfsph: view: this build has no viewer (it needs GLFW 3 and libepoxy at build time: Debian "
            "libglfw3-dev libepoxy-dev, then cmake -DPFSPH_VIEWER=ON); `pfsph render` makes PNG previews\n");
    return 2;
#endif
}

int main(int argc, char **argv)
{
    pfsph_omp_wait_default(argv); /* a spin count that does not collapse under load */
    if (argc < 2) {
        fputs(USAGE, stderr);
        return 2;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "run")) pfsph_mpi_start(&argc, &argv); /* a no-op without -DPFSPH_MPI=ON */
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
        printf("pfsph %s (%s precision, OpenMP %d threads)\n", PFSPH_VERSION, PFSPH_REAL_NAME, omp_get_max_threads());
        return 0;
    }
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        const char *topic = argc > 2 ? argv[2] : NULL;
        if (!topic) fputs(HELP, stdout), fputs("\n", stdout), fputs(USAGE, stdout);
        else if (!strcmp(topic, "run")) fputs(HELP_RUN, stdout);
        else if (!strcmp(topic, "check")) fputs(HELP_CHECK, stdout);
        else if (!strcmp(topic, "render")) fputs(HELP_RENDER, stdout);
        else if (!strcmp(topic, "mesh")) fputs(HELP_MESH, stdout);
        else if (!strcmp(topic, "export")) fputs(HELP_EXPORT, stdout);
        else if (!strcmp(topic, "view")) {
            char h[] = "--help";
            char *v[] = {h, NULL};
            return cmd_view(1, v);
        } else return usage_error("help: unknown command '%s'", topic);
        return 0;
    }
    if (!strcmp(cmd, "run")) return cmd_run(argc - 2, argv + 2);
    if (!strcmp(cmd, "check")) return cmd_check(argc - 2, argv + 2);
    if (!strcmp(cmd, "render")) return cmd_render(argc - 2, argv + 2);
    if (!strcmp(cmd, "mesh")) return cmd_mesh(argc - 2, argv + 2);
    if (!strcmp(cmd, "export")) return cmd_export(argc - 2, argv + 2);
    if (!strcmp(cmd, "view")) return cmd_view(argc - 2, argv + 2);
    return usage_error("unknown command '%s'", cmd);
}
