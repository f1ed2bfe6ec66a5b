#!/usr/bin/env bash
# `terrapolis catchment`: an outlet in lon/lat and in the DEM's CRS, mask output, refusals.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK
dem=$samples/whiteboxR_DEM_vermont.tif

# The documented example (docs/hydro.md).
"$bin" -q catchment "$dem" --outlet=-72.8,44.1 --snap-radius 500 --mask "$work/vt_mask.tif" "$work/vt.geojson"
[[ -s $work/vt.geojson && -s $work/vt_mask.tif ]]
ogrinfo -al "$work/vt.geojson" | grep "area_km2 (Real)" >/dev/null
area=$(ogrinfo -al "$work/vt.geojson" | sed -n 's/^ *area_km2 (Real) = //p' | head -1)
awk -v a="$area" 'BEGIN { exit !(a > 0.01) }' || { echo "catchment area $area"; exit 1; }
# The mask holds as many ones as the polygon's cell count says.
cells=$(ogrinfo -al "$work/vt.geojson" | sed -n 's/^ *cells (Integer) = //p' | head -1)
ones=$(gdalinfo -hist "$work/vt_mask.tif" | awk '/buckets/ {getline; print $2}')
[[ $cells == "$ones" ]] || { echo "mask has $ones cells, polygon says $cells"; exit 1; }

# The same outlet in the DEM's CRS (UTM 18N) gives the same catchment.
"$bin" -q catchment "$dem" --outlet 675807,4885699 --outlet-crs dem --snap-radius 0 "$work/utm.geojson"
cmp <(ogrinfo -al "$work/vt.geojson" | grep -E "area_km2|cells") <(ogrinfo -al "$work/utm.geojson" | grep -E "area_km2|cells")

expect_fail 2 "error: --outlet: the point is outside the DEM" "$bin" -q catchment "$dem" --outlet 10,10 "$work/bad1.geojson"
[[ ! -e $work/bad1.geojson ]]
expect_fail 2 "--outlet" "$bin" -q catchment "$dem" --outlet abc "$work/bad2.geojson"
expect_fail 2 "geojson" "$bin" -q catchment "$dem" --outlet=-72.8,44.1 "$work/bad3.shp"
expect_fail 2 "exists" "$bin" -q catchment "$dem" --outlet=-72.8,44.1 "$work/vt.geojson"
echo ok
# --fill and --sea-level come from the schema (hydro.fill, water.sea_level_m), as for `hydro`: the
# same catchment with the default Priority-Flood named, and bad values refused by the schema.
"$bin" -q catchment "$dem" --outlet=-72.8,44.1 --snap-radius 500 --fill priority-flood "$work/vt_pf.geojson"
cmp -s "$work/vt.geojson" "$work/vt_pf.geojson" || { echo "--fill priority-flood changed the catchment"; exit 1; }
expect_refused "$work/vt_bad.geojson" "--fill" "$bin" -q catchment "$dem" --outlet=-72.8,44.1 --fill sideways "$work/vt_bad.geojson"
expect_refused "$work/vt_bad.geojson" "--sea-level" "$bin" -q catchment "$dem" --outlet=-72.8,44.1 --sea-level 99999 "$work/vt_bad.geojson"
