#!/usr/bin/env bash
# terrapolis generate --method flow | tectonic | coast | planar | river: the DEM holds the generator's rivers. The report's
# figures must be in range, and an independent check (Python, on `terrapolis hydro`'s own streams
# and the skeleton GeoJSON) must find the same consistency. Same seed, same bytes at any thread count.
set -euo pipefail
BIN=$1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# name:seed:grid. One seed each (the figures vary with the seed: docs/terrain.md); coast needs a
# region of tens of km (its grammar edges are 2 km long).
for spec in "flow:8:--size 257x257 --cell 30" "tectonic:3:--size 257x257 --cell 30" "coast:3:--size 300x300 --cell 100" \
            "planar:3:--size 257x257 --cell 30 --nodes 150" "planar_uniform:3:--size 257x257 --cell 30 --nodes 40 --tree-law uniform"; do
  IFS=: read -r name seed args <<<"$spec"
  method=${name%_uniform}
  read -r -a grid <<<"$args"
  "$BIN" --quiet generate "$T/$name.tif" --method $method "${grid[@]}" --seed $seed
  "$BIN" --quiet --threads 1 generate "$T/${name}1.tif" --method $method "${grid[@]}" --seed $seed
  cmp "$T/$name.tif" "$T/${name}1.tif"
  cmp "$T/$name.skeleton.geojson" "$T/${name}1.skeleton.geojson"
  cmp "$T/$name.report.json" "$T/${name}1.report.json"
  threshold=$(/usr/bin/python3 -c "import json; print(json.load(open('$T/$name.report.json'))['d8_consistency']['d8_stream_threshold_km2'])")
  "$BIN" --quiet hydro "$T/$name.tif" "$T/$name-hydro" --hydrometry accumulation --outputs streams --streams-threshold "$threshold"
  /usr/bin/python3 - "$T/$name" "$name" <<'PY'
import json, math, sys
import numpy as np
from osgeo import gdal, ogr, osr
base, method = sys.argv[1], sys.argv[2]
report = json.load(open(base + ".report.json"))
c, h = report["d8_consistency"], report["horton"]
problems = []
# Known gaps, kept visible (docs/terrain.md): coast has three orders on a few hundred km², Rb drifts
# to 6 and Rl stays near 1; the planar method's balanced (increasing) trees give Rb below 3 (its
# uniform trees meet Horton's ranges; larger ones lose consistency on their thin facets).
least_share = 0.9
if c["share_within_2_cells"] < least_share: problems.append("consistency %s < %s" % (c["share_within_2_cells"], least_share))
if c["mouths_ending_in_pit"] != 0: problems.append("%d mouths end in a pit" % c["mouths_ending_in_pit"])
if c["mouths"] < 1: problems.append("no river reaches an outlet")
rb, rl = h["bifurcation_ratio"], h["length_ratio"]
rb_top = 6 if method == "coast" else 5
if method != "planar" and (rb is None or not 3 <= rb <= rb_top): problems.append("Rb %s outside 3-%d" % (rb, rb_top))
if method not in ("coast", "planar") and (rl is None or not 1.5 <= rl <= 3.5): problems.append("Rl %s outside 1.5-3.5" % rl)
if method == "coast":
    f = report["figures"]
    if not 0.36 <= f["river_km_per_km2"] <= 0.52: problems.append("density %s outside 0.36-0.52 (Tab. 2: 0.42-0.46)" % f["river_km_per_km2"])
    if not 9 <= f["terrain_primitives_per_km2"] <= 11: problems.append("%s primitives/km2 (Tab. 2: 10)" % f["terrain_primitives_per_km2"])
    if f["low_priority_stream_share"] <= 0.75: problems.append("low-priority share %s <= 0.75" % f["low_priority_stream_share"])
# Independent re-computation: hydro's streams and the skeleton, both read back from GeoJSON.
ds = gdal.Open(base + ".tif")
gt, cols, rows = ds.GetGeoTransform(), ds.RasterXSize, ds.RasterYSize
srs = osr.SpatialReference(); srs.ImportFromWkt(ds.GetProjection())
srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
def lines(path, kind=None):
    source = ogr.Open(path)  # kept alive while its layer is read
    layer = source.GetLayer()
    src = layer.GetSpatialRef(); src.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    tr = osr.CoordinateTransformation(src, srs)
    for f in layer:
        if kind and f.GetField("kind") != kind: continue
        g = f.GetGeometryRef().Clone(); g.Transform(tr)
        pts = [((x - gt[0]) / gt[1] - 0.5, (y - gt[3]) / gt[5] - 0.5) for x, y, *_ in g.GetPoints()]
        yield f.GetField("strahler"), pts
