/* The run driver: a scene in, a run directory out (frames, stats.csv, summary.json). */
#include "pfsph/run.h"

#include "pfsph/bodies.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/io_internal.h"
#include "pfsph/checkpoint.h"
#include "pfsph/dist.h"
#include "pfsph/io.h"
#include "pfsph/sim.h"
#include "pfsph/thermostat.h"
#include "run_control.h"

/* ---- the run directory: lock, what is pfsph's, temporaries, the run's own end ---- */

#define LOCK_NAME ".pfsph.lock"
#define RUN_JSON "run.json"

/* Take an exclusive flock on RUN/.pfsph.lock (kept open until run_unlock) and write our pid
 * and start time into it; PFSPH_EINPUT naming the holder when another process has it. */
static int run_lock(const char *dir, int *fd_out, pfsph_error *err)
{
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/" LOCK_NAME, dir);
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) return pfsph_fail(err, PFSPH_EINPUT, "cannot write into it: %s", strerror(errno));
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        int e = errno;
        char who[128] = "";
        ssize_t n = pread(fd, who, sizeof who - 1, 0);
        close(fd);
        if (e != EWOULDBLOCK) return pfsph_fail(err, PFSPH_EIO, "%s: cannot lock: %s", path, strerror(e));
        who[n > 0 ? n : 0] = 0;
        char *nl = strchr(who, '\n');
        if (nl) *nl = 0;
        return pfsph_fail(err, PFSPH_EINPUT,
                          "in use by another pfsph run (%s); wait for it to end or choose "
                          "another directory",
                          who[0] ? who : "holder unknown");
    }
    char who[128];
    time_t now = time(NULL);
    struct tm tm;
    char when[32] = "?";
    if (localtime_r(&now, &tm)) strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", &tm);
    int n = snprintf(who, sizeof who, "pid %ld, started %s\n", (long)getpid(), when);
    if (ftruncate(fd, 0) != 0 || pwrite(fd, who, (size_t)n, 0) != n) {
        /* the lock holds; only the holder's description is missing */
    }
    *fd_out = fd;
    return PFSPH_OK;
}

static void run_unlock(int fd)
{
    if (fd >= 0) close(fd); /* releases the flock; the file stays (removing it would race) */
}

/* "<prefix><digits>.<ext>" with prefix one of the frame sets; *num receives the digits. */
static int frame_file(const char *name, long *num)
{
    static const char *const sets[] = {"fluid_",    "boundary_", "diffuse_", "bodies_",
                                       "surfaces_", "liquid_",   "frame_",   NULL};
    for (int k = 0; sets[k]; k++) {
        size_t l = strlen(sets[k]);
        if (strncmp(name, sets[k], l) != 0) continue;
        const char *p = name + l;
        long v = 0;
        int digits = 0;
        while (*p >= '0' && *p <= '9' && digits < 10) v = v * 10 + (*p++ - '0'), digits++;
        if (!digits) return 0;
        if (*p == '_' && p[1] >= '0' && p[1] <= '9') { /* a piece: "fluid_NNNNN_QQQQ.vtp" */
            const char *q = p + 1;
            while (*q >= '0' && *q <= '9') q++;
            if (!strcmp(q, ".vtp")) {
                *num = v;
                return 1;
            }
            return 0;
        }
        if (!strcmp(p, ".vtp") || !strcmp(p, ".pvtp") || !strcmp(p, ".ply") || !strcmp(p, ".png") ||
            !strcmp(p, ".obj") || !strcmp(p, ".geo") || !strcmp(p, ".bgeo") || !strcmp(p, ".vdb")) {
            *num = v;
            return 1;
        }
        return 0;
    }
    return 0;
}

/* A temporary of the atomic writer: "<name>.tmp.<pid>" (or "frames.tmp.<pid>.mp4"). */
static int is_temporary(const char *name)
{
    const char *t = strstr(name, ".tmp.");
    if (!t || t == name) return 0;
    t += 5;
    if (*t < '0' || *t > '9') return 0;
    while (*t >= '0' && *t <= '9') t++;
    return *t == 0 || !strcmp(t, ".mp4");
}

/* Files pfsph writes at the top of a run directory. */
static int is_run_file(const char *name)
{
    static const char *const names[] = {"scene.json", "summary.json",       "stats.csv",  "bodies.csv",
                                        RUN_JSON,     "diffuse_counts.png", "frames.mp4", "solids.ply",
                                        "solids.obj", "solids.bgeo",        "solids.geo", NULL};
    for (int k = 0; names[k]; k++)
        if (!strcmp(name, names[k])) return 1;
    size_t len = strlen(name); /* the .pvd collections (io/meshing.c) */
    if (len > 4 && !strcmp(name + len - 4, ".pvd")) return 1;
    return is_temporary(name);
}

