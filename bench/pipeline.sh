#!/usr/bin/env bash
# Times whole scenario runs (`terrapolis run`): the default scenario on the bundled Cap Corse DEM
# and the same scenario on real tiles of ../shared/dems, with the share of each stage.
# Prints, per DEM, the median over RUNS runs of the whole process's wall time and peak memory
# (/usr/bin/time) and of each stage's wall time (run.json). No peer tool runs this pipeline.
# Usage: bench/pipeline.sh [TERRAPOLIS_BIN] [RUNS]   (run from the repository root; THREADS=2)
set -euo pipefail
bin=${1:-build/src/cli/terrapolis}
runs=${2:-3}
threads=${THREADS:-2}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
dems=(sample_dems/gebco2022_15s_north_corsica_capcorse.asc ${EXTRA_DEMS:-../shared/dems/gebco2022_15s_la_palma.asc ../shared/dems/N47E009.hgt ../shared/dems/N57E011.hgt})

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

printf '%-44s %8s %8s  %s\n' dem wall_s peak_MB "stages (median s): terrain hydro density sites network roads"
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
  for k in 1 2 3 4 5 6; do stages+=" $(cut -d' ' -f$k "$tmp/stages" | median)"; done
  printf '%-44s %8s %8s  %s\n' "$(basename "$dem")" "$(median < "$tmp/wall")" "$(median < "$tmp/mem")" "$stages"
  # Network quality of the last run: circuity (road length over the geodesic distance of its ends;
  # real regional networks: about 1.2-1.4, Ballou, Rahardja & Sakai 2002, Transp. Res. A) per link
  # and for links of 10 km or more, and roads whose steepest step passes the 15 deg (26.8 %) threshold.
  /usr/bin/python3 - "$tmp/run/roads.geojson" <<'PY' || true
import json, math, sys
def geod(a, b):  # haversine on the mean Earth radius (the ends are lon/lat on the SRTM and GEBCO tiles)
    p1, p2 = math.radians(a[1]), math.radians(b[1]); dl = math.radians(b[0] - a[0])
    h = math.sin((p2 - p1) / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * 6371008.8 * math.asin(math.sqrt(h))
f = [x for x in json.load(open(sys.argv[1]))['features'] if x['properties']['router'] == 'galin']
c = sorted(x['properties']['length_m'] / d for x in f if (d := geod(x['geometry']['coordinates'][0], x['geometry']['coordinates'][-1])) > 0)
c10 = sorted(x['properties']['length_m'] / d for x in f if (d := geod(x['geometry']['coordinates'][0], x['geometry']['coordinates'][-1])) >= 1e4)
q = lambda v, p: v[min(len(v) - 1, int(p * len(v)))] if v else float('nan')
km = sum(x['properties']['length_m'] for x in f) / 1000
steep = sum(1 for x in f if x['properties']['max_grade_pct'] > 26.8 + 0.05)
print('  network: %.0f km, circuity median %.2f p90 %.2f (links >= 10 km: %d, median %.2f p90 %.2f), roads over 26.8 %%: %d' %
      (km, q(c, .5), q(c, .9), len(c10), q(c10, .5), q(c10, .9), steep))
PY
  # The last run's roads: count, links not routed within roads.max_seconds, lakes the DEM flattens.
  /usr/bin/python3 -c "import json; r = json.load(open('$tmp/run/run.json'))['summary'].get('roads', {}); print('  roads:', {k: r.get(k) for k in ('roads', 'failed', 'not_routed_budget', 'flat_lakes', 'flat_lake_km2', 'length_km')})"
done
