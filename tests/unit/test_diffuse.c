/* Diffuse material (DF Sections 4-5): motion laws of spray, foam and bubbles (Eqs. 24-28),
 * classification, lifetime and cap, generation against Eq. 16, determinism across thread
 * counts. Every test builds its pfsph_ctx, fluid set and grid by hand; no solver runs. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/diffuse.h"
#include "pfsph/sim.h"
#include "testutil.h"

/* A hand-made simulation state: one liquid phase, fluid set, grid, kernel. */
typedef struct fixture {
    pfsph_scene scene;
    pfsph_particles fluid;
    pfsph_grid grid;
    pfsph_ctx ctx;
} fixture;

static void fx_init(fixture *f, int dim, double spacing, double dt)
{
    memset(f, 0, sizeof(*f));
    f->scene.dim = dim;
    f->scene.nphases = 1;
    f->scene.phases[0].kind = PFSPH_PHASE_FLUID;
    f->scene.phases[0].rest_density = 1000;
    f->scene.gravity[1] = -9.81;
    f->scene.seed = 12345;
    for (int a = 0; a < 3; a++) {
        f->scene.domain_min[a] = -10;
        f->scene.domain_max[a] = 10;
    }
    pfsph_diffuse_defaults(&f->scene.diffuse);
    f->scene.diffuse.enabled = true;
    assert_int_equal(pfsph_particles_init(&f->fluid, 16), PFSPH_OK);
    pfsph_ctx *c = &f->ctx;
    c->dim = dim;
    c->spacing = (pfsph_real)spacing;
    c->h = (pfsph_real)(2 * spacing);
    c->V0 = (pfsph_real)pow(spacing, dim);
    c->nd0 = 1 / c->V0;
    pfsph_kernel_init(&c->kern, dim, c->h);
    c->fluid = &f->fluid;
    c->grid = &f->grid;
    c->mass[0] = (pfsph_real)(1000 * c->V0);
    c->rest_density[0] = 1000;
    pfsph_ctx_set_model(c, &f->scene);
    c->dt = dt;
    c->step = 1;
}

static void fx_push(fixture *f, double x, double y, double z, double vx, double vy, double vz)
{
    const pfsph_real p[3] = {(pfsph_real)x, (pfsph_real)y, (pfsph_real)z};
    const pfsph_real v[3] = {(pfsph_real)vx, (pfsph_real)vy, (pfsph_real)vz};
    assert_true(pfsph_particles_push(&f->fluid, p, v, 0) >= 0);
}

/* Sort the fluid into the grid at the current positions (time t), then move it by dt v as the
 * integrator would: the state pfsph_diffuse_step sees (NOTES 19). */
static void fx_grid(fixture *f)
{
    const pfsph_real lo[3] = {-10, -10, -10}, hi[3] = {10, 10, 10};
    assert_int_equal(pfsph_grid_init(&f->grid, f->ctx.dim, lo, hi, f->ctx.h), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(&f->grid, &f->fluid, NULL), PFSPH_OK);
    pfsph_particles *p = &f->fluid;
    for (size_t i = 0; i < p->n; i++) {
        p->x[i] += (pfsph_real)f->ctx.dt * p->vx[i];
        p->y[i] += (pfsph_real)f->ctx.dt * p->vy[i];
        p->z[i] += (pfsph_real)f->ctx.dt * p->vz[i];
    }
}

static void fx_free(fixture *f)
{
    pfsph_grid_free(&f->grid);
    pfsph_particles_free(&f->fluid);
}

/* A block lattice [0, nx) x [0, ny) (x [0, nz) in 3D) of spacing d, uniform velocity. */
static void fx_lattice(fixture *f, int nx, int ny, int nz, double vx, double vy, double vz)
{
    double d = f->ctx.spacing;
    for (int k = 0; k < (f->ctx.dim == 3 ? nz : 1); k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) fx_push(f, i * d, j * d, k * d, vx, vy, vz);
}

static pfsph_diffuse *mk(fixture *f)
{
    pfsph_diffuse *d = NULL;
    pfsph_error err;
    pfsph_ctx_set_model(&f->ctx, &f->scene); /* the tests edit the scene after fx_init */
    assert_int_equal(pfsph_diffuse_create(&d, &f->ctx, &err), PFSPH_OK);
    return d;
}

/* Eq. 26: a spray particle away from any fluid follows the symplectic-Euler parabola
 * v_n = v0 + n g dt, x_n = x0 + n dt v0 + g dt^2 n (n + 1) / 2 (to float round-off), which is
 * the exact parabola x0 + v0 t + g t^2 / 2 plus the first-order term g dt t / 2. */
