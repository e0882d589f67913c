/* The scene hash of checkpoints (pfsph_scene_hash, docs/checkpoints.md), generated from one
 * table per scene struct that names every member: hashed, or left out and why. */
#include "pfsph/checkpoint.h"

#include <stddef.h>
#include <string.h>

/* How a table covers its struct, so that it cannot drift from scene.h and params.h:
 * - its rows also make two initializers of the struct (`*_cover`): a positional one, so that
 *   a member added to the struct without a row fails the build (-Wmissing-field-initializers,
 *   in -Wextra), and a designated one, so that a member with two rows does too (-Woverride-init,
 *   -Winitializer-overrides); a row of the wrong shape fails as well (a scalar's row gives 0, an
 *   aggregate's {}: C23's empty initializer, which GCC and Clang take in C11 too);
 * - a leaf's kind (int, double, string, ...) comes from its C type (_Generic), and a struct
 *   member's table from its struct type: no row states a type, and a new type fails the build.
 * Hashed are the members at a value other than zero (0, false, an empty string), each with its
 * path (member names and indices), as a sum of one mixed 64-bit hash per member: so a member
 * added at a default of zero leaves the hash of every scene that keeps it at zero as it was
 * (a checkpoint of such a scene stays resumable), and the order of the rows does not matter.
 * Counted arrays (blocks, solids, ...) are hashed up to their count. */

enum kind { K_OUT = 0, K_SUB, K_I32, K_BOOL, K_LONG, K_U64, K_F64, K_F32, K_STR };

typedef struct table table;

typedef struct row {
    const char *name;
    size_t off, size; /* offsetof, sizeof the whole member */
    enum kind kind;
    const table *sub; /* K_SUB: the element's table (a struct, or a fixed array of them) */
    long count_off;   /* K_SUB: offset of the int that counts the elements in use; -1: all */
    /* leaves: whether element i is the scene's own value, not one the simulation derives */
    bool (*stated)(const void *owner, size_t i);
} row;

struct table {
    size_t size; /* of the struct */
    const row *rows;
    int nrows;
    const void *cover; /* the initializers that prove the rows complete (see above) */
};

static const table keyframe_table, phase_table, block_table, solid_table, body_table, emitter_table, shift_table,
    thermo_table, pairwise_table, coupling_table, diffuse_table, film_table, scene_table;

/* The tables read as the structs they cover, a few rows a line: */
// clang-format off

/* The kind of a leaf member x (arrays decay to pointers); another type fails the build. */
#define KIND_OF(x)                                                                              \
    _Generic((x), int: K_I32, int *: K_I32, _Bool: K_BOOL, _Bool *: K_BOOL,                     \
             _Bool(*)[PFSPH_MAX_PHASES]: K_BOOL, long: K_LONG, unsigned long: K_U64,            \
             unsigned long long: K_U64, double: K_F64, double *: K_F64,                         \
             double(*)[PFSPH_MAX_PHASES]: K_F64, float: K_F32, float *: K_F32, char *: K_STR)
/* The table of a struct member x (a struct, or an array of them). */
#define TABLE_OF(x)                                                                             \
    _Generic((x), pfsph_keyframe *: &keyframe_table, pfsph_phase *: &phase_table,               \
             pfsph_block *: &block_table, pfsph_solid *: &solid_table,                          \
             pfsph_body_def *: &body_table, pfsph_emitter_params *: &emitter_table,             \
             pfsph_shift_params: &shift_table, pfsph_thermostat_params: &thermo_table,          \
             pfsph_pairwise_params: &pairwise_table, pfsph_diffuse_coupling *: &coupling_table, \
             pfsph_diffuse_params: &diffuse_table, pfsph_film_params: &film_table)

#define MEMBER(m) (((T *)0)->m)
/* Rows: F a scalar, A an array (or a string), M an array whose elements enter where `fn` says
 * the scene states them, S a struct or a fixed array of them, SN an array counted by the int
 * member `n`, O / OA a scalar / an aggregate left out. */
