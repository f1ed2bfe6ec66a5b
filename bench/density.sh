#!/usr/bin/env bash
# Times the density stage (hydrometry excluded: its weight is 0) on two real SRTM tiles and its
# growth with the ring's outer radius, which must stay flat (radius-independent disc sums).
# Prints the median over RUNS runs of the model's wall time and processor time (all threads; from
# `terrapolis -v`) and of the whole command's wall time (reading, model, writing five GeoTIFFs).
# Processor time is the steadier figure on a loaded machine. No peer tool computes this model.
# A third grid is the worst case: N47E009 resampled (bilinear) to 3601 x 3601, 13 M cells that are
# all land (S46W066 is 98.6 % sea, which the model skips).
# Usage: bench/density.sh [TERRAPOLIS_BIN] [RUNS]   (run from the repository root; THREADS=2)
set -euo pipefail
runs=${2:-5}
# shellcheck source=bench/timing_setup.sh
source "$(dirname "$0")/timing_setup.sh" "$@"  # bin, threads, tmp (removed at exit), median
gdal_translate -q -outsize 3601 3601 -r bilinear ../shared/dems/N47E009.hgt "$tmp/N47E009_3601_land.tif"
dems=(../shared/dems/S46W066.hgt ../shared/dems/N47E009.hgt "$tmp/N47E009_3601_land.tif")

printf '%-22s %8s %8s %10s %10s %10s %10s\n' dem r_max_m r_min_m model_s model_cpu_s command_s cells
for dem in "${dems[@]}"; do
  [[ -f $dem ]] || { echo "missing $dem" >&2; exit 1; }
  cells=$(gdalinfo "$dem" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 \2/p' | awk '{ print $1 * $2 }')
  for r_max in 500 1000 2000 5000 10000; do
    model=() cpu=() total=()
    for ((i = 0; i < runs; ++i)); do
      start=$(date +%s.%N)
      log=$("$bin" -v --progress none --threads "$threads" density "$dem" "$tmp/out" --weights 1,0,1.5,0.5 \
        --r-min 250 --r-max "$r_max" --overwrite 2>&1)
      end=$(date +%s.%N)
      model+=("$(sed -n 's/.*model \([0-9.]*\) s.*/\1/p' <<< "$log")")
      cpu+=("$(sed -n 's/.*(cpu \([0-9.]*\) s).*/\1/p' <<< "$log")")
      total+=("$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.3f", b - a }')")
    done
    printf '%-22s %8s %8s %10s %10s %10s %10s\n' "$(basename "$dem")" "$r_max" 250 \
      "$(printf '%s\n' "${model[@]}" | median)" "$(printf '%s\n' "${cpu[@]}" | median)" \
      "$(printf '%s\n' "${total[@]}" | median)" "$cells"
  done
done
