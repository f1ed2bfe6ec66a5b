#!/usr/bin/env bash
# `terrapolis lake` (Peytavie 2010 §2.4.1) on a real reservoir: the docs' example, its outputs and
# figures, roads and cities of a run folder, the stored GRASS r.lake figure, and the refusals.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK
zion=$samples/spDataLarge_srtm_zion.tif
json() { /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))$2)" "$1"; }

# The documented example (docs/lakes.md): a dam with a 1172 m crest across a valley of 255 km²
# south-west of Zion (Utah), the reservoir filled to 1167 m.
at=-113.1592,37.2258
dam="LINESTRING (-113.168 37.2261, -113.1537 37.2189)"
"$bin" -q lake "$zion" "$work/reservoir" --at=$at --dam "$dam" --crest 1172 --level 1167
for f in depth.tif shoreline.geojson lake.json; do [[ -s $work/reservoir/$f ]] || fail "missing $f"; done
# CRS and grid kept; depth 0 < d <= 10 m + the lake floor's relief; NaN where dry.
[[ "$(gdalsrsinfo -o wkt1 "$zion")" == "$(gdalsrsinfo -o wkt1 "$work/reservoir/depth.tif")" ]] || fail "CRS not kept"
grep -q "Size is 465, 457" <(gdalinfo "$work/reservoir/depth.tif") || fail "grid not kept"
grep -q "LEVEL_M=1167.000" <(gdalinfo "$work/reservoir/depth.tif") || fail "no LEVEL_M"
# The report's area and volume are the depth raster's: cells times their geodesic areas (checked
# independently with pyproj's geodesic areas of each row's cell).
/usr/bin/python3 - "$work/reservoir" <<'EOF'
import json, sys, math
from osgeo import gdal
folder = sys.argv[1]
r = json.load(open(folder + "/lake.json"))
ds = gdal.Open(folder + "/depth.tif")
a = ds.GetRasterBand(1).ReadAsArray()
gt = ds.GetGeoTransform()
from pyproj import Geod
geod = Geod(ellps="WGS84")
def cell_area(row):
    lat0, lat1 = gt[3] + row * gt[5], gt[3] + (row + 1) * gt[5]
    lons = [gt[0], gt[0] + gt[1], gt[0] + gt[1], gt[0]]
    return abs(geod.polygon_area_perimeter(lons, [lat0, lat0, lat1, lat1])[0])
cells = area = volume = 0
for row in range(a.shape[0]):
    ca = cell_area(row)
    for d in a[row]:
        if not math.isnan(d):
            assert 0 < d <= 1167 - 1100, d
            cells += 1; area += ca; volume += d * ca
assert cells == r["cells"], (cells, r["cells"])
assert abs(area / 1e6 - r["area_km2"]) < 1e-5 * r["area_km2"], (area / 1e6, r["area_km2"])
assert abs(volume - r["volume_m3"]) < 1e-5 * r["volume_m3"], (volume, r["volume_m3"])
assert r["level_m"] == 1167 and not r["spills"] and r["dam"]["cells"] > 0, r
assert abs(r["area_km2"] - 2.0175) < 0.001 and abs(r["volume_m3"] / 1e6 - 49.07) < 0.01, r  # docs/lakes.md
s = json.load(open(folder + "/shoreline.geojson"))
assert s["features"] and all(f["geometry"]["type"] == "Polygon" for f in s["features"])
assert abs(s["features"][0]["properties"]["area_km2"] - r["area_km2"]) < 1e-9
print("reservoir: %d cells, %.4f km2, %.0f m3" % (cells, r["area_km2"], r["volume_m3"]))
EOF

# Without the dam the water runs down the valley to the DEM's edge. GRASS 8.2 r.lake, same DEM,
# seed and level (bench/lake.sh; GRASS is not installed by CI), floods 8348 cells: within 0.5 %.
"$bin" -q lake "$zion" "$work/undammed" --at=$at --level 1167 2>"$work/undammed.log"
grep -q "spill beyond" "$work/undammed.log" || fail "no spill warning"
grass_cells=8348
cells=$(json "$work/undammed/lake.json" "['cells']")
/usr/bin/python3 -c "import sys; c, g = $cells, $grass_cells; sys.exit(0 if abs(c - g) <= 0.005 * g else 1)" \
  || fail "lake cells $cells differ from r.lake's $grass_cells by more than 0.5 %"

