/* The OpenVDB exporter behind src/pfsph/vdb.h: the liquid's mesh as a narrow-band level set
 * (openvdb::tools::meshToLevelSet), a velocity grid on its band and a fog volume, written to
 * memory and then through the library's checked atomic writer; the reader for the tests.
 * Compiled only when OpenVDB is found (PFSPH_OPENVDB); docs/artists.md#openvdb-level-sets-houdini-blender. */
#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <mutex>
#include <new>
#include <sstream>
#include <string>
#include <vector>

extern "C" {
#include "pfsph/io.h"
#include "pfsph/vdb.h"
/* src/io/io_internal.h (C only): the capped whole-file reader of frames read back */
int pfsph__read_file(const char *path, unsigned char **data, size_t *len, pfsph_error *err);
}

namespace
{

void init_once()
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

/* the velocity of the liquid at the active voxels of the level set: the particles' Shepard
 * average (pfsph_surface_velocity, as at the mesh's vertices) */
openvdb::Vec3SGrid::Ptr velocity_grid(const openvdb::FloatGrid &ls, const pfsph_vdb_frame *f)
{
    std::vector<openvdb::Coord> ijk;
    ijk.reserve(ls.activeVoxelCount());
    for (auto it = ls.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) ijk.push_back(it.getCoord());
    }
    std::vector<double> at(3 * (ijk.empty() ? 1 : ijk.size()));
    for (size_t i = 0; i < ijk.size(); i++) {
        openvdb::Vec3d w = ls.transform().indexToWorld(ijk[i]);
        for (int k = 0; k < 3; k++) at[3 * i + k] = w[k];
    }
    pfsph_surface_mesh pts = {};
    pts.nverts = ijk.size();
    pts.v = at.data();
    if (pfsph_surface_velocity(&pts, f->x, f->v, f->n, f->radius)) throw std::bad_alloc();
    auto g = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    g->setTransform(ls.transform().copy());
    auto acc = g->getAccessor();
    for (size_t i = 0; i < ijk.size(); i++)
        acc.setValue(ijk[i], openvdb::Vec3s(pts.vel[3 * i], pts.vel[3 * i + 1], pts.vel[3 * i + 2]));
    free(pts.vel);
    g->setName("velocity");
    g->setGridClass(openvdb::GRID_UNKNOWN);
    g->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    g->setIsInWorldSpace(true);
    return g;
}

/* OpenVDB puts a random UUID in every file's header (magic 8 bytes, versions 12, a flag 1, then
 * the UUID as 36 characters). pfsph's outputs are the same bytes for the same run (a resumed run
 * is checked against an uninterrupted one): the UUID becomes a hash of the rest of the file, so
 * that equal files share one and different ones differ, as tools that cache by it expect. */
void same_bytes_each_time(std::string &b)
{
    const size_t at = 21, n = 36;
    if (b.size() < at + n) return;
    for (size_t i = 0; i < n; i++) {
        const char c = b[at + i];
        const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
        if (dash ? c != '-' : !std::isxdigit((unsigned char)c)) return; /* not the layout known */
    }
    uint64_t h[2] = {1469598103934665603ull, 1099511628211ull * 31}; /* FNV-1a, two seeds */
    for (size_t i = 0; i < b.size(); i++) {
        if (i >= at && i < at + n) continue;
        for (int k = 0; k < 2; k++) h[k] = (h[k] ^ (unsigned char)b[i]) * 1099511628211ull;
    }
    char u[40];
    snprintf(u, sizeof u, "%08x-%04x-4%03x-%04x-%012llx", (unsigned)(h[0] >> 32), (unsigned)(h[0] >> 16) & 0xffff,
             (unsigned)h[0] & 0xfff, 0x8000u | ((unsigned)(h[1] >> 48) & 0x3fff),
             (unsigned long long)(h[1] & 0xffffffffffffull));
    b.replace(at, n, u, n);
}

int write_frame(const char *path, const pfsph_vdb_frame *f, pfsph_error *err)
{
    init_once();
    const pfsph_surface_mesh *m = f->mesh;
    if (!(f->voxel > 0) || !std::isfinite(f->voxel))
        return pfsph_fail(err, PFSPH_EINPUT, "%s: voxel size %g is not positive", path, f->voxel);
    const double hw = f->half_width > 0 ? f->half_width : 3.0;
    std::vector<openvdb::Vec3s> pts(m->nverts);
    for (size_t i = 0; i < m->nverts; i++)
        pts[i] = openvdb::Vec3s((float)m->v[3 * i], (float)m->v[3 * i + 1], (float)m->v[3 * i + 2]);
    std::vector<openvdb::Vec3I> tris(m->ntris);
    for (size_t t = 0; t < m->ntris; t++) tris[t] = openvdb::Vec3I(m->tri[3 * t], m->tri[3 * t + 1], m->tri[3 * t + 2]);
    /* cell-centred voxels on the grid of the mesher's nodes: voxel (i, j, k) at (i, j, k) * voxel */
    auto xf = openvdb::math::Transform::createLinearTransform(f->voxel);
    openvdb::FloatGrid::Ptr ls = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xf, pts, tris, (float)hw);
    ls->setName("surface");
    ls->setGridClass(openvdb::GRID_LEVEL_SET);
    ls->insertMeta("creator", openvdb::StringMetadata(std::string("pfsph ") + PFSPH_VERSION));
    openvdb::GridPtrVec grids;
    if (f->grids & PFSPH_VDB_SURFACE) grids.push_back(ls);
    if (f->grids & PFSPH_VDB_DENSITY) {
        openvdb::FloatGrid::Ptr fog = ls->deepCopy();
        openvdb::tools::sdfToFogVolume(*fog);
        fog->setName("density");
        grids.push_back(fog);
    }
    if ((f->grids & PFSPH_VDB_VELOCITY) && f->x && f->v) grids.push_back(velocity_grid(*ls, f));
    openvdb::MetaMap meta;
    meta.insertMeta("time", openvdb::DoubleMetadata(f->time));
    meta.insertMeta("creator", openvdb::StringMetadata(std::string("pfsph ") + PFSPH_VERSION));
    std::ostringstream os(std::ios_base::binary);
    openvdb::io::Stream(os).write(grids, meta);
    std::string bytes = os.str();
    same_bytes_each_time(bytes);
    return pfsph_write_file_atomic(path, bytes.data(), bytes.size(), err);
}

