#!/usr/bin/env bash
# `terrapolis hydro` tile by tile (--tile-size, --memory-limit, a folder of tiles, a VRT): the
# mosaic of its tiles equals the whole-grid outputs cell for cell, the river types the whole grid's;
# refusals; nothing left behind.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK

outputs=(filled flowdir accumulation)

# SRTM 1" of Zion (geographic) cut into 3 x 3 input tiles; processed on 5 x 5 tiles of 100.
zion=$samples/spDataLarge_srtm_zion.tif
mkdir "$work/zion_tiles"
for i in 0 1 2; do for j in 0 1 2; do  # 465 x 457 cells: columns 3 x 155, rows 152 + 152 + 153
  gdal_translate -q -srcwin $((i * 155)) $((j * 152)) 155 $((j == 2 ? 153 : 152)) "$zion" "$work/zion_tiles/z_${j}_${i}.tif"
done; done
"$bin" -q hydro "$zion" "$work/zion_whole" --outputs filled,flowdir,accumulation,streams,basins --streams-threshold 1
"$bin" -q hydro "$work/zion_tiles" "$work/zion_tiled" --tile-size 100 --streams-threshold 1 --outputs filled,flowdir,accumulation,streams,basins
# The same reaches (ids, orders, links, cells); areas and lengths to 1e-9, the folder's VRT having
# a geotransform a few ulps off the file's (the MPI case compares the file's streams byte for byte).
/usr/bin/python3 - "$work/zion_whole/streams.geojson" "$work/zion_tiled/streams.geojson" <<'PY' || fail "zion: tiled streams differ"
import json, math, sys
a, b = ([f for f in json.load(open(p))["features"]] for p in sys.argv[1:3])
same = lambda x, y: math.isclose(x, y, rel_tol=1e-9) if isinstance(x, float) else x == y
sys.exit(0 if len(a) == len(b) > 100 and all(
    all(same(f["properties"][k], g["properties"][k]) for k in f["properties"]) and
    all(math.isclose(u, v, abs_tol=1e-9) for p, q in zip(f["geometry"]["coordinates"], g["geometry"]["coordinates"]) for u, v in zip(p, q)) and
    len(f["geometry"]["coordinates"]) == len(g["geometry"]["coordinates"]) for f, g in zip(a, b)) else 1)
PY
for o in "${outputs[@]}" basins; do
  same_cells "$work/zion_whole/$o.tif" "$work/zion_tiled/$o.vrt" || fail "zion: tiled $o differs"
  [[ $(ls "$work/zion_tiled/$o"/tile_*.tif | wc -l) -eq 25 ]] || fail "zion: expected 25 $o tiles"
