#!/usr/bin/env python3
"""The hostile-user attack of issue 33, rerunnable: numeric edge values in ten scenes, JSON text
attacks, body sizes, broken OBJ files, run-directory abuses, kill -9 / resume cycles, full disks
and corrupt frames, against one pfsph program (a Release or a sanitizer build). Counts crashes
(a signal, a sanitizer report, an exit status the case does not allow), hangs (the time limit)
and silent losses (exit 0 while output is missing or wrong) per section; docs/robustness.md.

    tools/attack/attack.py --bin build/pfsph [--jobs 2] [--work DIR] [--json out.json] [SECTION...]

SECTION: numeric json bodies obj rundir kill diskfull frames (default all). The disk-full
section mounts small tmpfs file systems when run as root (else it uses PFSPH_FAULT_WRITE only).
"""
import argparse
import concurrent.futures as cf
import glob
import json
import math
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SANITIZER = re.compile(r"AddressSanitizer|LeakSanitizer|runtime error:|UndefinedBehaviorSanitizer")
ARGS = None


class Section:
    def __init__(self, name):
        self.name, self.cases, self.crashes, self.hangs, self.losses = name, 0, 0, 0, 0
        self.findings = []

    def finding(self, kind, what):
        setattr(self, kind, getattr(self, kind) + 1)
        self.findings.append(f"{kind}: {what}")
        print(f"  FINDING {self.name} {kind}: {what}", flush=True)

    def judge(self, what, rc, out, allowed=(0, 2), hang=False):
        """one case: rc must be in allowed; no signal, no sanitizer report, no hang"""
        self.cases += 1
        if hang:
            self.finding("hangs", f"{what}: no exit within the time limit")
        elif rc < 0 or rc >= 128 or SANITIZER.search(out):
            self.finding("crashes", f"{what}: exit {rc}: {tail(out)}")
        elif rc not in allowed:
            self.finding("crashes", f"{what}: exit {rc} (expected {allowed}): {tail(out)}")
        else:
            return True
        return False

    def row(self):
        return {"section": self.name, "cases": self.cases, "crashes": self.crashes, "hangs": self.hangs,
                "silent_losses": self.losses, "findings": self.findings}


def tail(s, n=300):
    s = s.strip().replace("\n", " | ")
    return s[-n:]


def run(args, timeout=60, env=None, cwd=None):
    """(rc, output, hung): the pfsph program with args"""
    e = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
    if env:
        e.update(env)
    try:
        p = subprocess.run([ARGS.bin] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout,
                           env=e, cwd=cwd, stdin=subprocess.DEVNULL)
        return p.returncode, p.stdout.decode("utf-8", "replace"), False
    except subprocess.TimeoutExpired as x:
        return -1, (x.stdout or b"").decode("utf-8", "replace"), True


def pmap(fn, items):
    with cf.ThreadPoolExecutor(max_workers=ARGS.jobs) as ex:
        return list(ex.map(fn, items))


def load(name):
    with open(os.path.join(SRC, "scenes", name)) as f:
        return json.load(f)


def dump(obj, path, nan_marker="__NAN__"):
    text = json.dumps(obj, indent=1).replace(f'"{nan_marker}"', "NaN")
    with open(path, "w") as f:
        f.write(text)


def leaves(o, path=()):
    if isinstance(o, bool):
        return []
    if isinstance(o, (int, float)):
        return [path]
    if isinstance(o, dict):
        return [p for k, v in o.items() for p in leaves(v, path + (k,))]
    if isinstance(o, list):
        return [p for i, v in enumerate(o) for p in leaves(v, path + (i,))]
    return []


def setleaf(o, path, v):
    for k in path[:-1]:
        o = o[k]
    o[path[-1]] = v


def scene_copy(name, work, tag):
    """a scene with its directory's meshes reachable (mesh paths are relative to the scene)"""
    s = load(name)
    for b in s.get("bodies", []):
        if "file" in b:
            b["file"] = os.path.join(SRC, "scenes", b["file"])
    return s


