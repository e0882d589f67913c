# Readers of pfsph's frame files (binary PLY, VTK XML PolyData with appended raw or ASCII data),
# numpy only, shared by the Blender loader and usable on their own. docs/artists.md.
import os
import re

import numpy as np

_PLY_TYPES = {"char": "i1", "uchar": "u1", "int8": "i1", "uint8": "u1", "short": "i2", "ushort": "u2",
              "int": "i4", "uint": "u4", "int32": "i4", "uint32": "u4", "float": "f4", "float32": "f4",
              "double": "f8", "float64": "f8"}


def read_ply(path):
    """Binary little-endian PLY as written by pfsph: returns (vertex fields, faces, face fields,
    comments). Faces: (n, 3) int array of triangles (None without a face element)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if header[0] != "ply" or header[1] != "format binary_little_endian 1.0":
        raise ValueError(f"{path}: not a binary little-endian PLY")
    elements, comments = [], []
    for line in header[2:]:
        w = line.split()
        if not w:
            continue
        if w[0] == "comment":
            comments.append(line[8:])
        elif w[0] == "element":
            elements.append([w[1], int(w[2]), []])
        elif w[0] == "property":
            elements[-1][2].append(w[1:])
    pos = end
    verts, faces, ffields = {}, None, {}
    for name, count, props in elements:
        if props and props[0][0] == "list":
            # pfsph faces: uchar 3, three uint indices, then scalar properties
            dt = [("n", "u1"), ("i", "<u4", 3)] + [(p[1], "<" + _PLY_TYPES[p[0]]) for p in props[1:]]
            arr = np.frombuffer(data, dtype=np.dtype(dt), count=count, offset=pos)
            pos += arr.nbytes
            if count and not np.all(arr["n"] == 3):
                raise ValueError(f"{path}: only triangles are read")
            faces = np.array(arr["i"], dtype=np.int64).reshape(-1, 3)
            ffields = {p[1]: np.array(arr[p[1]]) for p in props[1:]}
        else:
            dt = np.dtype([(p[1], "<" + _PLY_TYPES[p[0]]) for p in props])
            arr = np.frombuffer(data, dtype=dt, count=count, offset=pos)
            pos += arr.nbytes
            if name == "vertex":
                verts = {p[1]: np.array(arr[p[1]]) for p in props}
    return verts, faces, ffields, comments


_VTK_TYPES = {"Float32": "<f4", "Float64": "<f8", "UInt8": "u1", "Int8": "i1", "UInt32": "<u4", "Int32": "<i4",
              "Int64": "<i8", "UInt64": "<u8"}


def read_vtp(path):
    """pfsph's VTK XML PolyData: returns (points (n, 3), point arrays {name: array}, polys (m, 3) or
    None, cell arrays, field arrays)."""
    with open(path, "rb") as f:
        data = f.read()
    app = data.find(b"<AppendedData")
    head = data[: app if app >= 0 else len(data)].decode("utf-8", "replace")
    base = data.index(b"_", data.index(b">", app)) + 1 if app >= 0 else 0
    section = None
    out = {"Points": {}, "PointData": {}, "CellData": {}, "FieldData": {}, "Polys": {}, "Verts": {}}
    for m in re.finditer(r"<(/?)(\w+)([^>]*?)(/?)>", head):
        closing, tag, attrs, selfclose = m.groups()
        if tag in out and not closing:
            section = tag
        elif tag in out and closing:
            section = None
        if tag != "DataArray" or closing:
            continue
        a = dict(re.findall(r'(\w+)="([^"]*)"', attrs))
        dt = np.dtype(_VTK_TYPES[a["type"]])
        ncomp = int(a.get("NumberOfComponents", "1"))
        if a.get("format") == "appended":
            off = base + int(a["offset"])
            nbytes = int(np.frombuffer(data, "<u8", 1, off)[0])
            arr = np.frombuffer(data, dt, nbytes // dt.itemsize, off + 8)
        else:  # ascii: the text up to </DataArray>
            endtag = head.index("</DataArray>", m.end())
            arr = np.array(head[m.end():endtag].split(), dtype=dt)
        if ncomp > 1:
            arr = arr.reshape(-1, ncomp)
        out[section or "FieldData"][a.get("Name", "Points" if section == "Points" else "")] = np.array(arr)
    pts = next(iter(out["Points"].values())) if out["Points"] else np.zeros((0, 3), "f4")
    polys = None
    if "connectivity" in out["Polys"]:
        polys = out["Polys"]["connectivity"].astype(np.int64).reshape(-1, 3)
    return pts, out["PointData"], polys, out["CellData"], out["FieldData"]


def frame_files(run_dir, prefix, exts=("ply", "vtp")):
    """{frame number: path} of RUN/frames/<prefix>_NNNNN.<ext>, the first extension found wins."""
    d = os.path.join(run_dir, "frames")
    found = {}
    if not os.path.isdir(d):
        return found
    for ext in exts:
        pat = re.compile(re.escape(prefix) + r"_(\d{5})\." + ext + "$")
        for n in sorted(os.listdir(d)):
            m = pat.match(n)
            if m and int(m.group(1)) not in found:
                found[int(m.group(1))] = os.path.join(d, n)
    return dict(sorted(found.items()))


def read_particles(path):
    """Positions (n, 3) and fields {name: array} of a particle frame (.ply or .vtp)."""
    if path.endswith(".ply"):
        v, _, _, _ = read_ply(path)
        pts = np.stack([v["x"], v["y"], v["z"]], axis=1)
        fields = {k: a for k, a in v.items() if k not in ("x", "y", "z", "vx", "vy", "vz")}
        if "vx" in v:  # one vector, as the VTP files have it
            fields["velocity"] = np.stack([v["vx"], v["vy"], v["vz"]], axis=1)
        return pts, fields
    pts, pd, _, _, _ = read_vtp(path)
    return pts, pd


def read_mesh(path):
    """Vertices (n, 3), triangles (m, 3), per-face fields of a surface file (.ply or .vtp)."""
    if path.endswith(".ply"):
        v, f, ff, _ = read_ply(path)
        return np.stack([v["x"], v["y"], v["z"]], axis=1), f, ff
    pts, _, polys, cd, _ = read_vtp(path)
    return pts, polys, cd


def read_mesh_velocity(path):
    """The liquid's velocity at the vertices of a surface file, (n, 3) or None (older runs, OBJ)."""
    if path.endswith(".ply"):
        v, _, _, _ = read_ply(path)
        return np.stack([v["vx"], v["vy"], v["vz"]], axis=1) if "vx" in v else None
    _, pd, _, _, _ = read_vtp(path)
    return pd.get("velocity")


def y_up_to_z_up(p):
    """pfsph is y-up, Blender z-up: (x, y, z) -> (x, -z, y), a rotation (faces keep their side)."""
    p = np.asarray(p, dtype=np.float64)
    return np.stack([p[:, 0], -p[:, 2], p[:, 1]], axis=1)
