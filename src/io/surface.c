/* Body surfaces per frame: every body's triangle mesh in world coordinates, as binary PLY
 * (Blender, Houdini) and VTK XML PolyData (ParaView), with each body's pose as field data. */
#include <stdio.h>

#include "io/io_internal.h"
#include "pfsph/surface_io.h"

int pfsph_write_surfaces_ply(const char *path, const pfsph_mesh *meshes, int n, const pfsph_body_pose *poses,
                             double time, pfsph_error *err)
{
    size_t nv = 0, nt = 0;
    for (int b = 0; b < n; b++) nv += meshes[b].nverts, nt += meshes[b].ntris;
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    pfsph__enc_printf(&e, "ply\nformat binary_little_endian 1.0\ncomment pfsph %s\n", PFSPH_VERSION);
    pfsph__enc_printf(&e, "comment time %.17g\n", time);
    for (int b = 0; b < n; b++)
        pfsph__enc_printf(&e, "comment body %d %s position %.9g %.9g %.9g quaternion %.9g %.9g %.9g %.9g\n", b,
                          poses[b].name, poses[b].x[0], poses[b].x[1], poses[b].x[2], poses[b].q[0], poses[b].q[1],
                          poses[b].q[2], poses[b].q[3]);
    pfsph__enc_printf(&e, "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n", nv);
    pfsph__enc_printf(&e, "element face %zu\nproperty list uchar uint vertex_indices\nproperty uchar body\n", nt);
    pfsph__enc_printf(&e, "end_header\n");
    for (int b = 0; b < n; b++)
        for (size_t i = 0; i < 3 * meshes[b].nverts; i++) {
            float v = (float)meshes[b].v[i];
            pfsph__enc_put(&e, &v, 4);
        }
    uint32_t base = 0;
    for (int b = 0; b < n; b++) {
        const uint8_t three = 3, body = (uint8_t)b;
        for (size_t t = 0; t < meshes[b].ntris; t++) {
            pfsph__enc_put(&e, &three, 1);
            for (int k = 0; k < 3; k++) {
                uint32_t idx = base + meshes[b].tri[3 * t + k];
                pfsph__enc_put(&e, &idx, 4);
            }
            pfsph__enc_put(&e, &body, 1);
        }
        base += (uint32_t)meshes[b].nverts;
    }
    return pfsph__enc_commit(&e, &af, err);
}

int pfsph_write_surfaces_vtp(const char *path, const pfsph_mesh *meshes, int n, const pfsph_body_pose *poses,
                             double time, pfsph_error *err)
{
    size_t nv = 0, nt = 0;
    for (int b = 0; b < n; b++) nv += meshes[b].nverts, nt += meshes[b].ntris;
    pfsph__afile af;
    pfsph__enc e;
    int rc = pfsph__enc_open(&e, &af, path, err);
    if (rc != PFSPH_OK) return rc;
    /* ASCII: surfaces are small next to the particle frames, and text is easy to check */
    pfsph__enc_printf(&e,
                      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" "
                      "byte_order=\"LittleEndian\">\n<PolyData>\n");
    pfsph__enc_printf(&e,
                      "<FieldData>\n<DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
                      "format=\"ascii\">%.17g</DataArray>\n",
                      time);
    pfsph__enc_printf(&e,
                      "<DataArray type=\"Float64\" Name=\"body_pose\" NumberOfComponents=\"7\" NumberOfTuples=\"%d\" "
                      "format=\"ascii\">\n",
                      n);
    for (int b = 0; b < n; b++)
        pfsph__enc_printf(&e, "%.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", poses[b].x[0], poses[b].x[1], poses[b].x[2],
                          poses[b].q[0], poses[b].q[1], poses[b].q[2], poses[b].q[3]);
    pfsph__enc_printf(&e, "</DataArray>\n</FieldData>\n");
    pfsph__enc_printf(&e,
                      "<Piece NumberOfPoints=\"%zu\" NumberOfPolys=\"%zu\">\n<Points>\n<DataArray type=\"Float32\" "
                      "NumberOfComponents=\"3\" format=\"ascii\">\n",
                      nv, nt);
    for (int b = 0; b < n; b++)
        for (size_t i = 0; i < meshes[b].nverts; i++)
            pfsph__enc_printf(&e, "%.7g %.7g %.7g\n", meshes[b].v[3 * i], meshes[b].v[3 * i + 1],
                              meshes[b].v[3 * i + 2]);
    pfsph__enc_printf(
        &e, "</DataArray>\n</Points>\n<Polys>\n<DataArray type=\"UInt32\" Name=\"connectivity\" format=\"ascii\">\n");
    uint32_t base = 0;
    for (int b = 0; b < n; b++) {
        for (size_t t = 0; t < meshes[b].ntris; t++)
            pfsph__enc_printf(&e, "%u %u %u\n", base + meshes[b].tri[3 * t], base + meshes[b].tri[3 * t + 1],
                              base + meshes[b].tri[3 * t + 2]);
        base += (uint32_t)meshes[b].nverts;
    }
    pfsph__enc_printf(&e, "</DataArray>\n<DataArray type=\"UInt32\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t t = 1; t <= nt; t++) pfsph__enc_printf(&e, "%zu\n", 3 * t);
    pfsph__enc_printf(&e,
                      "</DataArray>\n</Polys>\n<CellData Scalars=\"body\">\n<DataArray type=\"UInt8\" Name=\"body\" "
                      "format=\"ascii\">\n");
    for (int b = 0; b < n; b++)
        for (size_t t = 0; t < meshes[b].ntris; t++) pfsph__enc_printf(&e, "%d\n", b);
    pfsph__enc_printf(&e, "</DataArray>\n</CellData>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    return pfsph__enc_commit(&e, &af, err);
}
