#!/usr/bin/env bash
# `terrapolis erode` on a real DEM: the grid, CRS and provenance kept, the report's mass balance,
# zero iterations copy the DEM, any thread count gives the same bytes, nodata and the mask are
# honoured, the layered ground (Peytavie 2010 §2.3) balances its loose volume, and bad input is
# refused with one line and nothing written.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK
dem=$samples/spDataLarge_dem_mongon.tif  # UTM 17S, 30 m, 117 x 117

"$bin" -q erode "$dem" "$work/out.tif" --iterations 40 --report "$work/out.json"
grep -q "Size is 117, 117" <(gdalinfo "$work/out.tif") || fail "grid not kept"
grep -q "Type=Float32" <(gdalinfo "$work/out.tif") || fail "not float32"
[[ "$(gdalsrsinfo -o wkt1 "$dem")" == "$(gdalsrsinfo -o wkt1 "$work/out.tif")" ]] || fail "CRS not kept"
grep -q "TERRAPOLIS_COMMAND=erode" <(gdalinfo "$work/out.tif") || fail "no provenance"
/usr/bin/python3 - "$dem" "$work/out.tif" "$work/out.json" <<'PY'
import json, sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1]); gt = src.GetGeoTransform(); area = gt[1] * -gt[5]  # UTM metres
a = src.ReadAsArray().astype(float); b = gdal.Open(sys.argv[2]).ReadAsArray().astype(float)
j = json.load(open(sys.argv[3]))
assert j["iterations"] == 40 and j["eroded_m3"] > 0, j
d = (b - a) * area  # m3 per cell
assert abs(d[d < 0].sum() + j["eroded_m3"]) < 1e-6 * j["eroded_m3"] + 1, (d[d < 0].sum(), j)
assert abs(d[d > 0].sum() - j["deposited_m3"]) < 1e-6 * j["eroded_m3"] + 1, (d[d > 0].sum(), j)
tol = np.abs(a).sum() * area * 2.0 ** -23  # float32 rounding of the heights written
assert abs(j["eroded_m3"] - j["deposited_m3"] - j["carried_out_m3"]) <= tol, j
assert abs(j["max_lowering_m"] + (b - a).min()) < 1e-9 and abs(j["max_raising_m"] - (b - a).max()) < 1e-9, j
PY

# Zero iterations: the DEM itself; one and two threads: the same bytes.
"$bin" -q erode "$dem" "$work/zero.tif" --iterations 0
same_cells "$dem" "$work/zero.tif" || fail "--iterations 0 changed the DEM"
"$bin" -q --threads 1 erode "$dem" "$work/t1.tif" --iterations 20
"$bin" -q --threads 2 erode "$dem" "$work/t2.tif" --iterations 20
cmp -s "$work/t1.tif" "$work/t2.tif" || fail "--threads 1 and 2 differ"

# Nodata stays nodata; outside the mask (the eastern half) heights are fixed.
/usr/bin/python3 - "$dem" "$work/holed.tif" "$work/mask.tif" <<'PY'
import sys
from osgeo import gdal
src = gdal.Open(sys.argv[1])
holed = gdal.GetDriverByName("GTiff").CreateCopy(sys.argv[2], src)
a = holed.GetRasterBand(1).ReadAsArray(); a[50:60, 40:70] = -9999
holed.GetRasterBand(1).SetNoDataValue(-9999); holed.GetRasterBand(1).WriteArray(a); holed = None
mask = gdal.GetDriverByName("GTiff").CreateCopy(sys.argv[3], src)
m = mask.GetRasterBand(1).ReadAsArray() * 0; m[:, :58] = 1
mask.GetRasterBand(1).DeleteNoDataValue(); mask.GetRasterBand(1).WriteArray(m); mask = None
PY
"$bin" -q erode "$work/holed.tif" "$work/holed_out.tif" --iterations 30 --mask "$work/mask.tif"
/usr/bin/python3 - "$work/holed.tif" "$work/holed_out.tif" <<'PY'
import sys
import numpy as np
from osgeo import gdal
a = gdal.Open(sys.argv[1]).ReadAsArray(); b = gdal.Open(sys.argv[2]).ReadAsArray()
hole = a == -9999
assert np.isnan(b[hole]).all() and not np.isnan(b[~hole]).any(), "nodata not kept"
assert np.array_equal(a[:, 58:][~hole[:, 58:]], b[:, 58:][~hole[:, 58:]]), "cells outside the mask changed"
assert (a[:, :58] != b[:, :58]).sum() > 1000, "nothing eroded inside the mask"
PY