#define ROW_F(m) {#m, offsetof(T, m), sizeof MEMBER(m), KIND_OF(MEMBER(m)), NULL, -1, NULL},
#define ROW_A(m) ROW_F(m)
#define ROW_M(m, fn) {#m, offsetof(T, m), sizeof MEMBER(m), KIND_OF(MEMBER(m)), NULL, -1, fn},
#define ROW_S(m) {#m, offsetof(T, m), sizeof MEMBER(m), K_SUB, TABLE_OF(MEMBER(m)), -1, NULL},
#define ROW_SN(m, n) {#m, offsetof(T, m), sizeof MEMBER(m), K_SUB, TABLE_OF(MEMBER(m)), (long)offsetof(T, n), NULL},
#define ROW_O(m) {#m, offsetof(T, m), sizeof MEMBER(m), K_OUT, NULL, -1, NULL},
#define ROW_OA(m) ROW_O(m)
#define ROW(form, ...) ROW_##form(__VA_ARGS__)
#define COVER_F 0,
#define COVER_O 0,
#define COVER_A {},
#define COVER_M {},
#define COVER_S {},
#define COVER_SN {},
#define COVER_OA {},
#define COVER(form, ...) COVER_##form
#define NAMED(form, m, ...) .m = COVER_##form
#define TABLE(name, ROWS)                                            \
    static const T name##_cover[2] = {{ROWS(COVER)}, {ROWS(NAMED)}}; \
    static const row name##_rows[] = {ROWS(ROW)};                    \
    static const table name = {sizeof(T), name##_rows, (int)(sizeof name##_rows / sizeof name##_rows[0]), name##_cover}

/* Values the simulation derives from the scene's own (pfsph_sim_create fills them into its
 * copy) are left out, so that a scene hashes the same as parsed and as pfsph_sim_scene. */
static bool c_stated(const void *owner, size_t i) /* c[a][b]: resolved from sigma or an angle */
{
    return ((const pfsph_pairwise_params *)owner)->c_set[i / PFSPH_MAX_PHASES][i % PFSPH_MAX_PHASES];
}
static bool volume_stated(const void *owner, size_t i) /* the film's volume: from its thickness */
{
    return !(((const pfsph_film_params *)owner)->thickness[i] > 0);
}

#define T pfsph_keyframe
#define KEYFRAME(X) X(F, t) X(A, position) X(A, rotation)
TABLE(keyframe_table, KEYFRAME);
#undef T

#define T pfsph_phase
#define PHASE(X) X(A, name) X(F, kind) X(F, rest_density) X(F, viscosity)                           \
    X(OA, color) X(O, color_set) /* drawing only */
TABLE(phase_table, PHASE);
#undef T

#define T pfsph_block
#define BLOCK(X) X(F, shape) X(F, phase) X(A, min) X(A, max) X(A, center) X(F, radius) X(F, height) \
    X(F, axis) X(A, velocity) X(F, jitter) X(F, bubble)
TABLE(block_table, BLOCK);
#undef T

#define T pfsph_solid
#define SOLID(X) X(F, shape) X(F, phase) X(A, min) X(A, max) X(A, center) X(A, normal) X(F, radius) \
    X(F, height) X(F, axis) X(F, layers) X(F, open_top) X(F, slip) X(F, own_viscosity)              \
    X(F, viscosity)
TABLE(solid_table, SOLID);
#undef T

#define T pfsph_body_def
#define BODY(X) X(A, name) X(F, shape) X(F, phase) X(A, half) X(F, radius) X(F, height) X(F, axis) \
    X(A, mesh) X(F, scale) X(A, position) X(A, rotation) X(A, velocity) X(A, angular_velocity)     \
    X(F, density) X(F, mass) X(A, inertia) X(F, friction) X(F, restitution) X(F, layers)            \
    X(F, kinematic) X(F, nkeys) X(SN, keys, nkeys)
TABLE(body_table, BODY);
#undef T

#define T pfsph_emitter_params
#define EMITTER(X) X(F, shape) X(F, phase) X(A, center) X(A, direction) X(F, axis) X(F, radius)     \
    X(A, size) X(F, speed) X(F, rate) X(F, start) X(F, stop) X(F, bubble)
TABLE(emitter_table, EMITTER);
#undef T

#define T pfsph_shift_params
#define SHIFT(X) X(F, D) X(F, A) X(F, surface) X(F, max_frac)
TABLE(shift_table, SHIFT);
#undef T

#define T pfsph_thermostat_params
#define THERMO(X) X(F, enabled) X(F, kT) X(F, reduced)                                              \
    X(O, kT_resolved) X(O, sigma_ref) X(O, rho_ref) /* derived (pfsph_pairwise_resolve) */
TABLE(thermo_table, THERMO);
#undef T

#define T pfsph_pairwise_params
#define PAIRWISE(X) X(F, enabled) X(F, k) X(F, filter) X(F, eta) X(F, eps_min) X(F, center)         \
    X(S, shift) X(S, thermo) X(M, c, c_stated) X(A, c_set) X(A, sigma_set) X(A, sigma)              \
    X(A, angle_set) X(A, angle_deg)                                                                 \
    X(O, resolved) X(O, radius) X(O, lambda) X(O, theta) X(O, sigma_factor) /* derived (resolve) */ \
    X(OA, sigma_factor_ab) /* derived (resolve) */                                                  \
    X(F, visc_correct)                                                                              \
    X(OA, nu_morris) X(OA, nu_struct) X(OA, nu_floor) /* derived (resolve) */
TABLE(pairwise_table, PAIRWISE);
#undef T

#define T pfsph_diffuse_coupling
#define COUPLING(X) X(F, k_ext) X(F, k_b) X(F, k_cp) X(F, k_t)
TABLE(coupling_table, COUPLING);
#undef T

#define T pfsph_diffuse_params
#define DIFFUSE(X) X(F, enabled) X(F, max_particles) X(F, sampling_rate) X(F, phi_v_min)            \
    X(F, phi_v_max) X(F, phi_e_min) X(F, phi_e_max) X(F, energy_mass) X(F, emit_radius)             \
    X(F, emit_radius_scale) X(F, emit_height_scale) X(F, lifetime_min) X(F, lifetime_max)          \
    X(F, foam_min_neighbors) X(F, foam_max_neighbors) X(S, type)
TABLE(diffuse_table, DIFFUSE);
#undef T

#define T pfsph_film_params
#define FILM(X) X(F, nbubbles) X(A, film) X(A, gas) X(A, block) X(A, thickness)                     \
    X(M, volume, volume_stated)
TABLE(film_table, FILM);
#undef T

/* The scene: what a resume may change is left out (docs/checkpoints.md): the source and name,
 * the end time (--end), the thread count, output and camera. */
#define T pfsph_scene
#define SCENE(X) X(OA, source) X(OA, name)                                                          \
    X(F, dim) X(F, particle_radius) X(F, support_factor) X(A, gravity) X(A, domain_min)             \
    X(A, domain_max) X(A, solver) X(A, solver_settings) X(F, mode) X(F, cfl) X(F, dt_min) X(F, dt_max)         \
    X(O, end_time) X(F, fps) X(F, seed) X(O, threads) X(F, sound_speed) X(F, gamma)                 \
    X(F, pressure_scale) X(F, nphases) X(SN, phases, nphases) X(F, nblocks) X(SN, blocks, nblocks)    \
    X(F, nsolids) X(SN, solids, nsolids) X(F, nbodies) X(SN, bodies, nbodies) X(F, nemitters)       \
    X(SN, emitters, nemitters) X(S, pairwise) X(S, diffuse) X(S, film) X(OA, output) X(OA, camera)
TABLE(scene_table, SCENE);
#undef T

// clang-format on

/* ---- hashing ---- */

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) {
        h ^= b[i];
        h *= 1099511628211ull;
    }
    return h;
}

