#!/usr/bin/env bash
# End-to-end benchmarks (`make bench`): bench/run.sh [BUILD_DIR]
#
# Needs BUILD_DIR configured with -DPIC_BUILD_BENCH=ON and built. Prints a report and writes
#   out/bench/results.json   every measured number, with the commands that produced it
#   out/bench/results.md     the same as markdown tables
# Peers (OpenVDB: BUILD_DIR/bench/pic_vdb_peer; Manifold: node + npm manifold-3d in bench/) are
# optional: a missing one is reported as "skipped: <why>". Individual failures are reported,
# never fatal: the script exits 0 unless the pic binary itself is missing.
#
# Knobs (environment): PIC_BENCH_REPS (5) runs per timing, median reported;
# PIC_BENCH_STROKES (1000); PIC_BENCH_VDB_VOXELS ("1/1024 1/2048"); PIC_BENCH_SUBDIV (4:
# spot 4-split 4 times = 1.5 M triangles); PIC_BENCH_MICRO (1: run pic_bench);
# PIC_BENCH_TIMEOUT (600 s per command); PIC_BENCH_ONLY (sections, e.g. "inputs,cad,thingi"; see
# bench/run.py); PIC_MFBENCH (native Manifold's mfbench), THINGI_DIR (the Thingi10K pair).
set -uo pipefail
BUILD=${1:-build}
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac

if [[ ! -x "$BUILD/pic" ]]; then
  echo "bench: $BUILD/pic not found; configure with -DPIC_BUILD_BENCH=ON and build first (make bench)" >&2
  exit 1
fi
if ! command -v python3 >/dev/null; then
  echo "bench: skipped: python3 is needed to drive the benchmarks" >&2
  exit 0
fi

# Manifold peer: install the pinned npm package next to the script (bench/node_modules, ignored
# by git) when node and npm are present and it is not installed yet.
if command -v node >/dev/null && command -v npm >/dev/null && [[ ! -d bench/node_modules/manifold-3d ]]; then
  echo "bench: installing manifold-3d (npm ci in bench/)"
  (cd bench && npm ci --no-audit --no-fund --loglevel=error >/dev/null 2>&1) ||
    echo "bench: npm ci failed; the Manifold peer will be skipped"
fi

python3 bench/run.py "$BUILD" || echo "bench: the driver failed (see above); partial results may be in out/bench/"
exit 0
