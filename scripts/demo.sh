#!/usr/bin/env bash
# The main job on bundled data: sample meshes into PIC objects, contour them back, run the
# paper's CSG examples, and print what came out. Everything is written under out/.
set -euo pipefail
PIC=${1:-build/pic}
OUT=out
mkdir -p "$OUT"
json() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }

echo "== Sampling (depth 12, error 1e-8) =="
printf "%-10s %10s %8s %10s %8s %10s  %s\n" model triangles PICs seconds bytes/PIC triangles_out contour
for m in fandisk cad_part spot; do
  s=$("$PIC" sample data/$m.obj -o $OUT/$m.pic --json)
  c=$("$PIC" mesh $OUT/$m.pic -o $OUT/$m.obj --json)
  printf "%-10s %10s %8s %10s %8s %10s  %s\n" $m \
    "$(echo "$s" | json "d['triangles_in']")" "$(echo "$s" | json "d['pics']")" \
    "$(echo "$s" | json "'%.3f' % d['seconds']")" \
    "$(echo "$s" | json "'%.2f' % (d['file_bytes'] / d['pics'])")" \
    "$(echo "$c" | json "d['triangles']")" \
    "$(echo "$c" | json "'closed manifold' if d['topology']['manifold'] else ('closed' if d['topology']['closed'] else 'OPEN')")"
done

echo
echo "== CAD tool (paper Table 3): cube, union a cylinder, minus two cylinders =="
CUBE=0,0,0,1
"$PIC" prim box --size 0.5,0.5,0.5 --center 0.5,0.5,0.5 --cube $CUBE -o $OUT/cube.pic >/dev/null
"$PIC" prim cylinder --radius 0.15 --height 0.8 --axis z --center 0.5,0.5,0.5 --cube $CUBE -o $OUT/cyl_z.pic >/dev/null
"$PIC" prim cylinder --radius 0.1 --height 0.8 --axis x --center 0.5,0.5,0.5 --cube $CUBE -o $OUT/cyl_x.pic >/dev/null
"$PIC" prim cylinder --radius 0.07 --height 0.8 --axis y --center 0.5,0.5,0.5 --cube $CUBE -o $OUT/cyl_y.pic >/dev/null
"$PIC" csg $OUT/cube.pic union $OUT/cyl_z.pic subtract $OUT/cyl_x.pic subtract $OUT/cyl_y.pic \
  -o $OUT/cad_tool.pic --mesh $OUT/cad_tool.obj --json > $OUT/cad_tool.json
printf "%-10s %12s %12s %10s %10s %14s\n" op contour_A_ms contour_B_ms csg_ms total_ms cells_visited
json "'\n'.join('%-10s %12.2f %12.2f %10.2f %10.2f %14d' % (o['op'], o['contour_a_seconds']*1e3, o['contour_b_seconds']*1e3, o['csg_seconds']*1e3, o['seconds']*1e3, o['cells_visited']) for o in d['ops'])" < $OUT/cad_tool.json
json "'result: %d PICs, %d triangles, %s' % (d['pics'], d['triangles'], 'closed manifold' if d['topology']['manifold'] else 'NOT manifold')" < $OUT/cad_tool.json

echo
echo "== Carved slab (paper Figure 10): slab minus a dimple, a groove and a V-notch =="
"$PIC" prim box --size 0.8,0.5,0.16 --center 0.5,0.5,0.5 --cube $CUBE -o $OUT/slab.pic >/dev/null
"$PIC" prim sphere --radius 0.12 --center 0.3,0.5,0.6 --cube $CUBE -o $OUT/dimple.pic >/dev/null
"$PIC" prim cylinder --radius 0.05 --height 0.7 --axis x --center 0.5,0.35,0.58 --cube $CUBE -o $OUT/groove.pic >/dev/null
"$PIC" prim box --size 0.12,0.7,0.12 --center 0.72,0.5,0.58 --rotate 0,1,0,45 --cube $CUBE -o $OUT/notch.pic >/dev/null
"$PIC" csg $OUT/slab.pic subtract $OUT/dimple.pic subtract $OUT/groove.pic subtract $OUT/notch.pic \
  -o $OUT/slab_carved.pic --mesh $OUT/slab_carved.obj --json > $OUT/slab.json
json "'\n'.join('%-10s %8.2f ms  %6d cells visited' % (o['op'], o['seconds']*1e3, o['cells_visited']) for o in d['ops'])" < $OUT/slab.json
json "'result: %d PICs, %d triangles, %s' % (d['pics'], d['triangles'], 'closed manifold' if d['topology']['manifold'] else 'NOT manifold')" < $OUT/slab.json

echo
echo "== Pictures =="
"$PIC" render $OUT/fandisk.pic -o $OUT/fandisk.png --octree --points --size 800,800
"$PIC" render $OUT/cad_tool.pic -o $OUT/cad_tool.png --size 800,800
"$PIC" render $OUT/slab_carved.pic -o $OUT/slab_carved.png --octree --points --size 800,800
"$PIC" view $OUT/cad_tool.pic -o $OUT/cad_tool.html
ls $OUT/*.png $OUT/*.html
