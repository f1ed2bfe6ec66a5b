#!/usr/bin/env bash
# `terrapolis density` on real sample DEMs: coasts (sea negative, near 0, nodata), inland, layers.
set -euo pipefail
bin=$1 samples=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
# Prints "min max" of band 1 of a raster.
minmax() { gdalinfo -mm "$1" | sed -n 's/.*Computed Min\/Max=\([^,]*\),\(.*\)/\1 \2/p'; }
in_unit() {  # every value of $1 lies in [0,1]
  read -r lo hi < <(minmax "$1")
  awk -v lo="$lo" -v hi="$hi" 'BEGIN { exit !(lo >= 0 && hi <= 1) }' || fail "$1 values $lo..$hi outside [0,1]"
}

# 1. North Corsica (GEBCO, geographic, sea < 0), hydrometry neutral: no hydrometry.tif.
"$bin" --quiet density "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$tmp/corsica" --weights 1,0,1.5,0 --report > "$tmp/report.txt"
for f in coast plateau plain buildable density; do [[ -f $tmp/corsica/$f.tif ]] || fail "corsica: $f.tif missing"; done
[[ ! -e $tmp/corsica/hydrometry.tif ]] || fail "corsica: hydrometry.tif written although unused"
for f in coast plateau plain density; do in_unit "$tmp/corsica/$f.tif"; done
read -r lo hi < <(minmax "$tmp/corsica/coast.tif")
[[ $hi == 1.000 ]] || fail "corsica: coast maximum is $hi, expected 1"
grep -q 'Size is 175, 175' <(gdalinfo "$tmp/corsica/density.tif") || fail "corsica: grid changed"
grep -q 'ID\["EPSG",4326\]' <(gdalinfo "$tmp/corsica/density.tif") || fail "corsica: CRS lost"
grep -q 'Description = Human population density' <(gdalinfo "$tmp/corsica/density.tif") || fail "corsica: no description"
grep -q 'WEIGHTS_COAST_HYDROMETRY_PLATEAU_PLAIN=1,0,1.5,0' <(gdalinfo "$tmp/corsica/coast.tif") || fail "corsica: no provenance"
grep -q 'buildable:' "$tmp/report.txt" || fail "report: no buildable share"
[[ $(grep -c '^    \[' "$tmp/report.txt") == 10 ]] || fail "report: histogram should have 10 lines"
# Deterministic whatever the thread count.
"$bin" --quiet --threads 1 density "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$tmp/corsica1" --weights 1,0,1.5,0
cmp "$tmp/corsica/density.tif" "$tmp/corsica1/density.tif" || fail "corsica: output depends on the thread count"

# 2. Vermont (UTM, inland) with a hydrometry file made here (altitude rescaled to [0,1]), river beds,
#    slope limit, a user layer and an exclusion raster, written as COG.
dem="$samples/whiteboxR_DEM_vermont.tif"
gdal_translate -q -ot Float32 -scale 212 1233 1 0 "$dem" "$tmp/hydro.tif"
gdal_translate -q -ot Float32 -scale 212 1233 0 500 "$dem" "$tmp/layer.tif"   # any range: rescaled
gdal_translate -q -ot Byte -scale 212 1233 0 2 "$dem" "$tmp/exclude.tif"       # non-zero on high ground
"$bin" --quiet density "$dem" "$tmp/vermont" --weights 0,1,1,0.5 --hydrometry "$tmp/hydro.tif" --river-bed-cap 0.95 \
  --max-slope 25 --layer "$tmp/layer.tif:-0.5" --exclude "$tmp/exclude.tif" --r-min 300 --r-max 3000 --cog --report > "$tmp/vt.txt"
