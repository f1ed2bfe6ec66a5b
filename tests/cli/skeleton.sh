#!/usr/bin/env bash
# `terrapolis skeleton` (Belhadj 2007 §5.2.2) on a real SRTM DEM: the docs' example, the lines on
# their kept cells with geodesic lengths and reliefs, the lattice, nodata honoured, the
# reconstruction round trip against random sampling at the same share, and the refusals.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK
zion=$samples/spDataLarge_srtm_zion.tif

# The documented example (docs/skeleton.md).
"$bin" -q skeleton "$zion" "$work/zion"
for f in ridges.geojson valleys.geojson ridges.qml valleys.qml skeleton.tif form_index.tif skeleton.json; do
  [[ -s $work/zion/$f ]] || fail "missing $f"
done
[[ "$(gdalsrsinfo -o wkt1 "$zion")" == "$(gdalsrsinfo -o wkt1 "$work/zion/skeleton.tif")" ]] || fail "CRS not kept"
grep -q "Size is 465, 457" <(gdalinfo "$work/zion/skeleton.tif") || fail "grid not kept"

# Every vertex lies on a cell of the DEM's sign of form index; every 3rd vertex from the first, and
# the last, is kept with the DEM's height, and so is every valid cell of the lattice (every 6th cell
# of every 6th row, from the 3rd), nothing else; lengths are geodesic (pyproj on WGS 84) and reliefs
# are the spread of the DEM's heights along the line; the report counts what was written.
/usr/bin/python3 - "$zion" "$work/zion" <<'EOF'
import json, sys, math
import numpy as np
from osgeo import gdal
from pyproj import Geod
dem_ds = gdal.Open(sys.argv[1]); folder = sys.argv[2]
dem = dem_ds.GetRasterBand(1).ReadAsArray().astype(float)
nodata = dem_ds.GetRasterBand(1).GetNoDataValue()
def band(path):  # the dataset must outlive its band
    ds = gdal.Open(path); return ds.GetRasterBand(1).ReadAsArray()
kept = band(folder + "/skeleton.tif")
index = band(folder + "/form_index.tif")
gt = dem_ds.GetGeoTransform()
geod = Geod(ellps="WGS84")
report = json.load(open(folder + "/skeleton.json"))
on_lines = set()
for layer, sign in (("ridges", 1), ("valleys", -1)):
    features = json.load(open(folder + "/" + layer + ".geojson"))["features"]
    assert len(features) == report[layer] > 50, (layer, len(features))
    for f in features:
        assert f["geometry"]["type"] == "LineString"
        pts = f["geometry"]["coordinates"]
        p = f["properties"]
        assert p["cells"] == len(pts) >= 3
        zs = []
        for j, (lon, lat) in enumerate(pts):
            c, r = int((lon - gt[0]) / gt[1]), int((lat - gt[3]) / gt[5])
            assert dem[r, c] != nodata, (layer, lon, lat)
            if j % 3 == 0 or j == len(pts) - 1:
                assert kept[r, c] == dem[r, c], (layer, lon, lat)
                on_lines.add((r, c))
            assert sign * index[r, c] > 0, (layer, index[r, c])
            zs.append(dem[r, c])
        length = sum(geod.inv(*pts[i], *pts[i + 1])[2] for i in range(len(pts) - 1))
        assert abs(length - p["length_m"]) < 1e-4 * length + 0.05, (length, p["length_m"])  # GeoJSON keeps 7 decimals
        assert abs(max(zs) - min(zs) - p["relief_m"]) < 1e-3, p
lattice = np.zeros(dem.shape, bool); lattice[3::6, 3::6] = True; lattice &= dem != nodata
expected = lattice.copy()
for r, c in on_lines: expected[r, c] = True
assert (np.isfinite(kept) == expected).all(), "kept cells are not the lines' and the lattice's"
assert (kept[expected] == dem[expected]).all()
kept_cells = int(np.isfinite(kept).sum())
assert kept_cells == report["kept_cells"] and report["line_cells"] == len(on_lines) and report["lattice_cells"] == lattice.sum()
valid = int((dem != nodata).sum())
assert report["valid_cells"] == valid and abs(report["kept_share"] - kept_cells / valid) < 1e-12
assert 0.03 < report["kept_share"] < 0.045, report  # 3.7 %: 1.0 % on the lines, 2.8 % on the lattice (docs/skeleton.md)
print("zion: %d ridges, %d valleys, %.1f %% kept" % (report["ridges"], report["valleys"], 100 * report["kept_share"]))
EOF

# Same outputs again, byte for byte, on one thread.
"$bin" -q --threads 1 skeleton "$zion" "$work/zion1"
for f in ridges.geojson valleys.geojson skeleton.tif form_index.tif; do
  cmp -s "$work/zion/$f" "$work/zion1/$f" || fail "$f differs on one thread"
done

# The round trip: reconstruct from the kept cells, and from as many random valid cells (seed 7;
# RMSE over the valid cells, in metres). With the defaults (every 3rd line cell and the lattice) the
# skeleton must rebuild the DEM closer than random cells; in the thesis's literal form (every line
# cell, no lattice) it does not: random cells do twice better (docs/skeleton.md).
"$bin" -q skeleton "$zion" "$work/literal" --lattice 0 --line-step 1
grep -q '"lattice_cells": 0' "$work/literal/skeleton.json" || fail "--lattice 0 kept lattice cells"
for run in zion literal; do
  "$bin" -q reconstruct "$work/$run/skeleton.tif" "$work/$run/rebuilt.tif"
  /usr/bin/python3 - "$zion" "$work/$run" <<'EOF'
import sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1]); folder = sys.argv[2]
a = src.GetRasterBand(1).ReadAsArray().astype(np.float32)
valid = a != src.GetRasterBand(1).GetNoDataValue()
ks = gdal.Open(folder + "/skeleton.tif")
kept = np.isfinite(ks.GetRasterBand(1).ReadAsArray())
pick = np.random.default_rng(7).choice(np.flatnonzero(valid), int(kept.sum()), replace=False)
random = np.full(a.size, np.nan, np.float32); random[pick] = a.flat[pick]
ds = gdal.GetDriverByName("GTiff").Create(folder + "/random.tif", src.RasterXSize, src.RasterYSize, 1, gdal.GDT_Float32)
ds.SetGeoTransform(src.GetGeoTransform()); ds.SetProjection(src.GetProjection())
b = ds.GetRasterBand(1); b.SetNoDataValue(float("nan")); b.WriteArray(random.reshape(a.shape)); ds = None
EOF
  "$bin" -q reconstruct "$work/$run/random.tif" "$work/$run/from_random.tif"
  /usr/bin/python3 - "$zion" "$work/$run" "$run" <<'EOF'
import json, sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1]); folder, run = sys.argv[2], sys.argv[3]
a = src.GetRasterBand(1).ReadAsArray().astype(np.float64)
valid = a != src.GetRasterBand(1).GetNoDataValue()
def band(path):
    ds = gdal.Open(path); return ds.GetRasterBand(1).ReadAsArray().astype(np.float64)
def rmse(path):
    b = band(path)
    assert np.isfinite(b[valid]).all()
    return float(np.sqrt(np.mean((b[valid] - a[valid]) ** 2)))
s, r = rmse(folder + "/rebuilt.tif"), rmse(folder + "/from_random.tif")
share = json.load(open(folder + "/skeleton.json"))["kept_share"]
print("zion %s: %.1f %% kept, RMSE %.2f m from the skeleton, %.2f m from random cells" % (run, 100 * share, s, r))
kept, rebuilt = band(folder + "/skeleton.tif"), band(folder + "/rebuilt.tif")
on = np.isfinite(kept)
assert np.abs(rebuilt[on] - kept[on]).max() < 0.5, "the kept heights are not honoured"
if run == "zion":
    assert s < 0.9 * r, (s, r)  # docs/skeleton.md: 31.0 m against 40.9 m
else:
    assert abs(s - 112.1) < 3 and 50 < r < 70, (s, r)
EOF
done

# Nodata honoured: Luxembourg's 30" grid is nodata outside the country; no line enters it.
lux=$samples/terra_elev_luxembourg.tif
"$bin" -q skeleton "$lux" "$work/lux" --lines valleys --tolerance 0.2
/usr/bin/python3 - "$lux" "$work/lux" <<'EOF'
import json, sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1]); folder = sys.argv[2]
a = src.GetRasterBand(1).ReadAsArray()
ks = gdal.Open(folder + "/skeleton.tif")
kept = ks.GetRasterBand(1).ReadAsArray()
assert not np.isfinite(kept[a == src.GetRasterBand(1).GetNoDataValue()]).any()
r = json.load(open(folder + "/skeleton.json"))
assert r["ridges"] == 0 and r["valleys"] > 0 and r["options"]["tolerance"] == 0.2, r
assert json.load(open(folder + "/ridges.geojson"))["features"] == []
EOF

# Existing outputs are refused and kept; --overwrite replaces them.
before=$(md5sum <"$work/zion/skeleton.json")
expect_fail 2 "exists" "$bin" -q skeleton "$zion" "$work/zion" --lines ridges
[[ $(md5sum <"$work/zion/skeleton.json") == "$before" ]] || fail "refused run changed skeleton.json"
"$bin" -q skeleton "$zion" "$work/zion" --lines ridges --overwrite
grep -q '"valleys": 0' "$work/zion/skeleton.json" || fail "--overwrite did not replace"

# Refusals: exit 2, one line, no output folder.
echo "not a DEM" >"$work/text.tif"
expect_refused "$work/no" "text.tif" "$bin" -q skeleton "$work/text.tif" "$work/no"
expect_refused "$work/no" "missing.tif" "$bin" -q skeleton "$work/missing.tif" "$work/no"
expect_refused "$work/no" "--tolerance" "$bin" -q skeleton "$zion" "$work/no" --tolerance 2
expect_refused "$work/no" "--lines" "$bin" -q skeleton "$zion" "$work/no" --lines crests
expect_refused "$work/no" "--min-cells" "$bin" -q skeleton "$zion" "$work/no" --min-cells 1
expect_refused "$work/no" "--lattice" "$bin" -q skeleton "$zion" "$work/no" --lattice -1
expect_refused "$work/no" "--line-step" "$bin" -q skeleton "$zion" "$work/no" --line-step 0
expect_refused "$work/no/deeper" "" "$bin" -q skeleton "$zion" "$work/no/deeper"
no_leftovers "$work"
echo ok