static void test_spray_parabola(void **state)
{
    (void)state;
    fixture f;
    fx_init(&f, 3, 0.05, 1e-3);
    fx_push(&f, 5, 5, 5, 0, 0, 0); /* far away */
    fx_grid(&f);
    f.scene.diffuse.sampling_rate = 0;
    pfsph_diffuse *d = mk(&f);
    const pfsph_real x0[3] = {-3, 1, 0.5}, v0[3] = {2, 3, -1};
    assert_int_equal(pfsph_diffuse_add(d, x0, v0, PFSPH_DIFFUSE_SPRAY, 100), 0);
    const int n = 500;
    const double dt = f.ctx.dt, g = -9.81;
    for (int s = 1; s <= n; s++) {
        f.ctx.step = (uint64_t)s;
        pfsph_diffuse_step(d, &f.ctx);
    }
    const pfsph_particles *p = pfsph_diffuse_particles(d);
    assert_int_equal(p->n, 1);
    assert_int_equal(p->phase[0], PFSPH_DIFFUSE_SPRAY);
    double t = n * dt;
    double xs = x0[0] + v0[0] * t, zs = x0[2] + v0[2] * t;
    double ys = x0[1] + v0[1] * t + g * dt * dt * n * (n + 1) / 2.0;
    double vy = v0[1] + g * t;
    /* float storage: ~n rounding steps of 6e-8 relative each */
    assert_true(fabs(p->vx[0] - v0[0]) < 1e-6 && fabs(p->vz[0] - v0[2]) < 1e-6);
    assert_true(fabs(p->vy[0] - vy) < 2e-5 * (fabs(vy) + 1));
    assert_true(fabs(p->x[0] - xs) < 1e-4 && fabs(p->z[0] - zs) < 1e-4);
    assert_true(fabs(p->y[0] - ys) < 1e-4);
    double ycont = x0[1] + v0[1] * t + 0.5 * g * t * t;
    assert_true(fabs(p->y[0] - ycont - 0.5 * g * dt * t) < 1e-4);
    pfsph_diffuse_destroy(d);
    fx_free(&f);
}

/* Eq. 27: foam in a uniform flow U. k_cp = 1: v = U after one step, x advances by U dt.
 * k_cp = 0.5: v_n - U = (1 - k_cp)^n (v_0 - U). */
static void test_foam_follows_flow(void **state)
{
    (void)state;
    const double U[3] = {0.7, -0.2, 0.3};
    const double kcp[2] = {1.0, 0.5};
    for (int c = 0; c < 2; c++) {
        fixture f;
        fx_init(&f, 3, 0.1, 1e-3);
        fx_lattice(&f, 12, 12, 12, U[0], U[1], U[2]);
        fx_grid(&f);
        f.scene.diffuse.sampling_rate = 0;
        f.scene.diffuse.foam_min_neighbors = 0;
        f.scene.diffuse.foam_max_neighbors = 100000;
        f.scene.diffuse.type[PFSPH_DIFFUSE_FOAM].k_cp = kcp[c];
        pfsph_diffuse *d = mk(&f);
        const pfsph_real x0[3] = {0.53f, 0.61f, 0.47f}, v0[3] = {-1, 2, 0.5};
        assert_int_equal(pfsph_diffuse_add(d, x0, v0, PFSPH_DIFFUSE_FOAM, 100), 0);
        const pfsph_particles *p = pfsph_diffuse_particles(d);
        double xe = x0[1];
        for (int s = 1; s <= 10; s++) {
            f.ctx.step = (uint64_t)s;
            pfsph_diffuse_step(d, &f.ctx);
            assert_int_equal(p->n, 1);
            assert_int_equal(p->phase[0], PFSPH_DIFFUSE_FOAM);
            double fac = pow(1 - kcp[c], s);
            double ve[3] = {U[0] + fac * (v0[0] - U[0]), U[1] + fac * (v0[1] - U[1]), U[2] + fac * (v0[2] - U[2])};
            assert_true(fabs(p->vx[0] - ve[0]) < 1e-6);
            assert_true(fabs(p->vy[0] - ve[1]) < 1e-6);
            assert_true(fabs(p->vz[0] - ve[2]) < 1e-6);
            xe += f.ctx.dt * ve[1];
            assert_true(fabs(p->y[0] - xe) < 1e-6);
        }
        pfsph_diffuse_destroy(d);
        fx_free(&f);
    }
}

/* Eq. 28: a bubble at rest in still fluid. k_cp = 0: dv/dt = (1 - k_b) g, upwards (against g)
 * when k_b > 1. k_cp > 0: the first step gives (1 - k_b) g dt; the velocity then settles at
 * (1 - k_b) g dt / k_cp (relative to the fluid), the fixed point of Eq. 28. */