def expected_message(out, path):
    """a refusal names the file and a JSON path (or a line of the text)"""
    return path in out and ("$" in out or "line" in out)


def summary_ok(d, need_finished=True):
    try:
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
    except Exception:
        return False, "no readable summary.json"
    if need_finished and s.get("status") != "finished":
        return False, f"status {s.get('status')}"
    return True, ""


# ---- numeric edges -----------------------------------------------------------------------
NUMERIC_SCENES = ["dam_break_2d.json", "dam_break_2d_dfsph.json", "dam_break_2d_iisph.json",
                  "emitter_stream_2d.json", "hydrostatic_tank_2d.json", "pf_menisci_2d.json",
                  "pf_two_bubbles_2d.json", "pf_crown_2d.json", "bodies_nine_bodies.json", "diffuse_dam_ball.json"]
EDGES = [0, -1, 1e-300, 1e308, "__NAN__", "x"]


def sec_numeric(work):
    sec = Section("numeric")
    cases = []
    for name in NUMERIC_SCENES:
        base = scene_copy(name, work, "num")
        for li, p in enumerate(leaves(base)):
            for vi, v in enumerate(EDGES):
                if (li + vi) % ARGS.numeric_every:
                    continue  # a subset: every value of every leaf in turn (sanitizer builds)
                s = json.loads(json.dumps(base))
                setleaf(s, p, v)
                s.setdefault("output", {})["directory"] = "unused"
                f = os.path.join(work, f"num_{name[:-5]}_{li}_{vi}.json")
                dump(s, f)
                cases.append((name, p, v, f, s))

    def check(c):
        name, p, v, f, s = c
        rc, out, hung = run(["check", f], timeout=ARGS.timeout)
        return c, rc, out, hung

    accepted = []
    for c, rc, out, hung in pmap(check, cases):
        what = f"{c[0]} {'.'.join(map(str, c[1]))}={c[2]}"
        if sec.judge(what, rc, out, hang=hung):
            if rc == 2 and not expected_message(out, c[3]):
                sec.findings.append(f"message without file or path: {what}: {tail(out)}")
            if rc == 0:
                accepted.append(c)
            os.remove(c[3])
    print(f"numeric: {len(cases)} variants checked, {len(accepted)} accepted", flush=True)
    # a sample of the accepted 2D variants runs two frames
    rnd = random.Random(1)
    two_d = [c for c in accepted if c[4].get("dimension", 3) == 2]
    sample = rnd.sample(two_d, min(ARGS.numeric_runs, len(two_d)))

    def go(c):
        name, p, v, f, s = c
        fps = s.get("time", {}).get("fps", 25)
        d = os.path.join(work, "numrun_" + os.path.basename(f)[:-5])
        dump(s, f)
        end = 2.0 / fps if isinstance(fps, (int, float)) and fps > 0 else 0.08
        rc, out, hung = run(["run", f, "-o", d, "--force", "--quiet", "--end", repr(end)], timeout=4 * ARGS.timeout)
        return c, d, rc, out, hung

    for c, d, rc, out, hung in pmap(go, sample):
        what = f"run {c[0]} {'.'.join(map(str, c[1]))}={c[2]}"
        if sec.judge(what, rc, out, allowed=(0, 2, 3), hang=hung) and rc == 0:
            ok, why = summary_ok(d)
            if not ok:
                sec.finding("losses", f"{what}: exit 0 but {why}")
        shutil.rmtree(d, ignore_errors=True)
        os.remove(c[3]) if os.path.exists(c[3]) else None
    print(f"numeric: {len(sample)} accepted 2D variants ran two frames", flush=True)
    return sec