/* What to remove from a run directory: every file of pfsph (clear), or only temporaries and
 * the output files of frames after `after_frame` (a resume). */
typedef struct sweep {
    int clear;
    long after; /* output frame index; frames above it go (resume) */
    int errors; /* unlink failures */
    int err_no;
    char failed[PFSPH_PATH_LEN + 64];
} sweep;

static void sweep_dir(const char *dir, const char *sub, sweep *sw)
{
    char path[2 * PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/%s", dir, sub);
    DIR *d = opendir(path);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d))) {
        const char *n = e->d_name;
        long num;
        int go;
        if (!strcmp(sub, "checkpoints"))
            go = is_temporary(n) || (sw->clear && !strncmp(n, "ckpt_", 5) && strstr(n, ".bin"));
        else go = is_temporary(n) || (frame_file(n, &num) && (sw->clear || num > sw->after));
        if (!go) continue;
        snprintf(path, sizeof path, "%s/%s/%s", dir, sub, n);
        if (unlink(path) != 0 && errno != ENOENT && !sw->errors++) {
            sw->err_no = errno;
            snprintf(sw->failed, sizeof sw->failed, "%s", path);
        }
    }
    closedir(d);
}

static int sweep_run(const char *dir, sweep *sw, pfsph_error *err)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char path[PFSPH_PATH_LEN + 300];
        while ((e = readdir(d))) {
            if (!(sw->clear ? is_run_file(e->d_name) : is_temporary(e->d_name))) continue;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            if (unlink(path) != 0 && errno != ENOENT && !sw->errors++) {
                sw->err_no = errno;
                snprintf(sw->failed, sizeof sw->failed, "%s", path);
            }
        }
        closedir(d);
    }
    sweep_dir(dir, "frames", sw);
    sweep_dir(dir, "checkpoints", sw);
    sweep_dir(dir, "png", sw);
    if (sw->errors) return pfsph_fail(err, PFSPH_EIO, "%s: cannot remove: %s", sw->failed, strerror(sw->err_no));
    return PFSPH_OK;
}

/* Entries of a directory other than ".", ".." and the lock, up to `cap` names listed in buf. */
static int dir_entries(const char *dir, char *buf, size_t cap)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    int n = 0;
    size_t len = 0;
    buf[0] = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") || !strcmp(e->d_name, LOCK_NAME)) continue;
        if (n < 4 && len + strlen(e->d_name) + 4 < cap)
            len += (size_t)snprintf(buf + len, cap - len, "%s%s", n ? ", " : "", e->d_name);
        n++;
    }
    closedir(d);
    if (n > 4 && len + 6 < cap) snprintf(buf + len, cap - len, ", ...");
    return n;
}

/* RUN/run.json: what the run itself was asked for (the end time), so that a resume without
 * an end time continues to the same end; and the frame interval its files are numbered by,
 * which a resume must keep (docs/checkpoints.md). */
static int write_run_json(const char *dir, double end, double fps, int frame_interval, pfsph_error *err)
{
    char text[256], path[PFSPH_PATH_LEN + 64];
    snprintf(text, sizeof text, "{\n\t\"end_time\":\t%.17g,\n\t\"fps\":\t%.17g,\n\t\"frame_interval\":\t%d\n}\n", end,
             fps, frame_interval);
    snprintf(path, sizeof path, "%s/" RUN_JSON, dir);
    return pfsph_write_file_atomic(path, text, strlen(text), err);
}

/* The end time recorded in RUN/run.json (end NULL: not wanted) and its frame interval (*fi
 * 0 when it has none: written before it was recorded); *end unchanged (and PFSPH_OK) when
 * there is no file. */
static int read_run_json(const char *dir, double *end, int *fi, pfsph_error *err)
{
    *fi = 0;
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/" RUN_JSON, dir);
    unsigned char *data;
    size_t len;
    FILE *f = fopen(path, "rb");
    if (!f)
        return errno == ENOENT ? PFSPH_OK : pfsph_fail(err, PFSPH_EIO, "%s: cannot read: %s", path, strerror(errno));
    fclose(f);
    int rc = pfsph__read_file(path, &data, &len, err);
    if (rc) return rc;
    cJSON *j = cJSON_ParseWithLength((const char *)data, len);
    free(data);
    const cJSON *fj = cJSON_GetObjectItemCaseSensitive(j, "frame_interval");
    if (cJSON_IsNumber(fj) && fj->valuedouble >= 1 && fj->valuedouble <= 1e6) *fi = (int)fj->valuedouble;
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(j, "end_time");
    if (!end) {
        cJSON_Delete(j);
        return PFSPH_OK;
    }
    if (!cJSON_IsNumber(e) || !(e->valuedouble >= 0) || !isfinite(e->valuedouble)) {
        cJSON_Delete(j);
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: $.end_time: missing or not a time >= 0 (the file is pfsph's; "
                          "give --end to resume)",
                          path);
    }
    *end = e->valuedouble;
    cJSON_Delete(j);
    return PFSPH_OK;
}

