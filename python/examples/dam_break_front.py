#!/usr/bin/env python3
"""Dam break: the surge front against Martin & Moyce (1952).

A 2D water column of width a and height 2a (their n^2 = 2) collapses onto a dry floor; the
front's position z (the farthest fluid particle's centre plus half a spacing: centres sit half
a spacing inside the surface) is recorded at every frame through a per-frame callback and
plotted dimensionless, Z = z / a against T = t sqrt(2 g / a), over the experiment's points.

Reference: J. C. Martin and W. J. Moyce, "An experimental study of the collapse of liquid
columns on a rigid horizontal plane", Phil. Trans. R. Soc. Lond. A 244 (1952) 312-324; the
n^2 = 2, a = 2.25 in series as tabulated in the SPH literature (e.g. Koshizuka & Oka 1996
compare with it). Check the values against the paper before relying on them.

    python3 dam_break_front.py [--radius 0.004] [--solver pcisph] [--out dam_break_front]
Writes dam_break_front.png and prints the front at the reference times."""
import argparse
import math

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pfsph  # noqa: E402

# Martin & Moyce (1952), n^2 = 2, a = 2.25 in: T = t sqrt(2 g / a), Z = z / a
MARTIN_MOYCE = np.array([
    [0.00, 1.00], [0.41, 1.11], [0.84, 1.22], [1.19, 1.44], [1.43, 1.67], [1.63, 1.89], [1.83, 2.11],
    [1.98, 2.33], [2.20, 2.56], [2.32, 2.78], [2.51, 3.00], [2.65, 3.22], [2.83, 3.44], [2.98, 3.67],
    [3.11, 3.89], [3.33, 4.11]])


def scene(a, radius, solver):
    g = 9.81
    return {
        "name": "Martin & Moyce dam break", "dimension": 2, "particle_radius": radius, "gravity": [0, -g],
        "domain": {"min": [-0.05, -0.05], "max": [6 * a + 0.05, 3 * a]},
        "solver": {"type": solver},
        "time": {"end": 3.4 / math.sqrt(2 * g / a), "fps": 200, "dt_max": 0.002},
        "phases": [{"name": "water", "kind": "fluid", "rest_density": 1000, "viscosity": 1e-6},
                   {"name": "wall", "kind": "solid"}],
        "fluid": [{"shape": "box", "min": [0, 0], "max": [a, 2 * a], "phase": "water"}],
        "solids": [{"shape": "container", "min": [0, 0], "max": [6 * a, 2.5 * a], "open_top": True,
                    "layers": 2, "phase": "wall"}],
        "output": {"formats": []},
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--a", type=float, default=0.2, help="column width a [m] (height 2a); default 0.2")
    ap.add_argument("--radius", type=float, default=0.004, help="particle radius [m]; default 0.004")
    ap.add_argument("--solver", default="pcisph", help="pcisph, dfsph, iisph, wcsph; default pcisph")
    ap.add_argument("--out", default="dam_break_front")
    args = ap.parse_args()
    a, g = args.a, 9.81
    sim = pfsph.Simulation(scene(a, args.radius, args.solver))
    d = 2 * args.radius
    T, Z = [], []

    def record(s, frame):
        T.append(s.time * math.sqrt(2 * g / a))
        Z.append((float(s.fluid.x.max()) + 0.5 * d) / a)  # x: a view, no copy

    record(sim, 0)
    sim.advance(callback=record)
    print("%s, %d fluid particles, %d steps to T = %.2f" % (args.solver, len(sim.fluid), sim.steps, T[-1]))
    T, Z = np.array(T), np.array(Z)
    zi = np.interp(MARTIN_MOYCE[:, 0], T, Z)
    print("   T    Z (Martin & Moyce)   Z (pfsph)")
    for (t, z), zs in zip(MARTIN_MOYCE, zi):
        print("%5.2f   %5.2f               %5.2f" % (t, z, zs))
    rms = float(np.sqrt(np.mean((zi[1:] - MARTIN_MOYCE[1:, 1]) ** 2)))
    print("rms difference in Z: %.3f" % rms)

    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(T, Z, "-", label="pfsph %s, %d particles" % (args.solver, len(sim.fluid)))
    ax.plot(MARTIN_MOYCE[:, 0], MARTIN_MOYCE[:, 1], "o", mfc="none", label="Martin & Moyce 1952 ($n^2$ = 2)")
    ax.set_xlabel(r"$T = t\,\sqrt{2g/a}$")
    ax.set_ylabel(r"$Z = z/a$")
    ax.set_title("Dam break surge front (rms difference %.2f)" % rms)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out + ".png", dpi=110)
    print("wrote", args.out + ".png")


if __name__ == "__main__":
    main()
