#!/usr/bin/env python3
"""The plots of docs/validation.md: pfsph against the reference data of each validation case.

The validation tests (tests/validation, label validation) write their measurements as CSV files
into validation/ in their working directory (ctest's: the build directory); this script reads
them and writes one PNG per case. The reference data come from the tests too (the dam-break
front's CSV carries Martin & Moyce's points, the Hysing test writes the benchmark's key values),
or from the file the test compiles in (tests/validation/spheric2_exp.inc), so that each figure
is typed in once, beside its source.

    python3 tools/validation_plots.py [--data build/validation] [--out docs]

Needs matplotlib and numpy (python3-matplotlib, python3-numpy; .ci/run installs them). A case
whose CSV is missing is skipped with a note."""
import argparse
import csv
import os
import re
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def dam_break(data, out):
    path = os.path.join(data, "dam_break_front.csv")
    if not os.path.exists(path):
        return print("skip dam break: no", path)
    runs = {}
    for r in rows(path):
        runs.setdefault(r["run"], []).append((float(r["T"]), float(r["Z"]), int(r["particles"])))
    ref = np.array([(t, z) for t, z, _ in runs.pop("martin_moyce_1952")])
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.8))
    labels = {"mm_a20": "a/d = 20", "mm_a40": "a/d = 40", "dam_break_2d": "scenes/dam_break_2d.json ($n^2$ = 4/3)"}
    for ax, shift in zip(axs, (False, True)):
        for name, pts in runs.items():
            p = np.array([(t, z) for t, z, _ in pts])
            dT = 0.0
            if shift:  # the least-squares shift in T (the gate's delay), as the test computes it
                cand = np.arange(0, 1.001, 0.01)
                mask = ref[:, 0] <= p[-1, 0]
                err = [np.sqrt(np.mean((np.interp(ref[mask, 0] - c, p[:, 0], p[:, 1]) - ref[mask, 1]) ** 2)) for c in cand]
                dT = cand[int(np.argmin(err))]
            ax.plot(p[:, 0] + dT, p[:, 1], "-", label="pfsph %s, %d particles%s" % (
                labels.get(name, name), pts[0][2], ", shifted by dT = %.2f" % dT if shift else ""))
        ax.plot(ref[:, 0], ref[:, 1], "ko", mfc="none", label="Martin & Moyce 1952, Fig. 3 ($n^2$ = 2, a = 2.25 in)")
        ax.set_xlabel(r"$T = t\,\sqrt{2g/a}$")
        ax.set_ylabel(r"$Z = z/a$")
        ax.set_title("Surge front" + (", pfsph shifted in time (gate delay)" if shift else ", as simulated from T = 0"))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left" if not shift else "lower right")
    fig.tight_layout()
    dst = os.path.join(out, "validation_dam_break_front.png")
    fig.savefig(dst, dpi=100)
    print("wrote", dst)


def hysing(data, out):
    cases = [c for c in (1, 2) if os.path.exists(os.path.join(data, "hysing_case%d.csv" % c))
             and os.path.exists(os.path.join(data, "hysing_case%d_reference.csv" % c))]
    if not cases:
        return print("skip Hysing: no hysing_case*.csv in", data)
    fig, axs = plt.subplots(len(cases), 3, figsize=(13, 3.8 * len(cases)), squeeze=False)
    for row, c in enumerate(cases):
        s = rows(os.path.join(data, "hysing_case%d.csv" % c))
        t = np.array([float(r["t"]) for r in s])
        ref = {r["quantity"]: (float(r["t"]), float(r["value"]))
               for r in rows(os.path.join(data, "hysing_case%d_reference.csv" % c))}
        vy = np.array([float(r["vy"]) for r in s])
        k = 5  # the test's 0.2 s running mean
        vs = np.convolve(vy, np.ones(k) / k, mode="same")
        ax = axs[row][0]
        ax.plot(t, vy, "-", color="0.7", lw=1, label="pfsph, every 0.05 s")
        ax.plot(t[2:-2], vs[2:-2], "-", label="pfsph, 0.2 s running mean")
        for q, lab in (("vmax", "Hysing max"), ("vmax2", "Hysing 2nd max")):
            if q in ref:
                ax.plot(*ref[q], "ks" if q == "vmax" else "kD", label="%s %.4f at %.2f s" % (lab, ref[q][1], ref[q][0]))
        ax.set_ylabel("rise velocity [m/s]")
        ax.set_title("Case %d: rise velocity" % c)
        ax2 = axs[row][1]
        ax2.plot(t, [float(r["yc"]) for r in s], "-", label="pfsph")
        ax2.plot(*ref["yc_end"], "ks", label="Hysing y(3) = %.4f" % ref["yc_end"][1])
        ax2.set_ylabel("centroid height [m]")
        ax2.set_title("Case %d: centroid" % c)
        ax3 = axs[row][2]
        ax3.plot(t, [float(r["circularity"]) for r in s], "-", label="pfsph")
        ax3.plot(*ref["circularity_min"], "ks", label="Hysing min %.4f at %.2f s" % (ref["circularity_min"][1],
                                                                                    ref["circularity_min"][0]))
        ax3.set_ylabel("circularity")
        ax3.set_title("Case %d: circularity" % c)
        for a in axs[row]:
            a.set_xlabel("t [s]")
            a.grid(alpha=0.3)
            a.legend(fontsize=8)
    fig.tight_layout()
    dst = os.path.join(out, "validation_hysing.png")
    fig.savefig(dst, dpi=100)
    print("wrote", dst)


