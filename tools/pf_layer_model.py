#!/usr/bin/env python3
"""T = 0 layered estimate of a pair-force liquid on a lattice wall (docs/pairwise.md, "The
wall's thickness and make"): when a monolayer on the wall becomes stable against the bare wall,
and the angle Young's law gives there. A guide, not a measurement: no temperature, no filter."""
# Layers of density 1/d^2 (continuum in-plane) d apart, the cosine pair potential of the force
# F = cos(U r) (repulsive below R / 3), phi(r) = -(sin(U r) + 1) / U, U = 3 pi / (2 R), R = k h =
# 3.4 d (the tests' k 1.7, h 2 d). Per area: B, a layer's binding to a liquid half-space; A, its
# binding to the wall (per unit adhesion ratio r); a monolayer beats the bare wall once r A < B
# (both negative); Young's law with the whole adhesion: cos = r W_adh / gamma_lv - 1. The
# "first-layer share" is the first layer's part of the work of adhesion (of cohesion: liquid).
import math
R = 3.4; U = 1.5 * math.pi / R
def V(D):  # interaction per area of two layers D apart (2 pi int_D^R r phi dr), d = 1
    if D >= R: return 0.0
    n = 4000; h = (R - D) / n; s = 0.0
    for i in range(n + 1):
        r = D + i * h; w = 0.5 if i in (0, n) else 1.0
        s += w * r * (-(math.sin(U * r) + 1) / U)
    return 2 * math.pi * s * h
N = 8
B = sum(V(n) for n in range(1, N))              # a layer's binding to a liquid half-space
Wcoh = -sum(n * V(n) for n in range(1, N))      # work of cohesion per area (2 gamma_lv)
def wall(d0, skip, depth=8):                    # wall layers' distances from fluid layer 0
    return [d0 + m for m in range(skip, depth)]
for name, d0, skip, depth in (("replica (first layer 1 d from the top wall layer)", 1.0, 0, 8),
                             ("as measured, 0.5 d", 0.5, 0, 8), ("0.6 d", 0.6, 0, 8), ("0.75 d", 0.75, 0, 8),
                             ("0.5 d, 2-layer wall", 0.5, 0, 2), ("0.62 d, 2-layer wall", 0.62, 0, 2),
                             ("skin: top layer without adhesion, 0.5 d", 0.5, 1, 8)):
    A = sum(V(x) for x in wall(d0, skip, depth))           # wall binding of fluid layer 0 (per unit r)
    Wad = -sum(V(x + i) for i in range(N) for x in wall(d0, skip, depth))  # work of adhesion per unit r
    rs = B / A                                             # monolayer stable above r*
    c = min(1, max(-1, rs * Wad / (0.5 * Wcoh) - 1))       # Young at r*: cos = W_adh / gamma_lv - 1
    r30 = (1 + math.cos(math.radians(30))) * 0.5 * Wcoh / Wad
    print("%-48s first-layer share %.2f, r* %.3f, Young's angle at r* %5.1f deg, r(30 deg) %.3f"
          % (name, -A / Wad, rs, math.degrees(math.acos(c)), r30))
print("liquid: first-layer share %.2f" % (-B / Wcoh))
