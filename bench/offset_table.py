#!/usr/bin/env python3
"""docs/benchmarks.md's table of offsets by +-2, +-20 and +-100 finest cells, two-sided against the exact offset.

    python3 bench/offset_table.py [DEPTH] [INPUT ...]
    (defaults: depth 9; fandisk, cad_part and spot from data/, Thingi A and B from ../shared/data/)

For each input and each distance N cells the root cube is fixed so that N cells is exactly the
distance (the cube around the input grown by the distance, 1/16 margin on each side, its size
512 cells at depth 9), then `pic offset IN -o out.stl --distance D --depth DEPTH --cube X,Y,Z,S`,
meshcheck's validity (closed, 2-manifold, no non-manifold vertex, exact self-intersection
test) and `pic compare out.stl IN --offset D` in finest cells, out -> exact / exact -> out
(the worst output vertex).
A shrink past the deepest point is refused (exit 2): "—". Prints one markdown row per input.
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")
PIC = os.environ.get("PIC", os.path.join(ROOT, "build", "pic"))
MESHCHECK = os.environ.get("MESHCHECK", os.path.join(ROOT, "..", "shared", "tools", "build", "meshcheck"))
SHARED = os.path.join(ROOT, "..", "shared", "data")
INPUTS = [("fandisk", os.path.join(ROOT, "data", "fandisk.obj")), ("cad_part", os.path.join(ROOT, "data", "cad_part.obj")),
          ("spot", os.path.join(ROOT, "data", "spot.obj")), ("Thingi A", os.path.join(SHARED, "thingi10k-1706459.obj")),
          ("Thingi B", os.path.join(SHARED, "thingi10k-1514499.obj"))]
CELLS = [2, -2, 20, -20, 100, -100]
MARGIN = 1 / 16


def box(path):
    lo, hi = [float("inf")] * 3, [-float("inf")] * 3
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                p = [float(x) for x in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, p)]
                hi = [max(a, b) for a, b in zip(hi, p)]
    return lo, hi


def cell_of(path, cells, depth):
    lo, hi = box(path)
    extent = max(h - l for l, h in zip(lo, hi))
    n = 2 ** depth
    grow = max(cells, 0)
    size = extent * (1 + 2 * MARGIN) / (1 - 2 * grow * (1 + 2 * MARGIN) / n)
    origin = [(l + h) / 2 - size / 2 for l, h in zip(lo, hi)]
    return origin, size, size / n


def one(path, cells, depth, out):
    origin, size, cell = cell_of(path, cells, depth)
    d = cells * cell
    cube = ",".join("%.17g" % x for x in origin + [size])
    p = subprocess.run([PIC, "offset", path, "-o", out, "--distance", "%.17g" % d, "--depth", str(depth), "--cube", cube],
                       capture_output=True, text=True)
    if p.returncode == 2 and cells < 0:
        return "—"
    if p.returncode != 0:
        return "exit %d" % p.returncode
    m = json.loads(subprocess.run([MESHCHECK, out], capture_output=True, text=True).stdout)
    valid = m.get("closed") and m.get("manifold") and m.get("nonmanifold_vertices", 0) == 0 and \
        m.get("self_intersections", 0) == 0
    c = json.loads(subprocess.run([PIC, "compare", out, path, "--offset", "%.17g" % d, "--samples", "100000",
                                   "--unit", "%.17g" % cell, "--json"], capture_output=True, text=True).stdout)
    text = "%.2f / %.2f (%.2f)" % (c["offset_worst"], c["offset_back_worst"], c["offset_worst_vertex"])
    return text if valid else text + " (NOT VALID)"


def main():
    depth = int(sys.argv[1]) if len(sys.argv) > 1 else 9
    inputs = [(os.path.basename(p), p) for p in sys.argv[2:]] or INPUTS
    out = "/tmp/pic_offset_table.stl"
    print("| input | " + " | ".join("%+d" % c for c in CELLS) + " |")
    print("|---|" + "---|" * len(CELLS))
    for name, path in inputs:
        print("| %s | %s |" % (name, " | ".join(one(path, c, depth, out) for c in CELLS)), flush=True)


if __name__ == "__main__":
    main()