/* The set-up's slow phases (a second or more: a scene of millions of particles) as messages, so
 * that minutes of set-up show what they do. */
static void setup_note(const char *done, double wall_s, double cpu_s, void *user)
{
    const pfsph_run_opts *o = user;
    if (!o || !o->progress || !o->message || wall_s < 1.0) return;
    char msg[320];
    snprintf(msg, sizeof msg, "set-up: %s (%.1f s, CPU %.1f s)", done, wall_s, cpu_s);
    o->message(msg, o->user);
}

static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void bodies_rows(FILE *f, int frame, const pfsph_sim *sim)
{
    const pfsph_bodies *B = pfsph_sim_bodies(sim);
    for (int i = 0; i < pfsph_bodies_count(B); i++) {
        pfsph_body_state st;
        double F[3], T[3];
        pfsph_bodies_get_state(B, i, &st);
        pfsph_bodies_last_force(B, i, F, T);
        fprintf(f, "%d,%.9g,%d,%s", frame, pfsph_sim_time(sim), i, pfsph_bodies_name(B, i));
        for (int a = 0; a < 3; a++) fprintf(f, ",%.9g", st.x[a]);
        for (int a = 0; a < 4; a++) fprintf(f, ",%.9g", st.q[a]);
        for (int a = 0; a < 3; a++) fprintf(f, ",%.9g", st.v[a]);
        for (int a = 0; a < 3; a++) fprintf(f, ",%.9g", st.w[a]);
        for (int a = 0; a < 3; a++) fprintf(f, ",%.9g", F[a]);
        for (int a = 0; a < 3; a++) fprintf(f, ",%.9g", T[a]);
        fputc('\n', f);
    }
    fflush(f);
}

/* The fluid's particle count: a distributed run's root may hold only its slice. */
static size_t fluid_count(const pfsph_sim *sim)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    return c->dist && !c->dist->fluid_whole ? c->dist->nglobal : c->fluid->n;
}

static void csv_row(FILE *f, int frame, const pfsph_sim *sim)
{
    const pfsph_step_stats *st = pfsph_sim_stats(sim);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    fprintf(f, "%d,%.9g,%.6g,%llu,%zu,%zu,%.6g,%.6g,%.6g,%.9g,%d", frame, pfsph_sim_time(sim), st->dt,
            (unsigned long long)pfsph_sim_steps(sim), fluid_count(sim), pfsph_sim_removed(sim), st->vmax,
            st->density_err_avg, st->density_err_max, st->ekin, st->iterations);
    if (c->diffuse->enabled) {
        size_t cnt[3];
        pfsph_sim_diffuse_counts(sim, cnt);
        fprintf(f, ",%zu,%zu,%zu", cnt[0], cnt[1], cnt[2]);
    }
    if (pfsph_thermostat_kT(c) > 0) /* kinetic temperature of the fluid and the one set */
        fprintf(f, ",%.6g,%.6g",
                c->dist && !c->dist->fluid_whole ? c->dist->kT_frame
                                                 : pfsph_thermostat_measure(c->fluid, c->mass, c->dim),
                pfsph_thermostat_kT(c));
    fputc('\n', f);
    fflush(f);
}

typedef struct run_info {
    int resumed_from; /* checkpoint frame, -1: fresh run */
    int ckpt_frame;   /* last checkpoint written by this process, -1: none */
    size_t ckpt_bytes;
    double ckpt_s; /* seconds to encode and write it */
} run_info;

