#!/usr/bin/env bash
# Lake benchmark: `terrapolis lake` vs GRASS r.lake, same DEM, seed and level, in the same run.
# Prints the flooded cells and areas of both (agreement) and whole-process wall and CPU times
# (paired runs, medians, ratio r.lake / terrapolis).
# Run from the repository root: bench/lake.sh [path/to/terrapolis] [runs]
# Needs grass (grass-core, from scripts/setup --bench); the DEMs in ../shared/dems.
# SPDX-License-Identifier: MIT
set -euo pipefail
bin=$(realpath "${1:-build/src/cli/terrapolis}")
runs=${2:-5}
command -v grass >/dev/null || { echo "missing grass (scripts/setup --bench)"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export GRASS_MESSAGE_FORMAT=silent
here=$(dirname "$0")

# name | DEM | seed lon,lat | level (m). Projected DEMs compare areas in map metres; the SRTM tile
# (geographic) compares cell counts and speed.
cases=(
  "bigtujunga|../shared/dems/topotoolbox_bigtujunga.tif|-118.2215,34.2925|${BIGTUJUNGA_LEVEL:-800}"
  "limburg|../shared/dems/osmtransform_limburg_an_der_lahn_dgm10.tif|8.0620,50.3880|${LIMBURG_LEVEL:-125}"
  "bodensee|../shared/dems/N47E009.hgt|9.40,47.60|${BODENSEE_LEVEL:-397}"
)
printf "%-11s %9s %7s | %10s %10s %12s %12s %8s | %9s %9s %6s | %9s %9s %6s\n" dem cells level tp_cells grass_cells \
  tp_km2 grass_km2 diff% tp_wall grass_wall ratio tp_cpu grass_cpu ratio
for c in "${cases[@]}"; do
  IFS='|' read -r name dem at level <<<"$c"
  dem=$(realpath "$dem")
  loc="$work/loc_$name"
  grass -c "$dem" "$loc" -e >/dev/null 2>&1
  gx() { grass "$loc/PERMANENT" --exec "$@"; }
  gx r.in.gdal -o input="$dem" output=dem >/dev/null 2>&1
  gx g.region raster=dem >/dev/null 2>&1
  # The seed in the DEM's CRS, as r.lake takes it (the same point terrapolis gets as lon,lat).
  xy=$(/usr/bin/python3 -c "
import sys
from osgeo import gdal, osr
t = osr.SpatialReference(); t.ImportFromWkt(gdal.Open(sys.argv[1]).GetProjection())
s = osr.SpatialReference(); s.ImportFromEPSG(4326)
for r in (s, t): r.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
lon, lat = map(float, sys.argv[2].split(','))
x, y, _ = osr.CoordinateTransformation(s, t).TransformPoint(lon, lat)
print('%.6f,%.6f' % (x, y))" "$dem" "$at")
  tp="$bin -q --threads 2 lake $dem $work/tp_$name --at $at --level $level --overwrite"
  gr="grass $loc/PERMANENT --exec r.lake --overwrite elevation=dem water_level=$level lake=lake coordinates=$xy"
  $tp
  $gr >/dev/null 2>&1
  tp_cells=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['cells'])" "$work/tp_$name/lake.json")
  tp_km2=$(python3 -c "import json,sys; print('%.4f' % json.load(open(sys.argv[1]))['area_km2'])" "$work/tp_$name/lake.json")
  g_cells=$(gx r.univar -g map=lake 2>/dev/null | sed -n 's/^n=//p')
  cells=$(gdalinfo "$dem" | awk -F'[ ,]+' '/^Size is/ {print $3*$4}')
  # r.lake's area: on a projected DEM its cells times the cell area; on a geographic one, our
  # ellipsoidal areas of the same count are not comparable, so only the counts are.
  if gdalsrsinfo -o proj4 "$dem" | grep -q longlat; then
    g_km2=-; diff=$(python3 -c "print('%.3f' % (100*($tp_cells-$g_cells)/$g_cells))")
  else
    res=$(gdalinfo "$dem" | sed -n 's/^Pixel Size = (\([^,]*\),-\?\([^)]*\))/\1 \2/p')
    g_km2=$(python3 -c "import sys; a,b=map(float,'$res'.split()); print('%.4f' % ($g_cells*a*abs(b)/1e6))")
    diff=$(python3 -c "print('%.3f' % (100*($tp_km2-$g_km2)/$g_km2))")
  fi
  read -r ta ga wr tc gc cr < <("$here/paired.py" "$runs" "$tp" "$gr")
  printf "%-11s %9s %7s | %10s %10s %12s %12s %8s | %8ss %8ss %6s | %8ss %8ss %6s\n" "$name" "$cells" "$level" "$tp_cells" "$g_cells" \
    "$tp_km2" "$g_km2" "$diff" "$ta" "$ga" "$wr" "$tc" "$gc" "$cr"
done
