#!/usr/bin/env bash
# `terrapolis catchment`: an outlet in lon/lat and in the DEM's CRS, mask output, refusals.
# SPDX-License-Identifier: MIT
set -euo pipefail
bin=$1 samples=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
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

expect_fail() {
  local code=$1 pattern=$2; shift 2
  set +e
  "$bin" -q "$@" 2>"$work/err"
  local got=$?
  set -e
  [[ $got -eq $code ]] || { echo "expected exit $code, got $got for: $*"; cat "$work/err"; exit 1; }
  grep -q -- "$pattern" "$work/err" || { echo "message '$pattern' missing for: $*"; cat "$work/err"; exit 1; }
}
expect_fail 2 "outside the DEM" catchment "$dem" --outlet 10,10 "$work/bad1.geojson"
[[ ! -e $work/bad1.geojson ]]
expect_fail 2 "--outlet" catchment "$dem" --outlet abc "$work/bad2.geojson"
expect_fail 2 "geojson" catchment "$dem" --outlet=-72.8,44.1 "$work/bad3.shp"
expect_fail 2 "exists" catchment "$dem" --outlet=-72.8,44.1 "$work/vt.geojson"
echo ok