# ---- JSON text -----------------------------------------------------------------------------
def sec_json(work):
    sec = Section("json")
    good = open(os.path.join(SRC, "scenes", "dam_break_2d.json"), "rb").read()
    big = b'{"comment": "' + b"a" * (30 << 20) + b'"}'
    texts = {
        "empty": b"",
        "whitespace": b"   \n\t ",
        "open brace": b"{",
        "array": b"[]",
        "null": b"null",
        "number": b"42",
        "truncated": good[: len(good) // 2],
        "deep nesting": b"[" * 200000 + b"]" * 200000,
        "deep objects": b'{"a":' * 100000 + b"1" + b"}" * 100000,
        "duplicate keys": good.replace(b'"dimension": 2', b'"dimension": 2, "dimension": 3', 1),
        "utf-8 BOM": b"\xef\xbb\xbf" + good,
        "invalid utf-8 name": good.replace(b'"name": "', b'"name": "\xff\xfe', 1),
        "overlong NUL": good.replace(b'"name": "', b'"name": "\xc0\x80', 1),
        "escaped NUL": good.replace(b'"name": "', b'"name": "a\\u0000b', 1),
        "NUL byte": good[:50] + b"\x00" + good[50:],
        "huge number": good.replace(b'"dimension": 2', b'"dimension": 1e99999', 1),
        "trailing garbage": good + b"\n}}}garbage",
        "30 MB scene": big,
        "binary": bytes(random.Random(3).getrandbits(8) for _ in range(4096)),
    }
    for k, t in texts.items():
        f = os.path.join(work, "json_" + re.sub(r"\W", "_", k) + ".json")
        open(f, "wb").write(t)
        rc, out, hung = run(["check", f], timeout=ARGS.timeout)
        if sec.judge(f"json {k}", rc, out, hang=hung) and rc == 2 and f not in out:
            sec.findings.append(f"message without the file: json {k}: {tail(out)}")
        os.remove(f)
    for k, f in {"/dev/zero": "/dev/zero", "a directory": work, "missing file": work + "/none.json"}.items():
        rc, out, hung = run(["check", f], timeout=ARGS.timeout)
        sec.judge(f"json {k}", rc, out, allowed=(2,), hang=hung)
    return sec


# ---- body sizes ----------------------------------------------------------------------------
def sec_bodies(work):
    sec = Section("bodies")
    base = scene_copy("bodies_nine_bodies.json", work, "b")
    names = [b["name"] for b in base["bodies"]]
    variants = []
    i_box = 0
    i_sph = next(i for i, b in enumerate(base["bodies"]) if b["shape"] == "sphere")
    i_cyl = next((i for i, b in enumerate(base["bodies"]) if b["shape"] == "cylinder"), None)
    i_mesh = next((i for i, b in enumerate(base["bodies"]) if b["shape"] == "mesh"), None)
    for v in (1e-300, 1e-20, 1e-6, 1e300):
        variants.append((i_sph, "radius", v))
        variants.append((i_box, "half_extents", [v, v, v]))
        if i_cyl is not None:
            variants.append((i_cyl, "radius", v))
        if i_mesh is not None:
            variants.append((i_mesh, "scale", v))
    for v in (1e-300, 0, -1, 1e300):
        variants.append((i_box, "density", v))
    for v in (1e-300, 1e300):
        variants.append((i_box, "mass", v))
    variants.append((i_box, "inertia", [1e-300, 1e-300, 1e-300]))
    variants.append((i_box, "inertia", [1, 1e-12, 1]))
    while len(variants) < 24:
        variants.append((i_sph, "density", 10 ** random.Random(len(variants)).uniform(-30, 30)))
    for n, (i, key, v) in enumerate(variants[:24]):
        s = json.loads(json.dumps(base))
        b = s["bodies"][i]
        if key == "mass":
            b.pop("density", None)
        b[key] = v
        f = os.path.join(work, f"body_{n}.json")
        dump(s, f)
        rc, out, hung = run(["check", f], timeout=ARGS.timeout)
        what = f"body {names[i]}.{key}={v}"
        if sec.judge(what, rc, out, hang=hung) and rc == 2 and not expected_message(out, f):
            sec.findings.append(f"message without file or path: {what}: {tail(out)}")
        os.remove(f)
    return sec


# ---- broken OBJ ----------------------------------------------------------------------------
def sec_obj(work):
    sec = Section("obj")
    cube = ("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
            "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\n"
            "f 4 1 5\nf 4 5 8\n")
    objs = {
        "empty": "",
        "vertices only": "v 0 0 0\nv 1 0 0\nv 0 1 0\n",
        "index out of range": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
        "index zero": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
        "negative beyond": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -7\n",
        "open mesh": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "NaN vertex": cube.replace("v 1 1 1", "v nan 1 1"),
        "inf vertex": cube.replace("v 1 1 1", "v inf 1 1"),
        "huge coordinates": cube.replace("v 1 1 1", "v 1e300 1 1"),
        "degenerate faces": "v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\nf 1 2 3\n",
        "two-vertex face": cube + "f 1 2\n",
        "garbage tokens": cube + "f a b c\nv x y z\n",
        "long line": "v " + "1" * 2000000 + " 0 0\n" + cube,
        "binary": bytes(random.Random(5).getrandbits(8) for _ in range(8192)),
        "inside out": "".join(l if not l.startswith("f") else "f " + " ".join(reversed(l.split()[1:])) + "\n"
                              for l in cube.splitlines(True)),
        "a directory": None,
    }
    base = scene_copy("bodies_nine_bodies.json", work, "o")
    base["bodies"] = [{"name": "m", "shape": "mesh", "file": "", "scale": 0.05, "position": [0.3, 0.45, 0.15],
                       "density": 500, "phase": base["bodies"][0]["phase"]}]
    for k, text in objs.items():
        o = os.path.join(work, "obj_" + re.sub(r"\W", "_", k) + ".obj")
        if text is None:
            os.makedirs(o, exist_ok=True)
        else:
            open(o, "wb").write(text if isinstance(text, bytes) else text.encode())
        s = json.loads(json.dumps(base))
        s["bodies"][0]["file"] = o
        f = os.path.join(work, "objscene.json")
        dump(s, f)
        rc, out, hung = run(["check", f], timeout=ARGS.timeout)
        if sec.judge(f"obj {k}", rc, out, hang=hung) and rc == 2 and o not in out and f not in out:
            sec.findings.append(f"message without the file: obj {k}: {tail(out)}")
        if text is None:
            os.rmdir(o)
        else:
            os.remove(o)
    return sec


# ---- small scenes for runs -----------------------------------------------------------------
SMALL2D = {
    "dimension": 2, "particle_radius": 0.01, "gravity": [0, -9.81],
    "domain": {"min": [-0.1, -0.1], "max": [0.7, 0.6]},
    "solver": {"type": "dfsph"}, "time": {"end": 0.5, "fps": 50},
    "phases": [{"name": "water"}, {"name": "wall", "kind": "solid"}],
    "fluid": [{"shape": "box", "min": [0, 0], "max": [0.2, 0.3], "phase": "water"}],
    "solids": [{"shape": "container", "min": [0, 0], "max": [0.6, 0.5], "open_top": True, "phase": "wall"}],
    "output": {"formats": ["vtp", "ply"], "fields": ["id"], "boundary": True, "checkpoint_interval": 1},
}
SMALL3D = {
    "dimension": 3, "particle_radius": 0.01, "gravity": [0, -9.81, 0],
    "domain": {"min": [-0.1, -0.1, -0.1], "max": [0.5, 0.5, 0.3]},
    "solver": {"type": "dfsph"}, "time": {"end": 0.3, "fps": 20},
    "phases": [{"name": "water"}, {"name": "wall", "kind": "solid"}],
    "fluid": [{"shape": "box", "min": [0, 0, 0], "max": [0.12, 0.16, 0.12], "phase": "water"}],
    "solids": [{"shape": "container", "min": [0, 0, 0], "max": [0.3, 0.3, 0.12], "open_top": True,
                "phase": "wall"}],
    "output": {"formats": ["vtp"], "checkpoint_interval": 1, "surface": {"formats": ["ply", "vtp"]}},
}


def vdb_built():
    rc, out, _ = run(["mesh", "/nonexistent", "--formats", "vdb"], timeout=30)
    return "no OpenVDB" not in out


def write_scene(obj, path):
    with open(path, "w") as f:
        json.dump(obj, f)
    return path


def same_tree(a, b):
    """files of run directory a missing or different in b (frames, stats.csv, bodies.csv)"""
    bad = []
    for root, _, files in os.walk(a):
        for n in files:
            if n in ("summary.json", "run.json", "scene.json", ".pfsph.lock") or n.startswith("ckpt") or "checkpoint" in root:
                continue
            pa = os.path.join(root, n)
            pb = os.path.join(b, os.path.relpath(pa, a))
            if not os.path.exists(pb):
                bad.append("missing " + os.path.relpath(pa, a))
            elif open(pa, "rb").read() != open(pb, "rb").read():
                bad.append("differs " + os.path.relpath(pa, a))
    return bad


# ---- run directories -------------------------------------------------------------------------
def sec_rundir(work):
    sec = Section("rundir")
    sc = write_scene(dict(SMALL2D, time={"end": 0.04, "fps": 50}), os.path.join(work, "rd.json"))
    afile = os.path.join(work, "a_file")
    open(afile, "w").write("x")
    other = os.path.join(work, "other")
    shutil.rmtree(other, ignore_errors=True)
    os.makedirs(other)
    open(os.path.join(other, "precious.txt"), "w").write("keep me")
    empty = os.path.join(work, "empty")
    shutil.rmtree(empty, ignore_errors=True)
    os.makedirs(empty)
    shutil.rmtree(os.path.join(work, "twice"), ignore_errors=True)
    loop = os.path.join(work, "loop")
    if not os.path.islink(loop):
        os.symlink(loop, loop)
    cases = [
        ("-o an existing file", ["run", sc, "-o", afile, "--force"], (2,)),
        ("-o below a file", ["run", sc, "-o", afile + "/run", "--force"], (1, 2)),
        ("-o path of 5000 characters", ["run", sc, "-o", work + "/" + "d" * 5000], (2,)),
        ("-o a directory of other files", ["run", sc, "-o", other], (2,)),
        ("-o a symlink loop", ["run", sc, "-o", loop, "--force"], (1, 2)),
        ("--resume an empty directory", ["run", "--resume", empty], (2,)),
        ("--resume a directory of other files", ["run", "--resume", other], (2,)),
        ("--resume a file", ["run", "--resume", afile], (2,)),
    ]
    for what, a, allowed in cases:
        rc, out, hung = run(a, timeout=ARGS.timeout)
        sec.judge(what, rc, out, allowed=allowed, hang=hung)
    if not os.path.exists(os.path.join(other, "precious.txt")):
        sec.finding("losses", "a run into a directory of other files removed them")
    # --force with other files in it: pfsph's own files only are replaced
    rc, out, hung = run(["run", sc, "-o", other, "--force", "--quiet"], timeout=ARGS.timeout)
    sec.judge("--force on a directory with other files", rc, out, allowed=(0, 2), hang=hung)
    if not os.path.exists(os.path.join(other, "precious.txt")):
        sec.finding("losses", "--force removed a file pfsph did not write")
    # two runs into one directory at once: the lock refuses the second
    d = os.path.join(work, "twice")
    slow = write_scene(dict(SMALL2D, time={"end": 20, "fps": 50}), os.path.join(work, "rd_slow.json"))
    e = dict(os.environ, OMP_NUM_THREADS="1")
    p = subprocess.Popen([ARGS.bin, "run", slow, "-o", d, "--force", "--quiet"], env=e, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    for _ in range(600):  # until the first run holds its lock (a sanitizer build starts slowly)
        if os.path.exists(os.path.join(d, ".pfsph.lock")) or p.poll() is not None:
            break
        time.sleep(0.1)
    time.sleep(0.5)
    if p.poll() is not None:
        sec.findings.append("the first run ended within a second: the lock case was not tried")
    rc, out, hung = run(["run", slow, "-o", d, "--force", "--quiet"], timeout=ARGS.timeout)
    sec.judge("a second run into a running run's directory", rc, out, allowed=(2,), hang=hung)
    p.send_signal(signal.SIGTERM)  # SIGINT: ignored in a background job of a script, and so by pfsph
    try:
        p.wait(timeout=60)
    except subprocess.TimeoutExpired:
        sec.finding("hangs", "a run did not stop within 60 s of SIGTERM")
        p.kill()
        p.wait()
    # resume with a corrupt scene.json
    open(os.path.join(d, "scene.json"), "w").write("{ not json")
    rc, out, hung = run(["run", "--resume", d], timeout=ARGS.timeout)
    sec.judge("--resume with a corrupt scene.json", rc, out, allowed=(2,), hang=hung)
    os.remove(loop)
    return sec


# ---- kill -9 / resume ---------------------------------------------------------------------
def sec_kill(work):
    sec = Section("kill")
    rnd = random.Random(7)
    scenes = [("2d", write_scene(SMALL2D, os.path.join(work, "k2.json")), 0.5)]
    s3 = json.loads(json.dumps(SMALL3D))
    if vdb_built():
        s3["output"]["surface"]["formats"].append("vdb")
    scenes.append(("3d", write_scene(s3, os.path.join(work, "k3.json")), 0.3))
    plan = [scenes[0]] * 3 + [scenes[1]] * 2  # five runs, three kills each
    for n, (tag, sc, end) in enumerate(plan):
        ref = os.path.join(work, f"kill_ref_{tag}")
        if not os.path.exists(ref):
            t0 = time.time()
            rc, out, hung = run(["run", sc, "-o", ref, "--force", "--quiet"], timeout=20 * ARGS.timeout)
            if rc:
                sec.finding("crashes", f"reference run {tag}: exit {rc}: {tail(out)}")
                continue
            dur = time.time() - t0
            setattr(sec, "dur_" + tag, dur)
        dur = getattr(sec, "dur_" + tag)
        d = os.path.join(work, f"kill_{n}")
        shutil.rmtree(d, ignore_errors=True)
        args = ["run", sc, "-o", d, "--force", "--quiet"]
        kills = 0
        target = 3 if n < len(plan) - 1 else max(3, 15 - sec.cases)  # fifteen kills in all
        e = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
        while True:
            p = subprocess.Popen([ARGS.bin] + args, env=e, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 stdin=subprocess.DEVNULL)
            if kills < target:
                try:
                    p.wait(timeout=rnd.uniform(0.15, 0.6) * dur)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()
                    kills += 1
                    sec.cases += 1
                    args = ["run", "--resume", d, "--quiet"]
                    continue
            try:
                out = p.communicate(timeout=20 * ARGS.timeout)[0].decode("utf-8", "replace")
            except subprocess.TimeoutExpired:
                p.kill()
                sec.finding("hangs", f"kill run {n}: the last resume did not end")
                break
            rc = p.returncode
            ckpts = glob.glob(os.path.join(d, "checkpoints", "*")) + glob.glob(os.path.join(d, "ckpt*"))
            if rc == 2 and args[1] == "--resume" and not ckpts:
                args = ["run", sc, "-o", d, "--force", "--quiet"]  # killed before the first checkpoint
                continue
            if rc != 0 or SANITIZER.search(out):
                sec.finding("crashes", f"kill run {n} ({tag}) after {kills} kills: exit {rc}: {tail(out)}")
                break
            bad = same_tree(ref, d) + same_tree(d, ref)
            if bad:
                sec.finding("losses", f"kill run {n} ({tag}) after {kills} kills: " + ", ".join(bad[:6]))
            break
        print(f"kill: run {n} ({tag}) {kills} kills, compared with the uninterrupted run", flush=True)
        shutil.rmtree(d, ignore_errors=True)
    return sec


# ---- full disks -----------------------------------------------------------------------------
def judge_full(sec, what, d, rc, out, hung, stats_rows):
    if not sec.judge(what, rc, out, allowed=(0, 1), hang=hung):
        return
    if rc == 1:
        if not re.search(r"(write|No space|ENOSPC|failed)", out):
            sec.findings.append(f"exit 1 without the cause: {what}: {tail(out)}")
        if "finished" in out:
            sec.finding("losses", f"{what}: exit 1 but says finished")
        try:
            st = json.load(open(os.path.join(d, "summary.json"))).get("status")
            if st == "finished":
                sec.finding("losses", f"{what}: exit 1 but summary.json says finished")
        except Exception:
            pass
    else:
        ok, why = summary_ok(d)
        rows = len(open(os.path.join(d, "stats.csv")).read().splitlines()) - 1 if os.path.exists(
            os.path.join(d, "stats.csv")) else -1
        if not ok or rows != stats_rows:
            sec.finding("losses", f"{what}: exit 0 but {why or ''} stats rows {rows} of {stats_rows}")


def sec_diskfull(work):
    sec = Section("diskfull")
    s = dict(SMALL2D, time={"end": 0.6, "fps": 200})
    s["output"] = {"formats": [], "checkpoint_interval": 0}
    sc = write_scene(s, os.path.join(work, "df.json"))
    rows = 121
    mnt = os.path.join(work, "tmpfs")
    os.makedirs(mnt, exist_ok=True)
    mounted = os.geteuid() == 0 and subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", mnt]).returncode == 0
    if mounted:
        try:
            for free in (2, 4, 10, 16, 24, 40, 58):
                for n in os.listdir(mnt):
                    p = os.path.join(mnt, n)
                    shutil.rmtree(p) if os.path.isdir(p) else os.remove(p)
                st = os.statvfs(mnt)
                fill = (st.f_bavail - free) * st.f_frsize
                with open(os.path.join(mnt, "filler"), "wb") as f:
                    f.write(b"\0" * max(fill, 0))
                d = os.path.join(mnt, "run")
                rc, out, hung = run(["run", sc, "-o", d, "--force", "--quiet"], timeout=4 * ARGS.timeout)
                judge_full(sec, f"tmpfs with {free} free pages", d, rc, out, hung, rows)
        finally:
            subprocess.run(["umount", mnt])
    faults = ["stats.csv:3", "summary.json", ".last_good.bin:2", "fluid_00003", "liquid_00002", "run.json",
              "ckpt"]
    s3 = json.loads(json.dumps(SMALL3D))
    s3["time"] = {"end": 0.15, "fps": 20}
    if vdb_built():
        s3["output"]["surface"]["formats"].append("vdb")
        faults[4] = "liquid_00002.vdb"
    sc3 = write_scene(s3, os.path.join(work, "df3.json"))
    for fault in faults:
        d = os.path.join(work, "fault_run")
        rc, out, hung = run(["run", sc3, "-o", d, "--force", "--quiet"], timeout=4 * ARGS.timeout,
                            env={"PFSPH_FAULT_WRITE": fault})
        judge_full(sec, f"PFSPH_FAULT_WRITE={fault}", d, rc, out, hung, 4)
        if rc == 0:
            sec.findings.append(f"PFSPH_FAULT_WRITE={fault}: no such write in this run")
    return sec


# ---- corrupt frames ---------------------------------------------------------------------------
def corruptions(data, rnd):
    n = len(data)
    out = {"empty": b"", "half": data[: n // 2], "one byte short": data[:-1], "header only": data[: min(n, 300)]}
    flip = bytearray(data)
    for _ in range(20):
        i = rnd.randrange(n)
        flip[i] ^= 1 << rnd.randrange(8)
    out["20 flipped bits"] = bytes(flip)
    body = bytearray(data)
    h = data.find(b"end_header\n")
    start = h + 11 if h >= 0 else n // 2
    for i in range(start, n, 4):
        body[i:i + 4] = b"\xff\xff\xff\x7f"  # NaN floats, huge integers
    out["data all 0x7fffffff"] = bytes(body)
    out["random bytes"] = bytes(rnd.getrandbits(8) for _ in range(n))
    out["counts 10^9"] = re.sub(rb"(element \w+ |NumberOfPoints=\")\d+", rb"\g<1>1000000000", data)
    return out


def sec_frames(work):
    sec = Section("frames")
    rnd = random.Random(11)
    runs = {}
    s2 = dict(SMALL2D, time={"end": 0.04, "fps": 50})
    s2["output"] = dict(SMALL2D["output"], checkpoint_interval=0)
    s3 = json.loads(json.dumps(SMALL3D))
    s3["time"] = {"end": 0.05, "fps": 20}
    s3["output"] = {"formats": ["vtp", "ply"], "surface": {"formats": ["ply", "vtp"]}, "checkpoint_interval": 0}
    for tag, s in (("2d", s2), ("3d", s3)):
        d = os.path.join(work, "frames_" + tag)
        rc, out, _ = run(["run", write_scene(s, d + ".json"), "-o", d, "--force", "--quiet"], timeout=20 * ARGS.timeout)
        if rc:
            sec.finding("crashes", f"frames: base run {tag}: exit {rc}: {tail(out)}")
            continue
        runs[tag] = d
    for tag, d in runs.items():
        targets = ["fluid_00001.vtp", "fluid_00001.ply"] + (["liquid_00001.ply"] if tag == "3d" else [])
        for t in targets:
            path = os.path.join(d, "frames", t)
            data = open(path, "rb").read()
            for k, bad in corruptions(data, rnd).items():
                work_run = d + "_c"
                shutil.rmtree(work_run, ignore_errors=True)
                shutil.copytree(d, work_run)
                open(os.path.join(work_run, "frames", t), "wb").write(bad)
                for cmd in (["render", work_run, "--size", "160x90"], ["export", work_run, "--houdini"],
                            ["mesh", work_run]):
                    if cmd[0] == "mesh" and tag == "2d" and t.endswith(".ply"):
                        pass
                    rc, out, hung = run(cmd, timeout=4 * ARGS.timeout)
                    what = f"{cmd[0]} {tag} {t} {k}"
                    if sec.judge(what, rc, out, allowed=(0, 2), hang=hung) and rc == 2 and t not in out:
                        sec.findings.append(f"message without the frame: {what}: {tail(out)}")
                shutil.rmtree(work_run, ignore_errors=True)
    return sec


SECTIONS = {"numeric": sec_numeric, "json": sec_json, "bodies": sec_bodies, "obj": sec_obj, "rundir": sec_rundir,
            "kill": sec_kill, "diskfull": sec_diskfull, "frames": sec_frames}


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", required=True)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=30, help="seconds per check (runs get a multiple)")
    ap.add_argument("--numeric-every", type=int, default=1, help="check every n-th numeric variant only")
    ap.add_argument("--numeric-runs", type=int, default=60, help="accepted 2D variants that run two frames")
    ap.add_argument("--work", default=None)
    ap.add_argument("--json", default=None)
    ap.add_argument("sections", nargs="*")
    ARGS = ap.parse_args()
    ARGS.bin = os.path.abspath(ARGS.bin)
    work = ARGS.work or tempfile.mkdtemp(prefix="pfsph_attack_")
    os.makedirs(work, exist_ok=True)
    rows = []
    for name in ARGS.sections or list(SECTIONS):
        t0 = time.time()
        print(f"== {name}", flush=True)
        sec = SECTIONS[name](work)
        r = sec.row()
        r["seconds"] = round(time.time() - t0, 1)
        rows.append(r)
        print(f"{name}: {sec.cases} cases, {sec.crashes} crashes, {sec.hangs} hangs, {sec.losses} silent losses, "
              f"{len(sec.findings)} findings ({r['seconds']} s)", flush=True)
        for f in sec.findings:
            print("   ", f[:400])
    print("\n| section | cases | crashes | hangs | silent losses | other findings |\n|---|---|---|---|---|---|")
    for r in rows:
        other = len(r["findings"]) - r["crashes"] - r["hangs"] - r["silent_losses"]
        print(f"| {r['section']} | {r['cases']} | {r['crashes']} | {r['hangs']} | {r['silent_losses']} | {other} |")
    if ARGS.json:
        json.dump(rows, open(ARGS.json, "w"), indent=1)
    if not ARGS.work:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if any(r["crashes"] or r["hangs"] or r["silent_losses"] for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
