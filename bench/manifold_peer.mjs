// The Manifold mesh-boolean library (npm manifold-3d, WebAssembly) as a peer of PIC's CSG, on
// the same OBJ inputs, evaluated left to right:
//
//   node bench/manifold_peer.mjs --out OUT.obj [--repeat N] A.obj union B.obj difference C.obj ...
//
// Prints one JSON object. Each boolean is forced to evaluate (numTri) before the next starts.
// The chain is run N times (default 20) on the same converted inputs: ops[k].ms_first is the
// first (cold) run, ops[k].ms the best (warm) run; chain_ms is the best whole chain.
// convert_ms (OBJ arrays -> Manifold, incl. merge and validity checks) and export_ms
// (Manifold -> mesh arrays) complete the end-to-end time end_to_end_ms = convert + chain + export.
// The result is written as OBJ with every float32 coordinate printed exactly.
//
// With --sculpt CENTRES.txt (lines `x y z r`, as pic_sculpt --centres writes them), the chain's
// result is then sculpted: one sphere (--segments, default 32) subtracted per line, in order,
// each forced to evaluate; sculpt.stroke_ms summarises those subtractions (the sphere's own
// construction is sculpt.tool_ms), and the sculpted solid is what OUT.obj gets.
import Module from 'manifold-3d';
import { readFileSync, openSync, writeSync, closeSync } from 'node:fs';

const USAGE = 'usage: node manifold_peer.mjs --out OUT.obj [--repeat N] A.obj (union|difference|intersection) B.obj ...';
const args = process.argv.slice(2);
let out = null;
let repeat = 20;
let sculptFile = null;
let segments = 32;
const chain = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--out') out = args[++i];
  else if (args[i] === '--repeat') repeat = Math.max(1, parseInt(args[++i], 10) || 1);
  else if (args[i] === '--sculpt') sculptFile = args[++i];
  else if (args[i] === '--segments') segments = Math.max(3, parseInt(args[++i], 10) || 32);
  else chain.push(args[i]);
}
if (!out || chain.length < (sculptFile ? 1 : 3) || chain.length % 2 === 0) { console.error(USAGE); process.exit(1); }
for (let k = 1; k < chain.length; k += 2)
  if (!['union', 'difference', 'intersection'].includes(chain[k])) { console.error(`unknown op ${chain[k]}\n${USAGE}`); process.exit(1); }

function readOBJ(path) {
  const pos = [];
  const tri = [];
  for (const raw of readFileSync(path, 'utf8').split('\n')) {
    const line = raw.trim();
    if (line.startsWith('v ') || line.startsWith('v\t')) {
      const p = line.slice(2).trim().split(/\s+/);
      pos.push(+p[0], +p[1], +p[2]);
    } else if (line.startsWith('f ') || line.startsWith('f\t')) {
      const nv = pos.length / 3;
      const idx = line.slice(2).trim().split(/\s+/).map((t) => {
        const i = parseInt(t, 10);
        return i > 0 ? i - 1 : nv + i;
      });
      for (let k = 1; k + 1 < idx.length; k++) tri.push(idx[0], idx[k], idx[k + 1]);
    }
  }
  return { pos, tri };
}

function writeOBJ(path, pos, tri, numProp) {
  const fd = openSync(path, 'w');
  const lines = [];
  for (let i = 0; i < pos.length; i += numProp) lines.push(`v ${pos[i]} ${pos[i + 1]} ${pos[i + 2]}`);
  for (let t = 0; t < tri.length; t += 3) lines.push(`f ${tri[t] + 1} ${tri[t + 1] + 1} ${tri[t + 2] + 1}`);
  writeSync(fd, lines.join('\n') + '\n');
  closeSync(fd);
}

