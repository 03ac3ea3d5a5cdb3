#!/usr/bin/env bash
# Writes every output a refactor must leave byte-identical into OUT_DIR, with the timings
# removed from the JSON: bundled models sampled, contoured (all contour variants) and inspected,
# CSG chains of .pic and mesh operands, OpenSCAD fixtures, CSG harness cases and a sculpting run.
#   scripts/identity_check.sh BIN_DIR OUT_DIR     (BIN_DIR holds pic [pic_csg_fuzz pic_sculpt])
#   diff -r OUT_BEFORE OUT_AFTER                 identical when it prints nothing
set -euo pipefail
BIN=$1
OUT=$2
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mkdir -p "$OUT"
PIC="$BIN/pic"
# Timings differ run to run: drop every *seconds* field (and file sizes stay).
strip() { sed -E "s#$OUT#OUT#g" | sed -E 's/"[a-z_]*seconds[a-z_]*": [-0-9.e+]+(, )?//g; s/, \}/}/g'; }

for m in fandisk cad_part spot suzanne teapot stanford-bunny; do
  for d in 8 10; do
    "$PIC" sample "$ROOT/data/$m.obj" --depth $d -o "$OUT/$m.$d.pic" --json | strip > "$OUT/$m.$d.sample.json"
    "$PIC" mesh "$OUT/$m.$d.pic" -o "$OUT/$m.$d.obj" --json | strip > "$OUT/$m.$d.mesh.json"
    "$PIC" mesh "$OUT/$m.$d.pic" -o "$OUT/$m.$d.plain.obj" --plain --no-split --json | strip > "$OUT/$m.$d.plain.json" || true
    "$PIC" info "$OUT/$m.$d.pic" --json | strip > "$OUT/$m.$d.info.json"
  done
done
"$PIC" sample "$ROOT/data/fandisk.obj" -o "$OUT/fandisk.12.pic" --json | strip > "$OUT/fandisk.12.sample.json"
"$PIC" mesh "$OUT/fandisk.12.pic" -o "$OUT/fandisk.12.obj" --json | strip > "$OUT/fandisk.12.mesh.json"
"$PIC" sample "$ROOT/data/spot.obj" --inside winding --depth 9 -o "$OUT/spot.w.pic" --json | strip > "$OUT/spot.w.json"

CUBE=0,0,0,1
"$PIC" prim box --size 0.5,0.5,0.5 --center 0.5,0.5,0.5 --cube $CUBE -o "$OUT/cube.pic" --json | strip > "$OUT/cube.json"
"$PIC" prim cylinder --radius 0.15 --height 0.8 --axis z --center 0.5,0.5,0.5 --cube $CUBE -o "$OUT/cyl_z.pic" > /dev/null
"$PIC" prim cylinder --radius 0.1 --height 0.8 --axis x --center 0.5,0.5,0.5 --cube $CUBE -o "$OUT/cyl_x.pic" > /dev/null
"$PIC" prim sphere --radius 0.12 --center 0.3,0.5,0.6 --cube $CUBE -o "$OUT/ball.pic" > /dev/null
"$PIC" prim box --size 0.12,0.7,0.12 --center 0.72,0.5,0.58 --rotate 0,1,0,45 --cube $CUBE -o "$OUT/notch.pic" > /dev/null
"$PIC" prim torus --radius 0.2 --minor 0.05 --center 0.5,0.5,0.5 --cube $CUBE -o "$OUT/torus.pic" > /dev/null
"$PIC" csg "$OUT/cube.pic" union "$OUT/cyl_z.pic" subtract "$OUT/cyl_x.pic" subtract "$OUT/ball.pic" \
  -o "$OUT/cad.pic" --mesh "$OUT/cad.obj" --json | strip > "$OUT/cad.json"
"$PIC" csg "$OUT/cube.pic" intersect "$OUT/torus.pic" union "$OUT/notch.pic" -o "$OUT/mix.obj" --json | strip > "$OUT/mix.json"
"$PIC" csg "$ROOT/data/spot.obj" subtract "$ROOT/data/suzanne.obj" --depth 9 -o "$OUT/spot_suz.pic" \
  --mesh "$OUT/spot_suz.obj" --json | strip > "$OUT/spot_suz.json"
"$PIC" csg "$ROOT/../shared/data/thingi10k-1514499.obj" subtract "$ROOT/../shared/data/thingi10k-1706459.obj" --depth 10 \
  -o "$OUT/thingi.obj" --json | strip > "$OUT/thingi.json" 2>/dev/null || true

for f in "$ROOT"/tests/data/scad/*.csg; do
  b=$(basename "$f" .csg)
  "$PIC" eval "$f" --depth 9 -o "$OUT/scad_$b.obj" --json 2>/dev/null | strip > "$OUT/scad_$b.json" || echo "exit $?" >> "$OUT/scad_$b.json"
done

if [[ -x "$BIN/pic_csg_fuzz" ]]; then
  for s in 3 43 56 74 105 117 250 300; do
    "$BIN/pic_csg_fuzz" --case $s --out "$OUT/harness" | sed -E 's/[0-9.]+ s\b//g; s/[0-9.]+ ms//g' > "$OUT/harness_$s.txt"
  done
  rm -f "$OUT"/harness/*_exact.obj  # CGAL's reference result: its vertex order varies run to run
fi
if [[ -x "$BIN/pic_sculpt" ]]; then
  "$BIN/pic_sculpt" "$OUT/spot.10.pic" --strokes 60 --seed 3 --out "$OUT/sculpt.pic" --mesh "$OUT/sculpt.obj" > /dev/null
fi
echo "identity_check: $(ls "$OUT" | wc -l) outputs in $OUT"
