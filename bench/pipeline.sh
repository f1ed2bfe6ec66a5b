#!/usr/bin/env bash
# Times whole scenario runs (`terrapolis run`): the default scenario on the bundled Cap Corse DEM
# and the same scenario on real tiles of ../shared/dems, with the share of each stage.
# Prints, per DEM, the median over RUNS runs of the whole process's wall time and peak memory
# (/usr/bin/time) and of each stage's wall time (run.json). No peer tool runs this pipeline.
# Usage: bench/pipeline.sh [TERRAPOLIS_BIN] [RUNS]   (run from the repository root; THREADS=2)
set -euo pipefail
runs=${2:-3}
# shellcheck source=bench/timing_setup.sh
source "$(dirname "$0")/timing_setup.sh" "$@"  # bin, threads, tmp (removed at exit), median
dems=(sample_dems/gebco2022_15s_north_corsica_capcorse.asc ${EXTRA_DEMS:-../shared/dems/gebco2022_15s_la_palma.asc ../shared/dems/N47E009.hgt ../shared/dems/N57E011.hgt})

printf '%-44s %8s %8s  %s\n' dem wall_s peak_MB "stages (median s): terrain hydro density sites network roads access"
for dem in "${dems[@]}"; do
  [[ -f $dem ]] || { echo "missing $dem (skipped)" >&2; continue; }
  : > "$tmp/wall" ; : > "$tmp/mem" ; : > "$tmp/stages"
  for ((i = 0; i < runs; ++i)); do
    /usr/bin/time -f '%e %M' -o "$tmp/time" "$bin" --quiet --threads "$threads" run --set dem="$(realpath "$dem")" \
      --set outputs.preview=false -o "$tmp/run" --overwrite
    read -r wall mem < "$tmp/time"
    echo "$wall" >> "$tmp/wall"; echo $((mem / 1024)) >> "$tmp/mem"
    /usr/bin/python3 -c "import json; print(' '.join('%.3f' % t['seconds'] for t in json.load(open('$tmp/run/run.json'))['timings']))" >> "$tmp/stages"
  done
  stages=""
  for k in 1 2 3 4 5 6 7; do stages+=" $(cut -d' ' -f$k "$tmp/stages" | median)"; done
  printf '%-44s %8s %8s  %s\n' "$(basename "$dem")" "$(median < "$tmp/wall")" "$(median < "$tmp/mem")" "$stages"
  # Network quality of the last run (bench/network_quality.py: km, junctions, circuity, grades, water).
  /usr/bin/python3 bench/network_quality.py "$tmp/run" || true
  # The last run's roads: count, links not routed within roads.max_seconds; the lakes the DEM flattens.
  /usr/bin/python3 -c "import json; r = json.load(open('$tmp/run/run.json'))['summary'].get('roads', {}); h = json.load(open('$tmp/run/run.json'))['summary'].get('hydro', {}); print('  roads:', {k: r.get(k) for k in ('roads', 'failed', 'not_routed_budget', 'redundant', 'junctions', 'length_km')}, 'flat lakes:', h.get('flat_lakes'), h.get('flat_lake_km2'), 'km2')"
done
