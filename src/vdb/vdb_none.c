/* The OpenVDB interface of a build without OpenVDB (src/pfsph/vdb.h): every call says so. */
#include "pfsph/vdb.h"

#define NO_VDB                                                                                   \
    "this build of pfsph has no OpenVDB (Debian: apt-get install libopenvdb-dev, then rebuild; " \
    "docs/artists.md#openvdb-level-sets-houdini-blender)"

bool pfsph_vdb_available(void) { return false; }

int pfsph_write_vdb(const char *path, const pfsph_vdb_frame *f, pfsph_error *err)
{
    (void)f;
    return pfsph_fail(err, PFSPH_EINPUT, "%s: %s", path, NO_VDB);
}

int pfsph_read_vdb(const char *path, const char *name, pfsph_vdb_grid_info *info, const double *p, size_t n,
                   double *out, pfsph_error *err)
{
    (void)name, (void)info, (void)p, (void)n, (void)out;
    return pfsph_fail(err, PFSPH_EINPUT, "%s: %s", path, NO_VDB);
}
