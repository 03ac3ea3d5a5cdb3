#!/usr/bin/env python3
"""Random CAD solids hollowed, skinned, thickened and rounded by PIC, against exact references.

    python3 bench/volume_fuzz.py FIRST_SEED COUNT [DEPTH] [OUTDIR]   (defaults: depth 9, /tmp/pic_volume_fuzz)

Each case is a model of bench/scad_fuzz.py rendered by OpenSCAD (a clean 2-manifold, else
skipped) and one operation with a random size of 3, 8 or 20 finest cells (plus 0.37 of a cell,
as in bench/offset_fuzz.py, in the same power-of-two root cube):

- `pic shell --thickness T` (walls inside) and `--outward` (a skin outside), and `pic thicken
  --thickness T` of the solid's closed surface: each is a difference of the input and PIC's own
  offsets of it (`pic offset`, checked against the exact offset in the same case), evaluated
  exactly by Manifold (../shared/tools/manifold/scad.mjs on an `import()` tree). The shell is
  measured against that difference both ways (`pic compare`).
- `pic round --radius R` (`--convex`, the opening) and `--concave` (the closing): the exact
  offset by +R (−R) of PIC's first offset of the input by −R (+R) (`pic compare --offset`), the
  second step's exact answer for the first step as PIC computed it.

A case is reported when a command crashes or fails other than by refusing an operation that
leaves nothing (exit 2), when an output is not closed, 2-manifold and free of
self-intersections (meshcheck), when a first offset lies more than 1.5 finest cells from the
exact offset, or when the result lies more than 1.5 finest cells from its reference either
way. Every case is replayable from its seed (OUTDIR/SEED: m.scad, ref.stl, the commands).
"""
import json
import math
import os
import random
import subprocess
import sys

from fuzz_tools import PIC, SCAD_MJS, arguments, meshcheck
from scad_fuzz import model
LIMIT_CELLS = 1.5
OPERATIONS = ["shell", "shell_outward", "thicken", "round_convex", "round_concave"]


class Report(Exception):
    """A finding: the case is reported with this text."""


class Skip(Exception):
    """No verdict: the case cannot be measured (the render, an operation that leaves nothing)."""



def valid(path, what):
    m = meshcheck(path)
    if not m or not m.get("closed") or not m.get("manifold") or m.get("nonmanifold_vertices", 0) != 0 \
            or m.get("self_intersections", 0) != 0:
        raise Report("%s INVALID: %s" % (what, json.dumps({k: m.get(k) for k in (
            "closed", "manifold", "nonmanifold_vertices", "self_intersections")} if m else None)))
    return m


def pic(d, args, what, refusable=False):
    """Runs `pic ARGS` (logged to d/commands); a refusal (exit 2) of an emptying operation skips."""
    with open(os.path.join(d, "commands"), "a") as f:
        f.write(" ".join([PIC] + args) + "\n")
    try:
        p = subprocess.run([PIC] + args, capture_output=True, text=True, timeout=600)
    except subprocess.TimeoutExpired:
        raise Report("%s TIMEOUT" % what)
    if p.returncode == 2 and refusable:
        raise Skip("%s refused: %s" % (what, p.stderr.strip().splitlines()[-1][:100]))
    if p.returncode != 0:
        raise Report("%s EXIT %d: %s" % (what, p.returncode, p.stderr.strip()[-200:]))


def compare(a, b, cell, offset=None):
    args = [PIC, "compare", a, b, "--samples", "20000", "--unit", "%.17g" % cell, "--json"]
    if offset is not None:
        args += ["--offset", "%.17g" % offset]
    c = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if c.returncode != 0:
        raise Report("COMPARE FAILED: %s" % c.stderr.strip()[-200:])
    m = json.loads(c.stdout)
    return (m["offset_worst"], m["offset_back_worst"]) if offset is not None else (m["a_to_b"], m["b_to_a"])


def root_cube(lo, hi, steps, depth):
    """A cube whose size is a power of two times the model's extent, grown to hold an offset of
    `steps` finest cells: (cube, cell)."""
    extent = max(h - l for l, h in zip(lo, hi))
    size = 2.0 ** round(1 + math.log2(extent))
    while size < extent + 2 * abs(steps) * size / 2 ** depth + size / 32:
        size *= 2
    return [(l + h) / 2 - size / 2 for l, h in zip(lo, hi)] + [size], size / 2 ** depth


