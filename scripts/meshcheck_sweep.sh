#!/usr/bin/env bash
# Every kind of mesh PIC writes, checked by an independent checker (MESHCHECK: the shared
# tools' meshcheck, exact self-intersection test on): the bundled models at depths 8-14 (as
# STL, merged by position as a reader does), the CSG harness cases, a 300-stroke sculpting run,
# point clouds of two models, and `pic eval` of the OpenSCAD examples that evaluate. Prints one line per mesh that is not a closed, 2-manifold,
# self-intersection-free solid (an empty result, such as an empty intersection, passes), and a
# count per kind.
#   MESHCHECK=... scripts/meshcheck_sweep.sh [BUILD_DIR] [OUT_DIR]
set -uo pipefail
BUILD=${1:-build}
OUT=${2:-out/meshcheck}
MESHCHECK=${MESHCHECK:?set MESHCHECK to the shared tools meshcheck}
GWN=${GWN:-/work/shared/tools/gwn.py}
CASES=${CASES:-300}
PIC="$BUILD/pic"
mkdir -p "$OUT"

check() {  # kind, mesh: prints a line when the mesh is not a valid solid; returns 1 then
  local r
  r=$("$MESHCHECK" "$2" | python3 -c "
import json,sys
d=json.load(sys.stdin)
bad=[k for k in ('boundary_edges','nonmanifold_edges','nonmanifold_vertices','self_intersections') if d.get(k)]
print('ok' if d['triangles'] == 0 or (not bad and d.get('closed') and d.get('manifold')) else 'BAD ' + ', '.join('%s %s' % (k, d[k]) for k in bad))")
  if [[ $r != ok ]]; then
    echo "$1 $2: $r"
    return 1
  fi
}

tally() {  # kind, checked, bad
  echo "$1: $2 meshes, $3 not valid"
}

n=0 bad=0
for m in data/*.obj; do
  name=$(basename "$m" .obj)
  for d in 8 9 10 11 12 13 14; do
    "$PIC" sample "$m" -o "$OUT/$name.$d.pic" --depth "$d" > /dev/null
    "$PIC" mesh "$OUT/$name.$d.pic" -o "$OUT/$name.$d.stl" > /dev/null 2>&1
    n=$((n + 1))
    check model "$OUT/$name.$d.stl" || bad=$((bad + 1))
  done
done
tally "bundled models, depths 8-14" $n $bad

n=0 bad=0
"$BUILD/bench/pic_csg_fuzz" --cases "$CASES" --out "$OUT/csg" > "$OUT/csg.txt"
for f in "$OUT"/csg/case*_pic.obj; do
  n=$((n + 1))
  check csg "$f" || bad=$((bad + 1))
done
tally "CSG harness cases" $n $bad

n=1 bad=0
"$PIC" sample data/spot.obj -o "$OUT/spot.10.pic" --depth 10 > /dev/null
"$BUILD/bench/pic_sculpt" "$OUT/spot.10.pic" --strokes 300 --seed 3 --mesh "$OUT/sculpt.obj" > /dev/null
check sculpt "$OUT/sculpt.obj" || bad=1
tally "sculpting, 300 strokes" $n $bad

n=0 bad=0
for m in spot stanford-bunny; do
  /usr/bin/python3 "$GWN" points "data/$m.obj" "$OUT/$m.points.ply" --n 200000 > /dev/null
  "$PIC" sample "$OUT/$m.points.ply" -o "$OUT/$m.points.pic" > /dev/null
  "$PIC" mesh "$OUT/$m.points.pic" -o "$OUT/$m.points.obj" > /dev/null 2>&1
  n=$((n + 1))
  check points "$OUT/$m.points.obj" || bad=$((bad + 1))
done
tally "point clouds" $n $bad

n=0 bad=0
for scad in /usr/share/openscad/examples/*/*.scad; do
  name=$(basename "$scad" .scad)
  timeout 60 "$PIC" eval "$scad" -o "$OUT/scad_$name.obj" > /dev/null 2>&1 || [[ $? == 4 ]] || continue
  n=$((n + 1))
  check eval "$OUT/scad_$name.obj" || bad=$((bad + 1))
done
tally "pic eval of the OpenSCAD examples" $n $bad
