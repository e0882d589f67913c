/* Uniform grid (grid.h): removal of outside / non-finite particles, neighbour ranges against the
 * brute-force oracle for radii h and 1.39 h, determinism across runs and thread counts. */
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/grid.h"
#include "testutil.h"

static const pfsph_real H = (pfsph_real)0.05;
static const pfsph_real KH = (pfsph_real)1.39; /* the pairwise-force radius factor */
static const pfsph_real LO[3] = {-0.2f, 0.1f, -0.3f};
static const pfsph_real HI[3] = {0.8f, 0.9f, 0.3f};

/* Fixed-seed LCG (Knuth MMIX constants): no dependence on libc rand. */
static uint64_t lcg_state;
static double lcg_uniform(void)
{
    lcg_state = lcg_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(lcg_state >> 11) * (1.0 / 9007199254740992.0);
}

static int inside(int dim, const pfsph_real p[3])
{
    for (int a = 0; a < dim; a++)
        if (!(p[a] >= LO[a] && p[a] <= HI[a])) return 0;
    return 1;
}

/* n random particles over the domain widened by 10% on each side (so some fall outside), plus
 * particles exactly on the faces and corners, on cell boundaries, and with NaN / inf positions.
 * in_flag[id] says whether the particle should survive the sort. */
static void make_set(pfsph_particles *ps, int dim, size_t n, uint64_t seed, unsigned char *in_flag, size_t *n_out)
{
    lcg_state = seed;
    assert_int_equal(pfsph_particles_init(ps, 16), PFSPH_OK);
    size_t outside = 0;
    for (size_t i = 0; i < n; i++) {
        pfsph_real p[3] = {0, 0, 0};
        for (int a = 0; a < dim; a++) {
            double w = (double)(HI[a] - LO[a]);
            p[a] = (pfsph_real)((double)LO[a] - 0.1 * w + 1.2 * w * lcg_uniform());
        }
        int kind = (int)(lcg_uniform() * 40);
        if (kind == 0) { /* exactly on a face */
            int a = (int)(lcg_uniform() * dim);
            p[a] = lcg_uniform() < 0.5 ? LO[a] : HI[a];
        } else if (kind == 1) { /* a corner */
            for (int a = 0; a < dim; a++) p[a] = lcg_uniform() < 0.5 ? LO[a] : HI[a];
        } else if (kind == 2) { /* on a cell boundary (as computed in float) */
            int a = (int)(lcg_uniform() * dim);
            int c = (int)(lcg_uniform() * (double)((HI[a] - LO[a]) / (KH * H)));
            p[a] = LO[a] + (pfsph_real)c * (KH * H);
        } else if (kind == 3) { /* non-finite */
            int a = (int)(lcg_uniform() * dim);
            p[a] = lcg_uniform() < 0.7 ? (pfsph_real)NAN : (pfsph_real)INFINITY;
        } else if (kind == 4) { /* a copy of the previous particle (zero distance) */
            if (ps->n) {
                p[0] = ps->x[ps->n - 1];
                p[1] = ps->y[ps->n - 1];
                p[2] = ps->z[ps->n - 1];
            }
        }
        long k = pfsph_particles_push(ps, p, NULL, (uint8_t)(i % 7));
        assert_true(k >= 0);
        ps->aux[k] = (pfsph_real)k; /* a payload that must follow the particle */
        in_flag[ps->id[k]] = (unsigned char)inside(dim, p);
        if (!in_flag[ps->id[k]]) outside++;
    }
    *n_out = outside;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Sort, then check the kept set and the neighbour ranges for both radii. */
/* fine: cells of max(h/2, k h/3) walked 2 (h) or 3 (k h) cells each way, as with pair forces */
static void check_dim(int dim, size_t n, int fine)
{
    pfsph_particles ps;
    unsigned char *in_flag = calloc(n, 1);
    assert_non_null(in_flag);
    size_t n_outside;
    make_set(&ps, dim, n, 1000 + (uint64_t)dim, in_flag, &n_outside);
    pfsph_grid g;
    /* fine 0: cells of k h; 1: of h / 2 (reaches 2 and 3); 2: of h (reaches 1 and 2, the
     * pair forces' grid) */
    const pfsph_real cell = fine == 1 ? (H / 2 > KH * H / 3 ? H / 2 : KH * H / 3) : fine == 2 ? H : KH * H;
    assert_int_equal(pfsph_grid_init(&g, dim, LO, HI, cell), PFSPH_OK);
    if (fine == 1) {
        g.reach = 2;
        g.reach_far = 3;
    } else if (fine == 2) {
        g.reach = 1;
        g.reach_far = 2;
    }
    size_t removed = 0;
    assert_int_equal(pfsph_grid_sort(&g, &ps, &removed), PFSPH_OK);
    printf("%dD: %zu particles, %zu outside/non-finite, removed %zu, kept %zu, grid %dx%dx%d\n", dim, n, n_outside,
           removed, ps.n, g.nc[0], g.nc[1], g.nc[2]);
    assert_int_equal(removed, n_outside);
    assert_int_equal(ps.n, n - n_outside);

    /* kept ids are exactly the inside ones, each once; payload and phase followed */
    unsigned char *seen = calloc(n, 1);
    assert_non_null(seen);
    for (size_t i = 0; i < ps.n; i++) {
        uint32_t id = ps.id[i];
        assert_true(id < n);
        assert_true(in_flag[id]);
        assert_false(seen[id]);
        seen[id] = 1;
        assert_true(ps.aux[i] == (pfsph_real)id);
        assert_int_equal(ps.phase[i], id % 7);
        pfsph_real p[3] = {ps.x[i], ps.y[i], ps.z[i]};
        assert_true(inside(dim, p));
    }
    assert_int_equal(g.start[g.ncells], ps.n);
    for (size_t c = 0; c < g.ncells; c++) assert_true(g.start[c] <= g.start[c + 1]);

    /* neighbour ranges filtered by distance == brute force, radius h and 1.39 h */
    uint32_t *brute = malloc(ps.n * sizeof(uint32_t)), *got = malloc(ps.n * sizeof(uint32_t));
    assert_non_null(brute);
    assert_non_null(got);
    const pfsph_real radii[2] = {H, KH * H};
    for (int ri = 0; ri < 2; ri++) {
        double r2 = (double)radii[ri] * (double)radii[ri];
        size_t total = 0, max_nb = 0, max_range = 0, trimmed = 0;
        for (size_t i = 0; i < ps.n; i++) {
            size_t nb = pfsph_neighbors_brute(&ps, i, radii[ri], brute, ps.n);
            pfsph_ranges rg;
            const int R = ri == 0 ? g.reach : g.reach_far;
            pfsph_grid_ranges_reach(&g, ps.x[i], ps.y[i], ps.z[i], R, &rg);
            assert_true(rg.n <= (dim == 3 ? (2 * R + 1) * (2 * R + 1) : 2 * R + 1));
            size_t cnt = 0, span = 0;
            for (int s = 0; s < rg.n; s++) {
                assert_true(rg.b[s] < rg.e[s] && rg.e[s] <= ps.n);
                span += rg.e[s] - rg.b[s];
                for (uint32_t j = rg.b[s]; j < rg.e[s]; j++) {
                    if (j == i) continue;
                    /* the same distance test as the oracle */
                    double dx = (double)ps.x[i] - ps.x[j], dy = (double)ps.y[i] - ps.y[j],
                           dz = (double)ps.z[i] - ps.z[j];
                    if (dx * dx + dy * dy + dz * dz < r2) got[cnt++] = j;
                }
            }
            qsort(got, cnt, sizeof(uint32_t), cmp_u32);
            for (size_t q = 1; q < cnt; q++) assert_true(got[q] != got[q - 1]); /* disjoint */
            if (cnt != nb || memcmp(got, brute, nb * sizeof(uint32_t)) != 0)
                fail_msg("%dD radius %.4f particle %zu at (%.9g, %.9g, %.9g): grid %zu, brute %zu", dim,
                         (double)radii[ri], i, (double)ps.x[i], (double)ps.y[i], (double)ps.z[i], cnt, nb);
            /* the band of cells the ball touches (pfsph_grid_ranges_radius): the same set */
            pfsph_grid_ranges_radius(&g, ps.x[i], ps.y[i], ps.z[i], radii[ri], &rg);
            cnt = 0;
            for (int s = 0; s < rg.n; s++)
                for (uint32_t j = rg.b[s]; j < rg.e[s]; j++) {
                    if (j == i) continue;
                    double dx = (double)ps.x[i] - ps.x[j], dy = (double)ps.y[i] - ps.y[j],
                           dz = (double)ps.z[i] - ps.z[j];
                    if (dx * dx + dy * dy + dz * dz < r2) got[cnt++] = j;
                }
            qsort(got, cnt, sizeof(uint32_t), cmp_u32);
            if (cnt != nb || memcmp(got, brute, nb * sizeof(uint32_t)) != 0)
                fail_msg("%dD radius %.4f particle %zu, trimmed walk: grid %zu, brute %zu", dim, (double)radii[ri], i,
                         cnt, nb);
            trimmed += rg.n;
            total += nb;
            if (nb > max_nb) max_nb = nb;
            if (span > max_range) max_range = span;
        }
        printf("%dD radius %.4f: mean %.2f neighbours (max %zu), largest candidate set %zu, trimmed walk "
               "%.2f rows\n",
               dim, (double)radii[ri], (double)total / (double)ps.n, max_nb, max_range, (double)trimmed / (double)ps.n);
    }
    free(brute);
    free(got);
    free(seen);
    free(in_flag);
    pfsph_grid_free(&g);
    pfsph_particles_free(&ps);
}

static void test_neighbours_2d(void **state)
{
    (void)state;
    check_dim(2, 3000, 0);
    check_dim(2, 3000, 1);
    check_dim(2, 3000, 2);
}
static void test_neighbours_3d(void **state)
{
    (void)state;
    check_dim(3, 8000, 0);
    check_dim(3, 8000, 1);
    check_dim(3, 8000, 2);
}

/* Sorting the same input with 1 and 2 threads, and twice in a row, gives the same order; a
 * second sort of an already sorted set is the identity (stable). */
static void sort_order(int dim, size_t n, int threads, uint32_t *order, size_t *kept)
{
    pfsph_particles ps;
    unsigned char *in_flag = calloc(n, 1);
    assert_non_null(in_flag);
    size_t n_outside;
    make_set(&ps, dim, n, 99 + (uint64_t)dim, in_flag, &n_outside);
    pfsph_grid g;
    assert_int_equal(pfsph_grid_init(&g, dim, LO, HI, KH * H), PFSPH_OK);
    omp_set_num_threads(threads);
    assert_int_equal(pfsph_grid_sort(&g, &ps, NULL), PFSPH_OK);
    memcpy(order, ps.id, ps.n * sizeof(uint32_t));
    *kept = ps.n;
    size_t removed = 0;
    assert_int_equal(pfsph_grid_sort(&g, &ps, &removed), PFSPH_OK);
    assert_int_equal(removed, 0);
    assert_int_equal(ps.n, *kept);
    assert_memory_equal(order, ps.id, ps.n * sizeof(uint32_t));
    free(in_flag);
    pfsph_grid_free(&g);
    pfsph_particles_free(&ps);
}

static void test_determinism(void **state)
{
    (void)state;
    int saved = omp_get_max_threads();
    for (int dim = 2; dim <= 3; dim++) {
        const size_t n = 5000;
        uint32_t *a = malloc(n * sizeof(uint32_t)), *b = malloc(n * sizeof(uint32_t)),
                 *c = malloc(n * sizeof(uint32_t));
        assert_non_null(a);
        assert_non_null(b);
        assert_non_null(c);
        size_t na, nb, nc;
        sort_order(dim, n, 1, a, &na);
        sort_order(dim, n, 2, b, &nb);
        sort_order(dim, n, 2, c, &nc);
        assert_int_equal(na, nb);
        assert_int_equal(na, nc);
        assert_memory_equal(a, b, na * sizeof(uint32_t));
        assert_memory_equal(a, c, na * sizeof(uint32_t));
        free(a);
        free(b);
        free(c);
    }
    omp_set_num_threads(saved);
}

/* pfsph_grid_near against pfsph_grid_ranges, and pfsph_grid_near_far (reach_far = reach + 1)
 * against pfsph_grid_ranges_far: a sparse set (a few clusters, as a boundary is), query points
 * over and beyond the domain; a flag is 0 exactly where its ranges are empty inside the grid,
 * 1 outside it. Reach 1 and 2, 2D and 3D. */
static void test_near(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++)
        for (int reach = 1; reach <= 2; reach++) {
            pfsph_grid g;
            assert_int_equal(pfsph_grid_init(&g, dim, LO, HI, H / (pfsph_real)reach), PFSPH_OK);
            g.reach = reach;
            g.reach_far = reach + 1; /* the pair forces' far walks: their own flags */
            g.want_near = 1;
            pfsph_particles ps;
            assert_int_equal(pfsph_particles_init(&ps, 16), PFSPH_OK);
            lcg_state = 99 + (uint64_t)(10 * dim + reach);
            for (int cl = 0; cl < 4; cl++) {
                pfsph_real c[3];
                for (int a = 0; a < 3; a++) c[a] = LO[a] + (pfsph_real)lcg_uniform() * (HI[a] - LO[a]);
                for (int k = 0; k < 30; k++) {
                    pfsph_real q[3];
                    for (int a = 0; a < 3; a++) q[a] = c[a] + (pfsph_real)(0.1 * (lcg_uniform() - 0.5));
                    if (dim == 2) q[2] = 0;
                    assert_true(pfsph_particles_push(&ps, q, NULL, 0) >= 0);
                }
            }
            assert_int_equal(pfsph_grid_sort(&g, &ps, NULL), PFSPH_OK);
            assert_non_null(g.near);
            assert_non_null(g.near_far);
            int zero = 0, one = 0, zero_far = 0;
            for (int t = 0; t < 20000; t++) {
                pfsph_real q[3];
                for (int a = 0; a < 3; a++) q[a] = LO[a] + (pfsph_real)((1.2 * lcg_uniform() - 0.1)) * (HI[a] - LO[a]);
                if (dim == 2) q[2] = 0;
                pfsph_ranges r;
                pfsph_grid_ranges(&g, q[0], q[1], q[2], &r);
                const int nr = pfsph_grid_near(&g, q[0], q[1], q[2]);
                /* inside the grid's cells the flags are exact; outside them they answer 1 */
                const int in_cells = inside(dim, q) && q[0] < LO[0] + (pfsph_real)g.nc[0] * g.cell &&
                    q[1] < LO[1] + (pfsph_real)g.nc[1] * g.cell &&
                    (dim == 2 || q[2] < LO[2] + (pfsph_real)g.nc[2] * g.cell);
                if (!nr) assert_int_equal(r.n, 0);
                if (in_cells) assert_int_equal(nr, r.n > 0);
                zero += !nr;
                one += nr;
                /* the far flags against the far walk (its radius-trimmed form walks a subset) */
                pfsph_grid_ranges_far(&g, q[0], q[1], q[2], &r);
                const int nf = pfsph_grid_near_far(&g, q[0], q[1], q[2]);
                if (!nf) assert_int_equal(r.n, 0);
                if (in_cells) assert_int_equal(nf, r.n > 0);
                if (nr) assert_true(nf); /* a wider reach finds at least as much */
                zero_far += !nf;
            }
            print_message("dim %d reach %d: %d empty, %d near of 20000 points; %d empty at reach %d\n", dim, reach,
                          zero, one, zero_far, g.reach_far);
            assert_true(zero > 1000 && one > 1000);
            assert_true(zero_far > 100 && zero_far < zero);
            pfsph_particles_free(&ps);
            pfsph_grid_free(&g);
        }
}

