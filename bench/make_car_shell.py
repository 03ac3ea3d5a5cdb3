#!/usr/bin/env python3
"""A car-like body shell with open windows: the open-mesh case of the any-input benchmarks.

The body is a loft of rounded-rectangle cross sections along x (a hood, a cabin, a trunk), its two
ends closed by fans; the quads of the side windows, the windscreen and the rear window are left
out (and with --open-bottom the floor, as in data/car_shell.obj), so the mesh has six (seven)
large holes whose inside the winding number has to settle.

  python3 bench/make_car_shell.py OUT.obj [--stations 48] [--around 26] [--open-bottom]
"""
import argparse, math

ap = argparse.ArgumentParser()
ap.add_argument("out")
ap.add_argument("--stations", type=int, default=48)
ap.add_argument("--around", type=int, default=26)
ap.add_argument("--open-bottom", action="store_true", help="leave the floor out too (one hole the length of the car)")
a = ap.parse_args()


def smoothstep(e0, e1, x):
    t = min(1.0, max(0.0, (x - e0) / (e1 - e0)))
    return t * t * (3 - 2 * t)


def roof(x):
    """Height of the top along the body (x in [-2, 2]): hood 1.0, cabin 1.55, trunk 1.1."""
    return 1.0 + 0.55 * smoothstep(-0.9, -0.2, x) - 0.45 * smoothstep(0.9, 1.4, x)


def half_width(x):
    return 0.9 - 0.15 * (abs(x) / 2) ** 4


def section(x, n):
    """n points around a rounded rectangle: bottom at z = 0.2, top at roof(x), corners rounded."""
    w, top, bot = half_width(x), roof(x), 0.2
    cy, cz = 0.0, (top + bot) / 2
    ry, rz = w, (top - bot) / 2
    pts = []
    for k in range(n):
        t = 2 * math.pi * k / n
        c, s = math.cos(t), math.sin(t)
        # superellipse, exponent 4: a box with round corners
        y = cy + ry * math.copysign(abs(c) ** 0.5, c)
        z = cz + rz * math.copysign(abs(s) ** 0.5, s)
        pts.append((x, y, z))
    return pts


def is_window(i, k, ns, n):
    """Station i (x), around index k: the side windows, windscreen and rear window."""
    x = -2 + 4 * (i + 0.5) / (ns - 1)
    t = 2 * math.pi * (k + 0.5) / n
    side = abs(math.cos(t)) > 0.6 and math.sin(t) > 0.35  # upper flanks
    top = math.sin(t) > 0.9                               # roof line
    if side and -0.45 < x < 0.95 and not (0.2 < x < 0.35):  # two windows a side, a pillar between
        return True
    if top and (-0.75 < x < -0.35 or 0.95 < x < 1.25):     # windscreen, rear window
        return True
    if a.open_bottom and math.sin(t) < -0.9 and -1.8 < x < 1.8:
        return True
    return False


ns, n = a.stations, a.around
verts, faces = [], []
for i in range(ns):
    x = -2 + 4 * i / (ns - 1)
    verts += section(x, n)
for i in range(ns - 1):
    for k in range(n):
        if is_window(i, k, ns, n):
            continue
        v00, v01 = i * n + k, i * n + (k + 1) % n
        v10, v11 = v00 + n, v01 + n
        faces += [(v00, v11, v10), (v00, v01, v11)]
for i, sign in ((0, -1), (ns - 1, 1)):  # the ends, fanned from a centre point
    c = len(verts)
    x = -2 + 4 * i / (ns - 1)
    verts.append((x, 0.0, (roof(x) + 0.2) / 2))
    for k in range(n):
        a0, a1 = i * n + k, i * n + (k + 1) % n
        faces.append((c, a1, a0) if sign < 0 else (c, a0, a1))
with open(a.out, "w") as f:
    f.write("# car-like body shell with open windows (bench/make_car_shell.py)\n")
    for v in verts:
        f.write("v %.6f %.6f %.6f\n" % v)
    for t in faces:
        f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
print(len(faces), "triangles")
