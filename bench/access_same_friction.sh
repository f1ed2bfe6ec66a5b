#!/usr/bin/env bash
# Access against GRASS r.walk on the same friction: a flat copy of the projected Olinda DEM (UTM
# 25S, 90 m cells), two settlements, walking off paths only. On the flat, Tobler's off-path speed is
# constant, 0.6 x 6 exp(-3.5 x 0.05) = 3.02205 km/h, and r.walk with walk_coeff=a,0,0,0 and no
# friction costs a seconds per metre: a = 3600 / 3022.05 = 1.191246 prices the same walk. Both
# search the same 16 neighbours (r.walk -k); the script prints the ratio of the two times over
# every cell (min, median, max) and the largest difference in minutes.
# Usage: bench/access_same_friction.sh [BUILD_DIR]   (run from the repository root; needs grass)
set -euo pipefail
bin=${1:-build}/src/cli/terrapolis
command -v grass >/dev/null || { echo "GRASS not installed (apt-get install -y grass-core)"; exit 0; }
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
/usr/bin/python3 - "$dir" sample_dems/stars_olinda_dem_utm25s.tif <<'PY'
import json, sys
import numpy as np
from osgeo import gdal, osr
out, dem = sys.argv[1], gdal.Open(sys.argv[2])
gt = dem.GetGeoTransform()
flat = gdal.GetDriverByName("GTiff").Create(out + "/flat.tif", dem.RasterXSize, dem.RasterYSize, 1, gdal.GDT_Float32)
flat.SetGeoTransform(gt)
flat.SetProjection(dem.GetProjection())
flat.GetRasterBand(1).WriteArray(np.full((dem.RasterYSize, dem.RasterXSize), 10.0, np.float32))
flat = None
utm = osr.SpatialReference(wkt=dem.GetProjection()); lonlat = osr.SpatialReference(); lonlat.ImportFromEPSG(4326)
for s in (utm, lonlat): s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
to_lonlat = osr.CoordinateTransformation(utm, lonlat)
cells = [(dem.RasterXSize // 3, dem.RasterYSize // 2), (2 * dem.RasterXSize // 3, dem.RasterYSize // 2)]
features = []
for i, (c, r) in enumerate(cells):
    x, y = gt[0] + gt[1] * (c + 0.5), gt[3] + gt[5] * (r + 0.5)
    lon, lat, _ = to_lonlat.TransformPoint(x, y)
    features.append({"type": "Feature", "properties": {"id": i, "population": 1000, "radius_m": 100},
                     "geometry": {"type": "Point", "coordinates": [lon, lat]}})
json.dump({"type": "FeatureCollection", "features": features}, open(out + "/places.geojson", "w"))
PY
"$bin" -q access "$dir/flat.tif" "$dir/ours" --to "$dir/places.geojson"
ogr2ogr -q -t_srs "$(gdalsrsinfo -o wkt1 "$dir/flat.tif" | tr -d '\n')" "$dir/places_utm.gpkg" "$dir/places.geojson" 2>/dev/null
grass -c "$dir/flat.tif" "$dir/loc" --exec bash -c "
  set -e
  r.in.gdal --quiet input=$dir/flat.tif output=dem
  g.region raster=dem
  r.mapcalc --quiet 'friction = 0'
  v.in.ogr -o --quiet input=$dir/places_utm.gpkg output=places
  r.walk -k --quiet elevation=dem friction=friction output=cost start_points=places walk_coeff=1.191246,0,0,0 lambda=0
  r.out.gdal --quiet input=cost output=$dir/rwalk.tif type=Float64 2>/dev/null
" >"$dir/grass.log" 2>&1 || { grep -i error "$dir/grass.log" | head -5; exit 1; }
/usr/bin/python3 - "$dir" <<'PY'
import sys
import numpy as np
from osgeo import gdal
ours = gdal.Open(sys.argv[1] + "/ours/access_minutes.tif").ReadAsArray().astype(float)
grass = gdal.Open(sys.argv[1] + "/rwalk.tif").ReadAsArray().astype(float) / 60
both = np.isfinite(ours) & np.isfinite(grass) & (grass > 0)
ratio = ours[both] / grass[both]
print("cells %d: terrapolis / r.walk time ratio min %.6f median %.6f max %.6f; largest difference %.4f min (of %.1f)"
      % (both.sum(), ratio.min(), np.median(ratio), ratio.max(), np.abs(ours[both] - grass[both]).max(), grass[both].max()))
PY
