# The shared regions with 10 or more GeoNames places (CC BY 4.0) on their land, for bench/realism.sh,
# bench/placement.sh and bench/density_terms.sh. Sourced with their arguments
# ([TERRAPOLIS] [DEMS_DIR] [PLACES_DIR] [KEEP_DIR]): sets TP, DEMS, PLACES, SRC and OUT (KEEP_DIR, a
# new folder, or a temporary one removed at exit) and goes there; sets `regions` (DEM file names),
# `dems`, `places` and `scenarios` (a --scenario per DEM; NZ's sea is nodata, NaN), and
# `default_fit`, the calibrate options the schema's default density weights were fitted with
# (docs/density.md, "Presets, terrain terms and calibration").
TP=$(realpath "${1:-build/src/cli/terrapolis}")
DEMS=$(realpath "${2:-../shared/dems}")
PLACES=$(realpath "${3:-../shared/reference/geonames}")
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [[ -n ${4:-} ]]; then
  mkdir "$4"  # refuses an existing folder: never mixes runs
  OUT=$(realpath "$4")
else
  OUT=$(mktemp -d)
  trap 'rm -rf "$OUT"' EXIT
fi
cd "$OUT"
regions=(N47E009.hgt N57E011.hgt demcompare_reduced_gironde_topobathy.tif osmtransform_heidelberg_mannheim_srtm3.tif
         pyflwdir_rhine_elv0.tif spDataLarge_nz_elev.tif terra_elev_luxembourg.tif gebco2022_15s_la_palma.asc
         gebco2022_15s_north_corsica_capcorse.asc gebco2022_15s_tenerife_east.asc)
default_fit=(--terms altitude,slope,coast_near,position_5km --ridge 0.1)
echo '{}' > plain.json
echo '{"water": {"nodata_is_sea": true}}' > sea_nodata.json
# The scenario of a region's runs.
region_scenario() { [[ $1 == spDataLarge_nz_elev.tif ]] && echo sea_nodata.json || echo plain.json; }
dems=() places=() scenarios=()
for f in "${regions[@]}"; do
  dems+=("$DEMS/$f")
  places+=("$PLACES/${f%.*}.geojson")
  scenarios+=(--scenario "$(region_scenario "$f")")
done
