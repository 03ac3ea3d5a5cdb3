#!/usr/bin/env python3
"""Random OpenSCAD models on integer coordinates, evaluated by `pic eval` and by OpenSCAD.

    python3 bench/scad_fuzz.py FIRST_SEED COUNT [DEPTH] [OUTDIR]   (defaults: depth 10, /tmp/pic_scad_fuzz)

CAD models put vertices, edges and faces on round coordinates, so on the octree's lattice
planes and lines when the model's cube is centred on them: the configurations where a
surface touches a cell only along an edge or at a corner. Each case is a random tree (union,
difference, intersection; depth <= 2) of cubes, $fn = 3..8 cylinders along x, y or z and
coarse spheres, all on integers. A case is reported when PIC's mesh is not closed and
2-manifold, when its volume is off by more than 1 % from OpenSCAD's CGAL render, or when the
two-sided Hausdorff distance exceeds 3 finest cells (an empty PIC result agrees with a render
without volume, measured by meshcheck as in scad_semantics_fuzz.py). Every case is replayable from its seed
(OUTDIR/SEED/m.scad, pic.stl, ref.stl). OpenSCAD's render can hold zero-volume sheets that
PIC drops: look at a reported case before calling it PIC's.
"""
import json
import os
import random
import subprocess

from scad_semantics_fuzz import volume as mesh_volume  # meshcheck's volume of a mesh file

from fuzz_tools import PIC, arguments


def primitive(r):
    k = r.random()
    x, y, z = (r.randint(-6, 6) for _ in range(3))
    if k < 0.4:
        sx, sy, sz = (r.randint(1, 8) for _ in range(3))
        centre = ", center=true" if r.random() < 0.3 else ""
        return f"translate([{x},{y},{z}]) cube([{sx},{sy},{sz}]{centre});"
    if k < 0.8:
        fn, radius, height = r.choice([3, 4, 6, 8]), r.randint(1, 6), r.randint(1, 10)
        rot = r.choice(["", "rotate([90,0,0]) ", "rotate([0,90,0]) "])
        centre = ", center=true" if r.random() < 0.4 else ""
        return f"translate([{x},{y},{z}]) {rot}cylinder(r={radius}, h={height}, $fn={fn}{centre});"
    radius, fn = r.randint(1, 5), r.choice([4, 6, 8])
    return f"translate([{x},{y},{z}]) sphere(r={radius}, $fn={fn});"


def model(r, level=0):
    if level >= 2 or r.random() < 0.3:
        return primitive(r)
    op = r.choice(["union", "difference", "intersection"])
    return op + "(){ " + " ".join(model(r, level + 1) for _ in range(r.randint(2, 4))) + " }"


def run_case(seed, depth, out):
    d = os.path.join(out, str(seed))
    os.makedirs(d, exist_ok=True)
    scad = os.path.join(d, "m.scad")
    with open(scad, "w") as f:
        f.write(model(random.Random(seed)) + "\n")
    ref = os.path.join(d, "ref.stl")
    subprocess.run(["openscad", "-o", ref, scad], capture_output=True, timeout=300)
    p = subprocess.run([PIC, "eval", scad, "-o", os.path.join(d, "pic.stl"), "--depth", str(depth), "--json"],
                       capture_output=True, text=True, timeout=600)
    ref_empty = not os.path.exists(ref) or os.path.getsize(ref) < 200
    if p.returncode != 0:
        return None if ref_empty else f"pic exit {p.returncode}: {p.stderr.strip().splitlines()[-1:]}"
    j = json.loads(p.stdout)
    if ref_empty:
        return None if j.get("pics", 0) == 0 else "OpenSCAD's render is empty, PIC's is not"
    if j.get("triangles", 0) == 0:
        v = mesh_volume(ref)
        return None if v is not None and abs(v) < 1e-9 else f"PIC's result is empty, OpenSCAD's has volume {v}"
    cell = j["cube"]["size"] / 2 ** depth
    c = subprocess.run([PIC, "compare", os.path.join(d, "pic.stl"), ref, "--unit", str(cell), "--json"],
                       capture_output=True, text=True)
    cmp = json.loads(c.stdout)
    t = j["topology"]
    if not (t["closed"] and t["manifold"]) or abs(cmp["volume_rel_diff"]) > 0.01 or cmp["hausdorff"] > 3:
        return (f"closed {t['closed']} manifold {t['manifold']} volume {100 * cmp['volume_rel_diff']:+.3f} % "
                f"hausdorff {cmp['hausdorff']:.2f} cells")
    return None


def main():
    first, count, depth, out = arguments(__doc__, 10, "/tmp/pic_scad_fuzz")
    reported = 0
    for seed in range(first, first + count):
        why = run_case(seed, depth, out)
        if why:
            reported += 1
            print(f"seed {seed}: {why}", flush=True)
    print(f"{count} cases, {reported} reported ({out})")


if __name__ == "__main__":
    main()