static void test_bubble_rises(void **state)
{
    (void)state;
    const double kb = 5.6, dt = 1e-3, g = -9.81;
    const double kcp[2] = {0.0, 0.5};
    for (int c = 0; c < 2; c++) {
        fixture f;
        fx_init(&f, 2, 0.05, dt);
        fx_lattice(&f, 40, 40, 1, 0, 0, 0);
        fx_grid(&f);
        f.scene.diffuse.sampling_rate = 0;
        f.scene.diffuse.foam_min_neighbors = 0;
        f.scene.diffuse.foam_max_neighbors = 0; /* any neighbour: bubble */
        f.scene.diffuse.type[PFSPH_DIFFUSE_BUBBLE] = (pfsph_diffuse_coupling){1, kb, kcp[c], 0};
        pfsph_diffuse *d = mk(&f);
        const pfsph_real x0[3] = {1.0f, 0.8f, 0}, v0[3] = {0, 0, 0};
        assert_int_equal(pfsph_diffuse_add(d, x0, v0, PFSPH_DIFFUSE_BUBBLE, 1), 0);
        const pfsph_particles *p = pfsph_diffuse_particles(d);
        f.ctx.step = 1;
        pfsph_diffuse_step(d, &f.ctx);
        assert_int_equal(p->phase[0], PFSPH_DIFFUSE_BUBBLE);
        assert_true(fabs(p->vy[0] - (1 - kb) * g * dt) < 1e-7);
        assert_true(p->vy[0] > 0); /* upwards: gravity points to -y */
        assert_true(p->vx[0] == 0);
        int n = 100;
        for (int s = 2; s <= n; s++) {
            f.ctx.step = (uint64_t)s;
            pfsph_diffuse_step(d, &f.ctx);
        }
        double expect = kcp[c] == 0 ? (1 - kb) * g * n * dt : (1 - kb) * g * dt / kcp[c];
        assert_true(fabs(p->vy[0] - expect) < 1e-5 * fabs(expect) + 1e-7);
        pfsph_diffuse_destroy(d);
        fx_free(&f);
    }
}

/* NOTES 18: spray below foam_min fluid neighbours, foam from foam_min to foam_max, bubble
 * above; the automatic thresholds are 0.2 and 2/3 of a full support. */
static void test_classification(void **state)
{
    (void)state;
    int lo, hi;
    pfsph_diffuse_params p;
    pfsph_diffuse_defaults(&p);
    pfsph_diffuse_thresholds(&p, 3, 2.0, 1.0, &lo, &hi); /* 4/3 pi 8 = 33.5 neighbours */
    assert_int_equal(lo, 7);
    assert_int_equal(hi, 22);
    pfsph_diffuse_thresholds(&p, 3, pow(30 / (4.0 / 3.0 * 3.141592653589793), 1.0 / 3.0), 1.0, &lo, &hi);
    assert_int_equal(lo, 6); /* the paper's 6 and 20 for 30 neighbours */
    assert_int_equal(hi, 20);
    pfsph_diffuse_thresholds(&p, 2, 2.0, 1.0, &lo, &hi); /* 4 pi = 12.6 */
    assert_int_equal(lo, 3);
    assert_int_equal(hi, 8);
    const int counts[] = {5, 6, 20, 21};
    const int expect[] = {PFSPH_DIFFUSE_SPRAY, PFSPH_DIFFUSE_FOAM, PFSPH_DIFFUSE_FOAM, PFSPH_DIFFUSE_BUBBLE};
    for (int c = 0; c < 4; c++) {
        fixture f;
        fx_init(&f, 3, 0.1, 1e-4);
        /* counts[c] fluid particles on a sphere of radius 0.6 h around the origin, and a few
         * just outside the support */
        for (int k = 0; k < counts[c]; k++) {
            double z = -1 + (2.0 * k + 1) / counts[c], r = sqrt(1 - z * z), ph = 2.4 * k;
            double R = 0.6 * f.ctx.h;
            fx_push(&f, R * r * cos(ph), R * r * sin(ph), R * z, 0, 0, 0);
        }
        for (int k = 0; k < 6; k++) fx_push(&f, k < 3 ? 1.02 * f.ctx.h : 0, 0, 0.21 + k, 0, 0, 0);
        fx_grid(&f);
        f.scene.diffuse.sampling_rate = 0;
        f.scene.diffuse.foam_min_neighbors = 6;
        f.scene.diffuse.foam_max_neighbors = 20;
        pfsph_diffuse *d = mk(&f);
        const pfsph_real x0[3] = {0, 0, 0}, v0[3] = {0, 0, 0};
        pfsph_diffuse_add(d, x0, v0, PFSPH_DIFFUSE_SPRAY, 10);
        pfsph_diffuse_step(d, &f.ctx);
        assert_int_equal(pfsph_diffuse_particles(d)->phase[0], expect[c]);
        size_t n3[3];
        pfsph_diffuse_counts(d, n3);
        assert_int_equal(n3[expect[c]], 1);
        pfsph_diffuse_destroy(d);
        fx_free(&f);
    }
}

/* Eq. 29: lifetime falls by k_t dt per step, by type; expired particles go; the cap holds;
 * particles leaving the domain go. */
