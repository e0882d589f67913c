/* The "diffuse" block of scene files (defaults, every key, validation messages), the checked-in
 * diffuse scenes, and the counts-over-time plot. */
#include <png.h>
#include <stdio.h>
#include <string.h>

#include "pfsph/diffuse.h"
#include "pfsph/io.h"
#include "pfsph/scene.h"
#include "scene/json_util.h"
#include "testutil.h"

static int parse_block(const char *json, pfsph_scene *s, pfsph_error *err)
{
    memset(s, 0, sizeof(*s));
    pfsph_diffuse_defaults(&s->diffuse);
    cJSON *root = cJSON_Parse(json);
    assert_non_null(root);
    pfsph_jctx ctx = {"test.json", err};
    int rc = pfsph__scene_parse_diffuse(root, "$.diffuse", s, &ctx);
    cJSON_Delete(root);
    return rc;
}

static void test_defaults(void **state)
{
    (void)state;
    pfsph_diffuse_params p;
    pfsph_diffuse_defaults(&p);
    assert_false(p.enabled);
    assert_true(p.phi_v_min < p.phi_v_max && p.phi_e_min < p.phi_e_max);
    assert_true(p.type[PFSPH_DIFFUSE_SPRAY].k_ext == 1 && p.type[PFSPH_DIFFUSE_SPRAY].k_cp == 0);
    assert_true(p.type[PFSPH_DIFFUSE_FOAM].k_ext == 0 && p.type[PFSPH_DIFFUSE_FOAM].k_b == 0);
    assert_true(p.type[PFSPH_DIFFUSE_BUBBLE].k_b > p.type[PFSPH_DIFFUSE_BUBBLE].k_ext);
    assert_true(p.type[PFSPH_DIFFUSE_FOAM].k_t == 1);
    assert_int_equal(p.foam_min_neighbors, -1);
    /* Eq. 14 */
    assert_true(pfsph_diffuse_phi(1, 2, 8) == 0 && pfsph_diffuse_phi(2, 2, 8) == 0);
    assert_true(pfsph_diffuse_phi(5, 2, 8) == 0.5 && pfsph_diffuse_phi(9, 2, 8) == 1);
}

static void test_all_keys(void **state)
{
    (void)state;
    pfsph_scene s;
    pfsph_error err;
    const char *j = "{\"max_particles\": 5000, \"sampling_rate\": 30, \"phi_v_min\": 1.5,"
                    "\"phi_v_max\": 5, \"phi_e_min\": 2, \"phi_e_max\": 7, \"energy_mass\": 1,"
                    "\"emit_radius\": 0.01, \"emit_radius_scale\": 20, \"emit_height_scale\": 8.5,"
                    "\"lifetime_min\": 1, \"lifetime_max\": 3, \"foam_min_neighbors\": 6,"
                    "\"foam_max_neighbors\": 20, \"comment\": \"x\","
                    "\"spray\": {\"k_t\": 0.67}, \"foam\": {\"k_cp\": 0.6, \"k_b\": 0.5},"
                    "\"bubble\": {\"k_ext\": 0, \"k_b\": 0.3, \"k_cp\": 0.6, \"k_t\": 0.33}}";
    assert_int_equal(parse_block(j, &s, &err), PFSPH_OK);
    const pfsph_diffuse_params *p = &s.diffuse;
    assert_true(p->enabled); /* a block present means on */
    assert_int_equal(p->max_particles, 5000);
    assert_true(p->sampling_rate == 30 && p->phi_v_min == 1.5 && p->phi_v_max == 5);
    assert_true(p->phi_e_min == 2 && p->phi_e_max == 7 && p->energy_mass == 1);
    assert_true(p->emit_radius == 0.01 && p->emit_radius_scale == 20);
    assert_true(p->emit_height_scale == 8.5 && p->lifetime_min == 1 && p->lifetime_max == 3);
    assert_int_equal(p->foam_min_neighbors, 6);
    assert_int_equal(p->foam_max_neighbors, 20);
    assert_true(p->type[0].k_t == 0.67 && p->type[0].k_ext == 1);
    assert_true(p->type[1].k_cp == 0.6 && p->type[1].k_b == 0.5);
    assert_true(p->type[2].k_ext == 0 && p->type[2].k_b == 0.3 && p->type[2].k_t == 0.33);
    assert_int_equal(parse_block("{\"enabled\": false}", &s, &err), PFSPH_OK);
    assert_false(s.diffuse.enabled);
}

