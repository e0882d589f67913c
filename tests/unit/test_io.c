/* Frame files: VTP and PLY round trips (bit for bit), atomic writes that never damage an existing
 * file or leave temporaries behind, and readers that reject malformed files. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pfsph/io.h"
#include "pfsph/mesh.h"
#include "pfsph/meshing.h"
#include "pfsph/surface_io.h"
#include "testutil.h"

typedef int (*writer_fn)(const char *, const pfsph_particles *, const pfsph_io_opts *, pfsph_error *);
typedef int (*reader_fn)(const char *, pfsph_particles *, double *, pfsph_error *);

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static uint32_t rnd32(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 16);
}
static pfsph_real rndr(double scale) { return (pfsph_real)(scale * ((double)rnd32() / 4294967296.0 * 2.0 - 1.0)); }

static void make_set(pfsph_particles *ps, size_t n, int dim)
{
    assert_int_equal(pfsph_particles_init(ps, n), PFSPH_OK);
    for (size_t i = 0; i < n; i++) {
        pfsph_real x[3] = {rndr(2), rndr(2), dim == 3 ? rndr(2) : 0};
        pfsph_real v[3] = {rndr(5), rndr(5), dim == 3 ? rndr(5) : 0};
        long k = pfsph_particles_push(ps, x, v, (uint8_t)(rnd32() % 256));
        assert_true(k >= 0);
        ps->rho[k] = (pfsph_real)(1000 + rndr(50));
        ps->p[k] = rndr(1e5);
        ps->aux[k] = rndr(1e-3);
        ps->id[k] = rnd32();
    }
}

static int same_bits(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }

static void compare_sets(const pfsph_particles *a, const pfsph_particles *b, int with_id, int with_aux)
{
    assert_int_equal(a->n, b->n);
    const size_t rb = a->n * sizeof(pfsph_real);
    for (int k = 0; k < PFSPH_F_AUX; k++) assert_true(same_bits(a->f[k], b->f[k], rb));
    assert_true(same_bits(a->phase, b->phase, a->n));
    if (with_id) assert_true(same_bits(a->id, b->id, a->n * sizeof(uint32_t)));
    else
        for (size_t i = 0; i < b->n; i++) assert_int_equal(b->id[i], 0);
    if (with_aux) assert_true(same_bits(a->aux, b->aux, rb));
    else
        for (size_t i = 0; i < b->n; i++) assert_true(b->aux[i] == 0);
}

static void roundtrip(writer_fn w, reader_fn r, const char *ext)
{
    const char *dir = tu_tmpdir();
    for (int dim = 2; dim <= 3; dim++)
        for (int opt = 0; opt < 2; opt++) {
            pfsph_particles ps, back;
            make_set(&ps, 257 + (size_t)opt * 1000, dim);
            pfsph_io_opts o = {.dim = dim,
                               .write_id = opt,
                               .write_speed = opt,
                               .aux_name = opt ? "volume" : NULL,
                               .time = 0.1 * dim + 1e-17};
            char path[512];
            snprintf(path, sizeof path, "%s/rt_%d_%d.%s", dir, dim, opt, ext);
            pfsph_error err = {0};
            assert_int_equal(w(path, &ps, &o, &err), PFSPH_OK);
            double t = -1;
            int rc = r(path, &back, &t, &err);
            if (rc) fprintf(stderr, "%s\n", err.msg);
            assert_int_equal(rc, PFSPH_OK);
            assert_true(same_bits(&t, &o.time, sizeof t));
            compare_sets(&ps, &back, opt, opt);
            pfsph_particles_free(&back);
            /* An empty set round-trips too. */
            ps.n = 0;
            assert_int_equal(w(path, &ps, &o, &err), PFSPH_OK);
            assert_int_equal(r(path, &back, NULL, &err), PFSPH_OK);
            assert_int_equal(back.n, 0);
            pfsph_particles_free(&back);
            pfsph_particles_free(&ps);
        }
}

static void test_vtp_roundtrip(void **state)
{
    (void)state;
    roundtrip(pfsph_write_vtp, pfsph_read_vtp, "vtp");
}

static void test_ply_roundtrip(void **state)
{
    (void)state;
    roundtrip(pfsph_write_ply, pfsph_read_ply, "ply");
}