static void test_lifetime_and_cap(void **state)
{
    (void)state;
    fixture f;
    fx_init(&f, 3, 0.1, 1e-2);
    fx_push(&f, 5, 5, 5, 0, 0, 0);
    fx_grid(&f);
    f.scene.diffuse.sampling_rate = 0;
    f.scene.diffuse.max_particles = 4;
    f.scene.gravity[1] = 0;
    /* No fluid near: every particle is spray; make spray's k_t = 0.5. */
    pfsph_diffuse *d = mk(&f);
    const pfsph_real v0[3] = {0, 0, 0}, vout[3] = {0, 0, 200};
    const pfsph_real xa[3] = {0, 0, 0}, xb[3] = {1, 0, 0}, xc[3] = {2, 0, 0}, xd[3] = {0, 0, 9};
    assert_int_equal(pfsph_diffuse_add(d, xa, v0, 0, 1.0f), 0);
    assert_int_equal(pfsph_diffuse_add(d, xb, v0, 0, 0.0125f), 1);
    assert_int_equal(pfsph_diffuse_add(d, xc, v0, 0, 0.5f), 2);
    assert_int_equal(pfsph_diffuse_add(d, xd, vout, 0, 10.0f), 3);
    assert_int_equal(pfsph_diffuse_add(d, xd, v0, 0, 1.0f), -1); /* cap 4 */
    const pfsph_particles *p = pfsph_diffuse_particles(d);
    pfsph_diffuse_step(d, &f.ctx);
    /* b: 0.0125 - 0.5 * 0.01 > 0 stays; d: z = 9 + 2 > 10 leaves the domain */
    assert_int_equal(p->n, 3);
    assert_int_equal(p->id[0], 0);
    assert_int_equal(p->id[1], 1);
    assert_int_equal(p->id[2], 2);
    assert_true(fabs(p->aux[0] - (1.0 - 0.5 * 0.01)) < 1e-6);
    pfsph_diffuse_step(d, &f.ctx);
    pfsph_diffuse_step(d, &f.ctx); /* b: 0.0125 - 0.015 < 0 */
    assert_int_equal(p->n, 2);
    assert_int_equal(p->id[1], 2);
    assert_true(fabs(p->aux[0] - (1.0 - 3 * 0.5 * 0.01)) < 1e-6);
    pfsph_diffuse_destroy(d);
    fx_free(&f);

    /* Per type: foam k_t = 1, bubble k_t = 0.33 over 10 steps. */
    const int types[2] = {PFSPH_DIFFUSE_FOAM, PFSPH_DIFFUSE_BUBBLE};
    for (int c = 0; c < 2; c++) {
        fx_init(&f, 2, 0.05, 1e-3);
        fx_lattice(&f, 30, 30, 1, 0, 0, 0);
        fx_grid(&f);
        f.scene.diffuse.sampling_rate = 0;
        f.scene.diffuse.foam_min_neighbors = types[c] == PFSPH_DIFFUSE_FOAM ? 0 : -1;
        f.scene.diffuse.foam_max_neighbors = types[c] == PFSPH_DIFFUSE_FOAM ? 1000 : 0;
        f.scene.diffuse.type[types[c]].k_cp = 0;
        f.scene.diffuse.type[types[c]].k_ext = f.scene.diffuse.type[types[c]].k_b = 0;
        d = mk(&f);
        const pfsph_real x0[3] = {0.7f, 0.7f, 0};
        pfsph_diffuse_add(d, x0, v0, types[c], 2.0f);
        for (int s = 0; s < 10; s++) pfsph_diffuse_step(d, &f.ctx);
        double kt = f.scene.diffuse.type[types[c]].k_t;
        assert_int_equal(pfsph_diffuse_particles(d)->phase[0], types[c]);
        assert_true(fabs(pfsph_diffuse_particles(d)->aux[0] - (2.0 - 10 * kt * 1e-3)) < 1e-6);
        pfsph_diffuse_destroy(d);
        fx_free(&f);
    }
}

/* A resting lattice (all velocities zero) has E = 0 and v_diff = 0: no emitters. */
static void test_rest_makes_nothing(void **state)
{
    (void)state;
    fixture f;
    fx_init(&f, 3, 0.1, 1e-3);
    fx_lattice(&f, 10, 10, 10, 0, 0, 0);
    fx_grid(&f);
    f.scene.diffuse.phi_v_min = 0;
    f.scene.diffuse.phi_e_min = 0;
    f.scene.diffuse.sampling_rate = 1e6;
    pfsph_diffuse *d = mk(&f);
    for (int s = 1; s <= 20; s++) {
        f.ctx.step = (uint64_t)s;
        pfsph_diffuse_step(d, &f.ctx);
    }
    assert_int_equal(pfsph_diffuse_particles(d)->n, 0);
    /* A uniformly moving lattice: E > 0 but v_diff = 0 (Galilean invariance of Eq. 13). */
    fx_free(&f);
    pfsph_diffuse_destroy(d);
    fx_init(&f, 3, 0.1, 1e-3);
    fx_lattice(&f, 10, 10, 10, 3, 1, 0);
    fx_grid(&f);
    f.scene.diffuse.phi_v_min = 0;
    f.scene.diffuse.phi_e_min = 0;
    f.scene.diffuse.sampling_rate = 1e6;
    d = mk(&f);
    pfsph_diffuse_step(d, &f.ctx);
    assert_int_equal(pfsph_diffuse_particles(d)->n, 0);
    pfsph_diffuse_destroy(d);
    fx_free(&f);
}

