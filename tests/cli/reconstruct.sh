#!/usr/bin/env bash
# terrapolis reconstruct: from a sparse raster and from lon,lat,z points; bad input fails cleanly.
set -euo pipefail
BIN=$1 SAMPLES=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
DEM=$SAMPLES/whiteboxR_DEM_vermont.tif
/usr/bin/python3 - "$DEM" "$T" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
src = gdal.Open(sys.argv[1]); t = sys.argv[2]
a = src.GetRasterBand(1).ReadAsArray().astype(np.float32)
nd = src.GetRasterBand(1).GetNoDataValue()
valid = a != nd if nd is not None else np.isfinite(a)
rng = np.random.default_rng(1)
keep = (rng.random(a.shape) < 0.05) & valid
ds = gdal.GetDriverByName("GTiff").Create(t + "/sparse.tif", src.RasterXSize, src.RasterYSize, 1, gdal.GDT_Float32)
ds.SetGeoTransform(src.GetGeoTransform()); ds.SetProjection(src.GetProjection())
b = ds.GetRasterBand(1); b.SetNoDataValue(-9999); b.WriteArray(np.where(keep, a, -9999)); ds = None
gt = src.GetGeoTransform()
tr = osr.CoordinateTransformation(src.GetSpatialRef(), osr.SpatialReference(osr.SRS_WKT_WGS84_LAT_LONG))
tr_sr = osr.SpatialReference(); tr_sr.ImportFromEPSG(4326); tr_sr.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
s2 = src.GetSpatialRef(); s2.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
tr = osr.CoordinateTransformation(s2, tr_sr)
with open(t + "/points.csv", "w") as f:
    f.write("lon,lat,z\n")
    for r, c in zip(*np.nonzero(keep)):
        x = gt[0] + (c + 0.5) * gt[1]; y = gt[3] + (r + 0.5) * gt[5]
        lon, lat, _ = tr.TransformPoint(x, y)
        f.write(f"{lon:.9f},{lat:.9f},{a[r, c]}\n")
PY
"$BIN" --quiet reconstruct "$T/sparse.tif" "$T/r.tif"
"$BIN" --quiet reconstruct "$T/points.csv" "$T/p.tif" --like "$DEM"
"$BIN" --quiet reconstruct "$T/points.csv" "$T/d.tif" --like "$DEM" --method dmmc
/usr/bin/python3 - "$DEM" "$T" <<'PY'
import sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1]); t = sys.argv[2]
a = src.GetRasterBand(1).ReadAsArray().astype(float)
nd = src.GetRasterBand(1).GetNoDataValue(); valid = a != nd if nd is not None else np.isfinite(a)
for name, limit in (("r", 25), ("p", 25), ("d", 35)):
    o = gdal.Open(f"{t}/{name}.tif")
    assert o.GetGeoTransform() == src.GetGeoTransform(), name
    b = o.GetRasterBand(1).ReadAsArray().astype(float)
    e = np.sqrt(np.mean((b[valid] - a[valid]) ** 2))
    assert e < limit, f"{name}: rmse {e}"
PY
# GeoJSON points with the height in a property.
cat >"$T/pts.geojson" <<'JSON'
{"type":"FeatureCollection","features":[
{"type":"Feature","properties":{"h":100},"geometry":{"type":"Point","coordinates":[-72.9,44.1]}},
{"type":"Feature","properties":{"h":300},"geometry":{"type":"Point","coordinates":[-72.8,44.15]}},
{"type":"Feature","properties":{"h":200},"geometry":{"type":"Point","coordinates":[-72.85,44.05]}}]}
JSON
"$BIN" --quiet reconstruct "$T/pts.geojson" "$T/g.tif" --like "$DEM" --z-field h
[ -s "$T/g.tif" ]
set +e
"$BIN" reconstruct "$T/pts.geojson" "$T/bad.tif" --like "$DEM" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "z-field" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "missing z field: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" reconstruct "$T/points.csv" "$T/bad.tif" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--like" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "points without grid: rc=$rc"; cat "$T/err"; exit 1; }
printf 'lon,lat,z\n1,2,x\n' >"$T/broken.csv"
"$BIN" reconstruct "$T/broken.csv" "$T/bad.tif" --like "$DEM" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "line 2" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "broken csv: rc=$rc"; cat "$T/err"; exit 1; }
printf 'lon,lat,z\n10,10,5\n' >"$T/far.csv"
"$BIN" reconstruct "$T/far.csv" "$T/bad.tif" --like "$DEM" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "no sample" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "no sample on grid: rc=$rc"; cat "$T/err"; exit 1; }
exit 0
