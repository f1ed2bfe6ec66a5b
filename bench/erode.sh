#!/usr/bin/env bash
# Erosion benchmark: `terrapolis erode` (hydraulic, thermal, both, layered) on a 513 x 513 crop of an SRTM 3"
# tile and on the whole tile (1201 x 1201): time per iteration (from --report), the hypsometric
# integral (mean - min) / (max - min) before and after (Strahler 1952), and the pits (cells lower
# than all 8 neighbours) before and after. One run per row.
# The drainage part: on a generated region (generate --method flow, 513², seed 1) and on two shared
# DEMs (Zion, the same 513² crop), the hypsometric integral, the drainage density (km of
# `terrapolis hydro` streams at its default 10 km² per km² of grid) and the pits, before and after
# erode at the defaults, each process alone and a stronger setting (STRONG), and on the generated region the D8 share
# of the generator's rivers the way its report computes it (river_checks.cpp: d8_consistency).
# Usage: bench/erode.sh [TERRAPOLIS_BIN] [timing|drainage]   (from the repository root; both if
# no part is named)
# Env: THREADS (default 2), ITERATIONS (default 100), DEM (default ../shared/dems/N47E009.hgt),
# STRONG (default "--capacity 0.02": ten times the sediment capacity).
# SPDX-License-Identifier: MIT
set -euo pipefail
cd "$(dirname "$0")/.."
source bench/timing_setup.sh "$@"
part=${2:-all}
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

