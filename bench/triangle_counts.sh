#!/usr/bin/env bash
# Triangles written by `pic eval x.csg` (simplified, the default) against Manifold's exact
# result of the same tree, over OpenSCAD's bundled examples (3D ones both evaluate).
#   bench/triangle_counts.sh [OUTDIR]     (default /tmp/pic_triangles; needs openscad, node)
set -uo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-/tmp/pic_triangles}
pic=${PIC:-$here/build/pic}
manifold=${MANIFOLD_SCAD:-$here/../shared/tools/manifold/scad.mjs}
mkdir -p "$out"
field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1])).get(sys.argv[2], ''))" "$1" "$2" 2>/dev/null; }
echo "| example | PIC triangles | Manifold triangles | PIC / Manifold | PIC valid |"
echo "|---|---:|---:|---:|---|"
for scad in /usr/share/openscad/examples/*/*.scad; do
  name=$(basename "$scad" .scad)
  d=$out/$name
  mkdir -p "$d"
  (cd "$(dirname "$scad")" && timeout 60 openscad -o "$d/x.csg" "$name.scad" >/dev/null 2>&1) || continue
  timeout 120 "$pic" eval "$d/x.csg" -o "$d/pic.obj" --json >"$d/pic.json" 2>/dev/null || continue
  timeout 120 node "$manifold" "$d/x.csg" "$d/exact.obj" --json >"$d/exact.json" 2>/dev/null || continue
  p=$(field "$d/pic.json" triangles)
  m=$(field "$d/exact.json" triangles)
  [[ -n $p && -n $m && $m != 0 ]] || continue
  valid=$(python3 -c "import json; t=json.load(open('$d/pic.json'))['topology']; print('yes' if t['closed'] and t['manifold'] else 'NO')")
  printf "| %s | %s | %s | %.1f× | %s |\n" "$name" "$p" "$m" "$(echo "$p / $m" | bc -l)" "$valid"
done