/* A 2D shear layer: rows with y >= 0 move at +U, rows below at -U. Expected emission per step
 * (Eq. 16) is sum_i R_D,i k_max dt with R_D from Eqs. 9-15, computed here by brute force
 * independently of the module; the measured count over many steps must match within 4 standard
 * deviations of the stochastic rounding (NOTES 15: per emitter, variance frac (1 - frac)). */
static void build_shear(fixture *f, double U, double jitter)
{
    fx_init(f, 2, 0.05, 1e-3);
    double d = f->ctx.spacing;
    uint32_t s = 1;
    for (int j = -8; j < 8; j++)
        for (int i = 0; i < 40; i++) {
            s = s * 1664525u + 1013904223u;
            double dx = jitter * d * ((s >> 8) / 16777216.0 - 0.5);
            double u = j >= 0 ? U : -U;
            fx_push(f, i * d + dx, (j + 0.5) * d, 0, u, 0.1 * dx / d, 0);
        }
    fx_grid(f);
    f->scene.diffuse.phi_e_min = 0;
    f->scene.diffuse.phi_e_max = 0.5 * f->ctx.mass[0] * U * U * 0.5; /* phi_E = 1 */
    f->scene.diffuse.phi_v_min = 1.0;
    f->scene.diffuse.phi_v_max = 6.0;
    f->scene.diffuse.sampling_rate = 2000;
    f->scene.diffuse.lifetime_min = f->scene.diffuse.lifetime_max = 1e-4; /* die next step */
}

static void test_shear_layer_rate(void **state)
{
    (void)state;
    fixture f;
    const double U = 1.0;
    build_shear(&f, U, 0.0);
    const pfsph_particles *fl = &f.fluid;
    const double h = f.ctx.h, dt = f.ctx.dt;
    double mean = 0, var = 0;
    int emitters = 0;
    pfsph_diffuse *d = mk(&f);
    for (size_t i = 0; i < fl->n; i++) {
        double vd = 0; /* Eq. 13 with lambda = 1 - vhat.xhat (NOTES 13), W^D = 1 - r/h */
        for (size_t j = 0; j < fl->n; j++) {
            /* at the start-of-step positions x - dt v, as the module (NOTES 19) */
            double dx = (fl->x[i] - dt * fl->vx[i]) - (fl->x[j] - dt * fl->vx[j]);
            double dy = (fl->y[i] - dt * fl->vy[i]) - (fl->y[j] - dt * fl->vy[j]);
            double ux = fl->vx[i] - fl->vx[j], uy = fl->vy[i] - fl->vy[j];
            double r = sqrt(dx * dx + dy * dy), u = sqrt(ux * ux + uy * uy);
            if (j == i || r >= h || u == 0) continue;
            vd += u * (1 - (ux * dx + uy * dy) / (u * r)) * (1 - r / h);
        }
        double vdm, em, rate;
        pfsph_diffuse_potentials(d, &f.ctx, i, &vdm, &em, &rate);
        assert_true(fabs(vdm - vd) < 1e-4 * (vd + 1));
        double E = 0.5 * f.ctx.mass[0] * (fl->vx[i] * fl->vx[i] + fl->vy[i] * fl->vy[i]);
        double rd = pfsph_diffuse_phi(vd, 1.0, 6.0) * pfsph_diffuse_phi(E, 0, f.scene.diffuse.phi_e_max);
        assert_true(fabs(rate - rd) < 1e-4);
        double n = rd * f.scene.diffuse.sampling_rate * dt, fr = n - floor(n);
        mean += n;
        var += fr * (1 - fr);
        emitters += rd > 0;
    }
    /* Only the rows next to the interface emit (v_diff of the second row is smaller). */
    assert_true(emitters >= 80 && emitters <= 160);
    const int steps = 200;
    uint64_t created = 0;
    for (int s = 1; s <= steps; s++) {
        f.ctx.step = (uint64_t)s;
        pfsph_diffuse_step(d, &f.ctx);
    }
    pfsph_diffuse_totals(d, &created, NULL);
    double expect = steps * mean, sd = sqrt(steps * var);
    print_message("shear layer: %d emitters, created %llu, Eq. 16 predicts %.1f +- %.1f\n", emitters,
                  (unsigned long long)created, expect, sd);
    assert_true(expect > 1000);
    assert_true(fabs((double)created - expect) < 4 * sd + 1);
    pfsph_diffuse_destroy(d);

    /* The cap: at most max_particles alive, the rest refused. */
    f.scene.diffuse.max_particles = 50;
    f.scene.diffuse.lifetime_min = f.scene.diffuse.lifetime_max = 1.0;
    d = mk(&f);
    for (int s = 1; s <= 20; s++) {
        f.ctx.step = (uint64_t)s;
        pfsph_diffuse_step(d, &f.ctx);
        assert_true(pfsph_diffuse_particles(d)->n <= 50);
    }
    uint64_t refused;
    pfsph_diffuse_totals(d, &created, &refused);
    assert_int_equal(pfsph_diffuse_particles(d)->n, 50);
    assert_int_equal(created, 50);
    assert_true(refused > 0);
    pfsph_diffuse_destroy(d);
    fx_free(&f);
}

