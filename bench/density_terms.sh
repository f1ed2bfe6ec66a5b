#!/usr/bin/env bash
# Which terms and ridge the density's default weights should be fitted with: `terrapolis calibrate`
# on the shared regions (bench/realism_regions.sh) for each variant below, every region scored by the
# weights fitted on the nine others (leave one region out). Prints, per variant, the mean held-out
# AUC (plain and population-weighted), how many regions beat their best single-factor baseline
# (minus the elevation, minus the slope, nearness to water), how many meet the issue's bar (>= 0.75
# and above it), the mean in-sample AUC (not a criterion), each region's held-out AUC and the weights
# fitted on all the regions (docs/benchmarks.md, "Held-out skill of the terrain terms").
# With --models: the same table for the default logistic fit against gradient-boosted trees
# (calibrate --model boosted) of several sizes (docs/benchmarks.md, "A boosted density model").
# Usage: bench/density_terms.sh [--models] [TERRAPOLIS] [DEMS_DIR] [PLACES_DIR] [KEEP_DIR]
set -euo pipefail
models=false
if [[ ${1:-} == --models ]]; then models=true; shift; fi
source "$(dirname "$0")/realism_regions.sh" "$@"  # TP, DEMS, PLACES, SRC, OUT (and cd there), the regions

four=altitude,slope,coast_near,position_5km
eight=coast,hydrometry,plateau,plain,altitude,slope,coast_near,river_near
variants=(  # label|calibrate options
  "eight terms (the default before 2026-12-02)|--terms $eight"
  "all ten terms|"
  "all ten terms, ridge 0.1|--ridge 0.1"
  "four: $four|--terms $four"
  "four + river_near|--terms $four,river_near"
  "four + hydrometry|--terms $four,hydrometry"
  "four + river_near, hydrometry|--terms $four,river_near,hydrometry"
  "four + position_1km|--terms $four,position_1km"
  "four + plain|--terms $four,plain"
  "four + coast|--terms $four,coast"
  "four + plateau|--terms $four,plateau"
  "four - coast_near|--terms altitude,slope,position_5km"
  "four, ridge 0|--terms $four --ridge 0"
  "four, ridge 0.01|--terms $four --ridge 0.01"
  "four, ridge 0.1 (the default)|--terms $four --ridge 0.1"
  "four, ridge 0.3|--terms $four --ridge 0.3"
  "four, ridge 1|--terms $four --ridge 1"
  "four + river_near, ridge 0.1|--terms $four,river_near --ridge 0.1"
  "four + hydrometry, ridge 0.1|--terms $four,hydrometry --ridge 0.1"
  "four + position_1km, ridge 0.1|--terms $four,position_1km --ridge 0.1"
)
if $models; then
  variants=(
    "logistic, four terms, ridge 0.1 (the default)|--terms $four --ridge 0.1"
    "boosted, ten terms, 200 trees of depth 3|--model boosted --depth 3 --trees 200 --min-leaf-weight 1"
    "boosted, ten terms, 100 stumps (depth 1)|--model boosted --depth 1 --trees 100 --min-leaf-weight 1"
    "boosted, ten terms, 100 trees of depth 2, leaf weight 20 (calibrate's defaults)|--model boosted"
    "boosted, ten terms, 300 trees of depth 2, rate 0.03, leaf weight 20|--model boosted --depth 2 --trees 300 --learning-rate 0.03 --min-leaf-weight 20"
    "boosted, four terms, 100 stumps|--model boosted --terms $four --depth 1 --trees 100 --min-leaf-weight 1"
    "boosted, four terms, 100 trees of depth 2|--model boosted --terms $four --depth 2 --trees 100 --min-leaf-weight 1"
    "boosted, four terms, 100 trees of depth 2, leaf weight 20|--model boosted --terms $four --depth 2 --trees 100 --min-leaf-weight 20"
  )
fi
for k in "${!variants[@]}"; do
  IFS='|' read -r label options <<< "${variants[$k]}"
  # shellcheck disable=SC2086  # the options are words
  "$TP" --quiet calibrate "${dems[@]}" --settlements "${places[@]}" "${scenarios[@]}" $options --report "v$k.json" > /dev/null
  echo "$label" > "v$k.label"
done
/usr/bin/python3 - "${#variants[@]}" <<'PY'
import json, sys
print("| variant | mean held-out AUC | population-weighted | above best baseline | bar (>= 0.75 and above) | in-sample | per region |")
print("|---|---|---|---|---|---|---|")
weights = []
for k in range(int(sys.argv[1])):
    label = open(f"v{k}.label").read().strip()
    rep = json.load(open(f"v{k}.json"))
    regs = rep["regions"]
    held = [r["held_out_region"]["auc"] for r in regs]
    weighted = [r["held_out_region"]["weighted_auc"] for r in regs]
    base = [max(v["auc"] for v in r["baselines"].values()) for r in regs]
    above = sum(h > b for h, b in zip(held, base))
    bar = sum(h > b and h >= 0.75 for h, b in zip(held, base))
    fit = sum(r["fitted_in_sample"]["auc"] for r in regs) / len(regs)
    print(f"| {label} | {sum(held) / len(held):.4f} | {sum(weighted) / len(weighted):.4f} | {above} | {bar} | {fit:.4f} | "
          + " ".join(f"{h:.3f}" for h in held) + " |")
    if rep.get("model") != "boosted":  # a boosted report's weights are its logistic comparison's
        weights.append((label, {t: v for t, v in rep["weights"].items() if v}))
print("\nregions:", ", ".join(r["region"] for r in regs))
print("best baseline:", " ".join(f"{b:.3f}" for b in base))
for label, w in weights:
    print(f"weights, {label}: {json.dumps(w)}")
PY
