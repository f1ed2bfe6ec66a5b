#!/usr/bin/env bash
# `terrapolis run` tile by tile (input.tile_size, input.memory_limit_mb; docs/scale.md): the
# terrain, hydro and density stages read the DEM (and the user's layers) by windows and write one GeoTIFF a tile and a VRT
# per raster, the same cells as the run on the whole grid, the same streams and figures; the sites
# stage reads the density's tiles by bands and blocks, the roads stage searches each link on a
# window of the DEM (on the given roads and the vegetation too; the corridors on a window around each road), the access stage its travel times by tiles; the settlements, the network, the
# roads, the catchments and preview.png are the whole grid's bytes, the realism figures the whole grid's; memory bounded by the limit;
# what is not computed on tiles yet refused before any stage.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
rasters=(elevation hillshade filled flowdir accumulation hydrometry inland_water coast plateau plain buildable density
  access_minutes access_minutes_10000 access_nearest)
layers=(streams.geojson cities.geojson city_extents.geojson network.geojson roads.geojson sections.geojson junctions.geojson road_sections.geojson
  access_catchments.geojson)
tiled=(--set density.preset=belhadj2007)  # a town of 10,000 or more: the access stage's second level

# The bundled DEM (GEBCO 15", sea below 0) on 3 x 3 tiles of 64 cells.
"$TP" -q run "${tiled[@]}" -o whole
"$TP" -v run "${tiled[@]}" --set input.tile_size=64 -o tiles 2> tiles.log
for r in "${rasters[@]}"; do
  same_cells "whole/$r.tif" "tiles/$r.vrt" || fail "$r differs from the whole grid's run"
  [[ $(ls tiles/$r/tile_*.tif | wc -l) -eq 9 ]] || fail "expected 9 tiles of $r"
done
for l in "${layers[@]}"; do cmp -s "whole/$l" "tiles/$l" || fail "$l differs from the whole grid's run"; done
grep -q "sites by tiles: bands of" tiles.log || fail "the sites stage did not read the tiles"
grep -q "roads by windows: windows of at most" tiles.log || fail "the roads stage did not search by windows"
grep -q "access by tiles: [0-9]* searches of 9 tiles" tiles.log || fail "the access stage did not search by tiles"
same_summary() {
  /usr/bin/python3 -c 'import json, sys; a, b = (json.load(open(f + "/run.json"))["summary"] for f in sys.argv[1:]); sys.exit(a != b)' "$1" "$2"
}
same_summary whole tiles || fail "the run's figures differ from the whole grid's"
grep -q "TERRAPOLIS_STAGE=density" <(gdalinfo tiles/density/tile_0001_0002.tif) || fail "a tile without its provenance"
grep -q 'density.vrt' tiles/project.qgs || fail "the QGIS project does not show the tiled rasters"
cmp -s whole/preview.png tiles/preview.png || fail "preview.png differs from the whole grid's run (drawn from the VRTs' rows)"

# The default preset: its terrain terms ranked and measured over the whole grid (the distances by
# bands of rows and strips of columns), on tiles of 50.
"$TP" -q run -o fitted_whole
"$TP" -q run --set input.tile_size=50 -o fitted_tiles
for r in density buildable access_minutes access_nearest; do same_cells "fitted_whole/$r.tif" "fitted_tiles/$r.vrt" || fail "default preset: $r differs on tiles"; done
for l in cities.geojson network.geojson roads.geojson access_catchments.geojson; do
  cmp -s "fitted_whole/$l" "fitted_tiles/$l" || fail "default preset: $l differs on tiles"
done
same_summary fitted_whole fitted_tiles || fail "default preset: the run's figures differ on tiles"

# A rerun from the density stage reads the hydro stage's tiles back, the sites stage the density's.
"$TP" -q run "${tiled[@]}" --set input.tile_size=64 --set density.r_max_m=4000 --from density -o tiles
"$TP" -q run --set density.preset=belhadj2007 --set density.r_max_m=4000 --until network -o whole4
same_cells whole4/density.tif tiles/density.vrt || fail "--from density on tiles differs from the whole grid's run"
cmp -s whole4/cities.geojson tiles/cities.geojson || fail "--from density on tiles: other settlements than the whole grid's run"
# A whole-grid run's saved files are GeoTIFFs, a tiled run's VRTs: neither is reused by the other.
expect_fail 2 "the saved run used other 'input' parameters; rerun from terrain" "$TP" run "${tiled[@]}" --set input.tile_size=64 --from sites -o whole
# Another limit cuts other tiles of the same cells: a rerun from the sites reuses the saved stages.
"$TP" -q run "${tiled[@]}" --set input.memory_limit_mb=2000 --set density.r_max_m=4000 --from sites -o tiles
cmp -s whole4/cities.geojson tiles/cities.geojson || fail "--from sites with another memory limit: other settlements"
/usr/bin/python3 -c 'import json; r = json.load(open("tiles/run.json"))["rerun"]; assert r["reused"] == ["terrain", "hydro", "density"], r' ||
  fail "--from sites with another memory limit did not reuse the terrain, hydro and density stages"
