#!/usr/bin/env bash
# `pic eval` against OpenSCAD 2021's own renderer on every example Debian's openscad ships.
#   bench/scad_examples.sh [OUTDIR] [DEPTH]     (default: /tmp/pic_scad_examples, depth 12)
# For each /usr/share/openscad/examples/*/*.scad: export the .csg; run
# `pic eval x.scad -o pic.stl` (timeout 120 s); render the reference with
# `openscad -o ref.stl x.scad` (timeout 100 s); compare volume and two-sided Hausdorff distance in finest cells (`pic compare`);
# evaluate the same .csg with Manifold (/work/shared/tools/manifold/scad.mjs) as a second
# reference. Each example runs whole under the CPU lock (/work/notes/cpu.lock) when it
# exists, one at a time. Prints a Markdown table and totals; raw JSON per example in OUTDIR.
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-/tmp/pic_scad_examples}
depth=${2:-12}
pic=${PIC:-$here/build/pic}
manifold=${MANIFOLD_SCAD:-/work/shared/tools/manifold/scad.mjs}
lock=/work/notes/cpu.lock
mkdir -p "$out"
# One example, run whole under the lock (one wait per example): PIC first; a model PIC refuses
# (unsupported node, 2D model) is not rendered by the references. Each timed run writes
# "exit seconds" to its .rc file; timeouts keep every locked run under ~5 minutes.
one() {
  local scad=$1 d=$2
  t() {  # t RCFILE TIMEOUT CMD...
    local rc=$1 lim=$2
    shift 2
    local t0=$(date +%s.%N)
    timeout "$lim" "$@"
    echo "$? $(echo "$(date +%s.%N) - $t0" | bc)" >"$rc"
  }
  t "$d/pic.rc" 120 "$pic" eval "$scad" -o "$d/pic.stl" --depth "$depth" --json >"$d/pic.json" 2>"$d/pic.err"
  if grep -q "a 2D model" "$d/pic.err"; then  # its outline, against OpenSCAD's DXF export
    t "$d/pic.rc" 60 "$pic" eval "$scad" -o "$d/pic.dxf" --json >"$d/pic.json" 2>"$d/pic.err"
    t "$d/openscad.rc" 100 openscad -o "$d/ref.dxf" "$scad" >"$d/openscad.log" 2>&1
    return 0
  fi
  [[ $(cut -d' ' -f1 "$d/pic.rc") == 2 ]] && return
  t "$d/openscad.rc" 100 openscad -o "$d/ref.stl" "$scad" >"$d/openscad.log" 2>&1
  if [[ -s $d/x.csg && -e $manifold ]]; then
    timeout 60 node "$manifold" "$d/x.csg" "$d/manifold.obj" --json >"$d/manifold.json" 2>"$d/manifold.err"
  fi
  if [[ -s $d/pic.stl ]]; then
    local cell
    cell=$(python3 -c "import json; j=json.load(open('$d/pic.json')); print(j['cube']['size']/2**$depth)")
    [[ -s $d/ref.stl ]] && "$pic" compare "$d/pic.stl" "$d/ref.stl" --unit "$cell" --json >"$d/cmp_ref.json" 2>/dev/null
    [[ -s $d/manifold.obj ]] && "$pic" compare "$d/pic.stl" "$d/manifold.obj" --unit "$cell" --json >"$d/cmp_manifold.json" 2>/dev/null
  fi
  return 0
}
export -f one
export pic depth manifold

