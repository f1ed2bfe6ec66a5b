#!/usr/bin/env bash
# Placement backtest (issue: placement that beats chance; docs/benchmarks.md "Placement backtest"):
# on every shared region with real places (GeoNames, CC BY 4.0), the largest half of the places is
# given as sites.existing, sites.population is the real total (all settled: urban_share 1), and the
# model places the rest. Scores the share of the hidden places with a new settlement within 5 km
# and their median distance to the nearest one, against as many points drawn uniformly on the
# buildable land and in proportion to the density (100 draws each; bench/placement.py). Places
# with no buildable cell within two cells (on nodata, in a lake) are left out of both halves.
# Usage: bench/placement.sh [TERRAPOLIS] [DEMS_DIR] [PLACES_DIR] [KEEP_DIR]
# (PLACEMENT_SET="sites.x=1 sites.y=2": more --set for every region run)
set -euo pipefail
source "$(dirname "$0")/realism_regions.sh" "$@"  # TP, DEMS, PLACES, SRC, OUT (and cd there), the regions
extra=()
for s in ${PLACEMENT_SET:-}; do extra+=(--set "$s"); done

echo "== placement backtest ($(date -u +%F)) ${PLACEMENT_SET:-}"
echo "| region | places given / hidden | new settlements | hidden within 5 km: model / uniform / density-weighted | median km: model / uniform / density-weighted |"
echo "|---|---|---|---|---|"
for f in "${regions[@]}"; do
  name=${f%.*}
  # The places on the run's land (a buildable cell within two cells, as sites.existing takes them).
  "$TP" --quiet run "$(region_scenario "$f")" -o "land_$name" --until density --set dem="\"$DEMS/$f\"" --set outputs.preview=false "${extra[@]}"
  read -r total given hidden < <(/usr/bin/python3 "$SRC/bench/placement.py" split "$PLACES/$name.geojson" "land_$name/buildable.tif" \
    "given_$name.geojson" "hidden_$name.geojson")
  "$TP" --quiet run "$(region_scenario "$f")" -o "run_$name" --until sites --set dem="\"$DEMS/$f\"" --set sites.existing="\"$OUT/given_$name.geojson\"" \
    --set sites.population="$total" --set sites.urban_share=1 --set outputs.preview=false "${extra[@]}" 2> "run_$name.log" || { echo "| $name | run failed: $(tail -1 "run_$name.log") |"; continue; }
  /usr/bin/python3 "$SRC/bench/placement.py" score "run_$name" "hidden_$name.geojson" > "score_$name.json"
  /usr/bin/python3 - "$name" "$given" "score_$name.json" <<'PY'
import json, sys
name, given, s = sys.argv[1], sys.argv[2], json.load(open(sys.argv[3]))
u, d = s.get("uniform", {}), s.get("density", {})
print(f"| {name} | {given} / {s['hidden']} | {s['new']} | {s['within_5km']:.2f} / {u.get('within_5km', 0):.2f} / {d.get('within_5km', 0):.2f} "
      f"| {s['median_km']} / {u.get('median_km', '-')} / {d.get('median_km', '-')} |")
PY
done
/usr/bin/python3 - score_*.json <<'PY'
import json, sys
rows = [json.load(open(p)) for p in sys.argv[1:]]
rows = [r for r in rows if r["new"] > 0]
beat_u = sum(r["within_5km"] > r["uniform"]["within_5km"] for r in rows)
beat_d = sum(r["within_5km"] > r["density"]["within_5km"] for r in rows)
mean = lambda k, sub=None: sum((r[sub][k] if sub else r[k]) for r in rows) / len(rows)
print(f"\nregions where the model beats uniform points: {beat_u} of {len(rows)}, density-weighted points: {beat_d}; "
      f"mean share within 5 km: model {mean('within_5km'):.3f}, uniform {mean('within_5km', 'uniform'):.3f}, density {mean('within_5km', 'density'):.3f}")
PY
