/* `pfsph export --houdini` (issue 33 item 11): the binary JSON (.bgeo) parsed here by a reader
 * written from SideFX's UT_JSONDefines.h equals the JSON text (.geo) value for value; points are
 * ordered by id with the frame's values, pscale and the diffuse type; the liquid mesh, the body
 * surfaces and the static solids are polygons with their primitive attributes. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/io.h"
#include "pfsph/meshing.h"
#include "testutil.h"

static char g_run[1200];

static const char *SCENE =
    "{\"dimension\": 3, \"particle_radius\": 0.02, \"gravity\": [0, -9.81, 0],\n"
    " \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [0.7, 0.6, 0.4]},\n"
    " \"solver\": {\"type\": \"dfsph\"}, \"time\": {\"end\": 0.1, \"fps\": 20},\n"
    " \"phases\": [{\"name\": \"water\"}, {\"name\": \"wall\", \"kind\": \"solid\"},\n"
    "            {\"name\": \"wood\", \"kind\": \"solid\", \"rest_density\": 600}],\n"
    " \"fluid\": [{\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.2, 0.3, 0.3], \"phase\": \"water\"}],\n"
    " \"solids\": [{\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [0.6, 0.5, 0.3], \"open_top\": true,\n"
    "             \"phase\": \"wall\"},\n"
    "            {\"shape\": \"sphere\", \"center\": [0.45, 0.05, 0.15], \"radius\": 0.06, \"phase\": \"wall\"}],\n"
    " \"bodies\": [{\"name\": \"ball\", \"shape\": \"sphere\", \"radius\": 0.06, \"position\": [0.3, 0.2, 0.15],\n"
    "             \"density\": 600, \"phase\": \"wood\"}],\n"
    " \"output\": {\"formats\": [\"vtp\", \"ply\"], \"fields\": [\"id\"], \"surface\": true}}\n";

/* ---- binary JSON -> cJSON (UT_JSONDefines.h: tokens, encoded lengths, uniform arrays) ---- */
typedef struct rd {
    const unsigned char *p, *end;
    char *tok[256];
} rd;

static int64_t len_(rd *r)
{
    unsigned b = *r->p++;
    uint64_t v = 0;
    if (b < 0xf1) return b;
    int n = b == 0xf2 ? 2 : b == 0xf4 ? 4 : b == 0xf8 ? 8 : -1;
    assert_true(n > 0 && r->p + n <= r->end);
    memcpy(&v, r->p, (size_t)n);
    r->p += n;
    return (int64_t)v;
}

static cJSON *value(rd *r);

static cJSON *scalar(rd *r, unsigned t)
{
    int32_t i32;
    int64_t i64;
    float f;
    double d;
    switch (t) {
    case 0x13: memcpy(&i32, r->p, 4), r->p += 4; return cJSON_CreateNumber(i32);
    case 0x14: memcpy(&i64, r->p, 8), r->p += 8; return cJSON_CreateNumber((double)i64);
    case 0x19: memcpy(&f, r->p, 4), r->p += 4; return cJSON_CreateNumber(f);
    case 0x1a: memcpy(&d, r->p, 8), r->p += 8; return cJSON_CreateNumber(d);
    case 0x30: return cJSON_CreateFalse();
    case 0x31: return cJSON_CreateTrue();
    case 0x27: {
        int64_t n = len_(r);
        char *s = strndup((const char *)r->p, (size_t)n);
        r->p += n;
        cJSON *j = cJSON_CreateString(s);
        free(s);
        return j;
    }
    case 0x26: return cJSON_CreateString(r->tok[len_(r)]);
    default: fail_msg("unexpected token 0x%02x", t); return NULL;
    }
}

static cJSON *value(rd *r)
{
    assert_true(r->p < r->end);
    unsigned t = *r->p++;
    if (t == 0x5b || t == 0x7b) {
        cJSON *c = t == 0x5b ? cJSON_CreateArray() : cJSON_CreateObject();
        while (*r->p != (t == 0x5b ? 0x5d : 0x7d)) {
            if (t == 0x7b) {
                cJSON *k = value(r);
                assert_true(cJSON_IsString(k));
                cJSON_AddItemToObject(c, k->valuestring, value(r));
                cJSON_Delete(k);
            } else cJSON_AddItemToArray(c, value(r));
        }
        r->p++;
        return c;
    }
    if (t == 0x40) {
        unsigned et = *r->p++;
        int64_t n = len_(r);
        cJSON *a = cJSON_CreateArray();
        for (int64_t k = 0; k < n; k++) cJSON_AddItemToArray(a, scalar(r, et));
        return a;
    }
    return scalar(r, t);
}