/* The PLY header is what Blender's importer reads: check it line by line. */
static void test_ply_header(void **state)
{
    (void)state;
    pfsph_particles ps;
    make_set(&ps, 3, 3);
    char path[512];
    snprintf(path, sizeof path, "%s/h.ply", tu_tmpdir());
    pfsph_io_opts o = {.dim = 3, .write_id = true, .write_speed = true, .aux_name = "lifetime", .time = 0.5};
    pfsph_error err;
    assert_int_equal(pfsph_write_ply(path, &ps, &o, &err), PFSPH_OK);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char buf[1024];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    const char *real = sizeof(pfsph_real) == 4 ? "float" : "double";
    char want[1024];
    snprintf(want, sizeof want,
             "ply\nformat binary_little_endian 1.0\ncomment pfsph %s\ncomment time 0.5\n"
             "element vertex 3\nproperty %s x\nproperty %s y\nproperty %s z\n"
             "property %s vx\nproperty %s vy\nproperty %s vz\nproperty %s density\n"
             "property %s pressure\nproperty uchar phase\nproperty uint id\n"
             "property %s speed\nproperty %s lifetime\nend_header\n",
             PFSPH_VERSION, real, real, real, real, real, real, real, real, real, real);
    assert_memory_equal(buf, want, strlen(want));
    /* 8 reals + phase + id + speed + aux per vertex */
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    assert_int_equal((size_t)st.st_size, strlen(want) + 3 * (10 * sizeof(pfsph_real) + 5));
    pfsph_particles_free(&ps);
}

/* Speed is |v| computed in double. */
static void test_speed_field(void **state)
{
    (void)state;
    pfsph_particles ps;
    assert_int_equal(pfsph_particles_init(&ps, 1), PFSPH_OK);
    pfsph_real x[3] = {0, 0, 0}, v[3] = {3, 4, 12};
    pfsph_particles_push(&ps, x, v, 0);
    char path[512];
    snprintf(path, sizeof path, "%s/speed.vtp", tu_tmpdir());
    pfsph_io_opts o = {.dim = 3, .write_speed = true};
    pfsph_error err;
    assert_int_equal(pfsph_write_vtp(path, &ps, &o, &err), PFSPH_OK);
    /* The speed block is the last of the PointData arrays: find 13.0 in the file. */
    FILE *f = fopen(path, "rb");
    char buf[4096];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    pfsph_real s = 13;
    int found = 0;
    for (size_t i = 0; i + sizeof s <= n; i++)
        if (memcmp(buf + i, &s, sizeof s) == 0) found = 1;
    assert_true(found);
    pfsph_particles_free(&ps);
}

static int count_tmp_files(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    int c = 0;
    struct dirent *de;
    while ((de = readdir(d)))
        if (strstr(de->d_name, ".tmp.")) c++;
    closedir(d);
    return c;
}

static void test_write_errors(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir();
    pfsph_particles ps;
    make_set(&ps, 10, 3);
    pfsph_io_opts o = {.dim = 3};
    pfsph_error err = {0};
    char path[512];
    /* Directory does not exist. */
    snprintf(path, sizeof path, "%s/no/such/dir/f.vtp", dir);
    assert_int_equal(pfsph_write_vtp(path, &ps, &o, &err), PFSPH_EIO);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, "No such file"));
    assert_int_equal(pfsph_write_ply(path, &ps, &o, &err), PFSPH_EIO);
    assert_non_null(strstr(err.msg, path));
    /* Parent is a regular file (permission checks do not stop root, this does). */
    char file[512];
    snprintf(file, sizeof file, "%s/plainfile", dir);
    assert_int_equal(tu_write_file(file, "x"), 0);
    snprintf(path, sizeof path, "%s/f.vtp", file);
    assert_int_equal(pfsph_write_vtp(path, &ps, &o, &err), PFSPH_EIO);
    assert_non_null(strstr(err.msg, path));
    assert_int_equal(pfsph_write_file_atomic(path, "abc", 3, &err), PFSPH_EIO);
    assert_int_equal(count_tmp_files(dir), 0);
    /* Bad aux names are refused before anything is written. */
    snprintf(path, sizeof path, "%s/aux.vtp", dir);
    o.aux_name = "a\"b";
    assert_int_equal(pfsph_write_vtp(path, &ps, &o, &err), PFSPH_EINPUT);
    o.aux_name = "density";
    assert_int_equal(pfsph_write_ply(path, &ps, &o, &err), PFSPH_EINPUT);
    assert_int_equal(access(path, F_OK), -1);
    pfsph_particles_free(&ps);
}

/* A failing rename (the target is a non-empty directory) leaves the old content and no
 * temporary file; a successful write replaces the file whole. */
