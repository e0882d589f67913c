#!/usr/bin/env python3
"""Read a run directory written by `pfsph run`: stats.csv and summary.json as numpy / dicts, a
frame's particles as arrays; plot the run's speed and energy over time and the last frame.

    python3 read_run.py RUN_DIR                # a run you made: pfsph run scene.json -o RUN_DIR
    python3 read_run.py                        # runs a small 2D dam break with the pfsph program
                                               # ($PFSPH_BIN, else pfsph on PATH, else build/pfsph)
Writes read_run.png (--out NAME for another stem)."""
import argparse
import json
import os
import shutil
import subprocess
import tempfile

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pfsph  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = {
    "name": "read_run example", "dimension": 2, "particle_radius": 0.005, "gravity": [0, -9.81],
    "domain": {"min": [-0.05, -0.05], "max": [1.05, 0.7]}, "solver": {"type": "pcisph"},
    "time": {"end": 0.8, "fps": 20, "dt_max": 0.004},
    "phases": [{"name": "water", "kind": "fluid", "viscosity": 1e-3}, {"name": "wall", "kind": "solid"}],
    "fluid": [{"shape": "box", "min": [0, 0], "max": [0.3, 0.5]}],
    "solids": [{"shape": "container", "min": [0, 0], "max": [1.0, 0.6], "open_top": True, "phase": "wall"}],
    "output": {"formats": ["vtp"], "fields": ["id", "speed"], "boundary": True},
}


def program():
    for p in (os.environ.get("PFSPH_BIN"), shutil.which("pfsph"), os.path.join(HERE, "..", "..", "build", "pfsph")):
        if p and os.path.isfile(p) and os.access(p, os.X_OK):
            return p
    raise SystemExit("no pfsph program: set PFSPH_BIN, or give a run directory")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir", nargs="?", help="a run directory (default: run a small dam break now)")
    ap.add_argument("--out", default="read_run", help="output stem (default read_run: read_run.png)")
    a = ap.parse_args()
    run_dir = a.run_dir
    if not run_dir:
        tmp = tempfile.mkdtemp(prefix="pfsph_read_run_")
        scene = os.path.join(tmp, "scene.json")
        with open(scene, "w") as fh:
            json.dump(SCENE, fh)
        run_dir = os.path.join(tmp, "run")
        subprocess.run([program(), "run", scene, "-o", run_dir, "--quiet"], check=True)

    run = pfsph.read_run(run_dir)
    s = run.summary
    print("%s: %s, %s, %dD %s, %d frames, %d steps, %d fluid particles, %.1f s of wall time" % (
        run_dir, s["status"], s["precision"], s["dimension"], s["solver"], s["frames"], s["steps"],
        s["particles"]["fluid"], s["wall_seconds"]))
    st = run.stats
    print("stats.csv columns:", ", ".join(st))
    last = run.frame(-1)
    print("last fluid frame:", last)
    speed = last["speed"] if "speed" in last else np.linalg.norm(last["velocity"], axis=1)

    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    ax[0].plot(st["time"], st["vmax"], label="largest speed [m/s]")
    ax[0].plot(st["time"], st["ekin"] / max(st["ekin"].max(), 1e-30) * st["vmax"].max(), "--",
               label="kinetic energy (scaled)")
    ax[0].set_xlabel("t [s]")
    ax[0].set_title("stats.csv")
    ax[0].legend()
    p = last["position"]
    if run.frame_numbers("boundary"):
        b = run.frame(0, "boundary")["position"]
        ax[1].scatter(b[:, 0], b[:, 1], s=1, c="0.6")
    sc = ax[1].scatter(p[:, 0], p[:, 1], s=1, c=speed, cmap="viridis")
    fig.colorbar(sc, ax=ax[1], label="speed [m/s]")
    ax[1].set_aspect("equal")
    ax[1].set_title("frame %s, t = %.2f s" % (os.path.basename(last.path), last.time))
    fig.tight_layout()
    fig.savefig(a.out + ".png", dpi=110)
    print("wrote", a.out + ".png")


if __name__ == "__main__":
    main()