done
grep -q "D8_CODES=esri" <(gdalinfo "$work/zion_tiled/flowdir/tile_0002_0003.tif") || fail "tile without its metadata"
# Basins stitched: the largest basin spreads over at least 9 of the 25 tiles, under one label; the
# labels are the outlets numbered 1..N, each outlet cell in its own basin's label.
/usr/bin/python3 - "$work/zion_tiled/basins.vrt" <<'PY' || fail "zion: basins not stitched across tiles"
import sys
import numpy as np
from osgeo import gdal
b = gdal.Open(sys.argv[1]).ReadAsArray()
labels, counts = np.unique(b[b > 0], return_counts=True)
big = labels[np.argmax(counts)]
rows, cols = np.nonzero(b == big)
tiles = {(r * 5 // b.shape[0], c * 5 // b.shape[1]) for r, c in zip(rows, cols)}
sys.exit(0 if len(tiles) >= 9 and labels[0] == 1 and labels[-1] == len(labels) else 1)
PY
grep -q 'ID\["EPSG",4326\]' <(gdalinfo "$work/zion_tiled/filled.vrt") || fail "VRT without the CRS"

# Corsica (sea level, coast) through a VRT with km2 and TauDEM codes, on one thread.
gdalbuildvrt -q "$work/corsica.vrt" "$samples/gebco2022_15s_north_corsica_capcorse.asc"
# The default outputs: Belhadj's hydrometry too, by tiles (each run t steps with a halo of t + 2).
"$bin" -q hydro "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$work/cor_whole" --sea-level 0 --area-units km2 \
  --d8-codes taudem --outputs filled,flowdir,accumulation,hydrometry
"$bin" -q hydro "$work/corsica.vrt" "$work/cor_tiled" --sea-level 0 --area-units km2 --d8-codes taudem --tile-size 40 --threads 1
for o in "${outputs[@]}" hydrometry; do same_cells "$work/cor_whole/$o.tif" "$work/cor_tiled/$o.vrt" || fail "corsica: tiled $o differs"; done
grep -q "HYDROMETRY=belhadj" <(gdalinfo "$work/cor_tiled/hydrometry/tile_0001_0002.tif") || fail "hydrometry tile without its provenance"

# NZ (NaN nodata) at twice its resolution: 6.5 M cells, 26 MB as float, within a memory limit of
# 100 MB for the whole process (the engine's state, GDAL's bounded cache and open files, the process
# itself: about 80 MB), checked from its report and its peak resident memory: many tiles, the same cells.
nz=$work/nz2.tif
gdal_translate -q -outsize 200% 200% -r bilinear "$samples/spDataLarge_nz_elev.tif" "$nz"
"$bin" -q hydro "$nz" "$work/nz_whole" --outputs filled,flowdir,accumulation --area-units cells
# Under AddressSanitizer the process holds about 280 MB more from the start (its shadow memory).
limit=100 min_tiles=8  # the share left to tiles moves with the process's own memory (20-30 tiles here)
[[ -n ${ASAN_OPTIONS:-} ]] && limit=500 min_tiles=2
"$bin" -v hydro "$nz" "$work/nz_tiled" --memory-limit $limit --area-units cells --threads 1 --outputs filled,flowdir,accumulation 2>"$work/nz.log"
for o in "${outputs[@]}"; do same_cells "$work/nz_whole/$o.tif" "$work/nz_tiled/$o.vrt" || fail "nz: tiled $o differs"; done
line=$(grep "^tiles: " "$work/nz.log") || fail "no tile report: $(cat "$work/nz.log")"
[[ $line =~ ^tiles:\ ([0-9]+)\ of\ [0-9]+\ cells\ a\ side,\ ([0-9]+)\ at\ once.*state\ ([0-9.]+)\ MB\ a\ tile\ \+\ ([0-9.]+)\ MB\ global\ \+\ ([0-9.]+)\ MB\ reader\ and\ process\;\ peak\ resident\ ([0-9.]+)\ MB ]] ||
  fail "unreadable tile report: $line"
(( BASH_REMATCH[1] >= min_tiles )) || fail "expected many tiles: $line"
awk -v n="${BASH_REMATCH[2]}" -v t="${BASH_REMATCH[3]}" -v g="${BASH_REMATCH[4]}" -v r="${BASH_REMATCH[5]}" -v l=$limit 'BEGIN { exit !(n * t + g + r <= l) }' ||
  fail "state over the memory limit: $line"
[[ -n ${ASAN_OPTIONS:-} ]] || (( BASH_REMATCH[6] <= limit )) || fail "the process went over the memory limit: $line"
[[ -z $(ls -A "$work/nz_tiled" | grep scratch) ]] || fail "scratch folder left behind"
no_leftovers "$work"

# River types on tiles (--classify): each reach's ends read back from the filled tiles. Cap Corse
# (GEBCO 15", sea below 0: mouths, so braided reaches too) on tiles of 40: the whole grid's streams
# byte for byte, with their style.
corsica=$samples/gebco2022_15s_north_corsica_capcorse.asc
"$bin" -q hydro "$corsica" "$work/types_whole" --sea-level 0 --classify --outputs filled,streams
"$bin" -q hydro "$corsica" "$work/types_tiled" --sea-level 0 --classify --outputs filled,streams --tile-size 40
cmp -s "$work/types_whole/streams.geojson" "$work/types_tiled/streams.geojson" || fail "--classify: the tiled streams differ"
[[ -s $work/types_tiled/streams.qml ]] || fail "--classify: no river types style on tiles"
/usr/bin/python3 -c '
import json, sys
types = {f["properties"]["river_type"] for f in json.load(open(sys.argv[1]))["features"]}
assert {"B", "E", "D"} <= types, types' "$work/types_tiled/streams.geojson" || fail "--classify: expected straight, sinuous and braided reaches"

# Refusals: exit 2, nothing written.
expect_refused "$work/r8" "--classify: on tiles the river types read the filled tiles" "$bin" hydro "$corsica" "$work/r8" --tile-size 40 \
  --sea-level 0 --classify --outputs streams
expect_refused "$work/r1" "only --fill priority-flood" "$bin" hydro "$zion" "$work/r1" --tile-size 64 --fill breach
expect_refused "$work/r2" "accumulation hydrometry is not computed on tiles" "$bin" hydro "$zion" "$work/r2" --tile-size 64 --outputs filled,hydrometry \
  --hydrometry accumulation
expect_refused "$work/r7" "need --area-units" "$bin" hydro "$zion" "$work/r7" --tile-size 64 --outputs streams --area-units cells
expect_refused "$work/r3" "at least 8" "$bin" hydro "$zion" "$work/r3" --tile-size 3
expect_refused "$work/r4" "too little" "$bin" hydro "$nz" "$work/r4" --memory-limit 1
mkdir "$work/empty"
expect_refused "$work/r5" "no GeoTIFF tile" "$bin" hydro "$work/empty" "$work/r5"
mkdir "$work/mixed"
cp "$work/zion_tiles/z_0_0.tif" "$work/mixed/"
gdal_translate -q -tr 0.001 0.001 "$work/zion_tiles/z_0_1.tif" "$work/mixed/z_0_1.tif"
expect_refused "$work/r6" "cell size differs" "$bin" hydro "$work/mixed" "$work/r6"
expect_fail 2 "exists" "$bin" hydro "$zion" "$work/zion_tiled" --tile-size 100
"$bin" -q hydro "$work/zion_tiles" "$work/zion_tiled" --tile-size 200 --overwrite
same_cells "$work/zion_whole/accumulation.tif" "$work/zion_tiled/accumulation.vrt" || fail "zion: overwrite differs"
[[ $(ls "$work/zion_tiled/accumulation" | wc -l) -eq 9 ]] || fail "zion: the tiles of the first run were left beside the new ones"
echo ok