def offset(d, ref, name, distance, cube_args, cell):
    """PIC's offset of the input, checked against the exact offset (it is half a reference)."""
    # OFF holds the doubles (an STL rounds them to floats, folding slivers a sign test then
    # misreads).
    out = os.path.join(d, name + ".off")
    pic(d, ["offset", ref, "-o", out, "--distance", "%.17g" % distance] + cube_args, name, refusable=True)
    valid(out, name)
    ab, ba = compare(out, ref, cell, distance)
    if max(ab, ba) > LIMIT_CELLS:
        raise Report("%s %.2f / %.2f cells from the exact offset" % (name, ab, ba))
    return out


def manifold_difference(d, a, b):
    """Manifold's exact A − B of two closed meshes (float32 output)."""
    csg, out = os.path.join(d, "reference.csg"), os.path.join(d, "reference.obj")
    with open(csg, "w") as f:
        f.write('difference() { import(file = "%s"); import(file = "%s"); }\n' % (a, b))
    m = subprocess.run(["node", SCAD_MJS, csg, out, "--json"], capture_output=True, text=True, timeout=900)
    try:
        if json.loads(m.stdout).get("ok") and os.path.exists(out):
            return out
    except ValueError:
        pass
    raise Skip("Manifold gave no difference")


def run_case(seed, depth, out):
    r = random.Random(seed)
    d = os.path.join(out, str(seed))
    os.makedirs(d, exist_ok=True)
    if os.path.exists(os.path.join(d, "commands")):
        os.remove(os.path.join(d, "commands"))
    scad, ref = os.path.join(d, "m.scad"), os.path.join(d, "ref.stl")
    with open(scad, "w") as f:
        f.write(model(r) + "\n")
    subprocess.run(["openscad", "-o", ref, scad], capture_output=True, timeout=300)
    info = meshcheck(ref) if os.path.exists(ref) else None
    if not info or not info.get("closed") or not info.get("manifold") or info.get("nonmanifold_vertices", 0) \
            or info.get("self_intersections", 0) or not (info.get("volume") or 0) > 1e-6:
        raise Skip("no clean closed solid from OpenSCAD")
    op = r.choice(OPERATIONS)
    cells = r.choice([3, 8, 20])
    steps = cells + 0.37
    cube, cell = root_cube(info["bbox"]["min"], info["bbox"]["max"], steps, depth)
    size = steps * cell
    cube_args = ["--depth", str(depth), "--cube", ",".join("%.17g" % c for c in cube)]
    result = os.path.join(d, "pic.stl")
    label = "%s %d cells" % (op, cells)
    if op.startswith("round"):
        convex = op == "round_convex"
        first = offset(d, ref, "first", -size if convex else size, cube_args, cell)
        pic(d, ["round", ref, "-o", result, "--radius", "%.17g" % size, "--convex" if convex else "--concave"]
            + cube_args, label, refusable=convex)
        valid(result, label)
        ab, ba = compare(result, first, cell, size if convex else -size)
    else:
        if op == "shell":
            inner = offset(d, ref, "inner", -size, cube_args, cell)
            reference = manifold_difference(d, ref, inner)
            pic(d, ["shell", ref, "-o", result, "--thickness", "%.17g" % size] + cube_args, label)
        elif op == "shell_outward":
            outer = offset(d, ref, "outer", size, cube_args, cell)
            reference = manifold_difference(d, outer, ref)
            pic(d, ["shell", ref, "-o", result, "--thickness", "%.17g" % size, "--outward"] + cube_args, label)
        else:
            outer = offset(d, ref, "outer", size / 2, cube_args, cell)
            inner = offset(d, ref, "inner", -size / 2, cube_args, cell)
            reference = manifold_difference(d, outer, inner)
            pic(d, ["thicken", ref, "-o", result, "--thickness", "%.17g" % size] + cube_args, label)
        valid(result, label)
        ab, ba = compare(result, reference, cell)
    text = "%s: %.2f / %.2f cells" % (label, ab, ba)
    if max(ab, ba) > LIMIT_CELLS:
        raise Report(text)
    return text


def main():
    first, count, depth, out = arguments(__doc__, 9, "/tmp/pic_volume_fuzz")
    reported = 0
    for seed in range(first, first + count):
        try:
            print(seed, "ok", run_case(seed, depth, out), flush=True)
        except Skip as s:
            print(seed, "skipped:", s, flush=True)
        except Report as e:
            reported += 1
            print(seed, "REPORT", e, flush=True)
    print("%d cases, %d reported (%s)" % (count, reported, out))
    return 1 if reported else 0


if __name__ == "__main__":
    sys.exit(main())
