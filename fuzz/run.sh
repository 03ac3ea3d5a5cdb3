#!/usr/bin/env bash
# Runs the libFuzzer harnesses for a fixed number of executions each (docs/reliability.md).
#   fuzz/run.sh BUILD_DIR [RUNS] [HARNESS ...]     (default RUNS=1000000; glTF gets RUNS/10)
# The evolving corpus lives in BUILD_DIR/corpus/<harness> (seeded from fuzz/corpus/<harness>);
# crashes, timeouts and out-of-memory inputs land in BUILD_DIR/findings/. Exit 1 on any finding.
set -uo pipefail
build=${1:?usage: fuzz/run.sh BUILD_DIR [RUNS] [HARNESS ...]}
runs=${2:-1000000}
shift $(( $# >= 2 ? 2 : 1 ))
harnesses=("$@")
(( ${#harnesses[@]} )) || harnesses=(pic obj stl ply off gltf)
src="$(cd "$(dirname "$0")" && pwd)"
mkdir -p "$build/findings"
status=0
for h in "${harnesses[@]}"; do
  n=$runs
  extra=()
  if [[ $h == gltf ]]; then
    n=$(( runs / 10 ))
    extra=(-detect_leaks=0)  # assimp itself leaks a few bytes per glTF import (not PIC's memory)
  fi
  corpus="$build/corpus/$h"
  mkdir -p "$corpus"
  cp -n "$src/corpus/$h/"* "$corpus/" 2>/dev/null || true
  log="$build/findings/$h.log"
  # -max_total_time is only a safety net: the run is meant to end by -runs.
  "$build/fuzz/fuzz_$h" -runs="$n" -max_len=4096 -timeout=10 -rss_limit_mb=2048 -max_total_time=3600 \
    -print_final_stats=1 -artifact_prefix="$build/findings/$h-" "${extra[@]}" "$corpus" >"$log" 2>&1
  rc=$?
  done_line=$(grep -E '^Done [0-9]+ runs' "$log" | tail -1)
  execs=$(grep -E 'stat::number_of_executed_units' "$log" | awk '{print $2}')
  line="fuzz $h: rc=$rc executions=${execs:-?} ${done_line:-} corpus=$(ls "$corpus" | wc -l)"
  echo "$line"
  echo "$(date -u +%FT%TZ) $line" >> "$build/findings/summary.txt"
  if (( rc != 0 )); then
    status=1
    grep -E 'ERROR|SUMMARY|runtime error|Test unit written' "$log" | head -5
  fi
done
exit $status
