# `terrapolis run` checks every stage's settings before the first stage runs (docs/pipeline.md):
# settings the schema accepts but a stage cannot use (cross-field rules) are refused at once, exit 2,
# one line naming the setting by its JSON pointer, no stage started, nothing written. The commands
# refuse the same settings naming their own flags.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
lux=$SAMPLES/terra_elev_luxembourg.tif

# refused POINTER_PATTERN --set ... : the run is refused before any stage starts.
refused() {
  local pattern=$1; shift
  expect_refused run "^terrapolis: error: \(default scenario\): $pattern" "$TP" run -o run "$@"
  [[ $(wc -l < "$WORK/stderr") -eq 1 ]] || fail "'$*': not one line, a stage started: $(cat "$WORK/stderr")"
}
refused "/density/plateau_max_m: lies below /density/plateau_min_m" --set density.plateau_min_m=900 --set density.plateau_max_m=500
refused "/water/reservoirs/0/level_m or /depth_m: the water level is required" --set 'water.reservoirs=[{"at": [9.4, 42.9]}]'
refused "/water/reservoirs/1/dam: needs /crest_m" \
  --set 'water.reservoirs=[{"at": [9.4, 42.9], "level_m": 50}, {"at": [9.4, 42.9], "dam": [[9.4, 42.9], [9.5, 42.9]]}]'
refused "/sites/r_max_m: sets the classes of /sites/quotas belhadj2007" --set sites.r_max_m=8000
refused "/density/weights: every weight is 0" \
  --set 'density.weights={"altitude": 0, "slope": 0, "coast_near": 0, "position_5km": 0}'
refused "/sites/u_max: must be >= /sites/u_min" --set sites.quotas=belhadj2007 --set sites.u_min=4 --set sites.u_max=2
refused "/density/r_max_m: must be larger than /density/r_min_m" --set density.r_min_m=5000 --set density.r_max_m=4000

# The commands name their flags for the same rules.
expect_refused d "^terrapolis: error: --weights: every weight is 0" "$TP" density "$lux" d --weights 0,0,0,0
expect_refused s "^terrapolis: error: --r-max: sets the classes of --quotas belhadj2007" "$TP" sites "$lux" s --r-max 8000
expect_refused l "^terrapolis: error: --level or --depth: the water level is required \(or --dam with --crest\)" "$TP" lake "$lux" l --at=6,49.7
expect_refused l "^terrapolis: error: --dam: needs --crest" "$TP" lake "$lux" l --at=6,49.7 --dam "LINESTRING (6 49.7, 6.1 49.7)"
no_leftovers "$WORK"
echo "run_prepare: ok"