static void test_atomic_keeps_old_file(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir();
    char sub[512], path[512], inner[600];
    snprintf(sub, sizeof sub, "%s/atomic", dir);
    assert_int_equal(mkdir(sub, 0755), 0);
    snprintf(path, sizeof path, "%s/data.bin", sub);
    pfsph_error err;
    assert_int_equal(pfsph_write_file_atomic(path, "first", 5, &err), PFSPH_OK);
    assert_int_equal(pfsph_write_file_atomic(path, "second!", 7, &err), PFSPH_OK);
    FILE *f = fopen(path, "rb");
    char buf[16] = {0};
    assert_int_equal(fread(buf, 1, sizeof buf, f), 7);
    fclose(f);
    assert_string_equal(buf, "second!");
    /* Target is a non-empty directory: rename fails after the data was written. */
    char dpath[512];
    snprintf(dpath, sizeof dpath, "%s/isdir.vtp", sub);
    assert_int_equal(mkdir(dpath, 0755), 0);
    snprintf(inner, sizeof inner, "%s/keep", dpath);
    assert_int_equal(tu_write_file(inner, "old"), 0);
    pfsph_particles ps;
    make_set(&ps, 50, 3);
    pfsph_io_opts o = {.dim = 3, .write_id = true};
    assert_int_equal(pfsph_write_vtp(dpath, &ps, &o, &err), PFSPH_EIO);
    assert_non_null(strstr(err.msg, dpath));
    assert_int_equal(count_tmp_files(sub), 0);
    /* An existing frame survives a failed write to it: make the temporary name unusable by
     * occupying it with a directory. */
    char frame[512], tmpn[600];
    snprintf(frame, sizeof frame, "%s/frame.vtp", sub);
    assert_int_equal(pfsph_write_vtp(frame, &ps, &o, &err), PFSPH_OK);
    struct stat st0, st1;
    assert_int_equal(stat(frame, &st0), 0);
    snprintf(tmpn, sizeof tmpn, "%s.tmp.%ld", frame, (long)getpid());
    assert_int_equal(mkdir(tmpn, 0755), 0);
    pfsph_particles other;
    make_set(&other, 5, 3);
    assert_int_equal(pfsph_write_vtp(frame, &other, &o, &err), PFSPH_EIO);
    assert_int_equal(rmdir(tmpn), 0);
    assert_int_equal(stat(frame, &st1), 0);
    assert_int_equal(st0.st_size, st1.st_size);
    pfsph_particles back;
    assert_int_equal(pfsph_read_vtp(frame, &back, NULL, &err), PFSPH_OK);
    compare_sets(&ps, &back, 1, 0);
    pfsph_particles_free(&back);
    pfsph_particles_free(&other);
    pfsph_particles_free(&ps);
    assert_int_equal(count_tmp_files(sub), 0);
}

/* Replace the first occurrence of `from` by `to` (same length or not) and write to out. */
static void patched(const unsigned char *b, size_t n, const char *from, const char *to, const char *out)
{
    size_t fl = strlen(from), tl = strlen(to);
    for (size_t i = 0; i + fl <= n; i++)
        if (memcmp(b + i, from, fl) == 0) {
            unsigned char *c = malloc(n - fl + tl);
            memcpy(c, b, i);
            memcpy(c + i, to, tl);
            memcpy(c + i + tl, b + i + fl, n - i - fl);
            tu_write_bytes(out, c, n - fl + tl);
            free(c);
            return;
        }
    fail_msg("pattern '%s' not found", from);
}

static void expect_reject(reader_fn r, const char *path)
{
    pfsph_particles ps;
    pfsph_error err = {0};
    int rc = r(path, &ps, NULL, &err);
    if (rc == PFSPH_OK) fail_msg("%s was accepted", path);
    assert_non_null(strstr(err.msg, path));
    assert_null(ps.x);
}

