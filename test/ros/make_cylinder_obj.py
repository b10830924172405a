#!/usr/bin/env python3
"""Writes a user's cylinder as an OBJ with UVs, in millimetres: radius 12, height 30, 128
facets, standing on z (the mesh a user first brought to gripper_sim.launch). Usage:
make_cylinder_obj.py OUT.obj"""
import math
import sys

RADIUS, HEIGHT, FACETS = 12.0, 30.0, 128

lines = []
for z in (-HEIGHT / 2, HEIGHT / 2):
    for k in range(FACETS + 1):  # the seam repeats for its UVs
        a = 2 * math.pi * k / FACETS
        lines.append(f"v {RADIUS * math.cos(a):.6f} {RADIUS * math.sin(a):.6f} {z:.6f}")
        lines.append(f"vt {k / FACETS:.6f} {(z + HEIGHT / 2) / HEIGHT:.6f}")
ring = FACETS + 1
for k in range(FACETS):
    a, b, c, d = k + 1, k + 2, ring + k + 2, ring + k + 1
    lines.append(f"f {a}/{a} {b}/{b} {c}/{c}")
    lines.append(f"f {a}/{a} {c}/{c} {d}/{d}")
# Caps: fans around their centres.
for z, base, flip in ((-HEIGHT / 2, 0, True), (HEIGHT / 2, ring, False)):
    lines.append(f"v 0 0 {z:.6f}")
    lines.append("vt 0.5 0.5")
    centre = 2 * ring + (1 if flip else 2)
    for k in range(FACETS):
        a, b = base + k + 1, base + k + 2
        tri = (centre, b, a) if flip else (centre, a, b)
        lines.append("f " + " ".join(f"{i}/{i}" for i in tri))
with open(sys.argv[1], "w") as out:
    out.write("\n".join(lines) + "\n")
