#!/usr/bin/env bash
# `terrapolis density` tile by tile (--tile-size, --memory-limit, a folder of tiles, a VRT): each
# tile computed with a halo of r_max + r_min; the VRT of every output equals the whole-grid file
# cell for cell; the sites command on the tiled folder places the whole folder's settlements; memory
# bounded by the window; user layers rescaled by the whole grid's range; refusals;
# nothing left behind.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK

# SRTM 3" of Zion (geographic, integer metres) cut into 3 x 3 input tiles; processed on 5 x 5
# tiles of about 93 cells, with the hydrometry the whole-grid hydro command computes.
zion=$samples/spDataLarge_srtm_zion.tif
mkdir "$work/zion_tiles"
for i in 0 1 2; do for j in 0 1 2; do  # 465 x 457 cells: columns 3 x 155, rows 152 + 152 + 153
  gdal_translate -q -srcwin $((i * 155)) $((j * 152)) 155 $((j == 2 ? 153 : 152)) "$zion" "$work/zion_tiles/z_${j}_${i}.tif"
done; done
"$bin" -q hydro "$zion" "$work/hydro" --outputs hydrometry
hydrometry=$work/hydro/hydrometry.tif
"$bin" -q density "$zion" "$work/whole" --hydrometry "$hydrometry" --max-slope 25 --report > "$work/whole.txt"
"$bin" -v density "$work/zion_tiles" "$work/tiled" --hydrometry "$hydrometry" --max-slope 25 --tile-size 93 --report \
  > "$work/tiled.txt" 2> "$work/tiled.log"
for o in coast plateau plain hydrometry buildable density; do
  same_cells "$work/whole/$o.tif" "$work/tiled/$o.vrt" || fail "zion: tiled $o differs"
  [[ $(ls "$work/tiled/$o"/tile_*.tif | wc -l) -eq 25 ]] || fail "zion: expected 25 $o tiles"
done
grep -q 'ID\["EPSG",4326\]' <(gdalinfo "$work/tiled/density.vrt") || fail "VRT without the CRS"
grep -q "WEIGHTS_COAST_HYDROMETRY_PLATEAU_PLAIN=1,1,1.5,0" <(gdalinfo "$work/tiled/density/tile_0002_0003.tif") || fail "tile without its provenance"
# The same report: buildable cells, radii, histogram (sums of integers); the mean to its 3 digits.
diff <(grep -v "^Density report" "$work/whole.txt") <(grep -v "^Density report" "$work/tiled.txt") || fail "zion: the reports differ"
# The halo follows the discs: r_max 5 km + r_min 500 m is about 74 columns of 74 m and 60 rows of 92 m at 37 N.
line=$(grep "^density tiles: [0-9]" "$work/tiled.log") || fail "no tile report: $(cat "$work/tiled.log")"
[[ $line =~ halo\ ([0-9]+)\ x\ ([0-9]+)\ cells ]] || fail "unreadable tile report: $line"
(( BASH_REMATCH[1] >= 70 && BASH_REMATCH[1] <= 80 && BASH_REMATCH[2] >= 56 && BASH_REMATCH[2] <= 64 )) || fail "unexpected halo: $line"

# The sites command on the tiled density folder (density.vrt, buildable.vrt): the land read by bands
# and blocks, the whole folder's settlements byte for byte; and on the whole folder within a limit.
"$bin" -q sites "$work/whole" "$work/sites_whole" > /dev/null
"$bin" -q sites "$work/tiled" "$work/sites_tiled" > /dev/null
limit=100
[[ -n ${ASAN_OPTIONS:-} ]] && limit=2000  # AddressSanitizer holds 400-700 MB more
"$bin" -q sites "$work/whole" "$work/sites_limit" --memory-limit $limit > /dev/null
for f in cities.geojson city_extents.geojson; do
  cmp -s "$work/sites_whole/$f" "$work/sites_tiled/$f" || fail "sites on the tiled density: $f differs"
  cmp -s "$work/sites_whole/$f" "$work/sites_limit/$f" || fail "sites --memory-limit: $f differs"