def spheric2(data, out):
    path = os.path.join(data, "spheric2.csv")
    if not os.path.exists(path):
        return print("skip SPHERIC test 2: no", path)
    s = rows(path)
    t = np.array([float(r["t"]) for r in s])
    exp = []
    with open(os.path.join(ROOT, "tests", "validation", "spheric2_exp.inc")) as f:
        for line in f:
            m = re.match(r"\s*\{([^}]*)\}", line)
            if m:
                exp.append([float(v) for v in m.group(1).split(",")])
    exp = np.array(exp)
    xs = {"H1": 0.496, "H2": 0.992, "H3": 1.488, "H4": 2.638}
    fig, axs = plt.subplots(2, 4, figsize=(16, 7))
    for i, h in enumerate(("H1", "H2", "H3", "H4")):
        ax = axs[0][i]
        ax.plot(t, [float(r[h]) for r in s], "-", label="pfsph, d = 0.04 m")
        ax.plot(exp[:, 0], exp[:, 1 + i], "ko", mfc="none", label="experiment (MARIN)")
        ax.set_title("water height at x = %.3f m" % xs[h])
        ax.set_ylabel("height [m]")
    for i, (p, col) in enumerate((("P1", 5), ("P3", 6), ("P5", 7), ("P7", 8))):
        ax = axs[1][i]
        v = np.array([float(r[p]) / 1000 for r in s])
        ax.plot(t, v, "-", lw=0.6, color="0.65", label="pfsph, d = 0.04 m, every 0.01 s")
        ax.plot(t[2:-2], np.convolve(v, np.ones(5) / 5, mode="same")[2:-2], "-", label="pfsph, 0.05 s running mean")
        lcol = "L" + p[1:]
        if lcol in s[0]:  # the first layer's own pressure, the reading before the force sensor
            vl = np.array([float(r[lcol]) / 1000 for r in s])
            ax.plot(t[2:-2], np.convolve(vl, np.ones(5) / 5, mode="same")[2:-2], "--", lw=0.8,
                    label="first layer's pressure (0.05 s mean)")
        ax.plot(exp[:, 0], exp[:, col] / 1000, "ko", mfc="none", label="experiment (MARIN), ~50 ms means")
        if p == "P1":
            ax.plot([0.415], [11.24], "k^", label="experiment's peak, 11.2 kPa at 0.415 s")
        ax.set_title("pressure %s (%s)" % (p, "box front" if p in ("P1", "P3") else "box top"))
        ax.set_ylabel("pressure [kPa]")
    for a in axs.flat:
        a.set_xlabel("t [s]")
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle("SPHERIC test 2 (Kleefsman et al. 2005): dam break against a box, pfsph at d = 0.04 m")
    fig.tight_layout()
    dst = os.path.join(out, "validation_spheric2.png")
    fig.savefig(dst, dpi=100)
    print("wrote", dst)


def angles_laplace(data, out):
    pa, pl = os.path.join(data, "contact_angles.csv"), os.path.join(data, "laplace.csv")
    if not os.path.exists(pa) and not os.path.exists(pl):
        return print("skip contact angles and Laplace: no CSV in", data)
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.8))
    ax = axs[0]
    ax.fill_between([20, 160], [10, 150], [30, 170], color="0.9", label="target +- 10 deg")
    ax.plot([20, 160], [20, 160], "k--", lw=1)
    if os.path.exists(pa):
        a = rows(pa)
        for dim, mk in (("2", "o"), ("3", "s")):
            sel = [r for r in a if r["dim"] == dim]
            if sel:
                ax.errorbar([float(r["target_deg"]) for r in sel], [float(r["measured_deg"]) for r in sel],
                            yerr=[float(r["sd_deg"]) for r in sel], fmt=mk, capsize=3,
                            label="pfsph %sD (sd of the samples)" % dim)
    ax.set_xlabel("target contact angle [deg]")
    ax.set_ylabel("measured contact angle [deg]")
    ax.set_title("Static contact angles on flat plates")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax = axs[1]
    if os.path.exists(pl):
        lp = rows(pl)
        for dim, mk in (("2", "o"), ("3", "s")):
            sel = [r for r in lp if r["dim"] == dim]
            if not sel:
                continue
            x = np.array([float(r["x_per_m"]) for r in sel])
            ax.errorbar(x, [float(r["p_in_pa"]) for r in sel], yerr=[float(r["p_err_pa"]) for r in sel], fmt=mk,
                        capsize=3, label="pfsph %sD drops" % dim)
            sig = float(sel[0]["sigma_target"])
            xx = np.linspace(0, x.max() * 1.1, 10)
            ax.plot(xx, sig * xx, "--", label=r"Laplace, $\sigma$ = %g N/m" % sig if dim == "2" else None, color="k")
    ax.set_xlabel(r"$(D-1)/R$ [1/m]  (2D: 1/R, 3D: 2/R)")
    ax.set_ylabel("pressure jump [Pa]")
    ax.set_title("Laplace's law")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    dst = os.path.join(out, "validation_contact_laplace.png")
    fig.savefig(dst, dpi=100)
    print("wrote", dst)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=os.path.join(ROOT, "build", "validation"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if not os.path.isdir(args.data):
        sys.exit("%s: no such directory (run the validation tests first: ctest -L validation)" % args.data)
    for f in (dam_break, hysing, spheric2, angles_laplace):
        f(args.data, args.out)


if __name__ == "__main__":
    main()
