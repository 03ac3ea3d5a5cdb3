#!/usr/bin/env python3
"""The any-input table: every mesh given, sampled by `pic sample` (auto classifier), contoured by
`pic mesh`, checked for closed/manifold, and compared with the exact winding number of the input
at random points more than 2 finest cells from its surface (../shared/tools/gwn.py agree).

  python3 bench/any_input.py build/pic OUT_DIR MESH... [--depth 12] [--points 2000]
"""
import argparse, json, os, subprocess, sys

ap = argparse.ArgumentParser()
ap.add_argument("pic")
ap.add_argument("out")
ap.add_argument("meshes", nargs="+")
ap.add_argument("--depth", type=int, default=12)
ap.add_argument("--points", type=int, default=2000)
ap.add_argument("--gwn", default=os.path.join(os.path.dirname(__file__), "../../shared/tools/gwn.py"))
a = ap.parse_args()
os.makedirs(a.out, exist_ok=True)

def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr.strip()
    return r.stdout, None

print("| input | defects | inside | PICs | sample s | contour | agreement |")
print("|---|---|---|---:|---:|---|---:|")
for m in a.meshes:
    name = os.path.basename(m).rsplit(".", 1)[0]
    pic = os.path.join(a.out, name + ".pic")
    out, err = run([a.pic, "sample", m, "-o", pic, "--depth", str(a.depth), "--json"])
    if out is None:
        print(f"| {name} | | refused | | | {err} | |")
        continue
    s = json.loads(out)
    d = s["defects"]
    defects = ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in d.items() if v and k not in ("shells",)) or "none"
    defects += f"; {d['shells']} shell" + ("s" if d["shells"] != 1 else "")
    obj = os.path.join(a.out, name + ".obj")
    mo, _ = run([a.pic, "mesh", pic, "-o", obj, "--json"])
    topo = json.loads(mo)["topology"]
    state = ("closed" if topo["closed"] else "OPEN") + ", " + ("manifold" if topo["manifold"] else "non-manifold")
    agree = ""
    if not m.endswith((".ply", ".xyz")):
        g, err = run(["/usr/bin/python3", a.gwn, "agree", m, obj, "--points", str(a.points), "--band", "2"])
        if g:
            j = json.loads(g)
            agree = f"{100 * j.get('agreement', j.get('agree', 0)):.2f} %"
    print(f"| {name} | {defects} | {s['inside']} | {s['pics']:,} | {s['seconds']:.2f} | {state} | {agree} |", flush=True)
