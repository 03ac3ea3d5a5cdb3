#!/usr/bin/env bash
# The compact-output table of docs/benchmarks.md: `pic eval x.csg` simplified (the default)
# against --raw on OpenSCAD's bundled examples, with Manifold's exact result as reference.
#   bench/compact_output.sh [OUTDIR]     (default /tmp/pic_compact; needs openscad, node, meshcheck)
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-/tmp/pic_compact}
pic=${PIC:-$here/build/pic}
tools=${TOOLS:-$here/../shared/tools}
meshcheck=$tools/build/meshcheck
mkdir -p "$out"
examples=(Old/example001 Old/example002 Old/example003 Old/example004 Old/example005 Old/example006
          Basics/CSG Basics/linear_extrude Basics/rotate_extrude Basics/LetterBlock)
seconds() { python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print(j['seconds'] + j['contour_seconds'], j['triangles'])" "$1"; }
hd() { "$meshcheck" "$1" "$2" --samples 50000 --no-si | python3 -c "import json,sys; j=json.load(sys.stdin); print(max(j['hausdorff_ab'], j['hausdorff_ba']) / float(sys.argv[1]))" "$3"; }
echo "| example | raw triangles / s | simplified triangles / s | Hausdorff simplified–raw | Hausdorff to exact: raw / simplified | valid | Manifold triangles |"
echo "|---|---|---|---|---|---|---|"
for e in "${examples[@]}"; do
  name=$(basename "$e")
  d=$out/$name
  mkdir -p "$d"
  (cd "/usr/share/openscad/examples/$(dirname "$e")" && openscad -o "$d/x.csg" "$name.scad" >/dev/null 2>&1)
  for run in 1 2 3; do
    "$pic" eval "$d/x.csg" -o "$d/raw.stl" --raw --json >"$d/raw$run.json" 2>/dev/null
    "$pic" eval "$d/x.csg" -o "$d/simple.stl" --json >"$d/simple$run.json" 2>/dev/null
  done
  median() { for r in 1 2 3; do seconds "$d/$1$r.json"; done | sort -n | sed -n 2p; }
  read -r raw_s raw_t <<<"$(median raw)"
  read -r simple_s simple_t <<<"$(median simple)"
  cell=$(python3 -c "import json; j=json.load(open('$d/simple1.json')); print(j['cube']['size'] / 2**j['depth'])")
  exact="—"; to_exact="—"; exact_t="—"
  if node "$tools/manifold/scad.mjs" "$d/x.csg" "$d/exact.obj" --json >"$d/exact.json" 2>/dev/null && [[ -s $d/exact.obj ]]; then
    exact_t=$(python3 -c "import json; print(f\"{json.load(open('$d/exact.json'))['triangles']:,}\")")
    to_exact="$(printf %.2f "$(hd "$d/raw.stl" "$d/exact.obj" "$cell")") / $(printf %.2f "$(hd "$d/simple.stl" "$d/exact.obj" "$cell")")"
  fi
  valid=$("$meshcheck" "$d/simple.stl" | python3 -c "import json,sys; j=json.load(sys.stdin); print('yes' if j['closed'] and j['manifold'] and j['self_intersections'] == 0 else 'NO')")
  printf "| %s | %'d / %.2f | %'d / %.2f | %.2f | %s | %s | %s |\n" "$name" "$raw_t" "$raw_s" "$simple_t" "$simple_s" \
    "$(hd "$d/simple.stl" "$d/raw.stl" "$cell")" "$to_exact" "$valid" "$exact_t"
done
