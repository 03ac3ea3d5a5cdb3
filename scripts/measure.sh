#!/usr/bin/env bash
# The README's figures: sampling (paper Table 2 setting) and the CAD tool (paper Table 3
# setting). Medians of 5 runs. Usage: scripts/measure.sh [path/to/pic]
set -euo pipefail
PIC=${1:-build/pic}
OUT=out/measure
mkdir -p $OUT
py() { python3 -c "$1"; }

"$PIC" prim cylinder --radius 0.3 --height 0.8 --segments 128 -o $OUT/cylinder.pic --mesh $OUT/cylinder.obj >/dev/null
echo "| model | triangles | PICs | sampling s (median of 5) | bytes/PIC on disk | bytes/PIC in memory | Hausdorff (root cube) | contour |"
echo "|---|---:|---:|---:|---:|---:|---:|---|"
for m in data/fandisk.obj data/spot.obj $OUT/cylinder.obj data/cad_part.obj; do
  name=$(basename $m .obj)
  times=()
  for i in 1 2 3 4 5; do
    j=$("$PIC" sample $m -o $OUT/$name.pic --json)
    times+=("$(echo "$j" | py "import json,sys; print(json.load(sys.stdin)['seconds'])")")
  done
  med=$(printf "%s\n" "${times[@]}" | sort -g | sed -n 3p)
  info=$("$PIC" info $OUT/$name.pic --json)
  cmp=$("$PIC" compare $OUT/$name.pic $m --json)
  echo "$j|$info|$cmp|$med" | py "
import json,sys
s,i,c,med=sys.stdin.read().strip().split('|')
s,i,c=json.loads(s),json.loads(i),json.loads(c)
topo='closed, manifold' if c['topology_a']['manifold'] else ('closed' if c['topology_a']['closed'] else 'OPEN')
print('| $name | %d | %d | %.3f | %.2f | %.1f | %.2e | %s |' % (s['triangles_in'], s['pics'], float(med), i['bytes_per_pic'], i['memory_bytes']/i['pics'], c['hausdorff'], topo))"
done

echo
CUBE=0,0,0,1
"$PIC" prim box --size 0.5,0.5,0.5 --center 0.5,0.5,0.5 --cube $CUBE -o $OUT/cube.pic >/dev/null
"$PIC" prim cylinder --radius 0.15 --height 0.8 --axis z --center 0.5,0.5,0.5 --segments 64 --cube $CUBE -o $OUT/cz.pic >/dev/null
"$PIC" prim cylinder --radius 0.1 --height 0.8 --axis x --center 0.5,0.5,0.5 --segments 64 --cube $CUBE -o $OUT/cx.pic >/dev/null
"$PIC" prim cylinder --radius 0.07 --height 0.8 --axis y --center 0.5,0.5,0.5 --segments 64 --cube $CUBE -o $OUT/cy.pic >/dev/null
for i in 1 2 3 4 5; do
  "$PIC" csg $OUT/cube.pic union $OUT/cz.pic subtract $OUT/cx.pic subtract $OUT/cy.pic -o $OUT/tool.pic --json > $OUT/tool.$i.json
done
py "
import json, statistics
runs=[json.load(open('$OUT/tool.%d.json' % i)) for i in range(1,6)]
print('| CAD tool op | contour A ms | contour B ms | CSG ms | total ms | cells visited | paper total ms |')
print('|---|---:|---:|---:|---:|---:|---:|')
paper=[46,59,1635]
for k in range(3):
  med=lambda key: statistics.median(r['ops'][k][key] for r in runs)*1e3
  o=runs[0]['ops'][k]
  print('| %s | %.2f | %.2f | %.2f | %.2f | %d | %d |' % (o['op'], med('contour_a_seconds'), med('contour_b_seconds'), med('csg_seconds'), med('seconds'), o['cells_visited'], paper[k]))
print('result: %d PICs' % runs[0]['pics'])"
