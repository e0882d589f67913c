"""Reading what `pfsph run` writes (docs/output.md): the frames (VTK XML PolyData with raw
appended data, binary little-endian PLY), stats.csv, bodies.csv, summary.json, scene.json."""
import csv
import json
import os
import re

import numpy as np

_VTK_TYPES = {"Float32": "<f4", "Float64": "<f8", "UInt8": "u1", "Int8": "i1", "UInt32": "<u4", "Int32": "<i4",
              "UInt64": "<u8", "Int64": "<i8"}
_PLY_TYPES = {"float": "<f4", "double": "<f8", "uchar": "u1", "char": "i1", "uint": "<u4", "int": "<i4",
              "ushort": "<u2", "short": "<i2", "float32": "<f4", "float64": "<f8", "uint8": "u1", "uint32": "<u4",
              "int32": "<i4"}
_SETS = ("fluid", "boundary", "diffuse", "bodies")


class Frame(dict):
    """One frame file's particles: a dict of numpy arrays by field name (``position`` and
    ``velocity`` (n, 3); ``density``, ``pressure``, ``phase`` or ``type``, ``id``, ``speed``,
    ``volume``, ``lifetime``, ``mechanical_pressure``, ``surface_layer``, ``film`` as the run
    wrote them), with ``time`` [s] and ``path``."""

    time = None
    path = None

    def __len__(self):
        return len(self["position"]) if "position" in self else 0

    def by_id(self):
        """The frame's arrays reordered by ascending particle id (the run must write "id":
        output.fields)."""
        order = np.argsort(self["id"], kind="stable")
        f = Frame({k: v[order] for k, v in self.items()})
        f.time, f.path = self.time, self.path
        return f

    def __repr__(self):
        return "<pfsph Frame %s: %d particles, t = %s s, fields %s>" % (
            os.path.basename(self.path or "?"), len(self), self.time, ", ".join(self))


def read_frame(path):
    """Read one particle frame file (.vtp or .ply as pfsph writes them) into a Frame."""
    with open(path, "rb") as fh:
        data = fh.read()
    f = _read_vtp(data, path) if path.endswith(".vtp") else _read_ply(data, path)
    f.path = path
    return f


