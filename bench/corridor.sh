#!/usr/bin/env bash
# Corridor benchmark: the time the corridors take per km of road (carriageway and earthworks
# polygons, cut and fill cross-sections, clearing), on DEMs from 10 m to 15", each road with the
# four materials; and the whole `path` process with and without --corridor (median of 3 runs).
# No peer: GRASS GIS and SAGA have no road corridor or cut-and-fill tool for a road line (GRASS
# v.buffer gives a carriageway-like buffer but no earthworks zone, volumes or side slopes).
# Usage: bench/corridor.sh [BUILD_DIR]   (run from the repository root)
set -euo pipefail
build=${1:-build}
bin=$build/src/cli/terrapolis
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

median() { sort -g | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }

bench() {  # label, DEM, path arguments...
  local label=$1 dem=$2; shift 2
  for material in sand earth stones rock; do
    "$bin" -v --progress none path "$dem" "$@" "$out/road.geojson" --corridor "$out/corridor.geojson" --material "$material" \
      --overwrite 2>"$out/log"
    local km secs
    km=$(grep -o 'galin: [0-9]* m' "$out/log" | awk '{print $2 / 1000}')
    secs=$(grep -o 'corridor: .*' "$out/log" | grep -o '[0-9.]* s$' | awk '{print $1}')
    echo "$label, $material: $km km; $(grep -o 'corridor: .*' "$out/log"); $(awk -v s="$secs" -v k="$km" 'BEGIN {printf "%.4f s per km", s / k}')"
  done
  local with=() without=()
  for _ in 1 2 3; do
    /usr/bin/time -f "%e" -o "$out/t" "$bin" -q path "$dem" "$@" "$out/plain.geojson" --overwrite
    without+=("$(cat "$out/t")")
    /usr/bin/time -f "%e" -o "$out/t" "$bin" -q path "$dem" "$@" "$out/road.geojson" --corridor "$out/corridor.geojson" --overwrite
    with+=("$(cat "$out/t")")
  done
  local a b
  a=$(printf '%s\n' "${without[@]}" | median)
  b=$(printf '%s\n' "${with[@]}" | median)
  echo "$label: whole process, median of 3: without --corridor ${a} s, with ${b} s (ratio $(awk -v a="$a" -v b="$b" 'BEGIN {printf "%.3f", b / a}'))"
}

bench "Cap Corse (GEBCO 15\", 350 x 460 m cells)" sample_dems/gebco2022_15s_north_corsica_capcorse.asc --from 9.30,42.68 --to 9.42,42.70
bench "Appenzell Alps (SRTM3, 63 x 93 m cells)" ../shared/dems/N47E009.hgt --from 9.3,47.4 --to 9.45,47.3 --no-bridges --no-tunnels
bench "Andes of Ecuador (10 m cells)" ../shared/dems/spDataLarge_ta_elev_band4.tif --crs dem --from 712967.7,9560406.76 --to 713967.7,9558806.76
