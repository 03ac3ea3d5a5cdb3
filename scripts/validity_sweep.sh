#!/usr/bin/env bash
# Issue 10's validity table at the current build: every bundled model (and the Thingi10K pair
# and its difference, when THINGI_DIR holds them) sampled at DEPTH, written by `pic mesh` /
# `pic csg --mesh`, with the exact checks PIC reports itself (self-intersections, non-manifold
# vertices and edges, components). With MESHCHECK set to the shared tools' meshcheck, also the
# two-sided Hausdorff distance to the input mesh. The last column: `pic mesh --plain --no-check`'s
# seconds (dual contouring's plain split, which may cross itself) on the same .pic.
#   scripts/validity_sweep.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-out/validity}
DEPTH=${DEPTH:-12}
THINGI_DIR=${THINGI_DIR:-/work/shared/data}
MESHCHECK=${MESHCHECK:-}
PIC="$BUILD/pic"
mkdir -p "$OUT"
json() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }

row() {  # name, json file, input mesh (or "")
  local fields haus=""
  fields=$(json "'%d | %d | %d | %d | {:,}'.format(d['triangles']) % (d['self_intersections'], d['nonmanifold_vertices'], d['nonmanifold_edges'], d['components'])" < "$2")
  if [[ -n "$MESHCHECK" && -n "$3" ]]; then
    haus=$("$MESHCHECK" "$OUT/$1.obj" "$3" --no-si --samples 100000 | json "'%.3g' % max(d['hausdorff_ab'], d['hausdorff_ba'])")
  fi
  local plain=""
  [[ -f "$OUT/$1.plain.json" ]] && plain=$(json "'%.3f' % d['seconds']" < "$OUT/$1.plain.json")
  echo "| $1 | $fields | $haus | $(json "'%.3f' % d['seconds']" < "$2") | $plain |"
}

echo "| mesh | self-intersecting pairs | non-manifold vertices | non-manifold edges | components | triangles | Hausdorff | seconds | plain split s |"
echo "|---|---|---|---|---|---|---|---|---|"
inputs=()
for m in data/*.obj; do inputs+=("$m"); done
[[ -f "$THINGI_DIR/thingi10k-1706459.obj" ]] && inputs+=("$THINGI_DIR/thingi10k-1706459.obj" "$THINGI_DIR/thingi10k-1514499.obj")
for m in "${inputs[@]}"; do
  name=$(basename "$m" .obj)
  "$PIC" sample "$m" -o "$OUT/$name.pic" --depth "$DEPTH" > /dev/null
  "$PIC" mesh "$OUT/$name.pic" -o "$OUT/$name.plain.obj" --plain --json --no-check > "$OUT/$name.plain.json" 2>/dev/null
  "$PIC" mesh "$OUT/$name.pic" -o "$OUT/$name.obj" --json > "$OUT/$name.json"
  row "$name" "$OUT/$name.json" "$m"
done
if [[ -f "$THINGI_DIR/thingi10k-1706459.obj" ]]; then
  # A - B with both meshes sampled in one cube around them (pic csg does that for mesh operands).
  "$PIC" csg "$THINGI_DIR/thingi10k-1706459.obj" subtract "$THINGI_DIR/thingi10k-1514499.obj" --depth "$DEPTH" \
    -o "$OUT/thingi_a_minus_b.pic" --mesh "$OUT/thingi_a_minus_b.obj" --json > "$OUT/thingi_a_minus_b.json"
  row thingi_a_minus_b "$OUT/thingi_a_minus_b.json" ""
fi
