/* Per-solid wall friction in the scene (issue 11): the "slip" and "viscosity" keys, their
 * errors, the wall model every boundary particle carries (also after a boundary sort), and the
 * scene hash of checkpoints (default walls keep the former hash). */
#include <stdio.h>
#include <string.h>

#include "pfsph/checkpoint.h"
#include "pfsph/ctx.h"
#include "pfsph/scene.h"
#include "pfsph/sim.h"
#include "testutil.h"

static pfsph_scene g_scene;

static const char *SCENE = "{\"dimension\":2,\"particle_radius\":0.01,\"domain\":{\"min\":[-0.1,-0.1],\"max\":[1,1]},"
                           "\"phases\":[{\"name\":\"w\",\"viscosity\":0.001}],"
                           "\"fluid\":[{\"shape\":\"box\",\"min\":[0.2,0.2],\"max\":[0.4,0.4]}],"
                           "\"solids\":[{\"shape\":\"container\",\"min\":[0,0],\"max\":[0.8,0.8]%s},"
                           "{\"shape\":\"sphere\",\"center\":[0.6,0.3],\"radius\":0.05%s},"
                           "{\"shape\":\"box\",\"min\":[0.5,0.6],\"max\":[0.7,0.7]%s}]}";

static int parse3(const char *a, const char *b, const char *c, pfsph_error *err)
{
    char json[2048];
    snprintf(json, sizeof json, SCENE, a, b, c);
    memset(err, 0, sizeof *err);
    return pfsph_scene_parse(&g_scene, json, "walls.json", err);
}

static void test_keys(void **state)
{
    (void)state;
    pfsph_error err;
    assert_int_equal(parse3("", ",\"slip\":\"free-slip\"", ",\"viscosity\":0.004", &err), PFSPH_OK);
    assert_int_equal(g_scene.solids[0].slip, PFSPH_NO_SLIP);
    assert_false(g_scene.solids[0].own_viscosity);
    assert_int_equal(g_scene.solids[1].slip, PFSPH_FREE_SLIP);
    assert_true(g_scene.solids[2].own_viscosity && g_scene.solids[2].viscosity == 0.004);
    static const struct {
        const char *key, *path, *msg;
    } bad[] = {
        {",\"slip\":\"partial\"", "$.solids[1].slip",
         "unknown value \"partial\" (expected one of \"no-slip\", \"free-slip\")"},
        {",\"slip\":true", "$.solids[1].slip", "expected a string"},
        {",\"viscosity\":-1", "$.solids[1].viscosity", "out of range"},
        {",\"viscosity\":1000", "$.solids[1].viscosity", "out of range"},
        {",\"slip\":\"free-slip\",\"viscosity\":0.01", "$.solids[1].viscosity", "a free-slip wall has no friction"},
        {",\"viscocity\":0.01", "$.solids[1]", "viscosity"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(parse3("", bad[i].key, "", &err), PFSPH_EINPUT);
        printf("%s\n", err.msg);
        assert_non_null(strstr(err.msg, "walls.json: "));
        assert_non_null(strstr(err.msg, bad[i].path));
        assert_non_null(strstr(err.msg, bad[i].msg));
    }
}

/* Each boundary particle carries its solid's wall model; equal settings share one. */
static void test_wall_models(void **state)
{
    (void)state;
    pfsph_error err;
    assert_int_equal(parse3(",\"slip\":\"free-slip\"", ",\"viscosity\":0.004", ",\"slip\":\"free-slip\"", &err),
                     PFSPH_OK);
    pfsph_sim *sim = NULL;
    assert_int_equal(pfsph_sim_create(&sim, &g_scene, &err), PFSPH_OK);
    const pfsph_ctx *c = pfsph_sim_ctx(sim);
    assert_int_equal(c->nwalls, 3); /* the default (unused here), free slip, 0.004 */
    int seen[3] = {0, 0, 0};
    for (size_t j = 0; j < c->boundary->n; j++) {
        int w = c->boundary->wall[j];
        assert_true(w >= 1 && w < 3);
        seen[w]++;
        /* the sphere (the only solid near x = 0.6, y = 0.3) is the one with its own viscosity */
        double dx = c->boundary->x[j] - 0.6, dy = c->boundary->y[j] - 0.3;
        int sphere = dx * dx + dy * dy < 0.06 * 0.06;
        assert_true((c->wall_scale[w] == 0 && c->wall_nu[w] == (pfsph_real)0.004) == sphere);
        assert_true((c->wall_scale[w] == 0 && c->wall_nu[w] == 0) == !sphere);
    }
    assert_true(seen[1] > 0 && seen[2] > 0);
    pfsph_sim_destroy(sim);
    /* default walls: one model, the fluid's viscosity */
    assert_int_equal(parse3("", "", "", &err), PFSPH_OK);
    assert_int_equal(pfsph_sim_create(&sim, &g_scene, &err), PFSPH_OK);
    c = pfsph_sim_ctx(sim);
    assert_int_equal(c->nwalls, 1);
    for (size_t j = 0; j < c->boundary->n; j++) assert_int_equal(c->boundary->wall[j], 0);
    pfsph_sim_destroy(sim);
}

/* The wall model follows its particle through a permutation (the boundary sort of bodies). */
static void test_permute_keeps_wall(void **state)
{
    (void)state;
    pfsph_particles ps;
    assert_int_equal(pfsph_particles_init(&ps, 4), PFSPH_OK);
    for (int i = 0; i < 5; i++) {
        pfsph_real x[3] = {(pfsph_real)i, 0, 0};
        long k = pfsph_particles_push(&ps, x, NULL, 0);
        assert_true(k == i);
        ps.wall[k] = (uint8_t)(10 + i);
    }
    const uint32_t perm[4] = {4, 2, 0, 3};
    assert_int_equal(pfsph_particles_permute(&ps, perm, 4, NULL), PFSPH_OK);
    for (int i = 0; i < 4; i++) {
        assert_int_equal(ps.wall[i], 10 + (int)perm[i]);
        assert_true(ps.x[i] == (pfsph_real)perm[i]);
    }
    pfsph_particles_free(&ps);
}

/* A checkpoint belongs to its walls: slip and viscosity change the scene hash, the default
 * spelled out does not (checkpoints of earlier versions stay resumable). */
static void test_hash(void **state)
{
    (void)state;
    pfsph_error err;
    assert_int_equal(parse3("", "", "", &err), PFSPH_OK);
    uint64_t base = pfsph_scene_hash(&g_scene);
    assert_int_equal(parse3(",\"slip\":\"no-slip\"", "", "", &err), PFSPH_OK);
    assert_true(pfsph_scene_hash(&g_scene) == base);
    assert_int_equal(parse3(",\"slip\":\"free-slip\"", "", "", &err), PFSPH_OK);
    uint64_t fs = pfsph_scene_hash(&g_scene);
    assert_true(fs != base);
    assert_int_equal(parse3(",\"viscosity\":0.001", "", "", &err), PFSPH_OK);
    uint64_t v1 = pfsph_scene_hash(&g_scene);
    assert_true(v1 != base && v1 != fs);
    assert_int_equal(parse3(",\"viscosity\":0.002", "", "", &err), PFSPH_OK);
    assert_true(pfsph_scene_hash(&g_scene) != v1);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keys),
        cmocka_unit_test(test_wall_models),
        cmocka_unit_test(test_permute_keeps_wall),
        cmocka_unit_test(test_hash),
    };
    return tu_run_group(tests, NULL, NULL);
}
