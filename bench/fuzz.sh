#!/usr/bin/env bash
# Runs each fuzz harness under libFuzzer (clang, AddressSanitizer + UBSan) for a given time.
# Usage: bench/fuzz.sh [SECONDS_PER_HARNESS (default 3600)] [HARNESS...]   harnesses: scenario raster vector
# Builds the harnesses alone in build-fuzz/ (needs clang: scripts/setup --fuzz), starts each from
# tests/fuzz/corpus/<harness>/ into build-fuzz/corpus/<harness>/ (the repo's corpus is not changed),
# one harness at a time in one process, and prints executions and failures per harness. Failing
# inputs (crash, timeout, out-of-memory) are kept as build-fuzz/<harness>-{crash,timeout,oom}-*;
# once fixed, copy them into tests/fuzz/corpus/<harness>/. Slow inputs (slow-unit-*) are not failures.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-3600}
shift || true
harnesses=("$@")
[[ ${#harnesses[@]} -gt 0 ]] || harnesses=(scenario raster vector)
command -v clang++ >/dev/null || { echo "bench/fuzz.sh: clang++ not found (scripts/setup --fuzz installs it)" >&2; exit 2; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTERRAPOLIS_FUZZ=ON \
  -DTERRAPOLIS_BENCH=OFF >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target "${harnesses[@]/#/fuzz_}"
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
for h in "${harnesses[@]}"; do
  mkdir -p "build-fuzz/corpus/$h"
  log=build-fuzz/fuzz-$h.log
  rc=0
  # -rss_limit_mb: GDAL's caches stay under it; larger grids are refused by the reader's memory check.
  rm -f build-fuzz/"$h"-{crash,timeout,oom,leak,slow-unit}-*
  # No -jobs: with it libFuzzer forks a worker that logs to ./fuzz-N.log and its exit code is lost.
  build-fuzz/tests/fuzz/fuzz_$h "build-fuzz/corpus/$h" "tests/fuzz/corpus/$h" -max_total_time="$seconds" \
    -rss_limit_mb=4096 -max_len=65536 -timeout=60 -artifact_prefix="build-fuzz/$h-" -print_final_stats=1 >"$log" 2>&1 || rc=$?
  runs=$(grep -Eo 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -Eo '[0-9]+$' | tail -1)
  failures=$(find build-fuzz -maxdepth 1 \( -name "$h-crash-*" -o -name "$h-timeout-*" -o -name "$h-oom-*" -o -name "$h-leak-*" \) | wc -l)
  slow=$(find build-fuzz -maxdepth 1 -name "$h-slow-unit-*" | wc -l)
  echo "fuzz $h: ${seconds} s, ${runs:-?} executions, $failures failing inputs, $slow slow inputs, exit $rc (log $log)"
  [[ $rc -eq 0 && $failures -eq 0 ]] || status=1
done
exit $status
