/* Surface particle detection (src/pfsph/surface_detect.h; Barecasco, Terissa & Naa 2013,
 * PF Fig. 9) against shapes whose surface is known: lattice disc, box and annulus (2D), sphere,
 * box and spherical shell (3D). The geometric outer layer of a lattice shape is the set of
 * particles with one of their 2 dim axis neighbours missing; its second layer is the outer
 * layer of what remains. A particle all of whose lattice sites within the detection radius
 * (2 d) are filled is deep interior and must never be flagged. Mistakes (an outer particle
 * missed, or a particle between the outer layer and the deep interior flagged) are counted per
 * hundred outer particles; bounds below, measured values printed. Also: jittered lattices,
 * walls that cover, groups (bubbles) that do not cover each other, 1 vs 2 threads. */
#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/grid.h"
#include "pfsph/surface_detect.h"
#include "testutil.h"

#define N 24 /* lattice sites per axis each side of 0: indices -N .. N-1 */
#define S (2 * N)

typedef bool (*shape_fn)(int dim, const double p[3], const double *par);

static bool in_disc(int dim, const double p[3], const double *par)
{
    double r2 = p[0] * p[0] + p[1] * p[1] + (dim == 3 ? p[2] * p[2] : 0);
    return r2 < par[0] * par[0] && r2 >= par[1] * par[1]; /* par: outer, inner radius */
}

static bool in_box(int dim, const double p[3], const double *par)
{
    for (int a = 0; a < dim; a++)
        if (fabs(p[a]) > par[a]) return false;
    return true;
}

typedef struct world {
    pfsph_particles fluid, boundary;
    pfsph_grid grid, bgrid;
    pfsph_ctx ctx;
    int dim;
    double d;
    bool occ[S * S * S]; /* lattice occupancy, in units of d */
    int site[S * S * S]; /* ids of the fluid particle at a site, -1 */
} world;

static int sidx(int i, int j, int k) { return ((k + N) * S + (j + N)) * S + (i + N); }

/* Fill the shape's lattice sites ((i + 1/2) d), optional jitter, then grids and context. */
static void build(world *w, int dim, shape_fn in, const double *par, double jitter, uint64_t seed)
{
    memset(w, 0, sizeof *w);
    w->dim = dim;
    w->d = 0.01;
    assert_int_equal(pfsph_particles_init(&w->fluid, 1024), PFSPH_OK);
    assert_int_equal(pfsph_particles_init(&w->boundary, 16), PFSPH_OK);
    uint64_t s = seed;
    const int kz0 = dim == 3 ? -N : 0, kz1 = dim == 3 ? N : 1;
    for (int k = kz0; k < kz1; k++)
        for (int j = -N; j < N; j++)
            for (int i = -N; i < N; i++) {
                double p[3] = {(i + 0.5), (j + 0.5), dim == 3 ? (k + 0.5) : 0};
                bool o = in(dim, p, par);
                w->occ[sidx(i, j, k)] = o;
                w->site[sidx(i, j, k)] = -1;
                if (!o) continue;
                pfsph_real x[3];
                for (int a = 0; a < 3; a++) {
                    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
                    double u = (double)(s >> 11) * (1.0 / 9007199254740992.0) - 0.5;
                    x[a] = (pfsph_real)((p[a] + (a < dim ? 2 * jitter * u : 0)) * w->d);
                }
                long id = pfsph_particles_push(&w->fluid, x, NULL, 0);
                assert_true(id >= 0);
                w->site[sidx(i, j, k)] = (int)id;
            }
}