static cJSON *read_bgeo(const char *path)
{
    size_t len;
    unsigned char *b = tu_slurp(path, &len);
    assert_non_null(b);
    uint32_t magic;
    assert_true(len > 5 && b[0] == 0x7f);
    memcpy(&magic, b + 1, 4);
    assert_true(magic == 0x624a534e);
    rd r = {.p = b + 5, .end = b + len};
    cJSON *j = value(&r);
    assert_true(r.p == r.end);
    free(b);
    return j;
}

static cJSON *read_geo(const char *path)
{
    size_t len;
    unsigned char *b = tu_slurp(path, &len);
    assert_non_null(b);
    cJSON *j = cJSON_ParseWithLength((const char *)b, len);
    assert_non_null(j);
    free(b);
    return j;
}

/* equal trees, numbers equal as floats (the text holds %.9g of the same floats) */
static void same(const cJSON *a, const cJSON *b)
{
    assert_int_equal(a->type & 0xff, b->type & 0xff);
    if (cJSON_IsNumber(a)) assert_true((float)a->valuedouble == (float)b->valuedouble);
    else if (cJSON_IsString(a)) assert_string_equal(a->valuestring, b->valuestring);
    else if (cJSON_IsArray(a) || cJSON_IsObject(a)) {
        assert_int_equal(cJSON_GetArraySize(a), cJSON_GetArraySize(b));
        for (const cJSON *x = a->child, *y = b->child; x; x = x->next, y = y->next) {
            if (cJSON_IsObject(a)) assert_string_equal(x->string, y->string);
            same(x, y);
        }
    }
}

/* the value after key k in a flat [key, value, ...] array */
static const cJSON *kv(const cJSON *arr, const char *k)
{
    for (const cJSON *x = arr->child; x && x->next; x = x->next->next)
        if (cJSON_IsString(x) && !strcmp(x->valuestring, k)) return x->next;
    return NULL;
}

/* an attribute's data array ("values" > "arrays"[0] or "tuples") by name */
static const cJSON *attr(const cJSON *geo, const char *owner, const char *name, const cJSON **def)
{
    const cJSON *list = kv(kv(geo, "attributes"), owner);
    assert_non_null(list);
    for (const cJSON *a = list->child; a; a = a->next) {
        const cJSON *d = cJSON_GetArrayItem(a, 0), *v = cJSON_GetArrayItem(a, 1);
        if (!strcmp(kv(d, "name")->valuestring, name)) {
            if (def) *def = v;
            const cJSON *vals = kv(v, "values");
            if (!vals) return v; /* a string attribute */
            const cJSON *arrays = kv(vals, "arrays");
            return arrays ? cJSON_GetArrayItem(arrays, 0) : kv(vals, "tuples");
        }
    }
    return NULL;
}

static int setup(void **state)
{
    (void)state;
    char scene[1400], cmd[4096], out[4096];
    snprintf(scene, sizeof scene, "%s/h.json", tu_tmpdir());
    snprintf(g_run, sizeof g_run, "%s/h", tu_tmpdir());
    if (tu_write_file(scene, SCENE)) return -1;
    snprintf(cmd, sizeof cmd, "'%s' run '%s' -o '%s' --quiet", tu_pfsph_bin(), scene, g_run);
    return tu_run(cmd, out, sizeof out);
}