# --depth: the level is the seed's ground (1107 m) plus the depth; with a dam and no level, the crest.
"$bin" -q lake "$zion" "$work/by_depth" --at=$at --depth 60 2>/dev/null
[[ $(json "$work/by_depth/lake.json" "['level_m']") == 1167.0 ]] || fail "--depth: wrong level"
[[ $(json "$work/by_depth/lake.json" "['cells']") == "$cells" ]] || fail "--depth: another lake"
"$bin" -q lake "$zion" "$work/full" --at=$at --dam "$dam" --crest 1170
[[ $(json "$work/full/lake.json" "['level_m']") == 1170.0 ]] || fail "--dam without a level: not full to the crest"

# A run folder: a road across the lake through the seed, and two cities, one on the shore.
mkdir -p "$work/run"
cat >"$work/run/roads.geojson" <<'EOF'
{"type": "FeatureCollection", "features": [
 {"type": "Feature", "properties": {"class": "national"}, "geometry": {"type": "LineString", "coordinates": [[-113.1592, 37.20], [-113.1592, 37.25]]}},
 {"type": "Feature", "properties": {"class": "national"}, "geometry": {"type": "LineString", "coordinates": [[-112.90, 37.20], [-112.88, 37.21]]}}]}
EOF
cat >"$work/run/cities.geojson" <<'EOF'
{"type": "FeatureCollection", "features": [
 {"type": "Feature", "properties": {"id": 1, "radius_m": 500.0}, "geometry": {"type": "Point", "coordinates": [-113.1592, 37.2258]}},
 {"type": "Feature", "properties": {"id": 2, "radius_m": 500.0}, "geometry": {"type": "Point", "coordinates": [-112.90, 37.20]}}]}
EOF
"$bin" -q lake "$zion" "$work/reservoir_run" --at=$at --dam "$dam" --crest 1172 --level 1167 --run "$work/run"
/usr/bin/python3 - "$work/reservoir_run/lake.json" "$work/reservoir/depth.tif" <<'EOF'
import json, sys, math
from osgeo import gdal
r = json.load(open(sys.argv[1]))
assert r["cities_touched"] == [1], r
# The flooded length of the north-south road: the lake's cells on its meridian times their height.
ds = gdal.Open(sys.argv[2]); a = ds.GetRasterBand(1).ReadAsArray(); gt = ds.GetGeoTransform()
col = int((-113.1592 - gt[0]) / gt[1])
wet = sum(1 for row in range(a.shape[0]) if 37.20 <= gt[3] + (row + 0.5) * gt[5] <= 37.25 and not math.isnan(a[row][col]))
expected = wet * abs(gt[5]) * 111000 / 1000  # km, ~111 km per degree of latitude at 37 N
assert wet > 0 and abs(r["flooded_road_km"] - expected) <= 0.05 * expected + 0.1, (r["flooded_road_km"], expected)
EOF


# Existing outputs are refused and kept; --overwrite replaces them.
before=$(md5sum <"$work/reservoir/lake.json")
expect_fail 2 "exists" "$bin" -q lake "$zion" "$work/reservoir" --at=$at --level 1150
[[ $(md5sum <"$work/reservoir/lake.json") == "$before" ]] || fail "refused run changed lake.json"
"$bin" -q lake "$zion" "$work/reservoir" --at=$at --level 1150 --overwrite
[[ $(json "$work/reservoir/lake.json" "['level_m']") == 1150.0 ]] || fail "--overwrite did not replace"

# Refusals: exit 2, one line, no output folder.
expect_refused "$work/no" "not below the water level" "$bin" -q lake "$zion" "$work/no" --at=$at --level 1100
expect_refused "$work/no" "outside the DEM" "$bin" -q lake "$zion" "$work/no" --at=10,45 --level 2400
expect_refused "$work/no" "level or --depth" "$bin" -q lake "$zion" "$work/no" --at=$at
expect_refused "$work/no" "one, not both" "$bin" -q lake "$zion" "$work/no" --at=$at --level 2490 --depth 3
expect_refused "$work/no" "not a WKT LINESTRING" "$bin" -q lake "$zion" "$work/no" --at=$at --dam "(1 2, 3 4)" --crest 2490
expect_refused "$work/no" "needs --crest" "$bin" -q lake "$zion" "$work/no" --at=$at --dam "$dam"
# The flags are a run's water.reservoirs item: the schema's ranges and shapes, named by flag.
expect_refused "$work/no" "error: --level: must be <= 9000" "$bin" -q lake "$zion" "$work/no" --at=$at --level 99999
expect_refused "$work/no" "error: --at: '10' is not an X,Y pair" "$bin" -q lake "$zion" "$work/no" --at=10 --level 1
expect_refused "$work/no" "error: --crest: only with --dam" "$bin" -q lake "$zion" "$work/no" --at=$at --crest 1200
expect_refused "$work/no" "not a folder" "$bin" -q lake "$zion" "$work/no" --at=$at --level 2490 --run "$work/nothing"
no_leftovers "$work"
echo ok