int read_grid(const char *path, const char *name, pfsph_vdb_grid_info *info, const double *p, size_t n, double *out,
              pfsph_error *err)
{
    init_once();
    unsigned char *data = nullptr;
    size_t len = 0;
    int rc = pfsph__read_file(path, &data, &len, err);
    if (rc) return rc;
    std::string bytes(reinterpret_cast<const char *>(data), len);
    free(data);
    std::istringstream is(bytes, std::ios_base::binary);
    openvdb::io::Stream st(is);
    openvdb::GridPtrVecPtr grids = st.getGrids();
    openvdb::MetaMap::Ptr meta = st.getMetadata();
    openvdb::GridBase::Ptr g;
    for (auto &h : *grids)
        if (h && h->getName() == name) g = h;
    if (!g) return pfsph_fail(err, PFSPH_EINPUT, "%s: no grid named '%s'", path, name);
    *info = pfsph_vdb_grid_info{};
    snprintf(info->name, sizeof info->name, "%s", g->getName().c_str());
    snprintf(info->value_type, sizeof info->value_type, "%s", g->valueType().c_str());
    info->level_set = g->getGridClass() == openvdb::GRID_LEVEL_SET;
    info->fog = g->getGridClass() == openvdb::GRID_FOG_VOLUME;
    openvdb::Vec3d vs = g->voxelSize();
    for (int k = 0; k < 3; k++) info->voxel[k] = vs[k];
    info->active = (size_t)g->activeVoxelCount();
    info->time = std::numeric_limits<double>::quiet_NaN();
    if (meta) {
        auto t = meta->getMetadata<openvdb::DoubleMetadata>("time");
        if (t) info->time = t->value();
    }
    if (auto fg = openvdb::GridBase::grid<openvdb::FloatGrid>(g)) {
        info->background = fg->background();
        if (p) {
            openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> s(*fg);
            for (size_t i = 0; i < n; i++) out[i] = s.wsSample(openvdb::Vec3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
        }
    } else if (auto vg = openvdb::GridBase::grid<openvdb::Vec3SGrid>(g)) {
        info->background = vg->background()[0];
        if (p) {
            openvdb::tools::GridSampler<openvdb::Vec3SGrid, openvdb::tools::BoxSampler> s(*vg);
            for (size_t i = 0; i < n; i++) out[i] = s.wsSample(openvdb::Vec3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]))[0];
        }
    } else if (p) {
        return pfsph_fail(err, PFSPH_EINPUT, "%s: grid '%s' of type %s cannot be sampled", path, name,
                          info->value_type);
    }
    return PFSPH_OK;
}

/* an exception's message as one printable line (a corrupt file's bytes can reach it) */
std::string printable(const char *m)
{
    std::string s;
    for (const char *c = m; *c && s.size() < 200; c++) s += (*c >= 32 && *c < 127) ? *c : '?';
    while (!s.empty() && (s.back() == ' ' || s.back() == '?')) s.pop_back();
    return s;
}

} // namespace

extern "C" bool pfsph_vdb_available(void) { return true; }

/* Exceptions never cross into C: OpenVDB's and the allocator's become status codes. */
extern "C" int pfsph_write_vdb(const char *path, const pfsph_vdb_frame *f, pfsph_error *err)
{
    try {
        return write_frame(path, f, err);
    } catch (const std::bad_alloc &) {
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    } catch (const std::exception &e) {
        return pfsph_fail(err, PFSPH_EIO, "%s: OpenVDB: %s", path, printable(e.what()).c_str());
    }
}

extern "C" int pfsph_read_vdb(const char *path, const char *name, pfsph_vdb_grid_info *info, const double *p, size_t n,
                              double *out, pfsph_error *err)
{
    try {
        return read_grid(path, name, info, p, n, out, err);
    } catch (const std::bad_alloc &) {
        return pfsph_fail(err, PFSPH_ENOMEM, "%s: out of memory", path);
    } catch (const std::exception &e) {
        return pfsph_fail(err, PFSPH_EINPUT, "%s: not an OpenVDB file pfsph can read: %s", path,
                          printable(e.what()).c_str());
    }
}
