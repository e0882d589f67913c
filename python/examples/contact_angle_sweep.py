#!/usr/bin/env python3
"""Contact angles: a parameter sweep in Python, plotted with matplotlib.

One 2D drop without gravity per target angle, on its own plate, the water-plate coefficient
given as a "contact_angle" target (docs/pairwise.md); each starts as the same 16 x 16 spacing
square and spreads or retracts. The angle is measured as tests/physics/test_pf_contact_angle.c
does: the drop's outline (the farthest particle from its centroid in each of 72 sectors) above
1.5 spacings is fitted with a circle (Kasa's least squares), its radius enlarged by half a
spacing; the cap meets the plate at cos(theta) = -z_c / R_c. Averaged over samples every
0.05 s in the second half of the run. The simulations run side by side in Python threads (a
step releases the GIL), one OpenMP thread each.

    python3 contact_angle_sweep.py [--angles 30,60,90,120,150] [--end 2] [--out contact_angle_sweep]
Writes contact_angle_sweep.png (measured against target angle, and the drops' final shapes)."""
import argparse
import concurrent.futures
import math
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pfsph  # noqa: E402

R = 0.005  # particle radius [m]
D = 2 * R  # spacing
HALF = 0.08  # half width of the starting square [m]
PLATE = 0.7  # plate length [m]: a 30-degree cap of this area is 0.47 m wide


def scene(angle, seed=11):
    return {
        "name": "contact angle %g" % angle, "dimension": 2, "seed": seed, "particle_radius": R, "gravity": [0, 0],
        "domain": {"min": [-0.05, -0.1], "max": [PLATE + 0.05, 0.4]},
        "solver": {"type": "pcisph"}, "time": {"dt_max": 0.002, "fps": 20},
        "phases": [{"name": "water", "viscosity": 0.001}, {"name": "plate", "kind": "solid"}],
        "fluid": [{"shape": "box", "min": [PLATE / 2 - HALF, 0], "max": [PLATE / 2 + HALF, 2 * HALF]}],
        "solids": [{"shape": "box", "min": [0, -0.06], "max": [PLATE, 0], "layers": 3, "phase": "plate"}],
        "pairwise": {"k": 1.7, "coefficients": [{"phases": ["water", "water"], "sigma": 4},
                                                {"phases": ["water", "plate"], "contact_angle": angle}]},
        "output": {"formats": []},
    }


def drop_angle(x, y):
    """Contact angle [deg] of the drop with particle centres x, y on the plate face y = 0."""
    cx, cy = x.mean(), y.mean()
    dx, dy = x - cx, y - cy
    r = np.hypot(dx, dy)
    sector = np.clip(((np.arctan2(dy, dx) + math.pi) / (2 * math.pi) * 72).astype(int), 0, 71)
    bx, by = [], []
    for k in range(72):
        m = np.nonzero(sector == k)[0]
        if len(m):
            i = m[np.argmax(r[m])]
            if y[i] >= 1.5 * D:
                bx.append(x[i])
                by.append(y[i])
    if len(bx) < 6:
        return float("nan")
    bx, by = np.array(bx, float), np.array(by, float)
    # Kasa: x^2 + y^2 + a x + b y + e = 0 in the least-squares sense
    A = np.stack([bx, by, np.ones_like(bx)], axis=1)
    a, b, e = np.linalg.lstsq(A, -(bx ** 2 + by ** 2), rcond=None)[0]
    xc, yc = -a / 2, -b / 2
    rc = math.sqrt(xc * xc + yc * yc - e) + 0.5 * D
    return math.degrees(math.acos(max(-1.0, min(1.0, -yc / rc))))


def measure(angle, t_end):
    """(target, mean, sd, times, angles, final x-y positions) of one drop."""
    sim = pfsph.Simulation(scene(angle), threads=1)
    times, angles = [], []

    def sample(s, frame):  # every frame (0.05 s): x, y are views of the library's arrays
        times.append(s.time)
        angles.append(drop_angle(s.fluid.x.astype(float), s.fluid.y.astype(float)))

    sim.advance(t_end, callback=sample)
    times, angles = np.array(times), np.array(angles)
    late = angles[(times > 0.5 * t_end) & np.isfinite(angles)]
    return angle, float(late.mean()), float(late.std()), times, angles, sim.fluid.positions[:, :2].copy()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--angles", default="30,60,90,120,150", help="target angles [deg], comma-separated")
    ap.add_argument("--end", type=float, default=2.0, help="simulated time per drop [s]; default 2")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="simulations at once")
    ap.add_argument("--out", default="contact_angle_sweep")
    args = ap.parse_args()
    angles = [float(a) for a in args.angles.split(",")]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.workers) as pool:
        results = list(pool.map(lambda a: measure(a, args.end), angles))
    print("target [deg]   measured [deg]   sd")
    for r in results:
        print("%8.1f        %8.1f     %5.1f" % r[:3])

    fig = plt.figure(figsize=(12, 8))
    gs = fig.add_gridspec(2, 2, height_ratios=[3, 1.3])
    ax = fig.add_subplot(gs[0, 0])
    t = np.array([r[0] for r in results])
    ax.errorbar(t, [r[1] for r in results], yerr=[r[2] for r in results], fmt="o", capsize=3,
                label="measured (mean, sd over %.1f-%.1f s)" % (0.5 * args.end, args.end))
    ax.plot([0, 180], [0, 180], "k--", lw=0.8, label="target")
    ax.set(xlim=(0, 180), ylim=(0, 180), xlabel="target contact angle [deg]", ylabel="measured contact angle [deg]")
    ax.legend(loc="upper left")
    ax = fig.add_subplot(gs[0, 1])
    for target, _, _, times, angles, _ in results:
        ax.plot(times, angles, label="target %g deg" % target)
        ax.axhline(target, color=ax.lines[-1].get_color(), lw=0.8, ls="--")
    ax.axvspan(0.5 * args.end, args.end, color="0.9", zorder=-1)
    ax.set(xlabel="t [s]", ylabel="contact angle [deg]", ylim=(0, 180), title="each drop over time (averaged: grey)")
    ax.legend(fontsize=8, loc="lower right")
    ax = fig.add_subplot(gs[1, :])
    span = PLATE / 2  # the whole plate
    for k, (target, mean, _, _, _, p) in enumerate(results):
        off = k * (PLATE + 0.06)
        ax.scatter(p[:, 0] + off, p[:, 1], s=1)
        ax.plot([PLATE / 2 - span + off, PLATE / 2 + span + off], [-0.003, -0.003], "k-", lw=2)
        ax.text(PLATE / 2 + off, -0.02, "%g -> %.0f deg" % (target, mean), ha="center", va="top")
    ax.set_aspect("equal")
    ax.set_ylim(-0.06, 0.22)
    ax.axis("off")
    ax.set_title("the drops at t = %g s" % args.end)
    fig.tight_layout()
    fig.savefig(args.out + ".png", dpi=110)
    print("wrote", args.out + ".png")


if __name__ == "__main__":
    main()