# Layered: a loose cover and a rockfall in the middle; the surface balances, the loose volume at the
# end is the loose volume at the start plus the rock loosened, 1 and 2 threads give the same bytes.
/usr/bin/python3 - "$dem" "$work/loose.tif" "$work/rockfall.tif" <<'PY'
import sys
from osgeo import gdal
src = gdal.Open(sys.argv[1])
for path, value in ((sys.argv[2], 0.5), (sys.argv[3], 0.0)):
    out = gdal.GetDriverByName("GTiff").CreateCopy(path, src)
    a = out.GetRasterBand(1).ReadAsArray() * 0 + value
    if value == 0: a[50:60, 50:60] = 6
    out.GetRasterBand(1).DeleteNoDataValue(); out.GetRasterBand(1).WriteArray(a); out = None
PY
for t in 1 2; do
  "$bin" -q --threads $t erode "$dem" "$work/layered$t.tif" --process layered --iterations 30 --erodibility 0.2 --strata 20 \
    --loose "$work/loose.tif" --rockfall "$work/rockfall.tif" --loose-out "$work/scree$t.tif" --report "$work/layered$t.json"
done
cmp -s "$work/layered1.tif" "$work/layered2.tif" && cmp -s "$work/scree1.tif" "$work/scree2.tif" || fail "layered: --threads 1 and 2 differ"
/usr/bin/python3 - "$dem" "$work/layered1.tif" "$work/scree1.tif" "$work/layered1.json" <<'PY'
import json, sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1]); gt = src.GetGeoTransform(); area = gt[1] * -gt[5]
a = src.ReadAsArray().astype(float); b = gdal.Open(sys.argv[2]).ReadAsArray().astype(float)
scree = gdal.Open(sys.argv[3]).ReadAsArray().astype(float); j = json.load(open(sys.argv[4]))
tol = np.abs(a).sum() * area * 2.0 ** -23
assert j["carried_out_m3"] == 0 and j["eroded_m3"] > 0 and abs(j["eroded_m3"] - j["deposited_m3"]) <= tol, j
assert j["loosened_m3"] > 100 * 6 * area * 1.5, j  # the rockfall and more weathered rock
loose_start = 0.5 * area * a.size
assert abs(scree.sum() * area - loose_start - j["loosened_m3"]) <= tol, (scree.sum() * area, loose_start, j)
assert scree.min() >= 0, scree.min()
PY

# Refused: one line naming the file or flag, exit 2, nothing written.
expect_refused "$work/bad.tif" "missing.tif" "$bin" erode "$work/missing.tif" "$work/bad.tif"
expect_refused "$work/bad.tif" "^terrapolis: error: --material" "$bin" erode "$dem" "$work/bad.tif" --material gravel
expect_refused "$work/bad.tif" "--dissolve" "$bin" erode "$dem" "$work/bad.tif" --dissolve 5
expect_refused "$work/bad.tif" "--angle" "$bin" erode "$dem" "$work/bad.tif" --angle 95
expect_refused "$work/bad.tif" "--iterations" "$bin" erode "$dem" "$work/bad.tif" --iterations -3
expect_refused "$work/bad.tif" "nomask.tif" "$bin" erode "$dem" "$work/bad.tif" --mask "$work/nomask.tif"
expect_refused "$work/bad.tif" "--erodibility" "$bin" erode "$dem" "$work/bad.tif" --process layered --erodibility 2
expect_refused "$work/bad.tif" "--radius: .* at most 25" "$bin" erode "$dem" "$work/bad.tif" --process layered --radius 900
[[ $(wc -l <"$work/stderr") -eq 1 ]] || fail "more than one line: $(cat "$work/stderr")"
expect_fail 2 "out.tif" "$bin" erode "$dem" "$work/out.tif"  # exists, no --overwrite
"$bin" -q erode "$dem" "$work/out.tif" --iterations 2 --overwrite
no_leftovers "$work"
echo "erode: ok"