static void corrupt_common(writer_fn w, reader_fn r, const char *ext)
{
    const char *dir = tu_tmpdir();
    char path[512], bad[512];
    snprintf(path, sizeof path, "%s/good.%s", dir, ext);
    snprintf(bad, sizeof bad, "%s/bad.%s", dir, ext);
    pfsph_particles ps;
    make_set(&ps, 100, 3);
    pfsph_io_opts o = {.dim = 3, .write_id = true, .write_speed = true, .aux_name = "vol"};
    pfsph_error err;
    assert_int_equal(w(path, &ps, &o, &err), PFSPH_OK);
    size_t n;
    unsigned char *b = tu_slurp(path, &n);
    /* Every truncation must be refused (and must not read past the end: ASan checks). */
    for (size_t cut = 0; cut + 1 < n; cut += (cut < 2000 ? 1 : 97)) {
        tu_write_bytes(bad, b, cut);
        expect_reject(r, bad);
    }
    /* Random byte flips in the header may be accepted or refused, but never crash. */
    size_t hdr = 0;
    while (hdr + 13 < n && memcmp(b + hdr, "<AppendedData", 13) != 0 && memcmp(b + hdr, "end_header", 10) != 0) hdr++;
    for (int k = 0; k < 300; k++) {
        unsigned char *c = malloc(n);
        memcpy(c, b, n);
        c[rnd32() % hdr] = (unsigned char)rnd32();
        c[rnd32() % hdr] = (unsigned char)("0123456789\"<>/= \n"[rnd32() % 17]);
        tu_write_bytes(bad, c, n);
        pfsph_particles q;
        if (r(bad, &q, NULL, &err) == PFSPH_OK) pfsph_particles_free(&q);
        free(c);
    }
    expect_reject(r, "/nonexistent/file");
    free(b);
    pfsph_particles_free(&ps);
}

static void test_vtp_corrupt(void **state)
{
    (void)state;
    corrupt_common(pfsph_write_vtp, pfsph_read_vtp, "vtp");
    const char *dir = tu_tmpdir();
    char path[512], bad[512];
    snprintf(path, sizeof path, "%s/good.vtp", dir);
    snprintf(bad, sizeof bad, "%s/bad.vtp", dir);
    size_t n;
    unsigned char *b = tu_slurp(path, &n);
    /* Header lies about the number of points, offsets or types. */
    patched(b, n, "NumberOfPoints=\"100\"", "NumberOfPoints=\"101\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "NumberOfPoints=\"100\"", "NumberOfPoints=\"99999999999999\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "NumberOfPoints=\"100\"", "NumberOfPoints=\"-1\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "offset=\"16\"", "offset=\"99999999\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "offset=\"16\"", "offset=\"18446744073709551615\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "offset=\"16\"", "offset=\"17\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "Name=\"phase\"", "Name=\"phase\" NumberOfComponents=\"2\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "LittleEndian", "BigEndian", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "encoding=\"raw\"", "encoding=\"base64\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "type=\"UInt8\"", "type=\"Float128\"", bad);
    expect_reject(pfsph_read_vtp, bad);
    patched(b, n, "<AppendedData", "<AppendedDota", bad);
    expect_reject(pfsph_read_vtp, bad);
    /* A block size beyond the file. */
    unsigned char *c = malloc(n);
    memcpy(c, b, n);
    unsigned char *u = memchr(c, '_', n);
    assert_non_null(u);
    memset(u + 1, 0xff, 8);
    tu_write_bytes(bad, c, n);
    expect_reject(pfsph_read_vtp, bad);
    free(c);
    free(b);
}

static void test_ply_corrupt(void **state)
{
    (void)state;
    corrupt_common(pfsph_write_ply, pfsph_read_ply, "ply");
    const char *dir = tu_tmpdir();
    char path[512], bad[512];
    snprintf(path, sizeof path, "%s/good.ply", dir);
    snprintf(bad, sizeof bad, "%s/bad.ply", dir);
    size_t n;
    unsigned char *b = tu_slurp(path, &n);
    patched(b, n, "element vertex 100", "element vertex 101", bad);
    expect_reject(pfsph_read_ply, bad);
    patched(b, n, "element vertex 100", "element vertex 18446744073709551615", bad);
    expect_reject(pfsph_read_ply, bad);
    patched(b, n, "element vertex 100", "element vertex -5", bad);
    expect_reject(pfsph_read_ply, bad);
    patched(b, n, "binary_little_endian", "binary_big_endian", bad);
    expect_reject(pfsph_read_ply, bad);
    patched(b, n, "uchar phase", "float phase", bad);
    expect_reject(pfsph_read_ply, bad);
    patched(b, n, "property uint id", "property list uchar int id", bad);
    expect_reject(pfsph_read_ply, bad);
    patched(b, n, "ply\n", "plx\n", bad);
    expect_reject(pfsph_read_ply, bad);
    patched(b, n, "end_header\n", "end_headr\n", bad);
    expect_reject(pfsph_read_ply, bad);
    free(b);
}