/* Small explicit cases: NaN in each coordinate is removed; faces, corners kept; a point outside
 * the domain still gets valid (possibly empty) ranges. */
static void test_edge_cases(void **state)
{
    (void)state;
    for (int dim = 2; dim <= 3; dim++) {
        pfsph_particles ps;
        assert_int_equal(pfsph_particles_init(&ps, 4), PFSPH_OK);
        const pfsph_real nan = (pfsph_real)NAN;
        pfsph_real pts[][3] = {
            {LO[0], LO[1], dim == 3 ? LO[2] : 0}, /* 0: corner lo: kept */
            {HI[0], HI[1], dim == 3 ? HI[2] : 0}, /* 1: corner hi: kept */
            {HI[0], 0.5f, 0},                     /* 2: face x = hi: kept */
            {0.3f, LO[1], 0},                     /* 3: face y = lo: kept */
            {nan, 0.5f, 0},                       /* 4: removed */
            {0.3f, nan, 0},                       /* 5: removed */
            {0.3f, 0.5f, dim == 3 ? nan : 0},     /* 6: removed in 3D */
            {nan, nan, nan},                      /* 7: removed */
            {nextafterf(HI[0], 1.0f), 0.5f, 0},   /* 8: just outside: removed */
            {0.3f, nextafterf(LO[1], -1.0f), 0},  /* 9: just outside: removed */
            {0.3f, 0.5f, dim == 3 ? HI[2] : 0},   /* 10: face z = hi in 3D: kept */
        };
        const int npts = (int)(sizeof pts / sizeof pts[0]);
        const int kept_2d[] = {1, 1, 1, 1, 0, 0, 1, 0, 0, 0, 1};
        const int kept_3d[] = {1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 1};
        size_t expect = 0;
        for (int i = 0; i < npts; i++) {
            assert_true(pfsph_particles_push(&ps, pts[i], NULL, 0) >= 0);
            expect += (size_t)(dim == 3 ? kept_3d[i] : kept_2d[i]);
        }
        pfsph_grid g;
        assert_int_equal(pfsph_grid_init(&g, dim, LO, HI, KH * H), PFSPH_OK);
        size_t removed = 7; /* the count is added to */
        assert_int_equal(pfsph_grid_sort(&g, &ps, &removed), PFSPH_OK);
        assert_int_equal(ps.n, expect);
        assert_int_equal(removed, 7 + (size_t)npts - expect);
        for (size_t i = 0; i < ps.n; i++) {
            uint32_t id = ps.id[i];
            assert_true(dim == 3 ? kept_3d[id] : kept_2d[id]);
        }
        /* every kept particle finds itself among its candidate ranges */
        for (size_t i = 0; i < ps.n; i++) {
            pfsph_ranges rg;
            pfsph_grid_ranges(&g, ps.x[i], ps.y[i], ps.z[i], &rg);
            int found = 0;
            for (int s = 0; s < rg.n; s++) found |= rg.b[s] <= i && i < rg.e[s];
            assert_true(found);
        }
        /* query points outside the domain: ranges stay in bounds */
        pfsph_ranges rg;
        pfsph_grid_ranges(&g, LO[0] - 10, 0.5f, 0, &rg);
        assert_int_equal(rg.n, 0);
        pfsph_grid_ranges(&g, HI[0] + KH * H * 0.5f, HI[1], dim == 3 ? HI[2] : 0, &rg);
        int found_corner = 0;
        for (int s = 0; s < rg.n; s++) {
            assert_true(rg.e[s] <= ps.n);
            for (uint32_t j = rg.b[s]; j < rg.e[s]; j++) found_corner |= ps.id[j] == 1;
        }
        assert_true(found_corner);
        pfsph_grid_free(&g);
        pfsph_particles_free(&ps);
    }
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_neighbours_2d), cmocka_unit_test(test_neighbours_3d), cmocka_unit_test(test_determinism),
        cmocka_unit_test(test_edge_cases),    cmocka_unit_test(test_near),
    };
    return tu_run_group(tests, NULL, NULL);
}
