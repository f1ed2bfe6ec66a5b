#!/usr/bin/env bash
# `terrapolis hydro` on the sample DEMs, and its refusals (exit 2, nothing left behind).
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK
outputs="filled.tif flowdir.tif accumulation.tif hydrometry.tif streams.geojson"

check_outputs() {
  for f in $outputs; do [[ -s $1/$f ]] || { echo "missing $1/$f"; exit 1; }; done
}

# The documented example (docs/hydro.md): Corsica, coastal GEBCO grid, sea as outlet.
"$bin" -q hydro "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$work/corsica" --sea-level 0
check_outputs "$work/corsica"
gdalinfo "$work/corsica/flowdir.tif" | grep "D8_CODES=esri" >/dev/null
gdalinfo "$work/corsica/hydrometry.tif" | grep "Description = Hydrometry" >/dev/null
gdalinfo -stats "$work/corsica/hydrometry.tif" | grep "STATISTICS_MAXIMUM=1" >/dev/null
reaches=$(ogrinfo -so -al "$work/corsica/streams.geojson" | sed -n 's/^Feature Count: //p')
[[ $reaches -gt 10 ]] || { echo "too few stream reaches: $reaches"; exit 1; }
ogrinfo -al "$work/corsica/streams.geojson" | grep "strahler (Integer)" >/dev/null

# Nodata border (Luxembourg), NaN nodata without EPSG (NZ), GRASS codes, MFD, accumulation hydrometry.
"$bin" -q hydro "$samples/terra_elev_luxembourg.tif" "$work/lux" --flow mfd --d8-codes grass --area-units km2
check_outputs "$work/lux"
gdalinfo "$work/lux/flowdir.tif" | grep "D8_CODES=grass" >/dev/null
gdalinfo "$work/lux/accumulation.tif" | grep "UNIT=km2" >/dev/null
"$bin" -q hydro "$samples/spDataLarge_nz_elev.tif" "$work/nz" --hydrometry accumulation --flow dinf --streams-threshold 500
check_outputs "$work/nz"
"$bin" -q hydro "$samples/whiteboxR_DEM_vermont.tif" "$work/vt" --fill breach --d8-codes taudem --streams-threshold 1 \
  --hydrometry belhadj --vertical normalised16 --iterations 20 --weights "$samples/whiteboxR_DEM_vermont.tif" --cog
check_outputs "$work/vt"
"$bin" -q hydro "$samples/spDataLarge_srtm_zion.tif" "$work/zion" --fill epsilon --belhadj-share fed --streams-threshold 2
check_outputs "$work/zion"
"$bin" -q hydro "$samples/stars_olinda_dem_utm25s.tif" "$work/olinda" --sea-level 0 --streams-threshold 0.5
check_outputs "$work/olinda"

# Existing outputs are refused and left untouched; --overwrite replaces them.
before=$(md5sum "$work/corsica/filled.tif")
expect_fail 2 "exists" "$bin" -q hydro "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$work/corsica"
[[ $(md5sum "$work/corsica/filled.tif") == "$before" ]]
"$bin" -q hydro "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$work/corsica" --overwrite --hydrometry accumulation

# Bad inputs: exit 2, one line naming the problem, no output folder left.
expect_fail 2 "missing.tif" "$bin" -q hydro "$work/missing.tif" "$work/bad1"
[[ ! -e $work/bad1 ]]
expect_fail 2 "--fill" "$bin" -q hydro "$samples/whiteboxR_DEM_vermont.tif" "$work/bad2" --fill magic
[[ ! -e $work/bad2 ]]
expect_fail 2 "--threshold" "$bin" -q hydro "$samples/whiteboxR_DEM_vermont.tif" "$work/bad3" --threshold 0
[[ ! -e $work/bad3 ]]
expect_fail 2 "--mfd-exponent" "$bin" -q hydro "$samples/whiteboxR_DEM_vermont.tif" "$work/bad4" --mfd-exponent -1
[[ ! -e $work/bad4 ]]
expect_fail 2 "nope.tif" "$bin" -q hydro "$samples/whiteboxR_DEM_vermont.tif" "$work/bad5" --weights "$work/nope.tif"
[[ ! -e $work/bad5 ]]
expect_fail 2 "streams-threshold" "$bin" -q hydro "$samples/whiteboxR_DEM_vermont.tif" "$work/bad6" --streams-threshold 0
[[ ! -e $work/bad6 ]]
expect_fail 2 "no land" "$bin" -q hydro "$samples/whiteboxR_DEM_vermont.tif" "$work/bad7" --sea-level 5000
[[ ! -e $work/bad7 ]]
echo ok
