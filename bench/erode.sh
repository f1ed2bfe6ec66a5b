#!/usr/bin/env bash
# Erosion benchmark: `terrapolis erode` (hydraulic, thermal, both) on a 513 x 513 crop of an SRTM 3"
# tile and on the whole tile (1201 x 1201): time per iteration (from --report), the hypsometric
# integral (mean - min) / (max - min) before and after (Strahler 1952), and the pits (cells lower
# than all 8 neighbours) before and after. One run per row.
# Usage: bench/erode.sh [TERRAPOLIS_BIN]   (from the repository root)
# Env: THREADS (default 2), ITERATIONS (default 100), DEM (default ../shared/dems/N47E009.hgt).
# SPDX-License-Identifier: MIT
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/timing_setup.sh "$@"
iterations=${ITERATIONS:-100}
dem=${DEM:-../shared/dems/N47E009.hgt}
gdal_translate -q -srcwin 344 344 513 513 -of GTiff "$dem" "$tmp/crop513.tif"

cat >"$tmp/measure.py" <<'PY'
# BEFORE AFTER: hypsometric integral and pits of both (NaN nodata; the border has no pits).
import sys
import numpy as np
from osgeo import gdal
def read(path):
    ds = gdal.Open(path); b = ds.GetRasterBand(1)  # the dataset must outlive its band
    a = b.ReadAsArray().astype(np.float64); nd = b.GetNoDataValue()
    if nd is not None and not np.isnan(nd): a[a == nd] = np.nan
    return a
def hypsometric(a):
    v = a[np.isfinite(a)]; return (v.mean() - v.min()) / (v.max() - v.min())
def pits(a):
    c = a[1:-1, 1:-1]; lower = np.isfinite(c)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            if dr or dc:
                n = a[1 + dr:a.shape[0] - 1 + dr, 1 + dc:a.shape[1] - 1 + dc]
                lower &= np.isfinite(n) & (c < n)
    return int(lower.sum())
a, b = read(sys.argv[1]), read(sys.argv[2])
print("%.4f %.4f %d %d" % (hypsometric(a), hypsometric(b), pits(a), pits(b)))
PY

echo "| DEM | cells | process | iterations | ms / iteration | hypsometric integral before -> after | pits before -> after | eroded m³ | carried out m³ |"
echo "|---|---|---|---|---|---|---|---|---|"
for input in "$tmp/crop513.tif" "$dem"; do
  name=$(basename "$input"); [[ $name == crop513.tif ]] && name="$(basename "$dem") 513² crop"
  size=$(gdalinfo "$input" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1x\2/p')
  for process in hydraulic thermal both; do
    "$bin" -q --threads "$threads" erode "$input" "$tmp/out.tif" --process "$process" --iterations "$iterations" \
      --report "$tmp/report.json" --overwrite
    read -r ms done eroded out < <(/usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print('%.1f %d %.4g %.4g' % (1000*j['seconds_per_iteration'], j['iterations'], j['eroded_m3'], j['carried_out_m3']))" "$tmp/report.json")
    read -r hi0 hi1 p0 p1 < <(/usr/bin/python3 "$tmp/measure.py" "$input" "$tmp/out.tif")
    echo "| $name | $size | $process | $done | $ms | $hi0 -> $hi1 | $p0 -> $p1 | $eroded | $out |"
  done
done