static int write_summary(const char *dir, const pfsph_scene *s, const pfsph_sim *sim, int frames, double wall,
                         const char *status, const char *message, const run_info *info, pfsph_error *err)
{
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "program", "pfsph");
    cJSON_AddStringToObject(j, "version", PFSPH_VERSION);
    cJSON_AddStringToObject(j, "precision", PFSPH_REAL_NAME);
    cJSON_AddStringToObject(j, "scene", s->source);
    cJSON_AddStringToObject(j, "status", status);
    if (message) cJSON_AddStringToObject(j, "message", message);
    cJSON_AddNumberToObject(j, "threads", omp_get_max_threads());
    cJSON_AddNumberToObject(j, "dimension", s->dim);
    cJSON_AddStringToObject(j, "solver", pfsph_scene_solver_name(s));
    if (sim) {
        const pfsph_ctx *c = pfsph_sim_ctx(sim);
        cJSON *n = cJSON_AddObjectToObject(j, "particles");
        cJSON_AddNumberToObject(n, "fluid", (double)fluid_count(sim));
        cJSON_AddNumberToObject(n, "boundary", (double)c->boundary->n);
        cJSON_AddNumberToObject(n, "removed", (double)pfsph_sim_removed(sim));
        const pfsph_particles *d = pfsph_sim_diffuse(sim);
        if (d) {
            uint64_t created;
            pfsph_sim_diffuse_totals(sim, &created, NULL);
            cJSON_AddNumberToObject(n, "diffuse", (double)d->n);
            cJSON_AddNumberToObject(n, "diffuse_created", (double)created); /* created - live: the deaths */
        }
        cJSON_AddNumberToObject(j, "simulated_time", pfsph_sim_time(sim));
        cJSON_AddNumberToObject(j, "steps", (double)pfsph_sim_steps(sim));
        cJSON *st = cJSON_AddObjectToObject(j, "stage_seconds");
        const double *ss = pfsph_sim_stage_seconds(sim);
        for (int k = 0; k < PFSPH_NSTAGES; k++) cJSON_AddNumberToObject(st, pfsph_stage_names[k], ss[k]);
        if (c->dist && c->dist->report) c->dist->report(c->dist, j); /* per-rank figures under MPI */
    }
    cJSON_AddNumberToObject(j, "frames", frames);
    if (info->resumed_from >= 0) cJSON_AddNumberToObject(j, "resumed_from_frame", info->resumed_from);
    if (info->ckpt_frame >= 0) {
        cJSON *ck = cJSON_AddObjectToObject(j, "last_checkpoint");
        cJSON_AddNumberToObject(ck, "frame", info->ckpt_frame);
        cJSON_AddNumberToObject(ck, "bytes", (double)info->ckpt_bytes);
        cJSON_AddNumberToObject(ck, "seconds", info->ckpt_s);
    }
    cJSON_AddNumberToObject(j, "wall_seconds", wall);
    char *text = cJSON_Print(j);
    cJSON_Delete(j);
    if (!text) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
    char path[PFSPH_PATH_LEN + 64];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    int rc = pfsph_write_file_atomic(path, text, strlen(text), err);
    free(text);
    return rc;
}

/* Keep the header and the rows of frames <= last of stats.csv (a resume rewrites the rest);
 * atomic. A missing file gets the header only. *kept: the frame of the last row kept, -1 for
 * none. */
static int truncate_csv(const char *path, const char *header, int last, long *kept, pfsph_error *err)
{
    FILE *f = fopen(path, "rb");
    char *out = NULL;
    size_t len = 0, cap = 0;
    int rc = PFSPH_OK;
    *kept = -1;
    if (!f) {
        if (errno != ENOENT) return pfsph_fail(err, PFSPH_EIO, "%s: cannot read: %s", path, strerror(errno));
        return pfsph_write_file_atomic(path, header, strlen(header), err);
    }
    char line[4096];
    int first = 1;
    while (fgets(line, sizeof line, f)) {
        size_t n = strlen(line);
        if (n == 0 || line[n - 1] != '\n') break; /* a row cut short by a kill: drop it and the rest */
        int keep = first;
        if (!first) {
            char *e;
            long fr = strtol(line, &e, 10);
            keep = e != line && *e == ',' && fr >= 0 && fr <= last;
            if (!keep) break; /* rows are in frame order */
            *kept = fr;
        }
        first = 0;
        if (len + n + 1 > cap) {
            cap = (len + n + 1) * 2;
            char *q = realloc(out, cap);
            if (!q) {
                rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory");
                break;
            }
            out = q;
        }
        memcpy(out + len, line, n);
        len += n;
    }
    fclose(f);
    if (!rc) {
        if (len == 0) rc = pfsph_write_file_atomic(path, header, strlen(header), err);
        else rc = pfsph_write_file_atomic(path, out, len, err);
    }
    free(out);
    return rc;
}

