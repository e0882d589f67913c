/* libFuzzer target: the OBJ reader, closedness check, mass properties and surface sampling must
 * return OK or a clean error for any bytes, and free everything. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "pfsph/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pfsph_mesh m;
    pfsph_error err;
    err.msg[0] = 0;
    /* the reader takes a length, so the bytes are passed as they are (no NUL terminator) */
    int rc = pfsph_mesh_parse_obj(&m, (const char *)data, size, "fuzz.obj", &err);
    if (rc != PFSPH_OK && rc != PFSPH_EINPUT && rc != PFSPH_ENOMEM) abort();
    if (rc != PFSPH_OK) {
        if (!err.msg[0] || m.v || m.tri || m.nverts || m.ntris) abort(); /* says why, left empty */
        return 0;
    }
    err.msg[0] = 0;
    rc = pfsph_mesh_validate_closed(&m, "fuzz.obj", &err);
    if (rc != PFSPH_OK && rc != PFSPH_EINPUT && rc != PFSPH_ENOMEM) abort();
    if (rc != PFSPH_OK && !err.msg[0]) abort();
    if (rc == PFSPH_OK) {
        double vol, com[3], inertia[9];
        pfsph_mesh_mass_properties(&m, &vol, com, inertia);
        if (!(vol > 0)) abort(); /* validate_closed promises a positive volume */
        /* sampling: spacing = bounding-box diagonal / 16; big meshes skipped to stay fast */
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < m.nverts; i++)
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], m.v[3 * i + a]);
                hi[a] = fmax(hi[a], m.v[3 * i + a]);
            }
        double d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
        double spacing = sqrt(d2) / 16;
        if (m.ntris <= 2000 && isfinite(spacing) && spacing > 0) {
            double *pts = NULL;
            size_t n = 0;
            rc = pfsph_mesh_sample_surface(&m, spacing, &pts, &n, &err);
            if (rc != PFSPH_OK && rc != PFSPH_EINPUT && rc != PFSPH_ENOMEM) abort();
            if (rc == PFSPH_OK && n == 0) abort(); /* a closed surface always gets samples */
            free(pts);
        }
    }
    pfsph_mesh_free(&m);
    return 0;
}