expect_fail 2 "--until: the run made the density stage: a rerun goes on to its last stage" "$TP" run --set sites.population=1000 --until hydro --from hydro -o "$(
  "$TP" -q run --until roads -o full > /dev/null && echo full)"

# New Zealand at 1 km (float metres, ten lakes the DEM flattens, nodata sea) within a memory limit;
# every raster but the plain (a float DEM's plain sums may round otherwise on tiles).
# (To the network: its ferries across Cook Strait search the whole islands, minutes of roads.)
nz=(--set dem="$SAMPLES/spDataLarge_nz_elev.tif" --set water.nodata_is_sea=true --set density.preset=belhadj2007 --until network)
"$TP" -q run "${nz[@]}" -o nz_whole
limit=170  # the run on the whole grid peaks at about 270 MB
[[ -n ${ASAN_OPTIONS:-} ]] && limit=2000  # AddressSanitizer holds 400-700 MB more (shadow memory, quarantine)
"$TP" -q run "${nz[@]}" --set input.memory_limit_mb=$limit -o nz_tiles
for r in "${rasters[@]}"; do
  [[ $r == plain || $r == access_* ]] && continue
  same_cells "nz_whole/$r.tif" "nz_tiles/$r.vrt" || fail "nz: $r differs from the whole grid's run"
done
for l in "${layers[@]:0:4}"; do cmp -s "nz_whole/$l" "nz_tiles/$l" || fail "nz: $l differs"; done
/usr/bin/python3 - "$limit" <<'PY' || fail "nz: figures or memory"
import json, sys
w, t = (json.load(open(f + "/run.json")) for f in ("nz_whole", "nz_tiles"))
assert w["summary"]["hydro"] == t["summary"]["hydro"], (w["summary"]["hydro"], t["summary"]["hydro"])
assert t["summary"]["hydro"]["flat_lakes"] >= 8, t["summary"]["hydro"]
peak = max(s["peak_memory_mb"] for s in t["timings"])
whole = max(s["peak_memory_mb"] for s in w["timings"])
print(f"nz: peak {peak:.0f} MB by tiles (limit {sys.argv[1]} MB), {whole:.0f} MB on the whole grid")
import os
# The heap's slack (freed pages a thread's arena keeps) is not planned: 5 % over the limit at most
# (the continuous integration once peaked at 172 MB here before large blocks were mapped apart).
assert os.environ.get("ASAN_OPTIONS") or peak <= 1.05 * float(sys.argv[1]) < whole, (peak, whole)
PY

# The region as it is: the real places of Cap Corse (GeoNames) kept where they are, on tiles too.
places=(--set sites.existing="$SOURCE/tests/data/geonames_capcorse.geojson" --set sites.population=94347)
"$TP" -q run "${tiled[@]}" "${places[@]}" -o places_whole
"$TP" -q run "${tiled[@]}" "${places[@]}" --set input.tile_size=50 -o places_tiles
for l in cities.geojson network.geojson roads.geojson; do cmp -s "places_whole/$l" "places_tiles/$l" || fail "sites.existing: $l differs on tiles"; done

# The roads as they are (roads.existing: every other road of the whole run) on tiles of 50: the
# links reuse them by windows as on the whole grid, the corridors of the new stretches read a window
# around each road (the DEM, the forest cleared and priced, the side angles); the same layers, the
# given roads as read, figures.
/usr/bin/python3 -c '
import json
g = json.load(open("whole/roads.geojson"))
json.dump({"type": "FeatureCollection", "features": g["features"][::2]}, open("given.geojson", "w"))'
# A forest layer in another CRS (UTM 32N, 250 m cells: downsampled onto the 15" grid), warped onto
# each window with the whole grid's kernel.
gdalwarp -q -t_srs EPSG:32632 -tr 250 250 -r bilinear "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" utm.tif
gdal_calc.py --quiet -A utm.tif --outfile forest.tif --type Float32 --calc "clip((A - 40) / 400.0, 0, 1)"
# A map of side angles (rock above 300 m, 60 deg; loose ground at 12 deg below; nodata at sea: the
# default angle), read on each corridor's window, the margin counting its shallowest angle.
gdal_calc.py --quiet -A "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" --outfile angles.tif --type Float32 --NoDataValue -1 \
  --calc "where(A <= 0, -1, where(A > 300, 60, 12))"
