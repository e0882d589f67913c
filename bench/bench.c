/* Throughput benchmark: a 3D dam break built in memory with a chosen number of fluid particles,
 * run for a few steps; prints particle-steps per second, time per stage, neighbour counts and
 * peak memory per particle. With --diffuse N, diffuse material is on with N seeded particles
 * and the diffuse stage is reported against the rest of the step. Results are recorded in
 * docs/benchmarks.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include <omp.h>

#include "cli/omp_env.h"
#include "core/stage.h"
#include "pfsph/grid.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "physics/solver.h"

static void usage(void)
{
    fprintf(stderr,
            "usage: bench [--particles N] [--steps N] [--warmup N] [--solver wcsph|pcisph|dfsph|iisph]\n"
            "             [--lists auto|true|false]\n"
            "             [--pairwise [--no-thermostat]] [--threads N] [--diffuse N] [--diffuse-emit-all]\n"
            "Runs a 3D dam break of about N fluid particles (default 50000) for --steps steps\n"
            "(default 20) after --warmup steps (default 3) and prints throughput figures.\n"
            "--diffuse N turns diffuse material on (the limits of scenes/diffuse_dam_*.json)\n"
            "and seeds N diffuse particles in and around the water block before the warm-up;\n"
            "--diffuse-emit-all sets phi_e_min = 0 so every moving fluid particle evaluates the\n"
            "velocity difference of Eqs. 10-13 (worst case of the generation stage).\n"
            "--wall-viscosity NU gives the container its own wall viscosity [m^2/s] (the\n"
            "friction loop then reads the per-solid wall table; 1e-3 is the fluid's own).\n"
            "--lists sets the solver's \"neighbour_lists\" (DFSPH, IISPH; default auto).\n");
}

/* Mean number of neighbours j != i within h of each fluid particle: fluid ones through the
 * fluid grid, boundary ones through the boundary grid. Uses the grid of the last step. */
static void count_neighbours(const pfsph_ctx *c, double *fluid_nb, double *bnd_nb, double *fluid_cand)
{
    const pfsph_particles *f = c->fluid, *b = c->boundary;
    const double h2 = (double)c->h * (double)c->h;
    long long nf = 0, nb = 0, nc = 0;
    const long n = (long)f->n;
#pragma omp parallel for reduction(+ : nf, nb, nc) schedule(static)
    for (long i = 0; i < n; i++) {
        pfsph_ranges r;
        pfsph_grid_ranges(c->grid, f->x[i], f->y[i], f->z[i], &r);
        for (int k = 0; k < r.n; k++)
            for (uint32_t j = r.b[k]; j < r.e[k]; j++) {
                nc++;
                if ((long)j == i) continue;
                double dx = f->x[i] - f->x[j], dy = f->y[i] - f->y[j], dz = f->z[i] - f->z[j];
                if (dx * dx + dy * dy + dz * dz < h2) nf++;
            }
        if (b && b->n > 0 && c->bgrid) {
            pfsph_grid_ranges(c->bgrid, f->x[i], f->y[i], f->z[i], &r);
            for (int k = 0; k < r.n; k++)
                for (uint32_t j = r.b[k]; j < r.e[k]; j++) {
                    double dx = f->x[i] - b->x[j], dy = f->y[i] - b->y[j], dz = f->z[i] - b->z[j];
                    if (dx * dx + dy * dy + dz * dz < h2) nb++;
                }
        }
    }
    *fluid_nb = n > 0 ? (double)nf / (double)n : 0;
    *bnd_nb = n > 0 ? (double)nb / (double)n : 0;
    *fluid_cand = n > 0 ? (double)nc / (double)n : 0;
}

/* Deterministic uniform in [0, 1) from an integer (splitmix64 finaliser). */
static double hash_unit(uint64_t k)
{
    k += 0x9E3779B97F4A7C15ull;
    k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
    k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
    k ^= k >> 31;
    return (double)(k >> 11) * (1.0 / 9007199254740992.0);
}

