#!/usr/bin/env bash
# Tile engine benchmark: `terrapolis hydro` whole-grid vs tile by tile (--tile-size, --memory-limit)
# on the shared SRTM tiles: wall and CPU time (medians), peak resident memory, and a check that
# the tiled outputs hold the whole-grid cells.
# Run from the repository root: bench/scale.sh [path/to/terrapolis] [runs]
# Needs GNU time (/usr/bin/time), gdal-bin, python3; the DEMs in ../shared/dems.
# SPDX-License-Identifier: MIT
set -euo pipefail
bin=$(realpath "${1:-build/src/cli/terrapolis}")
runs=${2:-3}
dems=(${BENCH_DEMS:-../shared/dems/N47E009.hgt ../shared/dems/S46W066.hgt})
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
outputs=filled,flowdir,accumulation

# run LABEL CMD...: median wall and CPU seconds and the largest peak resident MB over $runs runs.
run() {
  local label=$1; shift
  local log=$work/time.log
  : >"$work/times"
  for _ in $(seq "$runs"); do
    rm -rf "$work/out"
    /usr/bin/time -f "%e %U %S %M" -o "$log" "$@" >/dev/null 2>"$work/stderr" || { cat "$work/stderr"; exit 1; }
    cat "$log" >>"$work/times"
  done
  python3 - "$label" "$work/times" <<'PY'
import statistics, sys
rows = [list(map(float, l.split())) for l in open(sys.argv[2]) if l.strip()]
wall = statistics.median(r[0] for r in rows)
cpu = statistics.median(r[1] + r[2] for r in rows)
peak = max(r[3] for r in rows) / 1024
print(f"  {sys.argv[1]:<40} wall {wall:7.2f} s  cpu {cpu:7.2f} s  peak {peak:7.0f} MB")
PY
}

same_cells() {  # raw copies compared byte for byte
  rm -f "$work"/[ab].*
  GDAL_PAM_ENABLED=NO gdal_translate -q -of ENVI "$1" "$work/a.bin"
  GDAL_PAM_ENABLED=NO gdal_translate -q -of ENVI "$2" "$work/b.bin"
  if cmp -s "$work/a.bin" "$work/b.bin"; then echo "    $(basename "$2"): same cells"; else echo "    $(basename "$2"): DIFFERENT"; fi
}

for dem in "${dems[@]}"; do
  name=$(basename "$dem" .hgt)
  size=$(gdalinfo "$dem" | sed -n 's/^Size is //p')
  echo "$name ($size cells), $runs runs, $(nproc) cores"
  sea=()
  [[ $name == S46W066 ]] && sea=(--sea-level 0)
  run "whole grid" "$bin" -q hydro "$dem" "$work/out" --outputs $outputs "${sea[@]}"
  "$bin" -q hydro "$dem" "$work/whole" --outputs $outputs "${sea[@]}" --overwrite
  IFS=";" read -ra options <<<"${BENCH_OPTIONS:---tile-size 1201;--tile-size 600;--tile-size 300;--memory-limit 64;--memory-limit 32}"
  for option in "${options[@]}"; do
    run "tiled $option" "$bin" -q hydro "$dem" "$work/out" "${sea[@]}" $option
    "$bin" -v hydro "$dem" "$work/tiled" "${sea[@]}" $option --overwrite 2>&1 | grep "^tiles:" | sed 's/^/    /'
    for o in filled flowdir accumulation; do same_cells "$work/whole/$o.tif" "$work/tiled/$o.vrt"; done
  done
done