static uint64_t fnv_u64(uint64_t h, uint64_t v)
{
    unsigned char b[8];
    for (int k = 0; k < 8; k++) b[k] = (unsigned char)(v >> 8 * k);
    return fnv(h, b, 8);
}

/* splitmix64's finaliser: the members' hashes are summed, so each is mixed in full first */
static uint64_t mix(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static size_t leaf_size(enum kind k)
{
    switch (k) {
    case K_I32: return sizeof(int);
    case K_BOOL: return sizeof(bool);
    case K_LONG: return sizeof(long);
    case K_U64: return sizeof(uint64_t);
    case K_F64: return sizeof(double);
    case K_F32: return sizeof(float);
    default: return 0;
    }
}

/* Element i of a leaf member at p: its value as little-endian bytes in v (n of them), or 0
 * bytes when it is zero. */
static size_t leaf_value(enum kind k, const unsigned char *p, size_t size, unsigned char *v)
{
    if (k == K_STR) {
        size_t n = strnlen((const char *)p, size);
        memcpy(v, p, n);
        return n;
    }
    uint64_t u = 0;
    switch (k) {
    case K_I32: {
        int x;
        memcpy(&x, p, sizeof x);
        u = (uint64_t)(int64_t)x;
        break;
    }
    case K_BOOL: u = *(const bool *)p; break;
    case K_LONG: {
        long x;
        memcpy(&x, p, sizeof x);
        u = (uint64_t)(int64_t)x;
        break;
    }
    case K_U64: memcpy(&u, p, sizeof u); break;
    case K_F64: {
        double x;
        memcpy(&x, p, sizeof x);
        if (x == 0) return 0; /* -0 too */
        memcpy(&u, &x, sizeof u);
        break;
    }
    case K_F32: {
        float x;
        memcpy(&x, p, sizeof x);
        if (x == 0) return 0;
        uint32_t w;
        memcpy(&w, &x, sizeof w);
        u = w;
        break;
    }
    default: return 0;
    }
    if (!u) return 0;
    for (int b = 0; b < 8; b++) v[b] = (unsigned char)(u >> 8 * b);
    return 8;
}

/* Add the hashes of the non-zero members of the struct at base (path: its own) to *sum. */
static void hash_struct(uint64_t *sum, const table *t, const unsigned char *base, uint64_t path)
{
    unsigned char v[PFSPH_PATH_LEN];
    for (int r = 0; r < t->nrows; r++) {
        const row *w = &t->rows[r];
        if (w->kind == K_OUT) continue;
        const uint64_t rp = fnv(fnv(path, ".", 1), w->name, strlen(w->name));
        if (w->kind == K_SUB) {
            size_t n = w->size / w->sub->size;
            if (w->count_off >= 0) {
                int c;
                memcpy(&c, base + w->count_off, sizeof c);
                n = c < 0 ? 0 : (size_t)c < n ? (size_t)c : n;
            }
            for (size_t i = 0; i < n; i++) hash_struct(sum, w->sub, base + w->off + i * w->sub->size, fnv_u64(rp, i));
            continue;
        }
        const size_t es = w->kind == K_STR ? w->size : leaf_size(w->kind);
        for (size_t i = 0; i < w->size / es; i++) {
            if (w->stated && !w->stated(base, i)) continue;
            const size_t n = leaf_value(w->kind, base + w->off + i * es, es < sizeof v ? es : sizeof v, v);
            if (n) *sum += mix(fnv(fnv_u64(rp, i), v, n));
        }
    }
}

uint64_t pfsph_scene_hash(const pfsph_scene *s)
{
    uint64_t sum = 0;
    const uint64_t root = 14695981039346656037ull; /* FNV-1a's offset basis */
    hash_struct(&sum, &scene_table, (const unsigned char *)s, root);
    const unsigned char real = (unsigned char)sizeof(pfsph_real); /* a float build's state is not a double's */
    sum += mix(fnv(fnv(root, "real", 4), &real, 1));
    return mix(sum);
}
