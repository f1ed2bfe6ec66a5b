# A command computes what the run's stage computes (one stage object, docs/architecture.md):
# `terrapolis sites DEM` places the settlements of `terrapolis run --until sites` on the same DEM
# and settings, byte for byte; `terrapolis roads` on a run's network and cities routes its roads,
# byte for byte; `terrapolis access` on its cities and roads gives its travel times, cell for cell;
# `terrapolis density DEM` (the thesis's weights by default) gives the density stage's rasters of a
# run with those weights, cell for cell (inland water and hydrometry from the same functions);
# `terrapolis network --dem` builds its network byte for byte; a file written by both carries one description.
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

dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
rm -rf run
"$TP" --progress none --quiet run -o run --set "dem=\"$dem\"" 2> /dev/null
# network --dem: the run's network byte for byte (its cities put back on the DEM's cell centres).
"$TP" --progress none --quiet network run/cities.geojson network --dem "$dem" > /dev/null
cmp -s run/network.geojson network/network.geojson || fail "network --dem: the command and the run differ in network.geojson"
"$TP" --progress none --quiet roads "$dem" run/network.geojson roads --cities run/cities.geojson
for f in roads.geojson sections.geojson road_sections.geojson junctions.geojson; do
  cmp -s run/$f roads/$f || fail "roads: the command and the run differ in $f"
done
"$TP" --progress none --quiet access "$dem" access --to run/cities.geojson --roads run/roads.geojson 2> /dev/null
same_pixels() {  # A B: the same values (the metadata record each its own provenance)
  /usr/bin/python3 -c "
import sys; from osgeo import gdal; import numpy as np
a, b = (gdal.Open(p).ReadAsArray() for p in sys.argv[1:])
sys.exit(0 if a.shape == b.shape and np.array_equal(a, b, equal_nan=True) else 1)" "$1" "$2"
}
same_description() {  # A B: one description per output (pipeline::describe_output), and not an empty one
  local a b
  a=$(gdalinfo "$1" | grep -m1 '^  Description = ') b=$(gdalinfo "$2" | grep -m1 '^  Description = ')
  [[ -n $a && $a == "$b" ]] || fail "$1 and $2 carry different descriptions: '$a' and '$b'"
}
for f in access_minutes.tif access_nearest.tif; do
  same_pixels run/$f access/$f || fail "access: the command and the run differ in $f"
  same_description run/$f access/$f
done
"$TP" --progress none --quiet hydro "$dem" hydro --area-units km2
for f in filled.tif flowdir.tif accumulation.tif hydrometry.tif; do same_description run/$f hydro/$f; done
for dem in "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" "$SAMPLES/terra_elev_luxembourg.tif"; do
  rm -rf run density
  "$TP" --progress none --quiet run -o run --until density --set "dem=\"$dem\"" --set 'density.preset="belhadj2007"' 2> /dev/null
  "$TP" --progress none --quiet density "$dem" density
  for f in density buildable coast plateau plain hydrometry; do
    same_pixels run/$f.tif density/$f.tif || fail "density $(basename "$dem"): the command and the run differ in $f.tif"
  done
done
# --preset fitted: the run's default density.
rm -rf run density
"$TP" --progress none --quiet run -o run --until density --set "dem=\"$dem\"" 2> /dev/null
"$TP" --progress none --quiet density "$dem" density --preset fitted
for f in density buildable; do
  same_pixels run/$f.tif density/$f.tif || fail "density --preset fitted: the command and the run's default differ in $f.tif"
done
echo "stage_commands: ok"