/* Emission geometry (Eqs. 17-22, NOTES 16) in 3D: new particles lie in the cylinder of radius
 * s_r r around the path x_f(t) -> x_f(t) + s_h v_f dt, with v_d - v_f perpendicular to v_f and
 * of length equal to the radial offset; lifetimes in [min, max]; ids 0, 1, 2, ... */
static void test_emission_cylinder(void **state)
{
    (void)state;
    fixture f;
    fx_init(&f, 3, 0.1, 2e-3);
    /* two particles approaching head-on */
    fx_push(&f, 0, 0, 0, 3, 4, 0);
    fx_push(&f, 0.06, 0.08, 0, -3, -4, 0);
    fx_grid(&f);
    f.scene.diffuse.phi_v_min = 0;
    f.scene.diffuse.phi_v_max = 1e-3;
    f.scene.diffuse.phi_e_min = 0;
    f.scene.diffuse.phi_e_max = 1e-6;
    f.scene.diffuse.sampling_rate = 20000; /* 40 per step per emitter */
    f.scene.diffuse.emit_radius_scale = 3;
    f.scene.diffuse.emit_height_scale = 2;
    f.scene.diffuse.lifetime_min = 1;
    f.scene.diffuse.lifetime_max = 2;
    pfsph_diffuse *d = mk(&f);
    pfsph_diffuse_step(d, &f.ctx);
    const pfsph_particles *p = pfsph_diffuse_particles(d);
    assert_int_equal(p->n, 80);
    double R = 3 * 0.5 * f.ctx.spacing;
    for (size_t k = 0; k < p->n; k++) {
        assert_int_equal(p->id[k], k);
        /* the emitter: fluid 0 for the first 40 (fluid order after sort) */
        size_t e = k < 40 ? 0 : 1;
        double vf[3] = {f.fluid.vx[e], f.fluid.vy[e], f.fluid.vz[e]};
        double sp = 5.0;
        double xf[3] = {f.fluid.x[e] - f.ctx.dt * vf[0], f.fluid.y[e] - f.ctx.dt * vf[1],
                        f.fluid.z[e] - f.ctx.dt * vf[2]};
        double rel[3] = {p->x[k] - xf[0], p->y[k] - xf[1], p->z[k] - xf[2]};
        double along = (rel[0] * vf[0] + rel[1] * vf[1] + rel[2] * vf[2]) / sp;
        double perp2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2] - along * along;
        assert_true(along >= -1e-6 && along <= 2 * sp * f.ctx.dt + 1e-6);
        assert_true(perp2 <= R * R * (1 + 1e-5));
        double dv[3] = {p->vx[k] - vf[0], p->vy[k] - vf[1], p->vz[k] - vf[2]};
        double dvpar = (dv[0] * vf[0] + dv[1] * vf[1] + dv[2] * vf[2]) / sp;
        assert_true(fabs(dvpar) < 1e-5);
        double dv2 = dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2];
        assert_true(fabs(sqrt(dv2) - sqrt(fabs(perp2))) < 1e-4);
        assert_true(p->aux[k] >= 1 && p->aux[k] <= 2);
    }
    pfsph_diffuse_destroy(d);
    fx_free(&f);
}

/* Gas phases neither count as neighbours nor carry diffuse particles: a diffuse particle in
 * the middle of a gas block is spray and keeps its velocity; in a liquid block it is a bubble
 * and follows the liquid. */