static void finish(world *w)
{
    const pfsph_real lo[3] = {(pfsph_real)(-(N + 4) * w->d), (pfsph_real)(-(N + 4) * w->d),
                              (pfsph_real)(w->dim == 3 ? -(N + 4) * w->d : -w->d)};
    const pfsph_real hi[3] = {-lo[0], -lo[1], w->dim == 3 ? -lo[2] : (pfsph_real)w->d};
    const pfsph_real h = (pfsph_real)(2 * w->d);
    assert_int_equal(pfsph_grid_init(&w->grid, w->dim, lo, hi, h), PFSPH_OK);
    assert_int_equal(pfsph_grid_init(&w->bgrid, w->dim, lo, hi, h), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(&w->grid, &w->fluid, NULL), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(&w->bgrid, &w->boundary, NULL), PFSPH_OK);
    pfsph_ctx *c = &w->ctx;
    c->dim = w->dim;
    c->spacing = (pfsph_real)w->d;
    c->h = h;
    c->V0 = (pfsph_real)pow(w->d, w->dim);
    c->nd0 = 1 / c->V0;
    c->fluid = &w->fluid;
    c->boundary = &w->boundary;
    c->grid = &w->grid;
    c->bgrid = &w->bgrid;
}

static void world_free(world *w)
{
    pfsph_grid_free(&w->grid);
    pfsph_grid_free(&w->bgrid);
    pfsph_particles_free(&w->fluid);
    pfsph_particles_free(&w->boundary);
}

/* Geometric classes of every site of the occupancy `occ` (0 deep interior, 1 outer layer,
 * 3 in between); written by particle id (ids are the push order, stable under the sort). */
static void classify(const world *w, const bool *occ, int *cls)
{
    const int dim = w->dim;
    const int kz0 = dim == 3 ? -N : 0, kz1 = dim == 3 ? N : 1;
    for (int k = kz0; k < kz1; k++)
        for (int j = -N; j < N; j++)
            for (int i = -N; i < N; i++) {
                int id = w->site[sidx(i, j, k)];
                if (id < 0 || !occ[sidx(i, j, k)]) continue;
#define O(a, b, c) ((a) >= -N && (a) < N && (b) >= -N && (b) < N && (c) >= -N && (c) < N && occ[sidx(a, b, c)])
                bool outer = !O(i + 1, j, k) || !O(i - 1, j, k) || !O(i, j + 1, k) || !O(i, j - 1, k) ||
                    (dim == 3 && (!O(i, j, k + 1) || !O(i, j, k - 1)));
                bool full = true;
                const int r = 2, rz = dim == 3 ? 2 : 0;
                for (int c = -rz; c <= rz && full; c++)
                    for (int b = -r; b <= r && full; b++)
                        for (int a = -r; a <= r; a++) {
                            if (a * a + b * b + c * c >= 4) continue; /* within 2 d, strictly */
                            if (!O(i + a, j + b, k + c)) {
                                full = false;
                                break;
                            }
                        }
#undef O
                cls[id] = outer ? 1 : full ? 0 : 3;
            }
}

typedef struct tally {
    int outer, missed, band_flagged, deep_flagged;
} tally;

static tally compare(const world *w, const int *cls, const uint8_t *layer, int L, const bool *alive)
{
    tally t = {0, 0, 0, 0};
    for (size_t i = 0; i < w->fluid.n; i++) {
        const uint32_t id = w->fluid.id[i];
        if (alive && !alive[id]) continue;
        const bool got = layer[i] == L;
        if (cls[id] == 1) {
            t.outer++;
            if (!got) t.missed++;
        } else if (cls[id] == 3) {
            if (got) t.band_flagged++;
        } else if (got) {
            t.deep_flagged++;
        }
    }
    return t;
}

/* Detect two layers and compare each with geometry. max_per100: allowed mistakes per hundred
 * outer particles. */