order = np.zeros((rows, cols), np.int32)
for o, pts in lines(base + "-hydro/streams.geojson"):
    for x, y in pts:
        order[int(round(y)), int(round(x))] = max(order[int(round(y)), int(round(x))], o)
total = matched = 0.0
for o, pts in lines(base + ".skeleton.geojson", "river"):
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        n = max(1, math.ceil(math.hypot(x1 - x0, y1 - y0) * 2))
        for s in range(n):
            t = (s + 0.5) / n
            x, y = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
            cx, cy = int(round(x)), int(round(y))
            win = order[max(0, cy - 2):cy + 3, max(0, cx - 2):cx + 3]
            yy, xx = np.mgrid[max(0, cy - 2):cy + 3, max(0, cx - 2):cx + 3][:, :win.shape[0], :win.shape[1]]
            near = ((xx - cx) ** 2 + (yy - cy) ** 2 <= 4) & (win > 0) & (np.abs(win - o) <= 1)
            d = math.hypot(x1 - x0, y1 - y0) / n
            total += d; matched += d if near.any() else 0
share = matched / total
if abs(share - c["share_within_2_cells"]) > 0.02: problems.append("independent share %.4f vs report %.4f" % (share, c["share_within_2_cells"]))
if problems:
    print(base + ": " + "; ".join(problems)); sys.exit(1)
PY
done
# A different seed gives a different region.
"$BIN" --quiet generate "$T/other.tif" --method flow --size 257x257 --cell 30 --seed 4
! cmp -s "$T/flow.tif" "$T/other.tif"
# The one-river fractal (Belhadj §1.2.3): same bytes at 1 thread, one river into no pit, every river
# cell draining into the river, D8 streams along it, the thesis's H by default.
"$BIN" --quiet generate "$T/river.tif" --method river --size 257x257 --cell 30 --seed 2
"$BIN" --quiet --threads 1 generate "$T/river1.tif" --method river --size 257x257 --cell 30 --seed 2
cmp "$T/river.tif" "$T/river1.tif"
cmp "$T/river.skeleton.geojson" "$T/river1.skeleton.geojson"
cmp "$T/river.report.json" "$T/river1.report.json"
/usr/bin/python3 - "$T/river" <<'PY'
import json, sys
from osgeo import gdal
base = sys.argv[1]
r = json.load(open(base + ".report.json")); f = r["figures"]
ds = gdal.Open(base + ".tif")
problems = []
if r["river_reaches"] != 1 or r["d8_consistency"]["mouths_ending_in_pit"] != 0: problems.append("reaches or pits: %s" % r)
if f["river_cells_draining_into_river_share"] < 0.99: problems.append("draining share %s" % f)
if f["river_line_within_1_cell_of_d8_stream_share"] < 0.85: problems.append("stream share %s" % f)
if ds.GetMetadataItem("TERRAPOLIS_HURST") != "0.456500" or ds.GetMetadataItem("TERRAPOLIS_GENERATOR") != "river": problems.append("metadata")
if problems:
    print(base + ": " + "; ".join(problems)); sys.exit(1)