/* Seed n diffuse particles around the fluid of a freshly created simulation (through
 * pfsph_sim_restore, as a checkpoint would): of every five, three sit inside the water within
 * a spacing of a fluid particle (bubbles), one on the block's top surface (foam) and one in the
 * air above it (spray, up to 0.3 m higher). Fluid particles are taken in a fixed stride, so the
 * seeding is deterministic. Lifetimes are long enough that none expires during the run. */
static int seed_diffuse(pfsph_sim *sim, long n, double top, pfsph_error *err)
{
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    const pfsph_particles *f = c->fluid;
    pfsph_particles fc, dp;
    if (pfsph_particles_init(&fc, f->n) != PFSPH_OK) return PFSPH_ENOMEM;
    if (pfsph_particles_init(&dp, (size_t)n + 1) != PFSPH_OK) {
        pfsph_particles_free(&fc);
        return PFSPH_ENOMEM;
    }
    for (int k = 0; k < PFSPH_NFIELDS; k++) memcpy(fc.f[k], f->f[k], f->n * sizeof(pfsph_real));
    memcpy(fc.phase, f->phase, f->n);
    memcpy(fc.id, f->id, f->n * sizeof(uint32_t));
    fc.n = f->n;
    fc.next_id = f->next_id;
    const double d = (double)c->spacing;
    for (long i = 0; i < n; i++) {
        size_t j = (size_t)((unsigned long long)i * f->n / (unsigned long long)n);
        double u0 = hash_unit(4 * (uint64_t)i), u1 = hash_unit(4 * (uint64_t)i + 1),
               u2 = hash_unit(4 * (uint64_t)i + 2);
        double x = f->x[j] + d * (2 * u0 - 1), y = f->y[j], z = f->z[j] + d * (2 * u2 - 1);
        switch (i % 5) {
        case 3: y = top + 0.5 * d * u1; break;     /* foam layer */
        case 4: y = top + 2 * d + 0.3 * u1; break; /* spray */
        default: y += d * (2 * u1 - 1); break;     /* bubbles */
        }
        const pfsph_real p[3] = {(pfsph_real)x, (pfsph_real)y, (pfsph_real)z};
        long s = pfsph_particles_push(&dp, p, NULL, 0);
        if (s >= 0) dp.aux[s] = 100; /* lifetime [s] */
    }
    pfsph_sim_state st;
    pfsph_sim_get_state(sim, &st);
    int rc = pfsph_sim_restore(sim, &st, &fc, &dp, (uint64_t)dp.n, 0, err);
    pfsph_particles_free(&fc);
    pfsph_particles_free(&dp);
    return rc;
}

