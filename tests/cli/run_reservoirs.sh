#!/usr/bin/env bash
# A scenario with a reservoir (water.reservoirs) and classified streams (hydro.classify): the
# reservoir is water for the density, the streams carry river types, and `lake --run` reads the run.
# On tiles, reservoirs flooded by windows give the whole grid's water and figures.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
reservoir='{"at": [9.4187, 42.5187], "level_m": 90, "dam": [[9.4271, 42.4987], [9.4271, 42.5388]], "crest_m": 95}'
"$TP" --quiet run -o run --set outputs.preview_width=200 --set "water.reservoirs=[$reservoir]" --set hydro.classify=true \
  2>/dev/null
[[ -s run/inland_water.tif && -s run/inland_water.qml ]] || fail "no inland_water.tif"
/usr/bin/python3 - run <<'PY' || fail "reservoir figures"
import json, sys
from osgeo import gdal
run = sys.argv[1]
s = json.load(open(run + "/run.json"))["summary"]["hydro"]["reservoirs"]
assert len(s) == 1 and abs(s[0]["area_km2"] - 2.06) < 0.01 and s[0]["level_m"] == 90, s
water = gdal.Open(run + "/inland_water.tif").ReadAsArray()
buildable = gdal.Open(run + "/buildable.tif").ReadAsArray()
assert (water == 1).sum() > 0
assert ((water == 1) & (buildable == 1)).sum() == 0, "a reservoir cell is buildable"
streams = json.load(open(run + "/streams.geojson"))["features"]
assert all(f["properties"]["river_type"] in ("B", "E", "D", "delta") for f in streams)
PY
# By tiles of 50 (input.tile_size): each reservoir flooded on a window around its seed, its water
# added to the inland water's tiles, the river types read from the filled tiles; the whole grid's
# water, density, settlements, streams and figures.
second='{"at": [9.4187, 42.5187], "depth_m": 40}'
tiled=(--set outputs.preview=false --set "water.reservoirs=[$reservoir, $second]" --set hydro.classify=true --until sites)
"$TP" --quiet run -o res_whole "${tiled[@]}" 2>/dev/null
"$TP" --quiet run -o res_tiles "${tiled[@]}" --set input.tile_size=50 2>/dev/null
for r in inland_water buildable density; do same_cells "res_whole/$r.tif" "res_tiles/$r.vrt" || fail "reservoirs: $r differs on tiles"; done
cmp -s res_whole/cities.geojson res_tiles/cities.geojson || fail "reservoirs: other settlements on tiles"
cmp -s res_whole/streams.geojson res_tiles/streams.geojson || fail "hydro.classify: other river types on tiles"
/usr/bin/python3 - <<'PY' || fail "reservoirs: the figures differ on tiles"
import json
w, t = (json.load(open(f + "/run.json"))["summary"]["hydro"]["reservoirs"] for f in ("res_whole", "res_tiles"))
assert w == t and len(w) == 2 and w[1]["area_km2"] > w[0]["area_km2"], (w, t)
PY

# The lake command on the run's own roads and cities.
"$TP" --quiet lake "$dem" lake --at=9.4187,42.5187 --level 90 --dam "LINESTRING (9.4271 42.4987, 9.4271 42.5388)" --crest 95 --run run
/usr/bin/python3 -c "
import json; r = json.load(open('lake/lake.json'))
assert r['flooded_road_km'] >= 0 and isinstance(r['cities_touched'], list), r
assert abs(r['area_km2'] - 2.06) < 0.01, r" || fail "lake --run"
# A reservoir the scenario cannot hold is refused, naming it.
expect_fail 2 "/water/reservoirs/0/at: the ground" "$TP" --quiet run -o bad --set outputs.preview_width=200 \
  --set 'water.reservoirs=[{"at": [9.4187, 42.5187], "level_m": 10}]'
[[ ! -e bad ]] || fail "a refused run left its folder"
# A reservoir without a level is refused before any stage runs (no hydrology line on stderr).
expect_fail 2 "^terrapolis: error: \(default scenario\): /water/reservoirs/0/level_m or /depth_m: the water level is required" \
  "$TP" run -o bad --set 'water.reservoirs=[{"at": [9.4, 42.9]}]'
! grep -q "hydro\|fill" "$WORK/stderr" || fail "the run started before refusing the reservoir: $(cat "$WORK/stderr")"
[[ ! -e bad ]] || fail "a refused run left its folder"
echo ok
