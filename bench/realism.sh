#!/usr/bin/env bash
# Realism of the settlements against real places (GeoNames, CC BY 4.0) on every shared region with
# places: the density's skill after calibration on the other regions (leave one region out, with the
# options the schema's default weights were fitted with: bench/realism_regions.sh), the
# counts, largest and rank-size exponent with sites.population set to the reference total (the
# default: settlements at most land / hexagon(sites.spacing_km)), the ten largest real places near a generated top-10 settlement
# against random land points, and the default run's total on the bundled DEM. Prints one table
# (docs/benchmarks.md, "Settlements").
# Usage: bench/realism.sh [TERRAPOLIS] [DEMS_DIR] [PLACES_DIR] [KEEP_DIR]  (KEEP_DIR: keep the runs there;
# REALISM_SET=sites.spacing_km=0: one more --set for the region runs, e.g. the rank-size law alone)
set -euo pipefail
source "$(dirname "$0")/realism_regions.sh" "$@"  # TP, DEMS, PLACES, SRC, OUT (and cd there), the regions

echo "== calibration, leave one region out ($(date -u +%F))"
/usr/bin/time -f "calibrate: %e s, %M kB" "$TP" --quiet calibrate "${dems[@]}" --settlements "${places[@]}" "${scenarios[@]}" \
  "${default_fit[@]}" --report calibration.json --fragment fitted.json

echo "== runs with sites.population = the reference total, held-out weights"
for k in "${!regions[@]}"; do
  f=${regions[$k]}
  name=${f%.*}
  scen=$(region_scenario "$f")
  read -r total weights < <(/usr/bin/python3 - calibration.json "$name" <<'PY'
import json, sys
r = next(x for x in json.load(open(sys.argv[1]))["regions"] if x["region"] == sys.argv[2])
print(int(r["settlements"]["total"]), json.dumps(r["held_out_weights"], separators=(",", ":")))
PY
)
  # The reference total is the people of the places themselves: all of it settled (urban_share 1).
  sets=(--set dem="\"$DEMS/$f\"" --set sites.population="$total" --set sites.urban_share=1 --set sites.reference="\"$PLACES/$name.geojson\""
        --set density.weights="$weights")
  "$TP" --quiet run "$scen" -o "run_$name" --until sites "${sets[@]}" ${REALISM_SET:+--set "$REALISM_SET"}
done
# The default run on the bundled DEM: no population given.
"$TP" --quiet run -o run_default --until sites --set dem="\"$SRC/sample_dems/gebco2022_15s_north_corsica_capcorse.asc\"" \
  --set sites.reference="\"$SRC/tests/data/geonames_capcorse.geojson\""

/usr/bin/python3 - calibration.json "${regions[@]}" <<'PY'
import json, sys
cal = {r["region"]: r for r in json.load(open(sys.argv[1]))["regions"]}
print("| region | places | AUC held out (weighted) | best baseline | AUC in-region | thesis AUC | count gen/ref | largest gen/ref | q gen / ref | top-10 within 10 km (random) |")
print("|---|---|---|---|---|---|---|---|---|---|")
ok = {"count": 0, "largest": 0, "q": 0, "auc": 0}


def bars(m, tally):
    """Counts the bars `m` meets into `tally`; returns its count, largest and q ratios for the table."""
    cr = m["count"]["generated"] / max(1, m["count"]["reference"])
    lr = m["largest"]["generated"] / max(1, m["largest"]["reference"])
    qg, qr = m["rank_size_exponent"]["generated"], m["rank_size_exponent"]["reference"]
    tally["count"] += 1 / 1.5 <= cr <= 1.5
    tally["largest"] += 0.5 <= lr <= 2
    tally["q"] += qg is not None and qr is not None and abs(qg - qr) <= 0.25
    return qg if qg is None else round(qg, 2), qr if qr is None else round(qr, 2)


for f in sys.argv[2:]:
    name = f.rsplit(".", 1)[0]
    c = cal[name]
    m = json.load(open(f"run_{name}/run.json"))["summary"]["realism"]
    base = max(v["auc"] for v in c["baselines"].values())
    best = max(c["baselines"], key=lambda k: c["baselines"][k]["auc"])
    held = c["held_out_region"]
    qg, qr = bars(m, ok)
    ok["auc"] += held["auc"] >= 0.75 and held["auc"] > base
    print(f"| {name} | {c['places']} | {held['auc']:.3f} ({held['weighted_auc']:.3f}) | {base:.3f} ({best}) | {c['fitted_in_sample']['auc']:.3f} "
          f"| {c['belhadj2007']['auc']:.3f} | {m['count']['generated']}/{m['count']['reference']} "
          f"| {m['largest']['generated']:.0f}/{m['largest']['reference']:.0f} "
          f"| {qg} / {qr} | {m['top10']['within_10km']} ({m['top10']['random_within_10km']:.1f}) |")
n = len(sys.argv) - 2
print(f"\nregions meeting each bar (of {n}): count within x1.5 {ok['count']}, largest within x2 {ok['largest']}, "
      f"rank-size exponent within 0.25 {ok['q']}, held-out AUC >= 0.75 and above the best baseline {ok['auc']}")
d = json.load(open("run_default/run.json"))["summary"]
r = d["realism"]
print(f"default run on the bundled DEM: {d['sites']['target_population']:.0f} people ({d['sites']['population_source']}), "
      f"{d['sites'].get('settled_population', 0):.0f} settled, sizes {d['sites'].get('sizes')} (exponent {d['sites'].get('sizes_exponent', 0):.2f}); "
      f"reference {r['total']['reference']:.0f}: ratio {r['total']['ratio']}; {r['count']['generated']} settlements of 1,000+ for "
      f"{r['count']['reference']}, largest {r['largest']['generated']:.0f} for {r['largest']['reference']:.0f}")
print("fitted weights (all regions):", json.dumps(json.load(open("fitted.json"))["density"]["weights"]))
PY