static void expect_error(const char *json, const char *fragment)
{
    pfsph_scene s;
    pfsph_error err;
    memset(&err, 0, sizeof err);
    assert_int_equal(parse_block(json, &s, &err), PFSPH_EINPUT);
    if (!strstr(err.msg, fragment)) print_error("message \"%s\" lacks \"%s\"\n", err.msg, fragment);
    assert_non_null(strstr(err.msg, fragment));
}

static void test_errors(void **state)
{
    (void)state;
    expect_error("{\"sampling_rat\": 3}", "$.diffuse.sampling_rat: unknown key");
    expect_error("{\"sampling_rat\": 3}", "did you mean \"sampling_rate\"");
    expect_error("{\"phi_v_min\": 5, \"phi_v_max\": 4}", "phi_v_max (4) must exceed");
    expect_error("{\"phi_e_min\": -1}", "$.diffuse.phi_e_min");
    expect_error("{\"foam\": {\"k_cp\": 1.5}}", "$.diffuse.foam.k_cp");
    expect_error("{\"bubble\": {\"kb\": 1}}", "$.diffuse.bubble.kb");
    expect_error("{\"lifetime_min\": 4}", "lifetime_max (3) is below lifetime_min (4)");
    expect_error("{\"foam_min_neighbors\": 9, \"foam_max_neighbors\": 8}", "foam_max_neighbors");
    expect_error("{\"max_particles\": 1.5}", "expected an integer");
    expect_error("{\"spray\": 3}", "expected an object");
}

/* The checked-in scenes parse with the full loader and turn diffuse material on. */
static void test_scenes(void **state)
{
    (void)state;
    const char *names[] = {"diffuse_dam_cylinder.json", "diffuse_dam_ball.json"};
    for (int k = 0; k < 2; k++) {
        char path[2048];
        snprintf(path, sizeof path, "%s/scenes/%s", tu_source_dir(), names[k]);
        pfsph_scene s;
        pfsph_error err;
        memset(&err, 0, sizeof err);
        int rc = pfsph_scene_load(&s, path, &err);
        if (rc != PFSPH_OK) print_error("%s\n", err.msg);
        assert_int_equal(rc, PFSPH_OK);
        assert_true(s.diffuse.enabled);
        assert_int_equal(s.diffuse.max_particles, 100000);
    }
}

static void test_plot(void **state)
{
    (void)state;
    char csv[1024], png[1024];
    snprintf(csv, sizeof csv, "%s/stats.csv", tu_tmpdir());
    snprintf(png, sizeof png, "%s/diffuse.png", tu_tmpdir());
    char text[20000] = "frame,time,n_fluid,n_bubble,n_spray,n_foam\n";
    for (int i = 0; i <= 100; i++) {
        double t = 0.03 * i;
        char row[128];
        snprintf(row, sizeof row, "%d,%g,1000,%d,%d,%d\n", i, t, (int)(3000 * t * (3 - t)),
                 (int)(5000 * t * (3 - t) * (3 - t)), (int)(4000 * t * t * (3 - t)));
        strcat(text, row);
    }
    assert_int_equal(tu_write_file(csv, text), 0);
    pfsph_error err;
    int rc = pfsph_diffuse_plot(csv, png, &err);
    if (rc) print_error("%s\n", err.msg);
    assert_int_equal(rc, PFSPH_OK);
    FILE *f = fopen(png, "rb");
    assert_non_null(f);
    png_structp p = png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(p);
    if (setjmp(png_jmpbuf(p))) fail_msg("bad PNG");
    png_init_io(p, f);
    png_read_info(p, info);
    assert_true(png_get_image_width(p, info) >= 400);
    assert_true(png_get_image_height(p, info) >= 300);
    png_destroy_read_struct(&p, &info, NULL);
    fclose(f);
    /* missing column and missing file are errors, not crashes */
    assert_int_equal(tu_write_file(csv, "time,n_spray,n_foam\n0,1,2\n"), 0);
    assert_int_equal(pfsph_diffuse_plot(csv, png, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, "n_bubble"));
    assert_int_equal(tu_write_file(csv, "time,n_spray,n_foam,n_bubble\n0,1,x,3\n"), 0);
    assert_int_equal(pfsph_diffuse_plot(csv, png, &err), PFSPH_EINPUT);
    assert_int_equal(pfsph_diffuse_plot("/nonexistent/stats.csv", png, &err), PFSPH_EIO);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults), cmocka_unit_test(test_all_keys), cmocka_unit_test(test_errors),
        cmocka_unit_test(test_scenes),   cmocka_unit_test(test_plot),
    };
    return tu_run_group(tests, NULL, NULL);
}