done
expect_fail 2 "--tile-size, --memory-limit: for a density folder" "$bin" sites "$zion" "$work/sites_dem" --tile-size 50
# Read by tiles, a folder gets the checks of a whole read: densities in [0,1], one grid.
mkdir "$work/bad_density"
gdal_calc.py --quiet -A "$work/whole/density.tif" --outfile "$work/bad_density/density.tif" --calc "A+2" --type Float32
gdal_translate -q -srcwin 0 0 400 400 "$work/whole/buildable.tif" "$work/bad_density/buildable.tif"
expect_fail 2 "buildable.tif: not on the grid of the density" "$bin" sites "$work/bad_density" "$work/sites_bad" --tile-size 50
cp "$work/whole/buildable.tif" "$work/bad_density/buildable.tif"
expect_fail 2 "density.tif: density values must lie in \[0,1\]" "$bin" sites "$work/bad_density" "$work/sites_bad" --tile-size 50
[[ ! -e $work/sites_bad ]] || fail "a refused sites command left its folder"

# The hydrometry computed by tiles too (Belhadj's diffusion, each tile with a halo of its
# iterations + 2): the same cells as the whole-grid command on the same mosaic. (Against the one
# file they differ: the mosaic's cell size differs from the file's in its last bit, which the
# diffusion's 22 iterations amplify to 0.02 of hydrometry.)
gdalbuildvrt -q "$work/zion_tiles.vrt" "$work/zion_tiles"/*.tif
"$bin" -q density "$work/zion_tiles.vrt" "$work/bel_whole" --max-slope 25
"$bin" -v density "$work/zion_tiles" "$work/bel_tiled" --max-slope 25 --tile-size 93 2> "$work/bel.log"
for o in coast plateau plain hydrometry buildable density; do
  same_cells "$work/bel_whole/$o.tif" "$work/bel_tiled/$o.vrt" || fail "zion: tiled $o differs (hydrometry by tiles)"
done
grep -q "^hydrometry tiles: 25 of 93 cells a side, 22 Belhadj iterations .* halo 24 cells" "$work/bel.log" ||
  fail "no hydrometry tile report: $(grep tiles "$work/bel.log")"
[[ ! -e $work/bel_tiled/.computed ]] || fail "the computed hydrometry's tiles were left in the output"

# New Zealand at 1 km (spDataLarge, float metres): ten lakes the DEM flattens (Taupo, Te Anau,
# Wakatipu...), found by tiles, several across tile edges; the plain's sums of a float DEM may round
# otherwise on tiles (docs/scale.md), every other output is the whole grid's.
nz=$samples/spDataLarge_nz_elev.tif
"$bin" -q density "$nz" "$work/nz_whole"
"$bin" -v density "$nz" "$work/nz_tiled" --tile-size 300 2> "$work/nz.log"
for o in coast plateau hydrometry buildable density; do
  same_cells "$work/nz_whole/$o.tif" "$work/nz_tiled/$o.vrt" || fail "nz: tiled $o differs (lakes by tiles)"
done
grep -q "^inland water tiles: 20 of 300 cells a side, 10 lakes the DEM flattens, 133.00 km2" "$work/nz.log" ||
  fail "no flat water tile report: $(grep tiles "$work/nz.log")"

# North Corsica (GEBCO 15", sea below 0) through a VRT, hydrometry neutral, on one thread: coasts
# and the sea cross tile edges.
gdalbuildvrt -q "$work/corsica.vrt" "$samples/gebco2022_15s_north_corsica_capcorse.asc"
"$bin" -q density "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$work/cor_whole" --weights 1,0,1.5,0
"$bin" -q --threads 1 density "$work/corsica.vrt" "$work/cor_tiled" --weights 1,0,1.5,0 --tile-size 40
for o in coast plateau plain buildable density; do
  same_cells "$work/cor_whole/$o.tif" "$work/cor_tiled/$o.vrt" || fail "corsica: tiled $o differs"
done
[[ ! -e $work/cor_tiled/hydrometry.vrt && ! -e $work/cor_tiled/hydrometry ]] || fail "corsica: hydrometry written although unused"

# Memory: Zion with r_max 1.5 km within 90 MB for the whole process (the window and the global state,
# GDAL's bounded cache and open files, the process itself: about 75 MB), from the report and the
# peak resident memory.
"$bin" -q density "$zion" "$work/small_whole" --hydrometry "$hydrometry" --r-max 1500
# Under AddressSanitizer the process holds about 280 MB more from the start (its shadow memory).
limit=90 min_tiles=4
[[ -n ${ASAN_OPTIONS:-} ]] && limit=400 min_tiles=1
"$bin" -v density "$zion" "$work/small_tiled" --hydrometry "$hydrometry" --r-max 1500 --memory-limit $limit 2> "$work/small.log"
for o in plain buildable density; do
  same_cells "$work/small_whole/$o.tif" "$work/small_tiled/$o.vrt" || fail "memory limit: tiled $o differs"
done
line=$(grep "^density tiles: [0-9]" "$work/small.log") || fail "no tile report: $(cat "$work/small.log")"
[[ $line =~ ^density\ tiles:\ ([0-9]+)\ of.*state\ ([0-9.]+)\ MB\ a\ window\ \+\ ([0-9.]+)\ MB\ global\ \+\ ([0-9.]+)\ MB\ reader\ and\ process\;\ peak\ resident\ ([0-9.]+)\ MB ]] ||
  fail "unreadable tile report: $line"
(( BASH_REMATCH[1] >= min_tiles )) || fail "expected several tiles: $line"
awk -v w="${BASH_REMATCH[2]}" -v g="${BASH_REMATCH[3]}" -v r="${BASH_REMATCH[4]}" -v l=$limit 'BEGIN { exit !(w + g + r <= l) }' || fail "state over the memory limit: $line"
[[ -n ${ASAN_OPTIONS:-} ]] || (( BASH_REMATCH[5] <= limit )) || fail "the process went over the memory limit: $line"
no_leftovers "$work"

# User layers by tiles: each rescaled by its range over the whole grid, read once by bands first.
# Zion's heights in UTM 12N at 30 m (finer than the grid's 74 x 92 m, so downsampled: the warp's
# kernel scale fixed from the grid, not per window; nodata past the reprojected edge; metres, so rescaled) and
# the hydrometry (already in [0,1], used as is). The density and buildable tiles must be the whole
# grid's cells, and the layers must move the density.
gdalwarp -q -t_srs EPSG:32612 -tr 30 30 -r bilinear -dstnodata -9999 "$zion" "$work/height_utm.tif"
layered=(--hydrometry "$hydrometry" --max-slope 25 --layer "$work/height_utm.tif:2" --layer "$hydrometry:0.5")
"$bin" -q density "$zion" "$work/lay_whole" "${layered[@]}"
"$bin" -v density "$zion" "$work/lay_tiled" "${layered[@]}" --tile-size 93 2> "$work/lay.log"
for o in buildable density; do
  same_cells "$work/lay_whole/$o.tif" "$work/lay_tiled/$o.vrt" || fail "user layers: tiled $o differs"
done
/usr/bin/python3 - "$work/whole/density.tif" "$work/lay_whole/density.tif" <<'PY' || fail "the user layers did not change the density"
import sys
import numpy as np
from osgeo import gdal
a, b = (gdal.Open(f).ReadAsArray() for f in sys.argv[1:])
assert np.nanmax(np.abs(a - b)) > 0.05, np.nanmax(np.abs(a - b))
PY

# Refusals: exit 2, one line, nothing written.
expect_refused "$work/r3" "--tile-size: must be at least 8" "$bin" density "$zion" "$work/r3" --tile-size 3
expect_refused "$work/r4" "--memory-limit: .*too little" "$bin" density "$zion" "$work/r4" --weights 1,0,1.5,0 --memory-limit 1
echo "density tiles: ok"
