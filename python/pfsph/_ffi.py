"""The C library through cffi in ABI mode: declarations copied from include/pfsph.h, the library
opened with dlopen at import (no compiler needed). Which libpfsph.so: docs/python.md."""
import os

from cffi import FFI

# include/pfsph.h, less its macros (tests/test_api.py checks that every function of the header is
# declared here).
CDEF = """
enum { PFSPH_OK = 0, PFSPH_EINPUT = -2, PFSPH_EUNSTABLE = -3, PFSPH_EINTR = -4, PFSPH_EIO = -5, PFSPH_ENOMEM = -12 };
enum { PFSPH_FLOAT32 = 1, PFSPH_FLOAT64 = 2, PFSPH_UINT8 = 3, PFSPH_UINT32 = 4 };

const char *pfsph_strerror(int code);
typedef struct pfsph_error {
    int code;
    char msg[1024];
} pfsph_error;
const char *pfsph_version(void);
int pfsph_real_type(void);
int pfsph_threads(int n);

typedef struct pfsph_scene pfsph_scene;
int pfsph_scene_new_file(pfsph_scene **out, const char *path, pfsph_error *err);
int pfsph_scene_new_json(pfsph_scene **out, const char *json, const char *source, pfsph_error *err);
void pfsph_scene_free(pfsph_scene *s);
const char *pfsph_scene_default_json(void);
int pfsph_scene_dim(const pfsph_scene *s);
double pfsph_scene_end_time(const pfsph_scene *s);
double pfsph_scene_fps(const pfsph_scene *s);
const char *pfsph_scene_name(const pfsph_scene *s);

typedef struct pfsph_sim pfsph_sim;
int pfsph_sim_new(pfsph_sim **out, const pfsph_scene *scene, pfsph_error *err);
void pfsph_sim_free(pfsph_sim *sim);
int pfsph_sim_step(pfsph_sim *sim, double t_limit, pfsph_error *err);
int pfsph_sim_advance(pfsph_sim *sim, double t, pfsph_error *err);
double pfsph_sim_time(const pfsph_sim *sim);
uint64_t pfsph_sim_steps(const pfsph_sim *sim);
double pfsph_sim_dt(const pfsph_sim *sim);
int pfsph_sim_dim(const pfsph_sim *sim);
const pfsph_scene *pfsph_sim_scene(const pfsph_sim *sim);

typedef struct pfsph_stats {
    double time, dt;
    uint64_t steps;
    size_t n_fluid;
    size_t n_boundary;
    size_t n_diffuse;
    size_t n_removed;
    double vmax;
    double density_err_avg;
    double density_err_max;
    double ekin;
    int iterations;
    int div_iterations;
} pfsph_stats;
void pfsph_sim_stats_get(const pfsph_sim *sim, pfsph_stats *out);

typedef struct pfsph_field {
    void *data[3];
    size_t count;
    size_t stride;
    size_t itemsize;
    int components;
    int type;
    int writable;
    const char *unit;
} pfsph_field;
int pfsph_sim_field(const pfsph_sim *sim, const char *set, const char *name, pfsph_field *out, pfsph_error *err);
const char *pfsph_field_name(const char *set, int i);
int pfsph_sim_count(const pfsph_sim *sim, const char *set, size_t *n, pfsph_error *err);
int pfsph_sim_field_write(pfsph_sim *sim, const char *set, const char *name, pfsph_field *out, pfsph_error *err);
int pfsph_sim_fields_written(pfsph_sim *sim, pfsph_error *err);

int pfsph_sim_write_frame(pfsph_sim *sim, const char *dir, int frame, pfsph_error *err);

int pfsph_sim_body_count(const pfsph_sim *sim);
const char *pfsph_sim_body_name(const pfsph_sim *sim, int i);
int pfsph_sim_body_state(const pfsph_sim *sim, int i, double x[3], double q[4], double v[3], double w[3]);
"""

ffi = FFI()
ffi.cdef(CDEF)

_HERE = os.path.dirname(os.path.abspath(__file__))


def library_path():
    """The libpfsph.so this package opens: $PFSPH_LIBRARY if set, else the copy installed with
    the package (pfsph/_lib/libpfsph.so, put there by setup.py)."""
    env = os.environ.get("PFSPH_LIBRARY")
    if env:
        return env
    return os.path.join(_HERE, "_lib", "libpfsph.so")


def _open():
    path = library_path()
    if not os.path.exists(path):
        raise ImportError(
            "pfsph: no shared library at %s: install the package with pip (it builds one, "
            "docs/python.md) or set PFSPH_LIBRARY to a libpfsph.so built with -DPFSPH_SHARED=ON" % path)
    # What the pfsph program sets for itself (docs/embedding.md, "Threads"): libgomp's default
    # spins waiting threads, which collapses on a loaded machine. libgomp reads it when it is
    # loaded, that is with the library just below, unless something loaded it before.
    os.environ.setdefault("GOMP_SPINCOUNT", "1000")
    return ffi.dlopen(path)


lib = _open()
