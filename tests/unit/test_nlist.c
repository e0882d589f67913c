/* Neighbour lists (src/core/nlist.h) against a brute-force search: the two-walk build, and the
 * one-walk build of the density pass (physics/density.c), fluid and boundary lists, in its
 * three paths (first build, planned regions, a region that overflows and falls back to a
 * second walk); each list in
 * grid-walk order with the kernel derivative of each pair; the same lists and densities for 1
 * and 2 threads. */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/nlist.h"
#include "physics/density.h"
#include "testutil.h"

static const pfsph_real H = (pfsph_real)0.05;

static uint64_t lcg_state;
static double lcg_uniform(void)
{
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
}

/* a jittered lattice of spacing H / 2 (about 30 neighbours within H in 3D), sorted in g */
static void make_set(pfsph_particles *ps, pfsph_grid *g, int dim, int m)
{
    assert_int_equal(pfsph_particles_init(ps, 16), PFSPH_OK);
    const double d = (double)H / 2;
    for (int k = 0; k < (dim == 3 ? m : 1); k++)
        for (int j = 0; j < m; j++)
            for (int i = 0; i < m; i++) {
                pfsph_real p[3] = {(pfsph_real)(d * (i + 0.3 * lcg_uniform())),
                                   (pfsph_real)(d * (j + 0.3 * lcg_uniform())),
                                   dim == 3 ? (pfsph_real)(d * (k + 0.3 * lcg_uniform())) : 0};
                assert_true(pfsph_particles_push(ps, p, NULL, 0) >= 0);
            }
    const pfsph_real lo[3] = {-0.1f, -0.1f, dim == 3 ? -0.1f : 0}, hi[3] = {1, 1, dim == 3 ? 1 : 0};
    assert_int_equal(pfsph_grid_init(g, dim, lo, hi, H), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(g, ps, NULL), PFSPH_OK);
}

/* every boundary list holds exactly the boundary particles within H of the fluid particle, in
 * ascending order, with their kernel derivatives */
static void check_blists(const pfsph_nlist *l, const pfsph_particles *ps, const pfsph_particles *bs,
                         const pfsph_kernel *k)
{
    const pfsph_real h2 = H * H;
    size_t total = 0;
    assert_int_equal(l->n, ps->n);
    for (size_t i = 0; i < ps->n; i++) {
        uint32_t e = l->start[i];
        for (size_t j = 0; j < bs->n; j++) {
            pfsph_real dx = ps->x[i] - bs->x[j], dy = ps->y[i] - bs->y[j], dz = ps->z[i] - bs->z[j];
            pfsph_real r2 = dx * dx + dy * dy + dz * dz;
            if (!(r2 < h2)) continue;
            assert_true(e < l->start[i + 1]);
            assert_int_equal(l->idx[e], j);
            assert_true(l->dw[e] == pfsph_kernel_dw_r(k, pfsph_sqrt(r2)));
            e++;
        }
        assert_int_equal(e, l->start[i + 1]);
        total += e - l->start[i];
    }
    assert_true(total > 0);
}

/* every list holds exactly the j != i within H (the same float expression), in ascending order
 * (the grid walk's, for cells of H: rows in order), with dw = dW/dr / r of the pair */
static void check_lists(const pfsph_nlist *l, const pfsph_particles *ps, const pfsph_kernel *k)
{
    const pfsph_real h2 = H * H;
    assert_int_equal(l->n, ps->n);
    for (size_t i = 0; i < ps->n; i++) {
        uint32_t e = l->start[i];
        for (size_t j = 0; j < ps->n; j++) {
            pfsph_real dx = ps->x[i] - ps->x[j], dy = ps->y[i] - ps->y[j], dz = ps->z[i] - ps->z[j];
            pfsph_real r2 = dx * dx + dy * dy + dz * dz;
            if (j == i || !(r2 < h2)) continue;
            assert_true(e < l->start[i + 1]);
            assert_int_equal(l->idx[e], j);
            assert_true(l->dw[e] == pfsph_kernel_dw_r(k, pfsph_sqrt(r2)));
            e++;
        }
        assert_int_equal(e, l->start[i + 1]);
    }
}

static void test_two_walks(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        lcg_state = 7u + (uint64_t)dim;
        pfsph_particles ps;
        pfsph_grid g;
        pfsph_kernel k;
        pfsph_kernel_init(&k, dim, H);
        make_set(&ps, &g, dim, dim == 3 ? 14 : 40);
        pfsph_nlist l;
        memset(&l, 0, sizeof l);
        const pfsph_nlist_sets S = {&g, ps.x, ps.y, ps.z, ps.x, ps.y, ps.z, ps.n, 1, H * H, &k};
        assert_int_equal(pfsph_nlist_build(&l, &S), PFSPH_OK);
        check_lists(&l, &ps, &k);
        pfsph_nlist_free(&l);
        pfsph_nlist_free(NULL);
        pfsph_grid_free(&g);
        pfsph_particles_free(&ps);
    }
}