/* The surface mesh reader (the renderer's and the viewer's): a liquid mesh (normals, faces
 * tagged by phase) and a bodies' surface file (no normals, faces tagged by body) read back as
 * written (positions and normals are floats in the file, so exactly their float values), and
 * malformed files refused with the path named. */
static void surface_reject(const char *path, const char *what)
{
    pfsph_surface_mesh m;
    pfsph_error err = {0};
    assert_int_equal(pfsph_read_surface_ply(path, &m, NULL, &err), PFSPH_EINPUT);
    assert_non_null(strstr(err.msg, path));
    if (what) assert_non_null(strstr(err.msg, what));
    assert_null(m.v);
    assert_null(m.tri);
}

static void test_surface_ply_roundtrip(void **state)
{
    (void)state;
    const char *dir = tu_tmpdir();
    char path[512], bad[512];
    pfsph_error err = {0};
    /* a liquid: a tetrahedron of two phases */
    double v[12] = {0.1, 0.2, 0.3, 1.0 / 3, 0, 0, 0, 1.25, 0, 0, 0, -2.5e-3};
    float nn[12] = {0.57735f, 0.57735f, 0.57735f, 1, 0, 0, 0, 1, 0, 0, 0, -1};
    uint32_t tri[12] = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
    uint8_t ph[4] = {0, 0, 2, 2};
    pfsph_surface_mesh w = {.nverts = 4, .ntris = 4, .v = v, .n = nn, .tri = tri, .phase = ph};
    snprintf(path, sizeof path, "%s/liquid_00003.ply", dir);
    assert_int_equal(pfsph_write_surface_ply(path, &w, 0.125, &err), PFSPH_OK);
    pfsph_surface_mesh m;
    double t = -1;
    assert_int_equal(pfsph_read_surface_ply(path, &m, &t, &err), PFSPH_OK);
    assert_true(t == 0.125);
    assert_int_equal(m.nverts, 4);
    assert_int_equal(m.ntris, 4);
    assert_non_null(m.n);
    for (int i = 0; i < 12; i++) {
        assert_true(m.v[i] == (double)(float)v[i]);
        assert_true(m.n[i] == nn[i]);
        assert_int_equal(m.tri[i], tri[i]);
    }
    for (int i = 0; i < 4; i++) assert_int_equal(m.phase[i], ph[i]);
    pfsph_surface_mesh_free(&m);

    /* bodies: a box and a sphere in one file, faces tagged 0 and 1 */
    pfsph_mesh b[2];
    const double half[3] = {0.1, 0.05, 0.2};
    assert_int_equal(pfsph_mesh_box(&b[0], half), PFSPH_OK);
    assert_int_equal(pfsph_mesh_sphere(&b[1], 0.07, 12), PFSPH_OK);
    pfsph_body_pose pose[2] = {{"box", {0, 0, 0}, {1, 0, 0, 0}}, {"ball", {1, 2, 3}, {1, 0, 0, 0}}};
    snprintf(path, sizeof path, "%s/surfaces_00003.ply", dir);
    assert_int_equal(pfsph_write_surfaces_ply(path, b, 2, pose, 0.5, &err), PFSPH_OK);
    assert_int_equal(pfsph_read_surface_ply(path, &m, &t, &err), PFSPH_OK);
    assert_true(t == 0.5);
    assert_null(m.n);
    assert_int_equal(m.nverts, b[0].nverts + b[1].nverts);
    assert_int_equal(m.ntris, b[0].ntris + b[1].ntris);
    for (size_t i = 0; i < m.ntris; i++) {
        int body = i < b[0].ntris ? 0 : 1;
        size_t ti = body ? i - b[0].ntris : i;
        assert_int_equal(m.phase[i], body);
        for (int k = 0; k < 3; k++) {
            uint32_t want = b[body].tri[3 * ti + k] + (body ? (uint32_t)b[0].nverts : 0);
            assert_int_equal(m.tri[3 * i + k], want);
            const double *pv = b[body].v + 3 * b[body].tri[3 * ti + k];
            for (int c = 0; c < 3; c++) assert_true(m.v[3 * want + c] == (double)(float)pv[c]);
        }
    }
    pfsph_surface_mesh_free(&m);

    /* malformed: short data, a quad, an index out of range, a bad list, particles */
    size_t n;
    unsigned char *d = tu_slurp(path, &n);
    snprintf(bad, sizeof bad, "%s/bad.ply", dir);
    tu_write_bytes(bad, d, n - 1);
    surface_reject(bad, "bytes of data");
    const unsigned char *hdr = (const unsigned char *)strstr((const char *)d, "end_header\n");
    size_t nv = b[0].nverts + b[1].nverts;
    size_t f0 = (size_t)(hdr - d) + 11 + 12 * nv; /* the first face record: count, 3 indices */
    unsigned char *c = malloc(n);
    memcpy(c, d, n);
    c[f0] = 4;
    tu_write_bytes(bad, c, n);
    surface_reject(bad, "triangles only");
    memcpy(c, d, n);
    uint32_t big = (uint32_t)nv;
    memcpy(c + f0 + 5, &big, 4);
    tu_write_bytes(bad, c, n);
    surface_reject(bad, "out of range");
    free(c);
    patched(d, n, "list uchar uint", "list uint uint", bad);
    surface_reject(bad, "vertex_indices");
    patched(d, n, "element face", "element edge", bad);
    surface_reject(bad, NULL);
    patched(d, n, "binary_little_endian", "ascii", bad);
    surface_reject(bad, "format");
    free(d);
    pfsph_mesh_free(&b[0]);
    pfsph_mesh_free(&b[1]);
}

