#!/usr/bin/env bash
# terrapolis fill: a real DEM with a punched void is repaired, georeferencing kept; bad input fails cleanly.
set -euo pipefail
BIN=$1 SAMPLES=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# Punch a 12x10 void into the Vermont DEM (UTM, 90 m).
gdal_translate -q -of GTiff -ot Float32 -a_nodata -9999 "$SAMPLES/whiteboxR_DEM_vermont.tif" "$T/src.tif"
/usr/bin/python3 - "$T/src.tif" <<'PY'
import sys
from osgeo import gdal
ds = gdal.Open(sys.argv[1], gdal.GA_Update)
b = ds.GetRasterBand(1)
a = b.ReadAsArray()
a[40:50, 60:72] = -9999
b.WriteArray(a)
ds = None
PY
for m in thin-plate harmonic dmmc; do
  "$BIN" --quiet fill "$T/src.tif" "$T/out_$m.tif" --method "$m"
  /usr/bin/python3 - "$T/src.tif" "$T/out_$m.tif" "$SAMPLES/whiteboxR_DEM_vermont.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal
src, out, orig = (gdal.Open(p) for p in sys.argv[1:4])
a = src.GetRasterBand(1).ReadAsArray(); o = out.GetRasterBand(1).ReadAsArray(); t = orig.GetRasterBand(1).ReadAsArray().astype(float)
assert out.GetGeoTransform() == src.GetGeoTransform(), "geotransform changed"
assert out.GetSpatialRef().IsSame(src.GetSpatialRef()), "CRS changed"
hole = a == -9999
known = ~hole & (a != -9999)
assert np.array_equal(o[known], a[known]), "known cells changed"
nd = out.GetRasterBand(1).GetNoDataValue()
assert not np.isnan(o[hole]).any() and (nd is None or not (o[hole] == nd).any()), "void not filled"
err = np.sqrt(np.mean((o[hole] - t[hole]) ** 2))
assert err < 60, f"error {err} m too large"
PY
done
# Byte-identical whatever the thread count.
"$BIN" --quiet --threads 1 fill "$T/src.tif" "$T/t1.tif" --method dmmc --roughness 20 --seed 3
"$BIN" --quiet --threads 2 fill "$T/src.tif" "$T/t2.tif" --method dmmc --roughness 20 --seed 3
cmp "$T/t1.tif" "$T/t2.tif"
# The Luxembourg DEM's nodata border is outside the DEM, not a void: it stays nodata.
"$BIN" --quiet fill "$SAMPLES/terra_elev_luxembourg.tif" "$T/lux.tif"
/usr/bin/python3 - "$SAMPLES/terra_elev_luxembourg.tif" "$T/lux.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal
def nodata(p):
    ds = gdal.Open(p); b = ds.GetRasterBand(1); a = b.ReadAsArray().astype(float); nd = b.GetNoDataValue()
    return np.isnan(a) | (a == nd) if nd is not None else np.isnan(a)
assert nodata(sys.argv[1])[0, 0] and nodata(sys.argv[2])[0, 0], "border nodata was filled"
PY
# A void limit: the 120-cell void (about 0.97 km2) stays when the limit is 0.5 km2.
"$BIN" --quiet fill "$T/src.tif" "$T/lim.tif" --max-void-km2 0.5
/usr/bin/python3 -c "
from osgeo import gdal; import sys
ds = gdal.Open('$T/lim.tif'); b = ds.GetRasterBand(1); a = b.ReadAsArray()
sys.exit(0 if a[45, 65] == b.GetNoDataValue() or a[45, 65] != a[45, 65] else 1)"
# --sea-level (the schema's water.sea_level_m): with every cell below it the whole grid is sea,
# and a void in the sea stays a void.
"$BIN" --quiet fill "$T/src.tif" "$T/sea.tif" --sea-level 8000
/usr/bin/python3 -c "
from osgeo import gdal; import sys
ds = gdal.Open('$T/sea.tif'); b = ds.GetRasterBand(1); a = b.ReadAsArray()
sys.exit(0 if a[45, 65] == b.GetNoDataValue() or a[45, 65] != a[45, 65] else 1)" || { echo "a void in the sea was filled"; exit 1; }
# Bad input: exit 2, one line naming the problem, no output left.
set +e
"$BIN" fill "$T/missing.tif" "$T/bad.tif" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "missing.tif" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "missing input: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" fill "$T/src.tif" "$T/bad.tif" --method kriging 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "kriging" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "bad method: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" fill "$T/src.tif" "$T/out_dmmc.tif" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || { echo "existing output without --overwrite: rc=$rc"; exit 1; }
"$BIN" fill "$T/src.tif" "$T/nodir/x.tif" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || { echo "missing folder: rc=$rc"; exit 1; }
exit 0