/* the frame count fits an int (and the file names) */
static int check_end(const pfsph_scene *s, double end, pfsph_error *err)
{
    /* at most the range of $.time.end: with a tiny fps the frame count alone let `--end 2e300`
     * through, a run that never ended (the attack of issue 33, repeated) */
    if (isfinite(end) && end > PFSPH_MAX_END)
        return pfsph_fail(err, PFSPH_EINPUT, "%s: end time %g s: more than %g s, the range of $.time.end", s->source,
                          end, PFSPH_MAX_END);
    if (!isfinite(end) || !(end >= 0) || floor(end * s->fps + 1e-9) > PFSPH_MAX_FRAMES)
        return pfsph_fail(err, PFSPH_EINPUT,
                          "%s: end time %g s at %g fps ($.time.fps) makes %.3g frames, more "
                          "than the %d one run holds",
                          s->source, end, s->fps, end * s->fps, PFSPH_MAX_FRAMES);
    return PFSPH_OK;
}

static int run_locked(const pfsph_scene *s, const pfsph_run_opts *o, const char *dir, double w0, pfsph_error *err);

int pfsph_run(const pfsph_scene *s, const pfsph_run_opts *o, pfsph_error *err)
{
    const char *dir = o && o->out_dir ? o->out_dir : s->output.dir;
    const bool resume = o && o->resume;
    const char *what = resume ? "run directory" : o && o->out_dir ? "output directory" : "$.output.directory";
    double w0 = omp_get_wtime();
    int rc;
    /* refused before anything is written */
    if (o && o->end_time >= 0 &&
        ((rc = check_end(s, o->end_time, err)) || (rc = pfsph__run_end_on_frame(s, o->end_time, err))))
        return rc;
    if (!(o && o->end_time >= 0) && (rc = check_end(s, s->end_time, err))) return rc;
    /* a directory that cannot be made or written is bad input (exit status 2), as is one that
     * another run holds */
    pfsph_error e;
    if (pfsph_mkdirs(dir, &e)) return pfsph_fail(err, PFSPH_EINPUT, "%s: %s \"%s\": %s", s->source, what, dir, e.msg);
    int lock = -1;
    if ((rc = run_lock(dir, &lock, &e))) {
        pfsph_fail(err, rc, "%s: %s \"%s\": %s", s->source, what, dir, e.msg);
        return rc;
    }
    rc = run_locked(s, o, dir, w0, err);
    run_unlock(lock);
    return rc;
}