/* When VTK's Python bindings are installed (Debian: python3-vtk9), VTK's own reader -- the one
 * ParaView uses -- must accept the file and see the same data. Skipped otherwise. */
static void test_vtp_opens_in_vtk(void **state)
{
    (void)state;
    static const char *const pythons[] = {"python3", "/usr/bin/python3"};
    const char *py = NULL;
    char out[4096];
    for (int i = 0; i < 2 && !py; i++) {
        char cmd[256];
        snprintf(cmd, sizeof cmd, "%s -c 'import vtk' >/dev/null 2>&1", pythons[i]);
        if (tu_run(cmd, out, sizeof out) == 0) py = pythons[i];
    }
    if (!py) tu_skip("no python3 with the vtk module");
    pfsph_particles ps;
    make_set(&ps, 1234, 3);
    char path[512], script[512];
    snprintf(path, sizeof path, "%s/vtk.vtp", tu_tmpdir());
    snprintf(script, sizeof script, "%s/check_vtk.py", tu_tmpdir());
    pfsph_io_opts o = {.dim = 3, .write_id = true, .write_speed = true, .aux_name = "volume", .time = 0.75};
    pfsph_error err;
    assert_int_equal(pfsph_write_vtp(path, &ps, &o, &err), PFSPH_OK);
    assert_int_equal(tu_write_file(script,
                                   "import sys, vtk\n"
                                   "r = vtk.vtkXMLPolyDataReader(); r.SetFileName(sys.argv[1]); r.Update()\n"
                                   "d = r.GetOutput(); pd = d.GetPointData()\n"
                                   "names = sorted(pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays()))\n"
                                   "print('n', d.GetNumberOfPoints(), d.GetNumberOfVerts(), r.GetErrorCode())\n"
                                   "print('arrays', ','.join(names))\n"
                                   "print('time', d.GetFieldData().GetArray('TimeValue').GetValue(0))\n"
                                   "print('p7 %.9g %.9g %.9g' % d.GetPoint(7))\n"
                                   "print('id7', int(pd.GetArray('id').GetValue(7)))\n"
                                   "print('rho7 %.9g' % pd.GetArray('density').GetValue(7))\n"),
                     0);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "%s %s %s", py, script, path);
    assert_int_equal(tu_run(cmd, out, sizeof out), 0);
    char want[1024];
    snprintf(want, sizeof want,
             "n 1234 1234 0\narrays density,id,phase,pressure,speed,velocity,volume\n"
             "time 0.75\np7 %.9g %.9g %.9g\nid7 %u\nrho7 %.9g\n",
             (double)ps.x[7], (double)ps.y[7], (double)ps.z[7], ps.id[7], (double)ps.rho[7]);
    assert_string_equal(out, want);
    pfsph_particles_free(&ps);
}

int main(int argc, char **argv)
{
    tu_init(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_vtp_roundtrip),    cmocka_unit_test(test_ply_roundtrip),
        cmocka_unit_test(test_ply_header),       cmocka_unit_test(test_speed_field),
        cmocka_unit_test(test_write_errors),     cmocka_unit_test(test_atomic_keeps_old_file),
        cmocka_unit_test(test_vtp_corrupt),      cmocka_unit_test(test_ply_corrupt),
        cmocka_unit_test(test_vtp_opens_in_vtk), cmocka_unit_test(test_surface_ply_roundtrip),
    };
    return tu_run_group(tests, NULL, NULL);
}
