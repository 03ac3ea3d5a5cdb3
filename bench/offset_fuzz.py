#!/usr/bin/env python3
"""Random CAD solids grown and shrunk by `pic offset`, measured against the exact offset.

    python3 bench/offset_fuzz.py FIRST_SEED COUNT [DEPTH] [OUTDIR]   (defaults: depth 9, /tmp/pic_offset_fuzz)

Each case is a model of bench/scad_fuzz.py (a random tree of cubes, prisms and coarse spheres on
integer coordinates) rendered by OpenSCAD, then offset by a random distance of 2, 5, 20 or 60
finest cells, grown or shrunk, in a root cube fixed so that the distance is that many cells (as
docs/benchmarks.md's table of offsets) plus 0.37 of a cell: faces an integer apart grown by an
exact number of cells would meet exactly, where the exact offset keeps a sheet of no
thickness between them that no solid has. A case is reported when `pic offset` crashes
or fails other than by refusing (exit 2, "shrinking by D leaves nothing"), when its mesh is not
closed, 2-manifold and free of self-intersections (meshcheck), or when it lies farther than
1.5 finest cells from the exact offset surface either way (`pic compare --offset`; a render
that is not a clean 2-manifold, parts touching along an edge or float vertices crossing by a
hair, is only checked for validity: the exact offset needs one). Shrinks
that leave a slot or blade thinner than a cell are a known limit (docs/benchmarks.md): read a
reported case before calling it PIC's. Every case is replayable from its seed (OUTDIR/SEED).
"""
import json
import os
import random
import subprocess
import sys

from fuzz_tools import PIC, arguments, meshcheck
from scad_fuzz import model

LIMIT_CELLS = 1.5



def run_case(seed, depth, out):
    r = random.Random(seed)
    d = os.path.join(out, str(seed))
    os.makedirs(d, exist_ok=True)
    scad, ref = os.path.join(d, "m.scad"), os.path.join(d, "ref.stl")
    with open(scad, "w") as f:
        f.write(model(r) + "\n")
    subprocess.run(["openscad", "-o", ref, scad], capture_output=True, timeout=300)
    info = meshcheck(ref) if os.path.exists(ref) else None
    if not info or not info.get("closed") or not (info.get("volume") or 0) > 1e-6:
        return None, "skipped: no closed solid from OpenSCAD"
    lo, hi = info["bbox"]["min"], info["bbox"]["max"]
    sign = r.choice([1, -1])
    cells = r.choice([2, 5, 20, 60]) * sign
    steps = cells + 0.37 * sign
    # The cube around the grown solid, its size a power of two times the model's extent so
    # that `cells` is exact in finest cells.
    extent = max(h - l for l, h in zip(lo, hi))
    size = 2.0 ** round(1 + __import__("math").log2(extent))
    distance = steps * size / 2 ** depth
    while size < extent + 2 * abs(distance) + size / 32:
        size *= 2
        distance = steps * size / 2 ** depth
    cube = [(l + h) / 2 - size / 2 for l, h in zip(lo, hi)] + [size]
    cube_arg = ",".join("%.17g" % c for c in cube)
    stl = os.path.join(d, "pic.stl")
    cmd = [PIC, "offset", ref, "-o", stl, "--distance", "%.17g" % distance, "--depth", str(depth), "--cube", cube_arg]
    with open(os.path.join(d, "command"), "w") as f:
        f.write(" ".join(cmd) + "\n")
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    except subprocess.TimeoutExpired:
        return False, "TIMEOUT %+d cells" % cells
    if p.returncode == 2 and cells < 0:
        return None, "refused %+d cells: %s" % (cells, p.stderr.strip().splitlines()[-1][:100])
    if p.returncode != 0:
        return False, "EXIT %d %+d cells: %s" % (p.returncode, cells, p.stderr.strip()[-200:])
    check = meshcheck(stl)
    if not check or not check.get("closed") or not check.get("manifold") or check.get("self_intersections", 0) != 0 \
            or check.get("nonmanifold_vertices", 0) != 0:
        return False, "INVALID %+d cells: %s" % (cells, json.dumps({k: check.get(k) for k in (
            "closed", "manifold", "nonmanifold_vertices", "self_intersections")} if check else None))
    if not info.get("manifold") or info.get("nonmanifold_vertices", 0) != 0 or info.get("self_intersections", 0) != 0:
        # OpenSCAD's parts touching along an edge, or its float vertices crossing by a hair: PIC
        # offsets the solid (signs by the winding number), the exact offset needs a clean 2-manifold.
        return None, "valid %+d cells; the render is not a clean 2-manifold: no exact offset to compare" % cells
    c = subprocess.run([PIC, "compare", stl, ref, "--offset", "%.17g" % distance, "--samples", "20000",
                        "--unit", "%.17g" % (size / 2 ** depth), "--json"], capture_output=True, text=True, timeout=600)
    if c.returncode != 0:
        return False, "COMPARE FAILED %+d cells: %s" % (cells, c.stderr.strip()[-200:])
    m = json.loads(c.stdout)
    ab, ba = m["offset_worst"], m["offset_back_worst"]
    text = "%+d cells: %.2f / %.2f cells" % (cells, ab, ba)
    return (max(ab, ba) <= LIMIT_CELLS), text


def main():
    first, count, depth, out = arguments(__doc__, 9, "/tmp/pic_offset_fuzz")
    reported = 0
    for seed in range(first, first + count):
        ok, text = run_case(seed, depth, out)
        if ok is False:
            reported += 1
        print(seed, "ok" if ok else ("REPORT" if ok is False else ""), text, flush=True)
    print("%d cases, %d reported (%s)" % (count, reported, out))
    return 1 if reported else 0


if __name__ == "__main__":
    sys.exit(main())
