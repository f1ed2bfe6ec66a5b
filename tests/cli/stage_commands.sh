# A command given a DEM where a run has earlier stages computes what those stages compute (one
# stage object, docs/architecture.md): `terrapolis sites DEM` places the settlements of
# `terrapolis run --until sites` on the same DEM and settings, byte for byte.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"

same_sites() {  # DEM [SITES_FLAGS -- RUN_SETS]
  local dem=$1; shift
  local flags=() sets=()
  while [[ $# -gt 0 && $1 != -- ]]; do flags+=("$1"); shift; done
  [[ $# -gt 0 ]] && shift
  sets=("$@")
  rm -rf run sites
  "$TP" --progress none --quiet run -o run --until sites --set "dem=\"$dem\"" "${sets[@]}"
  "$TP" --progress none --quiet sites "$dem" sites "${flags[@]}" > /dev/null
  for f in cities.geojson city_extents.geojson; do
    cmp -s run/$f sites/$f || fail "$(basename "$dem") ${flags[*]}: sites DEM and run --until sites differ in $f"
  done
}
same_sites "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc"
same_sites "$SAMPLES/terra_elev_luxembourg.tif"
same_sites "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" --seed 7 --population 150000 -- \
  --set seed=7 --set sites.population=150000
echo "stage_commands: ok"