static void test_gas_not_counted(void **state)
{
    (void)state;
    for (int gas = 0; gas < 2; gas++) {
        fixture f;
        fx_init(&f, 3, 0.1, 1e-3);
        f.scene.nphases = 2;
        f.scene.phases[1].kind = PFSPH_PHASE_GAS;
        f.scene.phases[1].rest_density = 1;
        f.ctx.mass[1] = f.ctx.mass[0];
        fx_lattice(&f, 10, 10, 10, 0.5, 0, 0);
        for (size_t i = 0; i < f.fluid.n; i++) f.fluid.phase[i] = (uint8_t)gas;
        fx_grid(&f);
        f.scene.diffuse.sampling_rate = 0;
        pfsph_diffuse *d = NULL;
        for (int t = 0; t < PFSPH_DIFFUSE_NTYPES; t++) f.scene.diffuse.type[t].k_ext = 0;
        f.scene.diffuse.type[PFSPH_DIFFUSE_BUBBLE].k_b = 0;
        f.scene.diffuse.type[PFSPH_DIFFUSE_BUBBLE].k_cp = 1;
        d = mk(&f);
        const pfsph_real x0[3] = {0.45f, 0.45f, 0.45f}, v0[3] = {0, 0, 0};
        assert_int_equal(pfsph_diffuse_add(d, x0, v0, PFSPH_DIFFUSE_FOAM, 100), 0);
        pfsph_diffuse_step(d, &f.ctx);
        const pfsph_particles *p = pfsph_diffuse_particles(d);
        assert_int_equal(p->n, 1);
        if (gas) {
            assert_int_equal(p->phase[0], PFSPH_DIFFUSE_SPRAY);
            assert_true(p->vx[0] == 0);
        } else {
            assert_int_equal(p->phase[0], PFSPH_DIFFUSE_BUBBLE);
            assert_true(fabs(p->vx[0] - 0.5) < 1e-6);
        }
        pfsph_diffuse_destroy(d);
        fx_free(&f);
    }
}

/* The fluid is only read: 30 steps that emit and advect leave every byte of the fluid set
 * and of the grid's cell ranges as they were. */
static void test_fluid_untouched(void **state)
{
    (void)state;
    fixture f;
    build_shear(&f, 1.5, 0.3);
    f.scene.diffuse.emit_radius_scale = 4;
    const pfsph_particles *fl = &f.fluid;
    const size_t n = fl->n;
    pfsph_real *copy[PFSPH_NFIELDS];
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        copy[k] = malloc(n * sizeof(pfsph_real));
        assert_non_null(copy[k]);
        memcpy(copy[k], fl->f[k], n * sizeof(pfsph_real));
    }
    uint8_t *phase = malloc(n);
    uint32_t *id = malloc(n * sizeof(uint32_t));
    uint32_t *start = malloc((f.grid.ncells + 1) * sizeof(uint32_t));
    assert_true(phase && id && start);
    memcpy(phase, fl->phase, n);
    memcpy(id, fl->id, n * sizeof(uint32_t));
    memcpy(start, f.grid.start, (f.grid.ncells + 1) * sizeof(uint32_t));
    const uint32_t next_id = fl->next_id;
    pfsph_diffuse *d = mk(&f);
    for (int s = 1; s <= 30; s++) {
        f.ctx.step = (uint64_t)s;
        pfsph_diffuse_step(d, &f.ctx);
    }
    uint64_t created = 0;
    pfsph_diffuse_totals(d, &created, NULL);
    assert_true(created > 100);
    assert_int_equal(fl->n, n);
    assert_int_equal(fl->next_id, next_id);
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        assert_memory_equal(copy[k], fl->f[k], n * sizeof(pfsph_real));
        free(copy[k]);
    }
    assert_memory_equal(phase, fl->phase, n);
    assert_memory_equal(id, fl->id, n * sizeof(uint32_t));
    assert_memory_equal(start, f.grid.start, (f.grid.ncells + 1) * sizeof(uint32_t));
    free(phase);
    free(id);
    free(start);
    pfsph_diffuse_destroy(d);
    fx_free(&f);
}

/* Same seed: identical particles with 1 and 2 threads; another seed: different ones. */
static void run_shear(uint64_t seed, int threads, pfsph_particles *out)
{
    omp_set_num_threads(threads);
    fixture f;
    build_shear(&f, 1.5, 0.3);
    f.scene.seed = seed;
    f.scene.diffuse.lifetime_min = 0.01;
    f.scene.diffuse.lifetime_max = 0.05;
    f.scene.diffuse.emit_radius_scale = 4;
    f.scene.diffuse.foam_min_neighbors = 3;
    f.scene.diffuse.foam_max_neighbors = 8;
    pfsph_diffuse *d = mk(&f);
    for (int s = 1; s <= 30; s++) {
        f.ctx.step = (uint64_t)s;
        pfsph_diffuse_step(d, &f.ctx);
    }
    const pfsph_particles *p = pfsph_diffuse_particles(d);
    assert_int_equal(pfsph_particles_init(out, p->n + 1), PFSPH_OK);
    for (size_t i = 0; i < p->n; i++) {
        const pfsph_real x[3] = {p->x[i], p->y[i], p->z[i]}, v[3] = {p->vx[i], p->vy[i], p->vz[i]};
        pfsph_particles_push(out, x, v, p->phase[i]);
        out->id[i] = p->id[i];
        out->aux[i] = p->aux[i];
    }
    pfsph_diffuse_destroy(d);
    fx_free(&f);
}