if [[ $part == all || $part == timing ]]; then
echo "| DEM | cells | process | iterations | ms / iteration | hypsometric integral before -> after | pits before -> after | eroded m³ | carried out m³ |"
echo "|---|---|---|---|---|---|---|---|---|"
for input in "$tmp/crop513.tif" "$dem"; do
  name=$(basename "$input"); [[ $name == crop513.tif ]] && name="$(basename "$dem") 513² crop"
  size=$(gdalinfo "$input" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1x\2/p')
  for process in hydraulic thermal both layered; do
    "$bin" -q --threads "$threads" erode "$input" "$tmp/out.tif" --process "$process" --iterations "$iterations" \
      --report "$tmp/report.json" --overwrite
    read -r ms done eroded out < <(/usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print('%.1f %d %.4g %.4g' % (1000*j['seconds_per_iteration'], j['iterations'], j['eroded_m3'], j['carried_out_m3']))" "$tmp/report.json")
    read -r hi0 hi1 p0 p1 < <(/usr/bin/python3 "$tmp/measure.py" "$input" "$tmp/out.tif")
    echo "| $name | $size | $process | $done | $ms | $hi0 -> $hi1 | $p0 -> $p1 | $eroded | $out |"
  done
done
fi

[[ $part == all || $part == drainage ]] || exit 0
strong=${STRONG:---capacity 0.02}
cat >"$tmp/drainage.py" <<'PY'
# DEM STREAMS.geojson: drainage density, km of streams per km² of finite cells (geodesic cell areas
# on geographic grids: the exact area of an ellipsoidal quadrangle, WGS 84).
import json, math, sys
import numpy as np
from osgeo import gdal, osr
ds = gdal.Open(sys.argv[1]); b = ds.GetRasterBand(1)
a = b.ReadAsArray().astype(np.float64); nd = b.GetNoDataValue()
finite = np.isfinite(a) & ((a != nd) if nd is not None and not np.isnan(nd) else True)
gt = ds.GetGeoTransform(); srs = osr.SpatialReference(wkt=ds.GetProjection())
if srs.IsGeographic():
    A, F = srs.GetSemiMajor(), 1 / srs.GetInvFlattening(); e = math.sqrt(F * (2 - F)); b2 = (A * (1 - F)) ** 2
    def f(phi):
        s = math.sin(math.radians(phi))
        return s / (1 - e * e * s * s) + math.log((1 + e * s) / (1 - e * s)) / (2 * e)
    dlon = math.radians(abs(gt[1]))
    rows = np.array([b2 * dlon / 2 * abs(f(gt[3] + gt[5] * r) - f(gt[3] + gt[5] * (r + 1))) for r in range(a.shape[0])])
    area_m2 = float((finite.sum(axis=1) * rows).sum())
else:
    u = srs.GetLinearUnits(); area_m2 = float(finite.sum()) * abs(gt[1] * gt[5]) * u * u
km = sum(f["properties"]["length_m"] for f in json.load(open(sys.argv[2]))["features"]) / 1000
print("%.4f" % (km / (area_m2 / 1e6)))
PY
cat >"$tmp/d8share.py" <<'PY'
# DEM.tif SKELETON.geojson STREAMS.geojson: the share of the generator's river length within 2 cells
# of a D8 stream of the same or adjacent Strahler order, sampled every half cell, as d8_consistency
# (src/generate/river_checks.cpp) computes it; tests/cli/generate_methods.sh checks it against the report.
import math, sys
import numpy as np
from osgeo import gdal, ogr, osr
ds = gdal.Open(sys.argv[1]); gt, cols, rows = ds.GetGeoTransform(), ds.RasterXSize, ds.RasterYSize
srs = osr.SpatialReference(); srs.ImportFromWkt(ds.GetProjection()); srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
near = lambda v: int(math.floor(v + 0.5))
def lines(path, kind=None):
    source = ogr.Open(path); layer = source.GetLayer()
    src = layer.GetSpatialRef(); src.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    tr = osr.CoordinateTransformation(src, srs)
    for f in layer:
        if kind and f.GetField("kind") != kind: continue
        g = f.GetGeometryRef().Clone(); g.Transform(tr)
        yield f.GetField("strahler"), [((x - gt[0]) / gt[1] - 0.5, (y - gt[3]) / gt[5] - 0.5) for x, y, *_ in g.GetPoints()]
order = np.zeros((rows, cols), np.int32)
for o, pts in lines(sys.argv[3]):
    for x, y in pts:
        c, r = near(x), near(y)
        if 0 <= c < cols and 0 <= r < rows: order[r, c] = max(order[r, c], o)
disc = [(dc, dr) for dr in range(-2, 3) for dc in range(-2, 3) if dc * dc + dr * dr <= 4]
total = matched = 0.0
for o, pts in lines(sys.argv[2], "river"):
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        cells = math.hypot(x1 - x0, y1 - y0); n = max(1, math.ceil(cells * 2))
        for s in range(n):
            t = (s + 0.5) / n; c, r = near(x0 + t * (x1 - x0)), near(y0 + t * (y1 - y0))
            total += cells / n
            if any(0 <= c + dc < cols and 0 <= r + dr < rows and order[r + dr, c + dc] > 0 and abs(order[r + dr, c + dc] - o) <= 1
                   for dc, dr in disc):
                matched += cells / n
print("%.4f" % (matched / total))
PY
"$bin" -q --threads "$threads" generate "$tmp/flow.tif" --method flow --size 513x513 --cell 30 --seed 1
threshold=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['d8_consistency']['d8_stream_threshold_km2'])" "$tmp/flow.report.json")
reported=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['d8_consistency']['share_within_2_cells'])" "$tmp/flow.report.json")
d8share() {  # DEM: the share of the generator's rivers on the D8 streams of DEM
  "$bin" -q hydro "$1" "$tmp/d8" --hydrometry accumulation --outputs streams --streams-threshold "$threshold" --overwrite
  /usr/bin/python3 "$tmp/d8share.py" "$tmp/flow.tif" "$tmp/flow.skeleton.geojson" "$tmp/d8/streams.geojson"
}
density() {  # DEM: km of hydro streams at the default threshold per km²
  "$bin" -q hydro "$1" "$tmp/hy" --hydrometry accumulation --outputs streams --overwrite
  /usr/bin/python3 "$tmp/drainage.py" "$1" "$tmp/hy/streams.geojson"
}
echo
echo "generated region: report's D8 share $reported (D8 streams from $threshold km²), recomputed here before erosion $(d8share "$tmp/flow.tif")"
echo
echo "| DEM | erode settings | hypsometric integral before -> after | drainage density km/km² before -> after | pits before -> after (created) | D8 share of the generator's rivers kept |"
echo "|---|---|---|---|---|---|"
crop=$tmp/crop513.tif
[[ -f $crop ]] || gdal_translate -q -srcwin 344 344 513 513 -of GTiff "$dem" "$crop"
for input in "$tmp/flow.tif" ../shared/dems/spDataLarge_srtm_zion.tif "$crop"; do
  case $input in *flow.tif) name="generate --method flow 513² seed 1";; *crop513.tif) name="$(basename "$dem") 513² crop";; *) name=$(basename "$input");; esac
  dd0=$(density "$input")
  for settings in "" "--process hydraulic" "--process thermal" "$strong"; do
    # shellcheck disable=SC2086  # the settings are words
    "$bin" -q --threads "$threads" erode "$input" "$tmp/eroded.tif" $settings --overwrite
    read -r hi0 hi1 p0 p1 < <(/usr/bin/python3 "$tmp/measure.py" "$input" "$tmp/eroded.tif")
    share=n/a; [[ $input == *flow.tif ]] && share=$(d8share "$tmp/eroded.tif")
    echo "| $name | ${settings:-defaults} | $hi0 -> $hi1 | $dd0 -> $(density "$tmp/eroded.tif") | $p0 -> $p1 ($((p1 - p0))) | $share |"
  done
done