given=(--set roads.existing="$WORK/given.geojson" --set roads.corridor.enabled=true --set roads.vegetation="$WORK/forest.tif"
  --set roads.corridor.side_angles="$WORK/angles.tif" --until roads)
"$TP" -q run "${tiled[@]}" "${given[@]}" -o given_whole
"$TP" -q run "${tiled[@]}" "${given[@]}" --set input.tile_size=50 -o given_tiles
for l in existing_roads.geojson roads.geojson sections.geojson junctions.geojson road_sections.geojson corridors.geojson; do
  cmp -s "given_whole/$l" "given_tiles/$l" || fail "roads.existing: $l differs on tiles"
done
same_summary given_whole given_tiles || fail "roads.existing: the run's figures differ on tiles"
/usr/bin/python3 -c 'import json; r = json.load(open("given_tiles/run.json"))["summary"]["roads"]; assert r["on_existing_km"] > 1 and r["corridor"]["cut_m3"] > 0 and r["corridor"]["cleared_ha"] > 0, r' ||
  fail "roads.existing on tiles: the new roads do not run on the given ones, or no earthworks or clearing"

# A planner's own layers on tiles of 50: the UTM heights (metres, so rescaled by their range over
# the whole grid, read once by bands before the tiles) as a density layer, the forest as an
# exclusion; the density and the settlements are the whole grid's.
own=(--set 'density.layers=[{"file":"'"$WORK"'/utm.tif","weight":2}]' --set 'density.exclusions=["'"$WORK"'/forest.tif"]' --until sites)
"$TP" -q run "${tiled[@]}" "${own[@]}" -o own_whole
"$TP" -q run "${tiled[@]}" "${own[@]}" --set input.tile_size=50 -o own_tiles
for r in buildable density; do same_cells "own_whole/$r.tif" "own_tiles/$r.vrt" || fail "density.layers: $r differs on tiles"; done
cmp -s own_whole/cities.geojson own_tiles/cities.geojson || fail "density.layers: other settlements on tiles"
cmp -s whole/density.tif own_whole/density.tif && fail "density.layers: the layer did not change the density"

# The realism figures against the real places (sites.reference) on tiles of 40: the whole grid's.
reference=(--set sites.reference="$SOURCE/tests/data/geonames_capcorse.geojson" --until sites)
"$TP" -q run "${reference[@]}" -o real_whole
"$TP" -q run "${reference[@]}" --set input.tile_size=40 -o real_tiles
/usr/bin/python3 - <<'PY' || fail "sites.reference: the realism figures differ on tiles"
import json
w, t = (json.load(open(f + "/run.json"))["summary"] for f in ("real_whole", "real_tiles"))
assert w["realism"] == t["realism"], (w["realism"], t["realism"])
assert w["realism"]["places"] >= 10 and 0 <= w["realism"]["skill"]["auc"] <= 1, w["realism"]
assert w["sites"]["warnings"] == t["sites"]["warnings"]
PY

no_leftovers "$WORK"
[[ -z $(find . -name '.scratch*') ]] || fail "a scratch folder was left behind"

# Refused before any stage, exit 2, no folder: the later stages, and what the tiles do not compute yet.
expect_refused r4 "/hydro/flow mfd: not computed on tiles yet" "$TP" run "${tiled[@]}" --set input.tile_size=64 --set hydro.flow=mfd -o r4
expect_refused r8 "/roads/router: not computed on tiles yet" "$TP" run "${tiled[@]}" --set input.tile_size=64 --set roads.router=bezier -o r8
gdal_calc.py --quiet -A "$SAMPLES/spDataLarge_srtm_zion.tif" --outfile nodata.tif --calc "A*0+65535" --NoDataValue 65535 --type UInt16
expect_refused r5 "nodata.tif: holds no data" "$TP" run --set dem="$WORK/nodata.tif" "${tiled[@]}" --set input.tile_size=64 -o r5
echo "run by tiles: ok"