static void check_shape(const char *name, int dim, shape_fn in, const double *par, double jitter, double max_per100)
{
    world *w = malloc(sizeof *w);
    assert_non_null(w);
    build(w, dim, in, par, jitter, 12345);
    finish(w);
    const size_t n = w->fluid.n;
    uint8_t *layer = malloc(n), *work = malloc(n), *layer2 = malloc(n);
    int *cls = malloc(n * sizeof(int)), *cls2 = malloc(n * sizeof(int));
    bool *alive = malloc(n);
    assert_true(layer && work && layer2 && cls && cls2 && alive);
    pfsph_surface_opts o = {.radius = 0, .layers = 2, .group = NULL, .boundary = true, .reach = 0};
    omp_set_num_threads(1);
    pfsph_surface_detect(&w->ctx, &o, layer, work);
    omp_set_num_threads(2);
    pfsph_surface_detect(&w->ctx, &o, layer2, work);
    assert_memory_equal(layer, layer2, n); /* thread-count independent */
    classify(w, w->occ, cls);
    tally t1 = compare(w, cls, layer, 1, NULL);
    /* layer 2: the outer layer of the shape without its geometric outer layer */
    bool *occ2 = malloc(sizeof w->occ);
    assert_non_null(occ2);
    memcpy(occ2, w->occ, sizeof w->occ);
    for (size_t s = 0; s < (size_t)S * S * S; s++)
        if (occ2[s] && w->site[s] >= 0 && cls[w->site[s]] == 1) occ2[s] = false;
    for (size_t i = 0; i < n; i++) alive[i] = cls[i] != 1;
    for (size_t i = 0; i < n; i++) cls2[i] = -1;
    classify(w, occ2, cls2);
    tally t2 = compare(w, cls2, layer, 2, alive);
    const double m1 = 100.0 * (t1.missed + t1.band_flagged) / t1.outer;
    const double m2 = 100.0 * (t2.missed + t2.band_flagged) / t2.outer;
    print_message("%-22s %5zu particles, jitter %.2f d: layer 1: %4d outer, %3d missed, %3d flagged inside "
                  "the band, %d deep interior flagged (%.2f mistakes per 100, bound %.1f); layer 2: %4d, %3d "
                  "missed, %3d flagged in its band, %d deep flagged (%.2f per 100)\n",
                  name, n, jitter, t1.outer, t1.missed, t1.band_flagged, t1.deep_flagged, m1, max_per100, t2.outer,
                  t2.missed, t2.band_flagged, t2.deep_flagged, m2);
    assert_int_equal(t1.deep_flagged, 0);
    assert_int_equal(t2.deep_flagged, 0);
    assert_true(m1 <= max_per100);
    assert_true(m2 <= max_per100);
    /* deep interior of the whole shape is never in either layer */
    for (size_t i = 0; i < n; i++)
        if (cls[w->fluid.id[i]] == 0 && cls2[w->fluid.id[i]] == 0) assert_int_equal(layer[i], 0);
    free(occ2);
    free(layer);
    free(layer2);
    free(work);
    free(cls);
    free(cls2);
    free(alive);
    world_free(w);
    free(w);
}

/* Lattice shapes: the detection is exact (0 mistakes, both layers) on all six. With the
 * paper's single test point the 2D disc missed 8 of its 68 outer particles (the one-site
 * notches of the staircase, docs/film.md); the bound, 2 per 100, catches that. */
static void test_lattice_2d(void **state)
{
    (void)state;
    const double disc[2] = {12.3, 0}, ring[2] = {14.2, 6.1}, box[3] = {10, 7, 0};
    check_shape("2D disc R 12.3 d", 2, in_disc, disc, 0, 2);
    check_shape("2D annulus 6.1-14.2 d", 2, in_disc, ring, 0, 2);
    check_shape("2D box 20 x 14 d", 2, in_box, box, 0, 2);
}

static void test_lattice_3d(void **state)
{
    (void)state;
    const double sph[2] = {8.4, 0}, shell[2] = {9.3, 4.2}, box[3] = {6, 5, 4};
    check_shape("3D sphere R 8.4 d", 3, in_disc, sph, 0, 2);
    check_shape("3D shell 4.2-9.3 d", 3, in_disc, shell, 0, 2);
    check_shape("3D box 12 x 10 x 8 d", 3, in_box, box, 0, 2);
}

/* Lattices jittered by up to 0.1 d in each coordinate (a liquid's disorder): the deep interior
 * stays unflagged; measured mistakes per 100 outer particles, layer 1 / layer 2: disc 0 / 0,
 * annulus 2.6 / 4.3, sphere 0.9 / 3.1, shell 1.9 / 4.1 (missed ones in the inner cavity mostly);
 * allowed up to 10. */