static void test_bgeo(void **state)
{
    (void)state;
    char cmd[4096], out[4096], path[1400];
    snprintf(cmd, sizeof cmd, "'%s' export '%s' --houdini 2>&1", tu_pfsph_bin(), g_run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    printf("%s", out);
    assert_non_null(strstr(out, "exported 3 frames"));
    assert_non_null(strstr(out, "3 liquid_NNNNN, 3 bodies_NNNNN, 2 solids"));
    assert_null(strstr(out, "no particle ids"));
    snprintf(cmd, sizeof cmd, "'%s' export '%s' --houdini --ascii", tu_pfsph_bin(), g_run);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    static const char *const names[] = {"frames/fluid_00002", "frames/liquid_00002", "frames/bodies_00002", "solids"};
    cJSON *geo[4];
    for (int k = 0; k < 4; k++) {
        snprintf(path, sizeof path, "%s/%s.bgeo", g_run, names[k]);
        geo[k] = read_bgeo(path);
        snprintf(path, sizeof path, "%s/%s.geo", g_run, names[k]);
        cJSON *text = read_geo(path);
        same(geo[k], text);
        cJSON_Delete(text);
    }
    /* fluid: the VTP frame's particles, ordered by id, pscale = the particle radius */
    pfsph_particles ps;
    pfsph_error err = {0};
    snprintf(path, sizeof path, "%s/frames/fluid_00002.vtp", g_run);
    assert_int_equal(pfsph_read_vtp(path, &ps, NULL, &err), 0);
    assert_int_equal((size_t)kv(geo[0], "pointcount")->valuedouble, ps.n);
    const cJSON *P = attr(geo[0], "pointattributes", "P", NULL), *id = attr(geo[0], "pointattributes", "id", NULL),
                *sc = attr(geo[0], "pointattributes", "pscale", NULL),
                *rho = attr(geo[0], "pointattributes", "density", NULL);
    assert_true(P && id && sc && rho);
    double prev = -1;
    size_t k = 0;
    for (const cJSON *i = id->child, *p = P->child, *s = sc->child, *r = rho->child; i;
         i = i->next, p = p->next, s = s->next, r = r->next, k++) {
        assert_true(i->valuedouble > prev); /* ascending ids: point k is one particle in every frame */
        prev = i->valuedouble;
        size_t j = 0;
        while (j < ps.n && ps.id[j] != (uint32_t)i->valuedouble) j++;
        assert_true(j < ps.n);
        assert_true((float)cJSON_GetArrayItem(p, 1)->valuedouble == (float)ps.y[j]);
        assert_true((float)r->valuedouble == (float)ps.rho[j]);
        assert_true((float)s->valuedouble == 0.02f);
    }
    assert_int_equal(k, ps.n);
    pfsph_particles_free(&ps);
    /* liquid: the PLY's triangles (Houdini's winding: reversed), normals, velocities */
    pfsph_surface_mesh m;
    snprintf(path, sizeof path, "%s/frames/liquid_00002.ply", g_run);
    assert_int_equal(pfsph_read_surface_ply(path, &m, NULL, &err), 0);
    assert_non_null(m.vel);
    assert_int_equal((size_t)kv(geo[1], "primitivecount")->valuedouble, m.ntris);
    assert_int_equal((size_t)kv(geo[1], "pointcount")->valuedouble, m.nverts);
    const cJSON *idx = kv(kv(kv(geo[1], "topology"), "pointref"), "indices");
    assert_int_equal((size_t)cJSON_GetArraySize(idx), 3 * m.ntris);
    assert_int_equal((uint32_t)cJSON_GetArrayItem(idx, 0)->valuedouble, m.tri[2]);
    assert_int_equal((uint32_t)cJSON_GetArrayItem(idx, 2)->valuedouble, m.tri[0]);
    const cJSON *v = attr(geo[1], "pointattributes", "v", NULL), *N = attr(geo[1], "pointattributes", "N", NULL);
    assert_true(v && N && attr(geo[1], "primitiveattributes", "phase", NULL));
    assert_true((float)cJSON_GetArrayItem(cJSON_GetArrayItem(v, 5), 1)->valuedouble == m.vel[16]);
    pfsph_surface_mesh_free(&m);
    /* bodies: the ball's name; solids: the container and the sphere */
    const cJSON *def = NULL;
    attr(geo[2], "primitiveattributes", "name", &def);
    assert_non_null(def);
    assert_string_equal(cJSON_GetArrayItem(kv(def, "strings"), 0)->valuestring, "ball");
    attr(geo[3], "primitiveattributes", "name", &def);
    assert_string_equal(cJSON_GetArrayItem(kv(def, "strings"), 1)->valuestring, "solid_1_sphere");
    printf("fluid_00002.bgeo: %d points; liquid: %d triangles; solids: %d triangles\n",
           (int)kv(geo[0], "pointcount")->valuedouble, (int)kv(geo[1], "primitivecount")->valuedouble,
           (int)kv(geo[3], "primitivecount")->valuedouble);
    for (int q = 0; q < 4; q++) cJSON_Delete(geo[q]);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bgeo),
    };
    return tu_run_group(tests, setup, NULL);
}