static bool same(const pfsph_particles *a, const pfsph_particles *b)
{
    if (a->n != b->n) return false;
    for (int k = 0; k < PFSPH_NFIELDS; k++)
        if (memcmp(a->f[k], b->f[k], a->n * sizeof(pfsph_real)) != 0) return false;
    return memcmp(a->id, b->id, a->n * 4) == 0 && memcmp(a->phase, b->phase, a->n) == 0;
}

static void test_determinism(void **state)
{
    (void)state;
    pfsph_particles a, b, c;
    run_shear(7, 1, &a);
    run_shear(7, 2, &b);
    run_shear(8, 2, &c);
    assert_true(a.n > 100);
    size_t n3[3] = {0, 0, 0};
    for (size_t i = 0; i < a.n; i++) n3[a.phase[i]]++;
    print_message("determinism: %zu particles (spray %zu, foam %zu, bubble %zu)\n", a.n, n3[0], n3[1], n3[2]);
    assert_true(same(&a, &b));
    assert_false(same(&a, &c));
    pfsph_particles_free(&a);
    pfsph_particles_free(&b);
    pfsph_particles_free(&c);
}

/* A spray particle falling onto a floor of boundary particles (a 2D row at y = 0, spacing d)
 * is removed once it comes within d/2 of them (it has entered the solid); one falling beside
 * the floor's end is not. */
static void test_removed_in_solid(void **state)
{
    (void)state;
    fixture f;
    fx_init(&f, 2, 0.05, 1e-3);
    fx_push(&f, 5, 5, 0, 0, 0, 0); /* far away */
    fx_grid(&f);
    f.scene.diffuse.sampling_rate = 0;
    pfsph_particles b;
    pfsph_grid bg;
    assert_int_equal(pfsph_particles_init(&b, 64), PFSPH_OK);
    for (int i = 0; i < 20; i++) {
        const pfsph_real p[3] = {(pfsph_real)(0.05 * i), 0, 0};
        assert_true(pfsph_particles_push(&b, p, NULL, 0) >= 0);
    }
    const pfsph_real lo[3] = {-10, -10, 0}, hi[3] = {10, 10, 0};
    assert_int_equal(pfsph_grid_init(&bg, 2, lo, hi, f.ctx.h), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(&bg, &b, NULL), PFSPH_OK);
    f.ctx.boundary = &b;
    f.ctx.bgrid = &bg;
    pfsph_diffuse *d = mk(&f);
    const pfsph_real xa[3] = {0.5, 0.2, 0}, xb[3] = {1.5, 0.2, 0}, v0[3] = {0, -1, 0};
    assert_int_equal(pfsph_diffuse_add(d, xa, v0, PFSPH_DIFFUSE_SPRAY, 100), 0);
    assert_true(pfsph_diffuse_add(d, xb, v0, PFSPH_DIFFUSE_SPRAY, 100) >= 0);
    double ymin_seen = 1;
    for (int s = 1; s <= 300; s++) {
        f.ctx.step = (uint64_t)s;
        pfsph_diffuse_step(d, &f.ctx);
        const pfsph_particles *p = pfsph_diffuse_particles(d);
        for (size_t i = 0; i < p->n; i++)
            if (fabs(p->x[i] - 0.5) < 1e-3) ymin_seen = fmin(ymin_seen, p->y[i]);
    }
    const pfsph_particles *p = pfsph_diffuse_particles(d);
    assert_int_equal(p->n, 1);               /* the one over the floor is gone */
    assert_true(fabs(p->x[0] - 1.5) < 1e-6); /* the other falls on */
    assert_true(p->y[0] < -0.1);
    assert_true(ymin_seen >= 0.025 - 0.01 - 1e-6); /* removed within one step (1 cm) of d/2 */
    pfsph_diffuse_destroy(d);
    pfsph_grid_free(&bg);
    pfsph_particles_free(&b);
    fx_free(&f);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spray_parabola),   cmocka_unit_test(test_foam_follows_flow),
        cmocka_unit_test(test_bubble_rises),     cmocka_unit_test(test_classification),
        cmocka_unit_test(test_lifetime_and_cap), cmocka_unit_test(test_rest_makes_nothing),
        cmocka_unit_test(test_shear_layer_rate), cmocka_unit_test(test_emission_cylinder),
        cmocka_unit_test(test_determinism),      cmocka_unit_test(test_fluid_untouched),
        cmocka_unit_test(test_gas_not_counted),  cmocka_unit_test(test_removed_in_solid),
    };
    return tu_run_group(tests, NULL, NULL);
}
