#!/usr/bin/env bash
# terrapolis generate --labels: river cells of a sketch extrapolate up, ridge cells down (Belhadj
# §5.1.1); without labels nothing changes; bad labels fail cleanly.
set -euo pipefail
BIN=$1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
grid=(--size 129x97 --cell 30 --crs EPSG:32632 --origin 500000,5000000 --roughness 0)
# A valley line at 200 m (row 30) and a ridge line at 800 m (row 66); labels 1 on the valley, 2 on the ridge.
/usr/bin/python3 - "$T" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
def write(path, a, nodata, kind=gdal.GDT_Float32, crs=True):
    ds = gdal.GetDriverByName("GTiff").Create(path, a.shape[1], a.shape[0], 1, kind)
    # Without a CRS the file is read as lon/lat (only its size matters then).
    ds.SetGeoTransform((500000, 30, 0, 5000000, 0, -30) if crs else (0, 0.001, 0, 10, 0, -0.001))
    if crs:
        s = osr.SpatialReference(); s.ImportFromEPSG(32632); ds.SetProjection(s.ExportToWkt())
    b = ds.GetRasterBand(1)
    if nodata is not None: b.SetNoDataValue(nodata)
    b.WriteArray(a); ds = None
sketch = np.full((97, 129), -1, np.float32); sketch[30, 10:120] = 200; sketch[66, 10:120] = 800
write(sys.argv[1] + "/sketch.tif", sketch, -1)
labels = np.zeros((97, 129), np.uint8); labels[30, 10:120] = 1; labels[66, 10:120] = 2
write(sys.argv[1] + "/labels.tif", labels, 255, gdal.GDT_Byte)
write(sys.argv[1] + "/zeros.tif", np.zeros((97, 129), np.uint8), None, gdal.GDT_Byte)
bad = labels.copy(); bad[5, 7] = 3
write(sys.argv[1] + "/bad_value.tif", bad, 255, gdal.GDT_Byte)
write(sys.argv[1] + "/small.tif", np.zeros((10, 10), np.uint8), None, gdal.GDT_Byte, crs=False)
PY
gen() { "$BIN" --quiet "$@"; }
gen generate "$T/down.tif" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up 4
gen generate "$T/up.tif" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up -4
gen generate "$T/lab.tif" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up 4 --labels "$T/labels.tif"
gen --threads 1 generate "$T/lab1.tif" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up 4 --labels "$T/labels.tif"
cmp "$T/lab.tif" "$T/lab1.tif"
gen generate "$T/labneg.tif" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up -4 --labels "$T/labels.tif"
gen generate "$T/zero_labels.tif" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up 4 --labels "$T/zeros.tif"
/usr/bin/python3 - "$T" <<'PY'
import sys
import numpy as np
from osgeo import gdal
t = sys.argv[1]
def read(name):
    ds = gdal.Open(t + "/" + name + ".tif"); return ds.GetRasterBand(1).ReadAsArray().astype(np.float64), ds.GetMetadata()
down, _ = read("down"); up, _ = read("up"); lab, md = read("lab"); labneg, _ = read("labneg"); zeros, _ = read("zero_labels")
problems = []
for name, a in (("labels", lab), ("labels, negative --shape-up", labneg)):
    if not (np.all(a[30, 10:120] == 200) and np.all(a[66, 10:120] == 800) and np.isfinite(a).all()):
        problems.append(name + ": the sketch is not kept")
# The sign of --shape-up does not matter once every sketch cell has a label: |I_-1| does.
if not np.array_equal(lab, labneg): problems.append("labelled outputs differ with the sign of --shape-up")
# Beside the valley (rows 22-29 and 31-38, between its ends) the river label lifts the terrain above
# what the global I_-1 = 4 (down) gives; beside the ridge the ridge label keeps it below the global
# I_-1 = -4 (up).
valley = np.r_[22:30, 31:39]; ridge = np.r_[58:66, 67:75]
v_lab, v_down = lab[valley, 10:120].mean(), down[valley, 10:120].mean()
r_lab, r_up = lab[ridge, 10:120].mean(), up[ridge, 10:120].mean()
print("beside the valley: labels %.1f m, --shape-up 4 %.1f m; beside the ridge: labels %.1f m, --shape-up -4 %.1f m" % (v_lab, v_down, r_lab, r_up))
if not v_lab > v_down: problems.append("river label does not lift the valley's sides")
if not r_lab < r_up: problems.append("ridge label does not lower the ridge's sides")
if md.get("TERRAPOLIS_LABELS") != "110 river cells, 110 ridge cells": problems.append("metadata %r" % md.get("TERRAPOLIS_LABELS"))
# Labels of 0 everywhere are the global rule: the same heights as no labels.
if not np.array_equal(zeros, down): problems.append("all-zero labels change the heights")
if problems: print("\n".join(problems)); sys.exit(1)
PY
# Bad input: one line, exit code 2, no output.
refuse() {  # EXPECTED-MESSAGE ARGS...
  local expected=$1; shift
  set +e; "$BIN" generate "$T/bad.tif" "$@" 2>"$T/err"; local rc=$?; set -e
  [ $rc -eq 2 ] && [ "$(wc -l <"$T/err")" -eq 1 ] && grep -q -- "$expected" "$T/err" && [ ! -e "$T/bad.tif" ] ||
    { echo "expected '$expected', got rc=$rc:"; cat "$T/err"; exit 1; }
}
refuse "--labels: needs --constraints" "${grid[@]}" --shape-up 4 --labels "$T/labels.tif"
refuse "--labels: needs --shape-up" "${grid[@]}" --constraints "$T/sketch.tif" --labels "$T/labels.tif"
refuse "--labels: needs --bottom-up weighted" "${grid[@]}" --constraints "$T/sketch.tif" --bottom-up mean --labels "$T/labels.tif"
refuse "--labels: only --method dmmc" --method window "${grid[@]}" --constraints "$T/sketch.tif" --labels "$T/labels.tif"
refuse "--labels: only --method dmmc" --method flow --size 129x97 --cell 30 --labels "$T/labels.tif"
refuse "cell 7,5 holds 3" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up 4 --labels "$T/bad_value.tif"
refuse "small.tif: is 10x10 cells" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up 4 --labels "$T/small.tif"
refuse "missing.tif" "${grid[@]}" --constraints "$T/sketch.tif" --shape-up 4 --labels "$T/missing.tif"
echo ok