static int run_locked(const pfsph_scene *s, const pfsph_run_opts *o, const char *dir, double w0, pfsph_error *err)
{
    double end = o && o->end_time >= 0 ? o->end_time : s->end_time;
    char path[PFSPH_PATH_LEN + 64];
    int rc;
    bool resume = o && o->resume;
    if (resume) {
        /* the run's own end, which may have been given on its command line */
        int run_fi = 0;
        if ((rc = read_run_json(dir, o->end_time < 0 ? &end : NULL, &run_fi, err)) || (rc = check_end(s, end, err)))
            return rc;
        /* the files on disk are numbered frame / frame_interval and the .pvd collections give
         * them index * frame_interval / fps: another interval would relabel them (issue 33) */
        if (run_fi && run_fi != s->output.frame_interval)
            return pfsph_fail(err, PFSPH_EINPUT,
                              "%s: $.output.frame_interval: %d, but the run's frames were written every %d frames "
                              "(%s/" RUN_JSON "): a resume keeps the interval its files are numbered by; set it "
                              "back to %d, or run afresh with --force",
                              s->source, s->output.frame_interval, run_fi, dir, run_fi);
    }
    if (!resume) {
        char names[256];
        int n = dir_entries(dir, names, sizeof names);
        if (n && !(o && o->force))
            return pfsph_fail(err, PFSPH_EINPUT,
                              "%s: the run directory is not empty (%s): a fresh run does not "
                              "mix with what is there; continue it with --resume, or give --force to remove "
                              "pfsph's files from it first",
                              dir, names);
        sweep sw = {.clear = 1, .after = -1};
        if (n && (rc = sweep_run(dir, &sw, err))) return rc;
    }
    snprintf(path, sizeof path, "%s/frames", dir);
    if ((rc = pfsph_mkdirs(path, err))) return rc;
    if (o && o->scene_text && !(o->resume)) {
        snprintf(path, sizeof path, "%s/scene.json", dir);
        if ((rc = pfsph_write_file_atomic(path, o->scene_text, strlen(o->scene_text), err))) return rc;
    }
    if ((!resume || o->end_time >= 0) && (rc = write_run_json(dir, end, s->fps, s->output.frame_interval, err)))
        return rc;
    pfsph_sim *sim = NULL;
    if ((rc = pfsph_sim_create_ex(&sim, s, setup_note, (void *)o, err))) return rc;

    int frame0 = 0;
    int nframes = (int)floor(end * s->fps + 1e-9);
    const int fi = s->output.frame_interval, ci = s->output.checkpoint_interval;
    if (resume) {
        pfsph_checkpoint_info cki;
        rc = pfsph_checkpoint_resume(dir, sim, &cki, o->message, o->user, err);
        frame0 = cki.frame;
        if (!rc && frame0 > nframes)
            rc = pfsph_fail(err, PFSPH_EINPUT,
                            "%s: the end time %g s (frame %d) is before the newest checkpoint "
                            "(frame %d, t = %g s): nothing to resume; give a later --end, or run afresh with --force",
                            dir, end, nframes, frame0, cki.time);
        if (!rc) {
            /* temporaries of a killed writer go, and so do the frames after the checkpoint:
             * they are written again, and ones beyond a shorter end would outlive their rows */
            sweep sw = {.clear = 0, .after = frame0 >= 0 ? frame0 / fi : -1};
            rc = sweep_run(dir, &sw, err);
        }
        if (!rc && frame0 >= 0 && cki.threads != omp_get_max_threads() && o->message) {
            char msg[256];
            snprintf(msg, sizeof msg,
                     "the checkpoint of frame %d was written with %d threads, this run has %d: "
                     "frames will not be bit-identical to an uninterrupted run (use --threads %d)",
                     frame0, cki.threads, omp_get_max_threads(), cki.threads);
            o->message(msg, o->user);
        }
        if (!rc && frame0 < 0) {
            /* killed before its first checkpoint: start again */
            if (o->message) {
                char msg[PFSPH_PATH_LEN + 128];
                snprintf(msg, sizeof msg, "%s/checkpoints: no checkpoint yet; starting again from frame 0", dir);
                o->message(msg, o->user);
            }
            resume = false;
            frame0 = 0;
        }
    } else {
        rc = pfsph_checkpoint_clear(dir, err);
    }
    if (rc) {
        pfsph_sim_destroy(sim);
        return rc;
    }

    char header[256];
    snprintf(header, sizeof header,
             "frame,time,dt,steps,n_fluid,removed,vmax,density_err_avg,density_err_max,ekin,iterations%s%s\n",
             s->diffuse.enabled ? ",n_spray,n_foam,n_bubble" : "",
             pfsph_thermostat_kT(pfsph_sim_ctx(sim)) > 0 ? ",kT,kT_set" : "");
    char csv_path[PFSPH_PATH_LEN + 64], bcsv_path[PFSPH_PATH_LEN + 64];
    snprintf(csv_path, sizeof csv_path, "%s/stats.csv", dir);
    snprintf(bcsv_path, sizeof bcsv_path, "%s/bodies.csv", dir);
    snprintf(path, sizeof path, "%s/stats.csv", dir);
    long kept = -1;
    if (resume && (rc = truncate_csv(path, header, frame0, &kept, err))) {
        pfsph_sim_destroy(sim);
        return rc;
    }
    if (resume && kept < frame0 && o->message) {
        char msg[PFSPH_PATH_LEN + 256];
        snprintf(msg, sizeof msg,
                 "%s: the rows of frames %ld..%d are missing (the file was deleted or cut); "
                 "the resumed rows follow without them (a fresh run with --force rewrites them all)",
                 path, kept + 1, frame0);
        o->message(msg, o->user);
    }
    FILE *csv = fopen(path, resume ? "a" : "w");
    if (!csv) {
        pfsph_fail(err, PFSPH_EIO, "%s: cannot write: %s", path, strerror(errno));
        pfsph_sim_destroy(sim);
        return PFSPH_EIO;
    }
    static const char bheader[] = "frame,time,body,name,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,fx,fy,fz,tx,ty,tz\n";
    FILE *bcsv = NULL;
    if (pfsph_sim_bodies(sim)) {
        snprintf(path, sizeof path, "%s/bodies.csv", dir);
        if (resume && (rc = truncate_csv(path, bheader, frame0, &kept, err))) {
            fclose(csv);
            pfsph_sim_destroy(sim);
            return rc;
        }
        if (resume && kept < frame0 && o->message) {
            char msg[PFSPH_PATH_LEN + 256];
            snprintf(msg, sizeof msg,
                     "%s: the rows of frames %ld..%d are missing (the file was deleted or cut); "
                     "the resumed rows follow without them",
                     path, kept + 1, frame0);
            o->message(msg, o->user);
        }
        bcsv = fopen(path, resume ? "a" : "w");
        if (!bcsv) {
            pfsph_fail(err, PFSPH_EIO, "%s: cannot write: %s", path, strerror(errno));
            fclose(csv);
            pfsph_sim_destroy(sim);
            return PFSPH_EIO;
        }
        if (!resume) fputs(bheader, bcsv);
    }
    int frame = frame0, written = 0;
    if (!resume) {
        fputs(header, csv);
        double t0 = omp_get_wtime(), c0 = cpu_s();
        pfsph_sim_prime_output(sim);
        setup_note("sorted the fluid, its densities and pressures", omp_get_wtime() - t0, cpu_s() - c0, (void *)o);
        t0 = omp_get_wtime(), c0 = cpu_s();
        rc = pfsph__run_frame_files(s, dir, 0, sim, err);
        setup_note("wrote frame 0", omp_get_wtime() - t0, cpu_s() - c0, (void *)o);
        if (!rc) written++;
        csv_row(csv, 0, sim);
        if (bcsv) bodies_rows(bcsv, 0, sim);
        if (!rc) rc = pfsph__csv_flushed(csv, csv_path, err);
        if (!rc && bcsv) rc = pfsph__csv_flushed(bcsv, bcsv_path, err);
    } else {
        written = frame0 / fi + 1; /* on disk from before */
    }
    int ckpt_frame = -1;
    size_t ckpt_bytes = 0;
    double ckpt_s = 0;
    /* The state at the last finished frame, stashed in the run folder so that a blow-up can
     * leave it behind as a checkpoint. On disk rather than in memory (46 bytes per fluid particle,
     * which took a 493k run from 112 to 135 bytes per particle), and without fsync: it is written
     * every frame and needed only by this process. */
    char stash[PFSPH_PATH_LEN + 64];
    snprintf(stash, sizeof stash, "%s/.last_good.bin", dir);
    int good = 0;
    int good_frame = frame0;
    if (!rc && (rc = pfsph_checkpoint_stash(stash, sim, frame0, err)) == PFSPH_OK) good = 1;
    const double time0 = pfsph_sim_time(sim);
    double last_report = omp_get_wtime();
    if (o && o->progress) { /* at once, before the first step */
        pfsph_progress p = {frame0, nframes,          time0, end, pfsph_sim_steps(sim), last_report - w0,
                            0,      fluid_count(sim), time0, true};
        o->progress(&p, o->user);
    }
    const uint64_t steps0 = pfsph_sim_steps(sim);
    for (frame = frame0 + 1; frame <= nframes && !rc; frame++) {
        /* step by step, with pfsph_sim_advance's own test, so that progress is reported within
         * a frame (at most 4 times a second); advance then only lands the clock on the frame */
        const double tf = frame / s->fps;
        while (!rc && o && o->progress && pfsph_sim_time(sim) < tf - 1e-12 * fmax(1.0, fabs(tf))) {
            if (o->stop && *o->stop) {
                rc = PFSPH_EINTR;
                break;
            }
            rc = pfsph_sim_step(sim, tf, err);
            double now = omp_get_wtime();
            if (!rc && now - last_report >= 0.25) {
                last_report = now;
                double wall = now - w0;
                pfsph_progress p = {frame - 1,
                                    nframes,
                                    pfsph_sim_time(sim),
                                    end,
                                    pfsph_sim_steps(sim),
                                    wall,
                                    wall > 0 ? (double)(pfsph_sim_steps(sim) - steps0) / wall : 0,
                                    fluid_count(sim),
                                    time0,
                                    true};
                o->progress(&p, o->user);
            }
        }
        if (!rc && o && o->stop && *o->stop) rc = PFSPH_EINTR;
        if (!rc) rc = pfsph_sim_advance(sim, tf, err);
        if (rc == PFSPH_EINTR) {
            pfsph__run_interrupted(dir, s, sim, good ? stash : NULL, good_frame,
                                   ckpt_frame >= 0 ? ckpt_frame
                                       : resume    ? frame0
                                                   : -1,
                                   err);
            good = good && access(stash, F_OK) == 0;
        }
        if (rc == PFSPH_EUNSTABLE && good) {
            char cp[PFSPH_PATH_LEN + 64];
            pfsph_error e3;
            pfsph_checkpoint_path(cp, sizeof cp, dir, good_frame);
            snprintf(path, sizeof path, "%s/checkpoints", dir);
            size_t len = strlen(err->msg);
            if (pfsph_mkdirs(path, &e3) == PFSPH_OK && pfsph_checkpoint_keep(stash, cp, &e3) == PFSPH_OK) {
                good = 0;
                snprintf(err->msg + len, sizeof err->msg - len, ". The last good state (frame %d) is kept in %s",
                         good_frame, cp);
            }
        }
        if (rc) break;
        double t0 = omp_get_wtime();
        if (frame % fi == 0) {
            rc = pfsph__run_frame_files(s, dir, frame / fi, sim, err);
            if (!rc) written++;
        }
        csv_row(csv, frame, sim);
        if (bcsv) bodies_rows(bcsv, frame, sim);
        if (!rc) rc = pfsph__csv_flushed(csv, csv_path, err);
        if (!rc && bcsv) rc = pfsph__csv_flushed(bcsv, bcsv_path, err);
        /* every ci frames, and at the last one (so that --end can extend the run from there) */
        if (!rc && ci > 0 && (frame % ci == 0 || frame == nframes)) {
            double c0 = omp_get_wtime();
            size_t bytes = 0;
            /* a distributed run whose checkpoints the root writes alone (PFSPH_MPI_CHECKPOINTS=root):
             * the root gathers the fluid first; otherwise every rank writes its slice */
            const pfsph_ctx *c = pfsph_sim_ctx(sim);
            if (c->dist && !c->dist->fluid_whole && !c->dist->save) rc = c->dist->gather(c->dist, err);
            if (!rc) rc = pfsph_checkpoint_write_run(dir, sim, frame, PFSPH_CHECKPOINT_KEEP, &bytes, err);
            if (!rc) { /* only a checkpoint on disk, renamed into place, goes into summary.json */
                ckpt_s = omp_get_wtime() - c0;
                ckpt_frame = frame;
                ckpt_bytes = bytes;
            }
        }
        /* written beside the old stash and renamed over it: should this fail (a full disk), the
         * previous frame's state stays the last good one, and the run stops with the error. A
         * distributed run writes it collectively (every rank its slice); one whose root writes
         * checkpoints alone keeps, under collective frames, the stash of the last frame the root
         * held the fluid (a checkpoint's): no gather of the whole fluid a frame */
        const pfsph_dist *dist = pfsph_sim_ctx(sim)->dist;
        if (!rc && (!dist || dist->fluid_whole || dist->save) &&
            (rc = pfsph_checkpoint_stash(stash, sim, frame, err)) == PFSPH_OK) {
            good = 1;
            good_frame = frame;
        }
        pfsph_sim_add_stage_time(sim, PFSPH_STAGE_OUTPUT, omp_get_wtime() - t0);
        if (o && o->progress) {
            last_report = omp_get_wtime();
            double wall = last_report - w0;
            pfsph_progress p = {frame,
                                nframes,
                                pfsph_sim_time(sim),
                                end,
                                pfsph_sim_steps(sim),
                                wall,
                                wall > 0 ? (double)(pfsph_sim_steps(sim) - steps0) / wall : 0,
                                fluid_count(sim),
                                time0,
                                false};
            o->progress(&p, o->user);
        }
    }
    /* the last rows' close is checked too; the first error is the one reported */
    if (fclose(csv) != 0 && !rc) rc = pfsph_fail(err, PFSPH_EIO, "%s: close failed: %s", csv_path, strerror(errno));
    if (bcsv && fclose(bcsv) != 0 && !rc)
        rc = pfsph_fail(err, PFSPH_EIO, "%s: close failed: %s", bcsv_path, strerror(errno));
    if (good) unlink(stash);
    pfsph_error e2;
    const char *status = rc == PFSPH_OK ? "finished"
        : rc == PFSPH_EUNSTABLE         ? "unstable"
        : rc == PFSPH_EINTR             ? "interrupted"
                                        : "failed";
    run_info info = {resume ? frame0 : -1, ckpt_frame, ckpt_bytes, ckpt_s};
    int rc2 = write_summary(dir, s, sim, written, omp_get_wtime() - w0, status, rc ? err->msg : NULL, &info, &e2);
    if (!rc && s->diffuse.enabled) {
        char png[PFSPH_PATH_LEN + 64];
        snprintf(path, sizeof path, "%s/stats.csv", dir);
        snprintf(png, sizeof png, "%s/diffuse_counts.png", dir);
        rc2 = rc2 ? rc2 : pfsph_diffuse_plot(path, png, &e2);
    }
    pfsph_sim_destroy(sim);
    if (!rc && rc2) {
        *err = e2;
        rc = rc2;
    } else if (rc && rc2) { /* both lost: say so, the first error first */
        size_t len = strlen(err->msg);
        snprintf(err->msg + len, sizeof err->msg - len, "; and %s", e2.msg);
    }
    return rc;
}

int pfsph__run_write_frame(pfsph_sim *sim, const char *dir, int frame, pfsph_error *err)
{
    return pfsph__run_frame_files(pfsph_sim_scene(sim), dir, frame, sim, err);
}
