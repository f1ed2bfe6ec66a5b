#!/usr/bin/env bash
# `terrapolis path` on the Corsica sample: a road, and clean failures on bad points.
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES out=$WORK
dem=$samples/gebco2022_15s_north_corsica_capcorse.asc

"$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/road.geojson" --sections "$out/sections.geojson"
grep -q '"router": "galin"' "$out/road.geojson"
grep -q '"structure": "road"' "$out/sections.geojson"
# Same again with bidirectional A*: the same cost.
"$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/road2.geojson" --search bidir
c1=$(grep -o '"cost": [0-9.]*' "$out/road.geojson"); c2=$(grep -o '"cost": [0-9.]*' "$out/road2.geojson")
[[ "$c1" == "$c2" ]] || { echo "astar $c1 != bidir $c2"; exit 1; }
# Existing output without --overwrite is refused.
if "$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/road.geojson"; then exit 1; fi

refuse() { expect_refused "$out/bad.geojson" "$1" "$bin" -q path "$dem" "${@:2}" "$out/bad.geojson"; }
refuse "outside" --from 2.0,42.7 --to 9.42,42.70
refuse "same cell" --from 9.30,42.68 --to 9.30,42.68
refuse "in the sea" --from 9.0,43.15 --to 9.42,42.70
refuse "latitude" --from 42.68,95 --to 9.42,42.70
refuse "not a number" --from 9.3,abc --to 9.42,42.70
refuse "k" --from 9.30,42.68 --to 9.42,42.70 --k 0
# Coordinates in the DEM's CRS (UTM 25S, no nodata tag) and negative lon/lat typed as is.
"$bin" -q path "$samples/stars_olinda_dem_utm25s.tif" --crs dem --from 292000,9112000 --to 296000,9117000 "$out/olinda.geojson" --no-bridges --no-tunnels
grep -q LineString "$out/olinda.geojson"
"$bin" -q path "$samples/stars_olinda_dem_utm25s.tif" --from -34.9,-7.99 --to -34.88,-8.0 "$out/olinda2.geojson"
grep -q LineString "$out/olinda2.geojson"
# Pricing a given line (as the benchmark prices GRASS's path) prints a cost and writes nothing.
cost=$("$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/none.geojson" --evaluate "$out/road.geojson")
[[ "$cost" == cost* ]] || { echo "evaluate printed '$cost'"; exit 1; }
[[ ! -e "$out/none.geojson" ]]
# The Bézier router answers the same question.
"$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/bezier.geojson" --router bezier --bezier-evaluations 200
grep -q '"router": "bezier"' "$out/bezier.geojson"
# --water-mask: a 1 km band of water across the cape (3 cells at 9.355-9.365 E), as a run's
# water.water_mask: the road bridges it (no bridge without it); without bridges and tunnels the two
# sides are two land masses, joined by a ferry.
/usr/bin/python3 - "$dem" "$out/band.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1])
gt = src.GetGeoTransform()
band = np.zeros((src.RasterYSize, src.RasterXSize), np.uint8)
band[:, int((9.355 - gt[0]) / gt[1]):int((9.365 - gt[0]) / gt[1]) + 1] = 1
out = gdal.GetDriverByName('GTiff').Create(sys.argv[2], src.RasterXSize, src.RasterYSize, 1, gdal.GDT_Byte)
out.SetGeoTransform(gt)
out.SetProjection('EPSG:4326')
out.GetRasterBand(1).WriteArray(band)
PY
line() { "$bin" -v path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/$1.geojson" "${@:2}" 2>&1 | grep '^galin:'; }
[[ $(line dry) == *"bridges 0 m"* ]] || { echo "a bridge without the band"; exit 1; }
wet=$(line wet --water-mask "$out/band.tif")
[[ $wet =~ bridges\ ([0-9]+)\ m && ${BASH_REMATCH[1]} -ge 1000 ]] || { echo "no bridge over the masked band: $wet"; exit 1; }
"$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/ferry.geojson" --water-mask "$out/band.tif" --no-bridges --no-tunnels
grep -q '"router": "ferry"' "$out/ferry.geojson" || { echo "no ferry across the masked band"; exit 1; }
refuse "missing.tif" --from 9.30,42.68 --to 9.42,42.70 --water-mask "$out/missing.tif"