const now = () => performance.now();
try {
  const t0 = now();
  const wasm = await Module();
  wasm.setup();
  const initMs = now() - t0;

  const inputs = [];
  const solids = [];
  let convertMs = 0;
  for (let k = 0; k < chain.length; k += 2) {
    const t1 = now();
    const raw = readOBJ(chain[k]);
    const t2 = now();
    const mesh = new wasm.Mesh({ numProp: 3, vertProperties: Float32Array.from(raw.pos), triVerts: Uint32Array.from(raw.tri) });
    mesh.merge();
    const m = new wasm.Manifold(mesh);
    const st = m.status();
    if (st !== 'NoError' && st !== 0 && st?.value !== 0) throw new Error(`${chain[k]}: not a manifold (${JSON.stringify(st)})`);
    const t3 = now();
    convertMs += t3 - t2;
    inputs.push({ file: chain[k], triangles: raw.tri.length / 3, read_ms: t2 - t1, convert_ms: t3 - t2 });
    solids.push(m);
  }

  const ops = [];
  for (let k = 1; k < chain.length; k += 2) ops.push({ op: chain[k], operand: chain[k + 1], ms: Infinity, ms_first: 0, triangles: 0 });
  let chainMs = Infinity;
  let result = null;
  for (let rep = 0; rep < repeat; rep++) {
    const made = [];
    let acc = solids[0];
    const tc = now();
    for (let i = 0; i < ops.length; i++) {
      const o = ops[i];
      const b = solids[i + 1];
      const ta = now();
      const r = o.op === 'union' ? acc.add(b) : o.op === 'difference' ? acc.subtract(b) : acc.intersect(b);
      o.triangles = r.numTri();  // forces the lazy CSG tree to evaluate
      const dt = now() - ta;
      if (rep === 0) o.ms_first = dt;
      o.ms = Math.min(o.ms, dt);
      made.push(r);
      acc = r;
    }
    chainMs = Math.min(chainMs, now() - tc);
    if (rep + 1 < repeat) for (const m of made) m.delete();
    else result = acc;
  }

  if (result === null) result = solids[0];  // no Booleans before the sculpting
  let sculpt = null;
  if (sculptFile) {
    const strokes = [], tools = [];
    for (const line of readFileSync(sculptFile, 'utf8').split('\n')) {
      const v = line.trim().split(/\s+/).map(Number);
      if (v.length !== 4 || v.some((x) => !Number.isFinite(x))) continue;
      const ta = now();
      const tool = wasm.Manifold.sphere(v[3], segments).translate([v[0], v[1], v[2]]);
      tool.numTri();
      const tb = now();
      const next = result.subtract(tool);
      next.numTri();
      strokes.push(now() - tb);
      tools.push(tb - ta);
      tool.delete();
      result.delete();
      result = next;
    }
    const summary = (xs) => {
      const s = [...xs].sort((a, b) => a - b);
      const at = (q) => s.length ? s[Math.min(s.length - 1, Math.floor(q * (s.length - 1) + 0.5))] : 0;
      return { median: at(0.5), p95: at(0.95), mean: s.reduce((a, b) => a + b, 0) / Math.max(1, s.length), max: at(1) };
    };
    sculpt = { strokes: strokes.length, segments, stroke_ms: summary(strokes), tool_ms: summary(tools) };
  }

  const te = now();
  const mesh = result.getMesh();
  const exportMs = now() - te;
  const tw = now();
  writeOBJ(out, mesh.vertProperties, mesh.triVerts, mesh.numProp);
  const writeMs = now() - tw;

  console.log(JSON.stringify({
    system: 'manifold',
    manifold_version: JSON.parse(readFileSync(new URL('./node_modules/manifold-3d/package.json', import.meta.url))).version,
    repeat,
    init_ms: initMs,
    inputs,
    convert_ms: convertMs,
    ops,
    chain_ms: chainMs,
    export_ms: exportMs,
    end_to_end_ms: convertMs + chainMs + exportMs,
    write_ms: writeMs,
    triangles: result.numTri(),
    vertices: result.numVert(),
    volume: result.volume(),
    genus: result.genus(),
    peak_rss_bytes: process.resourceUsage().maxRSS * 1024,
    sculpt,
    out,
  }));
} catch (e) {
  console.error(`manifold_peer: error: ${e.message}`);
  process.exit(2);
}