static void test_jittered(void **state)
{
    (void)state;
    const double disc[2] = {12.3, 0}, ring[2] = {14.2, 6.1}, sph[2] = {8.4, 0}, shell[2] = {9.3, 4.2};
    check_shape("2D disc, jittered", 2, in_disc, disc, 0.1, 10);
    check_shape("2D annulus, jittered", 2, in_disc, ring, 0.1, 10);
    check_shape("3D sphere, jittered", 3, in_disc, sph, 0.1, 10);
    check_shape("3D shell, jittered", 3, in_disc, shell, 0.1, 10);
}

/* A box resting on a wall: with boundary particles covering, its bottom row is not surface;
 * without, it is. Two boxes side by side in two groups: the touching columns are surface of
 * their own group; in one group they are interior. */
static void test_walls_and_groups(void **state)
{
    (void)state;
    world *w = malloc(sizeof *w);
    assert_non_null(w);
    const double box[3] = {8, 4, 0};
    build(w, 2, in_box, box, 0, 1);
    for (int i = -12; i < 12; i++)
        for (int l = 1; l <= 2; l++) { /* wall rows below y = -4 d */
            const pfsph_real x[3] = {(pfsph_real)((i + 0.5) * w->d), (pfsph_real)((-4 - l + 0.5) * w->d), 0};
            assert_true(pfsph_particles_push(&w->boundary, x, NULL, 1) >= 0);
        }
    finish(w);
    const size_t n = w->fluid.n;
    uint8_t *L = malloc(n);
    assert_non_null(L);
    int bottom_with = 0, bottom_without = 0, nbottom = 0;
    pfsph_surface_opts o = {.layers = 1, .boundary = true};
    pfsph_surface_detect(&w->ctx, &o, L, NULL);
    for (size_t i = 0; i < n; i++)
        if (w->fluid.y[i] < (pfsph_real)(-3 * w->d) && fabs((double)w->fluid.x[i]) < 6 * w->d) {
            nbottom++;
            bottom_with += L[i] == 1;
        }
    o.boundary = false;
    pfsph_surface_detect(&w->ctx, &o, L, NULL);
    for (size_t i = 0; i < n; i++)
        if (w->fluid.y[i] < (pfsph_real)(-3 * w->d) && fabs((double)w->fluid.x[i]) < 6 * w->d)
            bottom_without += L[i] == 1;
    print_message("bottom row away from the corners: %d particles, %d flagged over a wall, %d without it\n", nbottom,
                  bottom_with, bottom_without);
    assert_true(nbottom > 0);
    assert_int_equal(bottom_with, 0);
    assert_int_equal(bottom_without, nbottom);
    /* groups: left half (x < 0) group 1, right half group 2 */
    uint8_t *g = malloc(n);
    assert_non_null(g);
    for (size_t i = 0; i < n; i++) g[i] = w->fluid.x[i] < 0 ? 1 : 2;
    o.boundary = true;
    o.group = g;
    pfsph_surface_detect(&w->ctx, &o, L, NULL);
    int seam = 0, seam_flagged = 0;
    for (size_t i = 0; i < n; i++)
        if (fabs((double)w->fluid.x[i]) < w->d && fabs((double)w->fluid.y[i]) < 2.5 * w->d) {
            seam++;
            seam_flagged += L[i] == 1;
        }
    o.group = NULL;
    pfsph_surface_detect(&w->ctx, &o, L, NULL);
    int seam_one = 0;
    for (size_t i = 0; i < n; i++)
        if (fabs((double)w->fluid.x[i]) < w->d && fabs((double)w->fluid.y[i]) < 2.5 * w->d) seam_one += L[i] == 1;
    print_message("seam between two groups: %d particles, %d flagged as two groups, %d as one\n", seam, seam_flagged,
                  seam_one);
    assert_true(seam > 0);
    assert_int_equal(seam_flagged, seam);
    assert_int_equal(seam_one, 0);
    free(g);
    free(L);
    world_free(w);
    free(w);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_lattice_2d), cmocka_unit_test(test_lattice_3d),
                                       cmocka_unit_test(test_jittered), cmocka_unit_test(test_walls_and_groups)};
    return tu_run_group(tests, NULL, NULL);
}