/* the density pass's one-walk build: first build, planned build, overflow; densities equal to
 * the plain density pass's bits; 1 and 2 threads alike */
static void test_one_walk(void **state)
{
    (void)state;
    pfsph_particles ps, none; /* fluid, boundary */
    pfsph_grid g, bg;
    lcg_state = 99;
    make_set(&ps, &g, 3, 14);
    /* a wall: a layer of boundary particles under the fluid, volume V0 */
    assert_int_equal(pfsph_particles_init(&none, 16), PFSPH_OK);
    for (int a = -2; a < 18; a++)
        for (int b = -2; b < 18; b++) {
            pfsph_real p[3] = {(pfsph_real)(a * 0.025), (pfsph_real)-0.02, (pfsph_real)(b * 0.025)};
            long q = pfsph_particles_push(&none, p, NULL, 1);
            assert_true(q >= 0);
            none.aux[q] = (pfsph_real)(0.025 * 0.025 * 0.025);
        }
    const pfsph_real lo[3] = {-0.1f, -0.1f, -0.1f}, hi[3] = {1, 1, 1};
    assert_int_equal(pfsph_grid_init(&bg, 3, lo, hi, H), PFSPH_OK);
    assert_int_equal(pfsph_grid_sort(&bg, &none, NULL), PFSPH_OK);
    pfsph_ctx c;
    memset(&c, 0, sizeof c);
    c.dim = 3;
    c.h = H;
    c.spacing = H / 2;
    c.V0 = c.spacing * c.spacing * c.spacing;
    pfsph_kernel_init(&c.kern, 3, H);
    c.fluid = &ps;
    c.boundary = &none;
    c.grid = &g;
    c.bgrid = &bg;
    const size_t n = ps.n;
    pfsph_real *nd = calloc(n, sizeof *nd), *nd_ref = calloc(n, sizeof *nd_ref), *nd1 = calloc(n, sizeof *nd1);
    uint32_t *idx1 = NULL;
    assert_non_null(nd);
    assert_non_null(nd_ref);
    assert_non_null(nd1);
    for (int threads = 1; threads <= 2; threads++) {
        omp_set_num_threads(threads);
        pfsph_nlist l, lb;
        memset(&l, 0, sizeof l);
        memset(&lb, 0, sizeof lb);
        for (int round = 0; round < 3; round++) {
            if (round == 2) { /* squeeze the set: more neighbours than the plan's 1/8 of room */
                for (size_t i = 0; i < n; i++) {
                    ps.x[i] *= (pfsph_real)0.8;
                    ps.y[i] *= (pfsph_real)0.8;
                    ps.z[i] *= (pfsph_real)0.8;
                }
                assert_int_equal(pfsph_grid_sort(&g, &ps, NULL), PFSPH_OK);
            }
            assert_int_equal(pfsph__number_density_list(&c, nd, &l, &lb, 40.0), PFSPH_OK);
            pfsph__number_density(&c, ps.x, ps.y, ps.z, nd_ref);
            assert_memory_equal(nd, nd_ref, n * sizeof *nd);
            check_lists(&l, &ps, &c.kern);
            check_blists(&lb, &ps, &none, &c.kern);
        }
        if (threads == 1) {
            memcpy(nd1, nd, n * sizeof *nd);
            idx1 = malloc(l.start[n] * sizeof *idx1);
            assert_non_null(idx1);
            memcpy(idx1, l.idx, l.start[n] * sizeof *idx1);
        } else {
            assert_memory_equal(nd1, nd, n * sizeof *nd);
            assert_memory_equal(idx1, l.idx, l.start[n] * sizeof *idx1);
        }
        pfsph_nlist_free(&l);
        pfsph_nlist_free(&lb);
        /* the next thread count starts from the same set */
        pfsph_grid_free(&g);
        pfsph_particles_free(&ps);
        lcg_state = 99;
        make_set(&ps, &g, 3, 14);
    }
    free(idx1);
    free(nd);
    free(nd_ref);
    free(nd1);
    pfsph_grid_free(&g);
    pfsph_grid_free(&bg);
    pfsph_particles_free(&ps);
    pfsph_particles_free(&none);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_walks),
        cmocka_unit_test(test_one_walk),
    };
    return tu_run_group(tests, NULL, NULL);
}