int main(int argc, char **argv)
{
    pfsph_omp_wait_default(argv); /* as pfsph does */
    long target = 50000, steps = 20, warmup = 3;
    const char *solver = "wcsph", *lists = NULL;
    int pairwise = 0, threads = 0, emit_all = 0, no_thermo = 0;
    long ndiffuse = -1;
    double wall_nu = -1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--particles") && v) {
            target = atol(v);
            i++;
        } else if (!strcmp(a, "--steps") && v) {
            steps = atol(v);
            i++;
        } else if (!strcmp(a, "--warmup") && v) {
            warmup = atol(v);
            i++;
        } else if (!strcmp(a, "--threads") && v) {
            threads = atoi(v);
            i++;
        } else if (!strcmp(a, "--solver") && v) {
            if (!pfsph_solver_find(v)) {
                usage();
                return 2;
            }
            solver = v;
            i++;
        } else if (!strcmp(a, "--lists") && v && (!strcmp(v, "auto") || !strcmp(v, "true") || !strcmp(v, "false"))) {
            lists = v;
            i++;
        } else if (!strcmp(a, "--pairwise")) pairwise = 1;
        else if (!strcmp(a, "--no-thermostat")) no_thermo = 1;
        else if (!strcmp(a, "--diffuse") && v) {
            ndiffuse = atol(v);
            i++;
        } else if (!strcmp(a, "--diffuse-emit-all")) emit_all = 1;
        else if (!strcmp(a, "--wall-viscosity") && v) {
            wall_nu = atof(v);
            i++;
        } else {
            usage();
            return !strcmp(a, "--help") || !strcmp(a, "-h") ? 0 : 2;
        }
    }
    if (target < 100 || steps < 1 || warmup < 0 || threads < 0 || (emit_all && ndiffuse < 0) || ndiffuse > 100000000) {
        usage();
        return 2;
    }
    /* the scene's "threads" key below is read by the pfsph program, not by the library: the
     * count must be set here (before 2026-12-02 --threads changed nothing) */
    if (threads > 0) omp_set_num_threads(threads);

    /* The block is 3 x 4 x 3 lattice units per unit k (0.45 x 0.6 x 0.45 m as in
     * scenes/dam_break_3d.json), so n = 36 k^3; the spacing follows from the 0.6 m height.
     * Extents carry a quarter spacing extra so floor(extent / d) cannot round down. */
    double k = cbrt((double)target / 36.0);
    long nx = lround(3 * k), ny = lround(4 * k), nz = lround(3 * k);
    if (nx < 1) nx = 1;
    if (nz < 1) nz = 1;
    if (ny < 1) ny = 1;
    const double d = 0.6 / (double)ny, r = 0.5 * d;
    const double bx = ((double)nx + 0.25) * d, by = ((double)ny + 0.25) * d, bz = ((double)nz + 0.25) * d;
    const double tx = 1.5 / 0.45 * bx, ty = 1.5 * by, tz = bz; /* tank inner size */
    const double m = 3.0 * d + 0.05;                           /* room for walls */

    char pair[256] = "";
    if (pairwise)
        snprintf(pair, sizeof pair,
                 ",\n\"pairwise\": {%s\"coefficients\": [{\"phases\": [\"water\", \"water\"], "
                 "\"c\": 1000}]}",
                 no_thermo ? "\"thermostat\": false, " : "");
    /* Diffuse block: the limits of scenes/diffuse_dam_*.json; the cap leaves room above the
     * seeded count so that generation runs (it is skipped at the cap). */
    char dif[1024] = "";
    if (ndiffuse >= 0)
        snprintf(dif, sizeof dif,
                 ",\n\"diffuse\": {\"max_particles\": %ld, \"sampling_rate\": 100, "
                 "\"phi_v_min\": 2, \"phi_v_max\": 8, \"phi_e_min\": %g, \"phi_e_max\": 4.5, "
                 "\"energy_mass\": 1, \"emit_radius_scale\": 2, \"lifetime_min\": 0.5, "
                 "\"lifetime_max\": 2.5}",
                 2 * ndiffuse + 100000, emit_all ? 0.0 : 0.5);
    char wallkey[64] = "";
    if (wall_nu >= 0) snprintf(wallkey, sizeof wallkey, ", \"viscosity\": %.9g", wall_nu);
    char lkey[64] = "";
    if (lists)
        snprintf(lkey, sizeof lkey, ", \"neighbour_lists\": %s%s%s", strcmp(lists, "auto") ? "" : "\"", lists,
                 strcmp(lists, "auto") ? "" : "\"");
    char json[8192];
    snprintf(json, sizeof json,
             "{\"name\": \"bench\", \"dimension\": 3, \"particle_radius\": %.9g,\n"
             "\"gravity\": [0, -9.81, 0], \"threads\": %d,\n"
             "\"domain\": {\"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]},\n"
             "\"solver\": {\"type\": \"%s\", \"tolerance\": 0.005, \"min_iterations\": 3, "
             "\"max_iterations\": 50%s},\n"
             "\"time\": {\"end\": 100, \"cfl\": 0.4, \"dt_max\": 0.004},\n"
             "\"phases\": [{\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, "
             "\"viscosity\": 1e-3}, {\"name\": \"wall\", \"kind\": \"solid\"}],\n"
             "\"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [%.9g, %.9g, %.9g], "
             "\"phase\": \"water\"}],\n"
             "\"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], "
             "\"max\": [%.9g, %.9g, %.9g], \"open_top\": true, \"layers\": 2, "
             "\"phase\": \"wall\"%s}],\n"
             "\"output\": {\"directory\": \"bench_run\", \"formats\": [], \"boundary\": false}"
             "%s%s}\n",
             r, threads, -m, -m, -m, tx + m, ty + m, tz + m, solver, lkey, bx, by, bz, tx, ty, tz, wallkey, pair, dif);

    static pfsph_scene scene;
    pfsph_error err = {0};
    if (pfsph_scene_parse(&scene, json, "<bench>", &err) != PFSPH_OK) {
        fprintf(stderr, "bench: %s\n", err.msg);
        return 2;
    }
    size_t est_f = 0, est_b = 0, est_bytes = 0;
    if (pfsph_scene_estimate(&scene, &est_f, &est_b, &est_bytes, &err) != PFSPH_OK) est_bytes = 0;

    pfsph_sim *sim = NULL;
    double t0 = omp_get_wtime();
    if (pfsph_sim_create(&sim, &scene, &err) != PFSPH_OK) {
        fprintf(stderr, "bench: %s\n", err.msg);
        return 1;
    }
    double t_create = omp_get_wtime() - t0;
    if (ndiffuse > 0 && seed_diffuse(sim, ndiffuse, by, &err) != PFSPH_OK) {
        fprintf(stderr, "bench: seeding diffuse particles: %s\n", err.msg);
        pfsph_sim_destroy(sim);
        return 1;
    }
    const pfsph_ctx *ctx = pfsph_sim_ctx(sim);
    const size_t n_fluid0 = ctx->fluid->n, n_bnd = ctx->boundary ? ctx->boundary->n : 0;

    printf("pfsph bench: 3D dam break, solver %s%s, %d threads (OMP_WAIT_POLICY=%s)\n", solver,
           pairwise ? " + pairwise" : "", threads > 0 ? threads : omp_get_max_threads(),
           getenv("OMP_WAIT_POLICY") ? getenv("OMP_WAIT_POLICY") : "unset");
    printf("  block %ld x %ld x %ld, particle radius %.4g m, h %.4g m, tank %.3f x %.3f x %.3f m\n", nx, ny, nz, r,
           (double)ctx->h, tx, ty, tz);
    printf("  fluid particles     %zu\n  boundary particles  %zu\n", n_fluid0, n_bnd);
    printf("  create              %.3f s (estimate %.1f MB)\n", t_create, (double)est_bytes / 1e6);

    int rc = 0;
    for (long s = 0; s < warmup && rc == PFSPH_OK; s++) rc = pfsph_sim_step(sim, 1e9, &err);
    double st0[PFSPH_NSTAGES];
    memcpy(st0, pfsph_sim_stage_seconds(sim), sizeof st0);
    double sc0[PFSPH_NSTAGES]; /* process CPU per stage: what a loaded machine does not distort */
    memcpy(sc0, pfsph_sim_stage_cpu_seconds(sim), sizeof sc0);
    const double sim_t0 = pfsph_sim_time(sim);
    long iters = 0, done = 0;
    double fluid_steps = 0;
    t0 = omp_get_wtime();
    for (long s = 0; s < steps && rc == PFSPH_OK; s++) {
        size_t nf = ctx->fluid->n;
        rc = pfsph_sim_step(sim, 1e9, &err);
        if (rc != PFSPH_OK) break;
        iters += pfsph_sim_stats(sim)->iterations;
        fluid_steps += (double)nf;
        done++;
    }
    const double wall = omp_get_wtime() - t0;
    if (rc != PFSPH_OK)
        printf("  FAILED at step %llu (t = %.4g s): %s\n", (unsigned long long)pfsph_sim_steps(sim),
               pfsph_sim_time(sim), err.msg);

    const pfsph_step_stats *st = pfsph_sim_stats(sim);
    const double rate = wall > 0 ? fluid_steps / wall : 0;
    printf("  steps               %ld measured after %ld warm-up, %.4f s simulated, last dt %.3g s\n", done, warmup,
           pfsph_sim_time(sim) - sim_t0, st->dt);
    printf("  last step           vmax %.3g m/s, density error avg %.3g%% max %.3g%%\n", st->vmax,
           100 * st->density_err_avg, 100 * st->density_err_max);
    printf("  wall time           %.3f s (%.2f ms/step)\n", wall, done ? 1e3 * wall / (double)done : 0);
    printf("  throughput          %.4g fluid particle-steps/s\n", rate);

    double nbf = 0, nbb = 0, ncand = 0;
    count_neighbours(ctx, &nbf, &nbb, &ncand);
    printf("  neighbours within h %.1f fluid + %.1f boundary per fluid particle\n", nbf, nbb);
    printf("  grid candidates     %.1f fluid particles tested per fluid particle (cell %.4g m)\n", ncand,
           (double)ctx->grid->cell);
    const double avg_it = done ? (double)iters / (double)done : 0;
    if (strcmp(solver, "wcsph")) printf("  solver iterations   %.2f per step (average)\n", avg_it);

    const double *st1 = pfsph_sim_stage_seconds(sim);
    const double *sc1 = pfsph_sim_stage_cpu_seconds(sim);
    double tot = 0, cpu_tot = 0;
    for (int i = 0; i < PFSPH_NSTAGES; i++) tot += st1[i] - st0[i];
    for (int i = 0; i < PFSPH_NSTAGES; i++) cpu_tot += sc1[i] - sc0[i];
    printf("  stage        seconds      %%    CPU [s]\n");
    for (int i = 0; i < PFSPH_NSTAGES; i++) {
        double sec = st1[i] - st0[i];
        printf("  %-10s %9.4f  %5.1f  %9.4f\n", pfsph_stage_names[i], sec, tot > 0 ? 100 * sec / tot : 0,
               sc1[i] - sc0[i]);
    }
    printf("  %-10s %9.4f  (wall %.4f)  %9.4f\n", "sum", tot, wall, cpu_tot);
    const double dif_s = st1[PFSPH_STAGE_DIFFUSE] - st0[PFSPH_STAGE_DIFFUSE];
    const double fluid_s = tot - dif_s - (st1[PFSPH_STAGE_OUTPUT] - st0[PFSPH_STAGE_OUTPUT]);
    size_t dc[3] = {0, 0, 0};
    if (ndiffuse >= 0) {
        pfsph_sim_diffuse_counts(sim, dc);
        uint64_t created = 0, refused = 0;
        pfsph_sim_diffuse_totals(sim, &created, &refused);
        printf("  diffuse particles   %zu at the end (spray %zu, foam %zu, bubble %zu); %llu "
               "created in all (seeded included), %llu refused\n",
               dc[0] + dc[1] + dc[2], dc[0], dc[1], dc[2], (unsigned long long)created, (unsigned long long)refused);
        printf("  diffuse stage       %.4f s = %.1f%% of the fluid step (%.4f s: all other stages)"
               "\n",
               dif_s, fluid_s > 0 ? 100 * dif_s / fluid_s : 0, fluid_s);
    }

    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    const double rss = (double)ru.ru_maxrss * 1024.0; /* Linux: kilobytes */
    const double bpp = n_fluid0 ? rss / (double)n_fluid0 : 0;
    printf("  peak RSS            %.1f MB = %.0f bytes per fluid particle (boundary and process "
           "included)\n",
           rss / 1e6, bpp);

    /* One line for grep. */
    printf("BENCH solver=%s lists=%d pairwise=%d threads=%d fluid=%zu boundary=%zu steps=%ld wall_s=%.3f "
           "psteps_per_s=%.4g iters=%.2f nb_fluid=%.1f nb_bnd=%.1f cand=%.1f bytes_per_particle=%.0f "
           "diffuse=%zu diffuse_s=%.4f fluid_s=%.4f diffuse_pct=%.1f cpu_s=%.4f status=%s\n",
           solver, pfsph_sim_step_state(sim)->lists, pairwise, threads > 0 ? threads : omp_get_max_threads(), n_fluid0,
           n_bnd, done, wall, rate, avg_it, nbf, nbb, ncand, bpp, dc[0] + dc[1] + dc[2], dif_s, fluid_s,
           fluid_s > 0 ? 100 * dif_s / fluid_s : 0, cpu_tot, rc == PFSPH_OK ? "ok" : "failed");
    pfsph_sim_destroy(sim);
    return rc == PFSPH_OK ? 0 : 3;
}
