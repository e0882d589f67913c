#!/usr/bin/env python3
"""Writes egg_half_left.obj / egg_half_right.obj next to this script (closed thick shell caps
of an egg-shaped ellipsoid, long axis x, split at x = 0) and prints, as JSON on stdout, the
fluid blocks and kinematic keyframes of scenes/bodies_cracked_egg.json. The body code places a
mesh body's centre of mass at "position" and rotates it about that point, so the keyframes
carry the halves' centres of mass (about the hinge at the top of the rim)."""
import math, json, os, sys
HERE = os.path.dirname(os.path.abspath(__file__))
d = 0.01            # particle spacing
RI = 0.09           # inner radius (y, z)
T = 0.015           # shell thickness (1.5 d: layers 1)
RO = RI + T
AX = 1.2            # x stretch (egg's long axis)
NPHI, NPSI = 10, 32

def half(sign):
    """sign -1: x <= 0 half, +1: x >= 0 half. Returns verts, tris (outward, CCW)."""
    V, F = [], []
    def ring(R, phi):
        out = []
        for j in range(NPSI):
            psi = 2 * math.pi * j / NPSI
            x = sign * AX * R * math.cos(phi)
            y = R * math.sin(phi) * math.cos(psi)
            z = R * math.sin(phi) * math.sin(psi)
            V.append((x, y, z)); out.append(len(V) - 1)
        return out
    rings = {}
    for name, R in (("o", RO), ("i", RI)):
        V.append((sign * AX * R, 0.0, 0.0)); pole = len(V) - 1
        rs = [ring(R, (math.pi / 2) * k / NPHI) for k in range(1, NPHI + 1)]
        rings[name] = (pole, rs)
    def tri(a, b, c, flip):
        F.append((a, c, b) if flip else (a, b, c))
    for name in ("o", "i"):
        pole, rs = rings[name]
        flip = (name == "i")
        for j in range(NPSI):
            j1 = (j + 1) % NPSI
            tri(pole, rs[0][j], rs[0][j1], flip)
            for k in range(NPHI - 1):
                a, b = rs[k][j], rs[k][j1]
                c, e = rs[k + 1][j], rs[k + 1][j1]
                tri(a, c, e, flip); tri(a, e, b, flip)
    ro, ri = rings["o"][1][-1], rings["i"][1][-1]
    for j in range(NPSI):
        j1 = (j + 1) % NPSI
        tri(ro[j], ri[j], ri[j1], False); tri(ro[j], ri[j1], ro[j1], False)
    # orient: signed volume must be positive; the sign of x flips handedness
    vol = sum(sum(V[a][k] * (V[b][(k+1)%3] * V[c][(k+2)%3] - V[b][(k+2)%3] * V[c][(k+1)%3]) for k in range(1)) for a, b, c in F) / 6
    if vol < 0:
        F = [(a, c, b) for a, b, c in F]
    return V, F

def props(V, F):
    vol, cx = 0.0, [0.0, 0.0, 0.0]
    for a, b, c in F:
        A, B, C = V[a], V[b], V[c]
        v = (A[0]*(B[1]*C[2]-B[2]*C[1]) - A[1]*(B[0]*C[2]-B[2]*C[0]) + A[2]*(B[0]*C[1]-B[1]*C[0])) / 6
        vol += v
        for k in range(3): cx[k] += v * (A[k] + B[k] + C[k]) / 4
    return vol, [c / vol for c in cx]

out = {}
for sign, name in ((-1, "left"), (1, "right")):
    V, F = half(sign)
    vol, com = props(V, F)
    with open(os.path.join(HERE, f"egg_half_{name}.obj"), "w") as f:
        f.write(f"# egg shell half ({name}): ellipsoidal cap, inner radius {RI} m (x {AX} times), "
                f"thickness {T} m, {len(V)} vertices, {len(F)} triangles; written by make_egg_halves.py\n")
        for v in V: f.write("v %.6f %.6f %.6f\n" % v)
        for a, b, c in F: f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
    out[name] = (vol, com)
    print(name, "volume", vol, "com", com, file=sys.stderr)

# keyframes: hold closed, then each half turns about its top rim point (0, RO, 0) (hinge) away
# from the other, opening from below, then both lift away.
C = [0.0, 0.17, 0.0]       # egg centre (world)
def pose(name, theta_deg, lift, spread):
    s = -1 if name == "left" else 1
    th = math.radians(s * theta_deg)   # left half turns clockwise (negative about z)
    com = out[name][1]
    h = [0.0, RO, 0.0]
    r = [com[0] - h[0], com[1] - h[1], com[2] - h[2]]
    rx = math.cos(th) * r[0] - math.sin(th) * r[1]
    ry = math.sin(th) * r[0] + math.cos(th) * r[1]
    p = [C[0] + h[0] + rx + s * spread, C[1] + h[1] + ry + lift, C[2] + r[2]]
    return [round(v, 6) for v in p], [0, 0, round(math.degrees(th), 4)]
keys = {}
for name in ("left", "right"):
    ks = []
    for t, th, lift, spread in ((0.0, 0, 0, 0), (0.15, 0, 0, 0), (0.4, 50, 0.01, 0.02), (0.65, 85, 0.06, 0.07), (0.95, 110, 0.12, 0.12)):
        p, r = pose(name, th, lift, spread)
        ks.append({"t": t, "position": p, "rotation": r})
    keys[name] = ks

# white: voxels of the cavity (centres at least 0.6 d inside the inner surface) outside the
# yolk's cube, merged greedily into boxes; yolk: a sphere at the centre
YR = 0.05
lim = RI - 0.6 * d
nx = int(AX * RI / d) + 1; ny = int(RI / d) + 1
vox = set()
for i in range(-nx, nx):
    for j in range(-ny, ny):
        for k in range(-ny, ny):
            x, y, z = (i + 0.5) * d, (j + 0.5) * d, (k + 0.5) * d
            if (x / AX) ** 2 + y * y + z * z > lim * lim: continue
            if max(abs(x), abs(y), abs(z)) < YR: continue
            vox.add((i, j, k))
blocks = []
left = set(vox)
while left:
    best = None
    for (i, j, k) in sorted(left):
        # grow x, then z, then y
        i1 = i
        while (i1 + 1, j, k) in left: i1 += 1
        k1 = k
        while all((ii, j, k1 + 1) in left for ii in range(i, i1 + 1)): k1 += 1
        j1 = j
        while all((ii, j1 + 1, kk) in left for ii in range(i, i1 + 1) for kk in range(k, k1 + 1)): j1 += 1
        n = (i1 - i + 1) * (j1 - j + 1) * (k1 - k + 1)
        if best is None or n > best[0]: best = (n, i, i1, j, j1, k, k1)
    n, i, i1, j, j1, k, k1 = best
    if n < 4 or len(blocks) >= 62: break
    for ii in range(i, i1 + 1):
        for jj in range(j, j1 + 1):
            for kk in range(k, k1 + 1): left.discard((ii, jj, kk))
    blocks.append(([round(C[0] + i * d, 4), round(C[1] + j * d, 4), round(C[2] + k * d, 4)],
                   [round(C[0] + (i1 + 1) * d, 4), round(C[1] + (j1 + 1) * d, 4), round(C[2] + (k1 + 1) * d, 4)]))
print("white voxels", len(vox), "in blocks", len(vox) - len(left), "blocks", len(blocks), file=sys.stderr)
json.dump({"keys": keys, "blocks": blocks, "C": C, "YR": YR}, sys.stdout)
