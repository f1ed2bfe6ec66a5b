#!/usr/bin/env bash
# terrapolis generate: fractal terrain, seeded, constrained by a sketch; bad input fails cleanly.
set -euo pipefail
BIN=$1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$BIN" --quiet generate "$T/a.tif" --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --seed 4 --roughness 500
"$BIN" --quiet --threads 1 generate "$T/b.tif" --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --seed 4 --roughness 500
cmp "$T/a.tif" "$T/b.tif"
"$BIN" --quiet generate "$T/c.tif" --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --seed 5 --roughness 500
! cmp -s "$T/a.tif" "$T/c.tif"
# A sketch: a ridge at 800 m across the grid; the generated terrain keeps it exactly.
/usr/bin/python3 - "$T/sketch.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
ds = gdal.GetDriverByName("GTiff").Create(sys.argv[1], 129, 97, 1, gdal.GDT_Float32)
ds.SetGeoTransform((500000, 30, 0, 5000000, 0, -30))
s = osr.SpatialReference(); s.ImportFromEPSG(32632); ds.SetProjection(s.ExportToWkt())
a = np.full((97, 129), -1, np.float32); a[48, 10:120] = 800
b = ds.GetRasterBand(1); b.SetNoDataValue(-1); b.WriteArray(a); ds = None
PY
"$BIN" --quiet generate "$T/s.tif" --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --constraints "$T/sketch.tif" --roughness 100
/usr/bin/python3 -c "
from osgeo import gdal; import numpy as np, sys
ds = gdal.Open('$T/s.tif'); a = ds.GetRasterBand(1).ReadAsArray()
sys.exit(0 if np.all(a[48, 10:120] == 800) and np.isfinite(a).all() else 1)"
# Alg. 10's bottom-up rule: the sketch still kept exactly, same bytes at 1 thread, the rule in the metadata.
"$BIN" --quiet generate "$T/m.tif" --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --constraints "$T/sketch.tif" --roughness 100 --bottom-up mean
"$BIN" --quiet --threads 1 generate "$T/m1.tif" --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --constraints "$T/sketch.tif" --roughness 100 --bottom-up mean
cmp "$T/m.tif" "$T/m1.tif"
! cmp -s "$T/m.tif" "$T/s.tif"
/usr/bin/python3 -c "
from osgeo import gdal; import numpy as np, sys
ds = gdal.Open('$T/m.tif'); a = ds.GetRasterBand(1).ReadAsArray()
sys.exit(0 if np.all(a[48, 10:120] == 800) and np.isfinite(a).all() and ds.GetMetadataItem('TERRAPOLIS_BOTTOM_UP') == 'mean' else 1)"
# The growing window (Belhadj Alg. 1) from the same sketch: the ridge kept exactly, same bytes at 1 thread.
"$BIN" --quiet generate "$T/w.tif" --method window --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --constraints "$T/sketch.tif" --roughness 100
"$BIN" --quiet --threads 1 generate "$T/w1.tif" --method window --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --constraints "$T/sketch.tif" --roughness 100
cmp "$T/w.tif" "$T/w1.tif"
/usr/bin/python3 -c "
from osgeo import gdal; import numpy as np, sys
ds = gdal.Open('$T/w.tif'); a = ds.GetRasterBand(1).ReadAsArray()
sys.exit(0 if np.all(a[48, 10:120] == 800) and np.isfinite(a).all() and ds.GetMetadataItem('TERRAPOLIS_GENERATOR') == 'window' else 1)"
/usr/bin/python3 - "$T/empty_sketch.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
ds = gdal.GetDriverByName("GTiff").Create(sys.argv[1], 129, 97, 1, gdal.GDT_Float32)
ds.SetGeoTransform((500000, 30, 0, 5000000, 0, -30))
s = osr.SpatialReference(); s.ImportFromEPSG(32632); ds.SetProjection(s.ExportToWkt())
b = ds.GetRasterBand(1); b.SetNoDataValue(-1); b.WriteArray(np.full((97, 129), -1, np.float32)); ds = None
PY
set +e
"$BIN" generate "$T/bad.tif" --method window --size 65x65 --cell 30 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && [ $(wc -l <"$T/err") -eq 1 ] && grep -q -- "--method window: needs --constraints" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "window without sketch: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --method window --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --constraints "$T/empty_sketch.tif" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "has no cell with a value" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "window, empty sketch: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --method window --size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --constraints "$T/sketch.tif" --shape 2 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--shape: not used by --method window" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "window with --shape: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --size 65x65 --cell 30 --bottom-up mean --shape-up 1 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--shape-up: needs --bottom-up weighted" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "mean with shape-up: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --size 65x65 --cell 30 --bottom-up thesis 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--bottom-up" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "unknown rule: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --size 12 --cell 30 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--size" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "bad size: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --size 10x10 --cell 30 --crs EPSG:4326 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "geographic" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "geographic crs: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --size 10x10 --cell 30 --hurst 3 2>"$T/err"; rc=$?
[ $rc -ne 0 ] && [ ! -e "$T/bad.tif" ] || { echo "bad hurst: rc=$rc"; exit 1; }
# A grid larger than the Earth, or outside its CRS's domain, is refused like a raster read with that georeferencing.
for method in dmmc coast flow; do
  "$BIN" generate "$T/bad.tif" --method $method --size 65x65 --cell 1e12 2>"$T/err"; rc=$?
  [ $rc -eq 2 ] && grep -q "larger than the Earth" "$T/err" && ! grep -q -- "--origin" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "$method huge cell: rc=$rc"; cat "$T/err"; exit 1; }
done
"$BIN" generate "$T/bad.tif" --size 65x65 --cell 30 --crs EPSG:32632 --origin 9e7,0 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--origin 9e7,0.*cannot be transformed" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "origin off the CRS: rc=$rc"; cat "$T/err"; exit 1; }
# A region that holds a single river reach (no Voronoi vertex) crashed the coast method.
"$BIN" generate "$T/one_reach.tif" --method coast --seed 11 --size 193x161 --cell 30 2>"$T/err" >/dev/null || { echo "coast, one reach: rc=$?"; cat "$T/err"; exit 1; }
[ -s "$T/one_reach.tif" ] || { echo "coast, one reach: no output"; exit 1; }
exit 0