[[ -f $tmp/vermont/hydrometry.tif ]] || fail "vermont: hydrometry.tif missing"
for f in coast plateau plain hydrometry density; do in_unit "$tmp/vermont/$f.tif"; done
read -r lo hi < <(minmax "$tmp/vermont/coast.tif")
[[ $hi == 0.000 ]] || fail "vermont: inland but coast reaches $hi"
grep -q 'LAYOUT=COG' <(gdalinfo "$tmp/vermont/density.tif") || fail "vermont: not a COG"
grep -q 'ID\["EPSG",26918\]' <(gdalinfo "$tmp/vermont/density.tif") || fail "vermont: CRS lost"

# 3. New Zealand (projected, no EPSG code): sea is NaN nodata; with --nodata-is-sea it is water
#    (83 % of the grid), without it unknown: only land cells at 0 m are water.
"$bin" --quiet density "$samples/spDataLarge_nz_elev.tif" "$tmp/nz" --weights 1,0,1,0 --nodata-is-sea --r-min 1000 --r-max 8000 --report > "$tmp/nz.txt"
read -r lo hi < <(minmax "$tmp/nz/coast.tif")
[[ $hi == 1.000 ]] || fail "nz: coast maximum is $hi with --nodata-is-sea"
in_unit "$tmp/nz/density.tif"
grep -q 'cells: *1616750 (1616750 with data or water, 13[0-9]\{5\} water)' "$tmp/nz.txt" || fail "nz: sea not counted as water: $(grep cells: "$tmp/nz.txt")"
"$bin" --quiet density "$samples/spDataLarge_nz_elev.tif" "$tmp/nz2" --weights 1,0,1,0 --r-min 1000 --r-max 8000 --report > "$tmp/nz2.txt"
grep -q 'cells: *1616750 (2[0-9]\{5\} with data or water' "$tmp/nz2.txt" || fail "nz: nodata counted as known: $(grep cells: "$tmp/nz2.txt")"
grep -q 'NoData Value=nan' <(gdalinfo -mm "$tmp/nz2/density.tif") || fail "nz: density lost its nodata"

# 4. Olinda (UTM, sea near 0 m, no nodata) and Luxembourg (nodata border).
"$bin" --quiet density "$samples/stars_olinda_dem_utm25s.tif" "$tmp/olinda" --weights 1,0,0,1
read -r lo hi < <(minmax "$tmp/olinda/coast.tif")
[[ $hi == 1.000 ]] || fail "olinda: coast maximum is $hi"
"$bin" --quiet density "$samples/terra_elev_luxembourg.tif" "$tmp/lux" --weights 0,0,1,1 --r-min 1500 --r-max 10000
in_unit "$tmp/lux/density.tif"
grep -q 'NoData Value=255' <(gdalinfo "$tmp/lux/buildable.tif") || fail "luxembourg: buildable has no nodata"

# 5. --overwrite replaces; the water mask makes the coast appear inland.
gdal_translate -q -ot Byte -scale 212 1233 0 1.6 "$dem" "$tmp/lake.tif"   # 0 below ~850 m, 1 above: a "lake"
"$bin" --quiet density "$dem" "$tmp/vermont" --weights 1,0,0,0 --water-mask "$tmp/lake.tif" --overwrite
read -r lo hi < <(minmax "$tmp/vermont/coast.tif")
[[ $hi == 1.000 ]] || fail "vermont: water mask gave no coast ($hi)"
# 6. An OUTDIR holding an input (its --hydrometry) is refused, the input left as it is.
mkdir "$tmp/reuse"
cp "$tmp/hydro.tif" "$tmp/reuse/hydrometry.tif"
before=$(md5sum < "$tmp/reuse/hydrometry.tif")
set +e
"$bin" --quiet density "$dem" "$tmp/reuse" --weights 0,1,1,0 --hydrometry "$tmp/reuse/hydrometry.tif" --overwrite 2> "$tmp/err"
code=$?
set -e
[[ $code == 2 ]] && grep -q "holds the input" "$tmp/err" || fail "an OUTDIR holding the input: exit $code, $(cat "$tmp/err")"
[[ $(md5sum < "$tmp/reuse/hydrometry.tif") == "$before" ]] || fail "reuse: hydrometry.tif was rewritten"
echo "density CLI cases passed"
