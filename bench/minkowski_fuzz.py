#!/usr/bin/env python3
"""Random non-convex CAD solids summed with a faceted sphere, by `pic eval` and by Manifold.

    python3 bench/minkowski_fuzz.py FIRST_SEED COUNT [DEPTH] [OUTDIR]   (defaults: depth 9, /tmp/pic_minkowski_fuzz)

Each case is `minkowski() { MODEL; sphere(r, $fn = 24 or 32); }` with MODEL a random tree of
bench/scad_fuzz.py (cubes, prisms and coarse spheres on integers) that is not one convex part,
so PIC takes its one-sampling path for a round body (docs/algorithms.md, "Minkowski sums with a
round body"). OpenSCAD writes the tree (`openscad -o m.csg`); Manifold (WASM,
../shared/tools/manifold/scad.mjs) evaluates the same tree exactly. A case is reported when
PIC fails, or refuses (exit 2) calling the model empty where Manifold's sum is not, when its
mesh is not closed, 2-manifold and free of
self-intersections (meshcheck), or when its raw contour's volume (`--simplify 0`) is off
Manifold's by more than 0.5 % and by more than a finest cell's layer over the sum's area,
or when it lies more than 1.5 finest cells from Manifold's mesh either way. Every case is
replayable from its seed (OUTDIR/SEED).
"""
import json
import os
import random
import subprocess

from fuzz_tools import PIC, SCAD_MJS, arguments, meshcheck
from scad_fuzz import model


def case(seed):
    r = random.Random(seed)
    return "minkowski() { %s sphere(r=%g, $fn=%d); }" % (
        model(r), r.choice([0.3, 0.5, 0.8, 1.2, 2]), r.choice([24, 32]))



def run_case(seed, depth, outdir):
    d = os.path.join(outdir, str(seed))
    os.makedirs(d, exist_ok=True)
    scad, csg = os.path.join(d, "m.scad"), os.path.join(d, "m.csg")
    with open(scad, "w") as f:
        f.write(case(seed) + "\n")
    subprocess.run(["openscad", "-o", csg, scad], capture_output=True, timeout=120)
    if not os.path.exists(csg):
        return "skipped: OpenSCAD wrote no tree"
    ref = os.path.join(d, "manifold.obj")
    m = subprocess.run(["node", SCAD_MJS, csg, ref, "--json"], capture_output=True, text=True, timeout=900)
    try:
        mf = json.loads(m.stdout)
    except ValueError:
        return "skipped: Manifold gave no result"
    if mf.get("empty") or not os.path.exists(ref):
        return "skipped: Manifold's sum is empty"
    out = os.path.join(d, "pic.stl")
    p = subprocess.run([PIC, "eval", csg, "-o", out, "--depth", str(depth), "--simplify", "0", "--json"],
                       capture_output=True, text=True, timeout=900)
    if p.returncode == 2:
        # A refusal is fine where the sum is beyond PIC's limits, wrong where PIC calls it empty.
        why = p.stderr.strip().splitlines()[-1]
        return ("REPORT refused, Manifold's volume %g: " % mf["volume"] if "empty" in why else "skipped: refused: ") + why
    if p.returncode != 0:
        return "REPORT pic exit %d: %s" % (p.returncode, p.stderr.strip().splitlines()[-1:])
    j = json.loads(p.stdout)
    c = meshcheck(out) or {}
    if not (c.get("closed") and c.get("manifold") and c.get("nonmanifold_vertices", 0) == 0
            and c.get("self_intersections", 0) == 0):
        return "REPORT invalid mesh: %s" % {k: c.get(k) for k in ("closed", "manifold", "self_intersections")}
    cell = j["cube"]["size"] / 2 ** depth
    cmp = json.loads(subprocess.run([PIC, "compare", out, ref, "--unit", str(cell), "--json"],
                                    capture_output=True, text=True).stdout)
    got, want = j["volume"], mf["volume"]
    off = abs(got - want) / abs(want)
    layer = cell * mf.get("area", 0)
    text = "volume %.6g vs %.6g (%+.3f %%), %.2f / %.2f cells" % (got, want, 100 * (got - want) / want,
                                                               cmp["a_to_b"], cmp["b_to_a"])
    if (off > 5e-3 and abs(got - want) > layer) or max(cmp["a_to_b"], cmp["b_to_a"]) > 1.5:
        return "REPORT " + text
    return "ok " + text


def main():
    first, count, depth, outdir = arguments(__doc__, 9, "/tmp/pic_minkowski_fuzz")
    reported = 0
    for seed in range(first, first + count):
        line = run_case(seed, depth, outdir)
        reported += line.startswith("REPORT")
        print(seed, line, flush=True)
    print("%d of %d reported" % (reported, count))


if __name__ == "__main__":
    main()