PY
"$BIN" --quiet generate "$T/river_other.tif" --method river --size 257x257 --cell 30 --seed 3
! cmp -s "$T/river.tif" "$T/river_other.tif"
# Ridges given as lines: the flow method follows them.
/usr/bin/python3 - "$T/ridges.geojson" <<'PY'
import json, sys
# Two ridges across a 257 x 257 grid of 30 m cells in EPSG:3035 centred on its origin.
x0, y0 = 4321000 - 257 * 15, 3210000 + 257 * 15
line = lambda a, b: {"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": [a, b]}}
from osgeo import osr
s = osr.SpatialReference(); s.ImportFromEPSG(3035); w = osr.SpatialReference(); w.ImportFromEPSG(4326)
w.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER); s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
tr = osr.CoordinateTransformation(s, w)
ll = lambda c, r: list(tr.TransformPoint(x0 + c * 30, y0 - r * 30)[:2])
fc = {"type": "FeatureCollection", "features": [line(ll(60, 128), ll(200, 110)), line(ll(128, 40), ll(128, 100))]}
json.dump(fc, open(sys.argv[1], "w"))
PY
"$BIN" --quiet generate "$T/given.tif" --method flow --size 257x257 --cell 30 --ridges "$T/ridges.geojson"
/usr/bin/python3 -c "
from osgeo import gdal; import sys
ds = gdal.Open('$T/given.tif'); a = ds.GetRasterBand(1).ReadAsArray()
sys.exit(0 if a[119, 130] > a[30, 30] + 500 else 1)"
# Bad input: one line, exit 2, nothing written.
set +e
"$BIN" generate "$T/bad.tif" --method nope --size 65x65 --cell 30 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--method" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "bad method: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --method tectonic --size 65x65 --cell 30 --ridges "$T/ridges.geojson" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--ridges" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "ridges for tectonic: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --method river --size 2x65 --cell 30 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && [ $(wc -l <"$T/err") -eq 1 ] && grep -q -- "--size: the river method needs 3 to 65535 cells" "$T/err" && [ ! -e "$T/bad.tif" ] && [ ! -e "$T/bad.report.json" ] || { echo "river, thin grid: rc=$rc"; cat "$T/err"; exit 1; }
"$BIN" generate "$T/bad.tif" --method river --size 65x65 --cell 30 --river-convergence 0 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--river-convergence" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "river, bad convergence: rc=$rc"; cat "$T/err"; exit 1; }
# generate --erode-iterations (hydraulic by default): an older landscape whose rivers stay on the
# D8 streams (issue 36's bar, >= 90 % on 513 cells: docs/erode.md); same bytes at any thread count;
# 0 iterations is the plain generator; bad values refused.
for run in "e:" "e1:--threads 1" "e0:" "plain:"; do
  IFS=: read -r out threads <<<"$run"
  iterations=(--erode-iterations 50)
  [[ $out == e0 ]] && iterations=(--erode-iterations 0)
  [[ $out == plain ]] && iterations=()
  # shellcheck disable=SC2086  # $threads: none or two words
  "$BIN" --quiet $threads generate "$T/$out.tif" --method flow --size 257x257 --cell 30 --seed 1 "${iterations[@]}" || { echo "erode: $out failed"; exit 1; }
done
cmp "$T/e.tif" "$T/e1.tif" || { echo "erode: 1 and 2 threads differ"; exit 1; }
cmp "$T/e0.tif" "$T/plain.tif" || { echo "erode: 0 iterations changed the DEM"; exit 1; }
! cmp -s "$T/e.tif" "$T/plain.tif" || { echo "erode: the DEM did not change"; exit 1; }
grep -q 'TERRAPOLIS_ERODE=.*"process":"hydraulic"' <(gdalinfo "$T/e.tif") || { echo "erode: no TERRAPOLIS_ERODE metadata"; exit 1; }
/usr/bin/python3 - "$T" <<'PY' || exit 1
import json, sys
share = lambda f: json.load(open(f"{sys.argv[1]}/{f}.report.json"))["d8_consistency"]["share_within_2_cells"]
eroded, plain = share("e"), share("plain")
assert eroded >= 0.85 and eroded >= plain - 0.02, (eroded, plain)
PY
"$BIN" generate "$T/bad.tif" --method flow --size 65x65 --cell 30 --erode-process sand 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q -- "--erode-process: must be one of" "$T/err" && [ ! -e "$T/bad.tif" ] || { echo "bad erode process: rc=$rc"; cat "$T/err"; exit 1; }
echo '{"type":"FeatureCollection","features":[]}' > "$T/empty.geojson"
"$BIN" generate "$T/bad.tif" --method flow --size 65x65 --cell 30 --ridges "$T/empty.geojson" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "empty.geojson" "$T/err" && [ ! -e "$T/bad.tif" ] && [ ! -e "$T/bad.skeleton.geojson" ] || { echo "empty ridges: rc=$rc"; cat "$T/err"; exit 1; }
exit 0