# An example is done once its pic.rc exists (and, when PIC evaluated it, openscad.rc): an
# interrupted run resumes where it stopped. Batches of examples share one lock acquisition
# while it has been held for under 150 s (with the timeouts, at most ~5 minutes).
batch() {
  local start=$SECONDS scad name d
  for scad in "$@"; do
    name=$(basename "$scad" .scad)
    d="$out/$name"
    if [[ -e $d/pic.rc ]] && { [[ $(cut -d' ' -f1 "$d/pic.rc") == 2 ]] || [[ -e $d/openscad.rc ]]; }; then continue; fi
    ((SECONDS - start > 150)) && return 1
    rm -rf "$d"
    mkdir -p "$d"
    # OpenSCAD resolves relative -o paths against the input's folder: use absolute paths.
    timeout 60 openscad -o "$d/x.csg" "$scad" >"$d/export.log" 2>&1
    one "$scad" "$d"
    echo "$name: $(cat "$d/pic.rc") $(tail -1 "$d/pic.err" | cut -c1-120)" >&2
  done
  return 0
}
export -f batch
export out
# The classic examples (Old/) first: they are the CSG models.
examples=(/usr/share/openscad/examples/Old/*.scad /usr/share/openscad/examples/Parametric/*.scad
          /usr/share/openscad/examples/Functions/*.scad /usr/share/openscad/examples/Basics/*.scad
          /usr/share/openscad/examples/Advanced/*.scad)
if [[ -e $lock ]]; then
  until flock "$lock" bash -c 'batch "$@"' _ "${examples[@]}"; do :; done
else
  until batch "${examples[@]}"; do :; done
fi

python3 - "$out" <<'PY'
import json, os, sys, statistics
out = sys.argv[1]
def load(p):
    try:
        with open(p) as f: return json.load(f)
    except Exception: return None
def dxf_area(path):
    # Shoelace area of a DXF's LINE and LWPOLYLINE entities (OpenSCAD writes LINEs, PIC
    # LWPOLYLINEs), each ring oriented as its boundary runs.
    try:
        lines = [l.strip() for l in open(path).read().split("\n")]
    except OSError:
        return None
    pairs, area, i = list(zip(lines[0::2], lines[1::2])), 0.0, 0
    while i < len(pairs):
        code, value = pairs[i]
        i += 1
        if code != "0" or value not in ("LINE", "LWPOLYLINE"): continue
        xs, ys = [], []
        while i < len(pairs) and pairs[i][0] != "0":
            if pairs[i][0] in ("10", "11"): xs.append(float(pairs[i][1]))
            if pairs[i][0] in ("20", "21"): ys.append(float(pairs[i][1]))
            i += 1
        n = len(xs)
        if value == "LINE" and n == 2: area += (xs[0] * ys[1] - xs[1] * ys[0]) / 2
        elif value == "LWPOLYLINE": area += sum(xs[k] * ys[(k + 1) % n] - xs[(k + 1) % n] * ys[k] for k in range(n)) / 2
    return area
rows, speed, ok_n, total_ref, total_pic = [], [], 0, 0.0, 0.0
for name in sorted(os.listdir(out)):
    d = os.path.join(out, name)
    if not os.path.isdir(d) or not os.path.exists(f"{d}/pic.rc"): continue
    prc, psec = open(f"{d}/pic.rc").read().split()
    orc, osec = open(f"{d}/openscad.rc").read().split() if os.path.exists(f"{d}/openscad.rc") else ("-", "nan")
    osec, psec = float(osec), float(psec)
    ref_ok = orc == "0" and os.path.getsize(f"{d}/ref.stl") > 0 if os.path.exists(f"{d}/ref.stl") else False
    pj = load(f"{d}/pic.json")
    mj = load(f"{d}/manifold.json")
    if prc != "0" or not pj:
        err = open(f"{d}/pic.err").read().strip().splitlines()
        why = err[-1].replace("pic: error: ", "") if err else f"exit {prc}"
        why = why.split(": ", 1)[-1] if ".scad: " in why else why
        if prc == "124": why = "PIC timed out (120 s)"
        rows.append(f"| {name} | no | {why} | | | | | | |")
        continue
    ok_n += 1
    if "area" in pj:  # a 2D model: areas of the two DXF outlines
        ref_area = dxf_area(f"{d}/ref.dxf") if orc == "0" else None
        diff = f"{100 * (pj['area'] - ref_area) / ref_area:+.3f} % (area)" if ref_area else "–"
        ref_ok = ref_area is not None
        sp = ""
        if ref_ok:
            s = osec / psec
            speed.append(s); total_ref += osec; total_pic += psec
            sp = f"{s:.1f}x"
        rows.append(f"| {name} | yes | 2D outline, {pj['rings']} rings | {osec:.2f}{'' if ref_ok else ' (failed)'} | "
                    f"{psec:.2f} | {sp} | {diff} | – | – |")
        continue
    cr, cm = load(f"{d}/cmp_ref.json"), load(f"{d}/cmp_manifold.json")
    topo = pj.get("topology", {})
    man = "yes" if topo.get("manifold") else ("closed" if topo.get("closed") else "no")
    sp = ""
    if ref_ok:
        s = osec / psec
        speed.append(s); total_ref += osec; total_pic += psec
        sp = f"{s:.1f}x"
    vol = f"{100*cr['volume_rel_diff']:+.3f} %" if cr else "–"
    hd = f"{cr['hausdorff']:.2f}" if cr else "–"
    hm = f"{cm['hausdorff']:.2f}" if cm else "–"
    mt = f"{mj['ms_total']/1000:.2f}" if mj and mj.get("ok") else "–"
    rows.append(f"| {name} | yes | {pj['leaves']} leaves, {pj['booleans']} Booleans, {man} | "
                f"{osec:.2f}{'' if ref_ok else ' (failed)'} | {psec:.2f} | {sp} | {vol} | {hd} | {mt} / {hm} |")
print("| example | evaluated | PIC result | OpenSCAD s | PIC s | speed-up | volume vs OpenSCAD | Hausdorff vs OpenSCAD (cells) | Manifold s / Hausdorff (cells) |")
print("|---|---|---|---|---|---|---|---|---|")
print("\n".join(rows))
if speed:
    print(f"\nEvaluated {ok_n} of {len(rows)}; median speed-up {statistics.median(speed):.1f}x, "
          f"total {total_ref:.1f} s (OpenSCAD) vs {total_pic:.1f} s (PIC) = {total_ref/total_pic:.1f}x "
          f"over the {len(speed)} with an OpenSCAD result.")
PY