def _read_vtp(data, path):
    start = data.find(b"<AppendedData")
    if start < 0:
        raise ValueError("%s: no <AppendedData> section" % path)
    head = data[:start].decode("utf-8", "replace")
    if 'header_type="UInt64"' not in head or "compressor=" in head:
        raise ValueError("%s: not a pfsph frame (UInt64 headers, uncompressed)" % path)
    base = data.index(b"_", data.index(b">", start)) + 1
    frame = Frame()
    section = None
    for m in re.finditer(r"<(/?)(FieldData|PointData|Points|Verts|DataArray)\b([^>]*)>", head):
        closing, tag, attrs = m.groups()
        if tag != "DataArray":
            section = None if closing else tag
            continue
        a = dict(re.findall(r'(\w+)="([^"]*)"', attrs))
        off = base + int(a["offset"])
        nbytes = int(np.frombuffer(data, "<u8", 1, off)[0])
        arr = np.frombuffer(data, _VTK_TYPES[a["type"]], nbytes // np.dtype(_VTK_TYPES[a["type"]]).itemsize, off + 8)
        ncomp = int(a.get("NumberOfComponents", 1))
        if ncomp > 1:
            arr = arr.reshape(-1, ncomp)
        if section == "FieldData" and a["Name"] == "TimeValue":
            frame.time = float(arr[0])
        elif section == "Points":
            frame["position"] = arr
        elif section == "PointData":
            frame[a["Name"]] = arr
    return frame


def _read_ply(data, path):
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise ValueError("%s: not a PLY file" % path)
    head = data[:end].decode("utf-8", "replace").splitlines()
    if "format binary_little_endian 1.0" not in head:
        raise ValueError("%s: not binary little-endian PLY" % path)
    frame = Frame()
    n, props, element = 0, [], None
    for line in head:
        w = line.split()
        if w[:2] == ["comment", "time"]:
            frame.time = float(w[2])
        elif w[:1] == ["element"]:
            element = w[1]
            if element == "vertex":
                n = int(w[2])
        elif w[:1] == ["property"] and element == "vertex":
            if w[1] == "list":
                raise ValueError("%s: vertex list properties are not pfsph's" % path)
            props.append((w[2], _PLY_TYPES[w[1]]))
    rec = np.frombuffer(data, np.dtype(props), n, end + len(b"end_header\n"))
    names = [p[0] for p in props]
    for group, keys in (("position", ("x", "y", "z")), ("velocity", ("vx", "vy", "vz"))):
        if all(k in names for k in keys):
            frame[group] = np.stack([rec[k] for k in keys], axis=1)
    for k in names:
        if k not in ("x", "y", "z", "vx", "vy", "vz"):
            frame[k] = np.ascontiguousarray(rec[k])
    return frame


def _read_csv(path):
    """A CSV with a header row as a dict of numpy arrays by column (numbers as float64 or
    int64, other columns as str)."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        return {}
    cols = {}
    for j, name in enumerate(rows[0]):
        vals = [r[j] for r in rows[1:] if j < len(r)]
        for conv in (np.int64, np.float64):
            try:
                cols[name] = np.array([conv(v) for v in vals]) if vals else np.empty(0, conv)
                break
            except ValueError:
                continue
        else:
            cols[name] = np.array(vals, dtype=str)
    return cols


class Run:
    """A run directory written by `pfsph run` (or by Simulation.write_frame).

    ``summary`` (summary.json), ``scene`` (scene.json) and ``run`` (run.json) are dicts (None
    when missing); ``stats`` (stats.csv) and ``bodies`` (bodies.csv) dicts of numpy arrays by
    column. ``frame_numbers(set)`` lists the frames on disk, ``frame(k, set)`` reads one,
    ``frames(set)`` yields them in order."""

    def __init__(self, directory):
        self.directory = os.fspath(directory)
        if not os.path.isdir(self.directory):
            raise FileNotFoundError("%s: no such run directory" % self.directory)
        self.summary = self._json("summary.json")
        self.scene = self._json("scene.json")
        self.run = self._json("run.json")
        p = os.path.join(self.directory, "stats.csv")
        self.stats = _read_csv(p) if os.path.exists(p) else None
        p = os.path.join(self.directory, "bodies.csv")
        self.bodies = _read_csv(p) if os.path.exists(p) else None

    def _json(self, name):
        p = os.path.join(self.directory, name)
        if not os.path.exists(p):
            return None
        with open(p) as fh:
            return json.load(fh)

    def _files(self, set_name):
        d = os.path.join(self.directory, "frames")
        out = {}
        if not os.path.isdir(d):
            return out
        pat = re.compile(r"^%s_(\d{5,})\.(vtp|ply)$" % re.escape(set_name))
        for name in os.listdir(d):
            m = pat.match(name)
            if m:
                k = int(m.group(1))
                # both formats written: the VTP (it carries every field, as the program's readers prefer)
                if k not in out or m.group(2) == "vtp":
                    out[k] = os.path.join(d, name)
        return out

    def frame_numbers(self, set_name="fluid"):
        """Frame indices on disk for a set ("fluid", "boundary", "diffuse", "bodies")."""
        return sorted(self._files(set_name))

    def frame(self, k, set_name="fluid"):
        """Frame k of a set as a Frame (a dict of numpy arrays); k = -1 is the last."""
        files = self._files(set_name)
        if not files:
            raise FileNotFoundError("%s: no %s frames" % (self.directory, set_name))
        if k < 0:
            k = sorted(files)[k]
        if k not in files:
            raise FileNotFoundError("%s: no %s frame %d (frames %d..%d)" % (
                self.directory, set_name, k, min(files), max(files)))
        return read_frame(files[k])

    def frames(self, set_name="fluid"):
        """Yields (k, Frame) for every frame of a set, in order."""
        files = self._files(set_name)
        for k in sorted(files):
            yield k, read_frame(files[k])

    def __len__(self):
        return len(self._files("fluid"))

    def __repr__(self):
        return "<pfsph Run %s: %d fluid frames%s>" % (
            self.directory, len(self), ", status %s" % self.summary.get("status") if self.summary else "")


def read_run(directory):
    """Open a run directory: a Run (frames, stats, summary)."""
    return Run(directory)
