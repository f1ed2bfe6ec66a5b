#!/usr/bin/env bash
# Renders cities (red circles, suburbs magenta) and the kept network (yellow, parent-child orange)
# over a hillshade: bash docs/sites_quicklook.sh TERRAPOLIS DEM OUT.png [sites options...]
# The density model is a stand-in made from the DEM: buildable = land below 1000 m,
# density = exp(-z / 400 m).
set -euo pipefail
BIN=$1 DEM=$2 PNG=$3
shift 3
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
mkdir "$T/in"
gdal_calc.py --quiet -A "$DEM" --outfile "$T/in/buildable.tif" --type Byte --calc "(A>0)*(A<1000)" --NoDataValue 255
gdal_calc.py --quiet -A "$DEM" --outfile "$T/in/density.tif" --type Float32 --calc "(A>0)*(A<1000)*exp(-maximum(A,0)/400.0)"
"$BIN" --quiet sites "$T/in" "$T/out" "$@"
"$BIN" --quiet network "$T/out/cities.geojson" "$T/out"
# Frame: the cities' extent plus a margin.
read -r x0 x1 y0 y1 < <(ogrinfo -so -al "$T/out/city_extents.geojson" | sed -n 's/^Extent: (\(.*\), \(.*\)) - (\(.*\), \(.*\))/\1 \3 \2 \4/p')
read -r x0 y0 x1 y1 < <(awk -v a="$x0" -v b="$y0" -v c="$x1" -v d="$y1" 'BEGIN { m = 0.08 * (c - a); print a - m, b - m, c + m, d + m }')
gdalwarp -q -t_srs EPSG:4326 -te "$x0" "$y0" "$x1" "$y1" -ts 560 0 -r bilinear "$DEM" "$T/dem.tif"
gdaldem hillshade -q -z 3 -s 111120 "$T/dem.tif" "$T/hs.tif"
gdal_calc.py --quiet -A "$T/dem.tif" --outfile "$T/sea.tif" --type Byte --calc "A<=0"
for band in "r:150:0.55:100" "g:185:0.55:95" "b:215:0.5:70"; do
  IFS=: read -r name sea gain offset <<< "$band"
  gdal_calc.py --quiet -A "$T/hs.tif" -B "$T/sea.tif" --outfile "$T/$name.tif" --type Byte --calc "where(B==1, $sea, A*$gain+$offset)"
done
gdal_merge.py -q -separate -o "$T/rgb.tif" "$T/r.tif" "$T/g.tif" "$T/b.tif"
ogr2ogr -q -nlt MULTILINESTRING "$T/rings.gpkg" "$T/out/city_extents.geojson" -nln rings
burn() { gdal_rasterize -q -b 1 -b 2 -b 3 -burn "$1" -burn "$2" -burn "$3" "${@:4}" "$T/rgb.tif"; }
burn 250 210 0 -where "kept=1 and kind<>'parent_child'" "$T/out/network.geojson"
burn 255 120 0 -where "kind='parent_child'" "$T/out/network.geojson"
burn 200 0 0 -where "depth=0" "$T/rings.gpkg"
burn 170 0 170 -where "depth>0" "$T/rings.gpkg"
gdal_translate -q -of PNG "$T/rgb.tif" "$PNG"
rm -f "$PNG.aux.xml"
