#!/usr/bin/env bash
# `terrapolis path --memory-limit` (docs/roads.md, "One road on a region larger than memory"): the
# road searched on windows of the DEM, grown until the bound proves it the whole grid's, is the
# whole-grid road byte for byte (road, sections, corridor, with a vegetation layer and a map of side
# angles too), on a file
# and on a 3 x 3 VRT of tiles;
# what reads the whole DEM, and a limit too small for the road, refused before anything is written.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
corsica=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc zion=$SAMPLES/spDataLarge_srtm_zion.tif
ends=(--from 9.30,42.68 --to 9.42,42.70)
limit=300
[[ -n ${ASAN_OPTIONS:-} ]] && limit=2000  # AddressSanitizer holds 400-700 MB more (shadow memory, quarantine)

"$TP" -q path "$corsica" "${ends[@]}" whole.geojson --sections whole_s.geojson --corridor whole_c.geojson
"$TP" -v path "$corsica" "${ends[@]}" win.geojson --sections win_s.geojson --corridor win_c.geojson --memory-limit $limit 2> win.log
grep -q "path by windows: 1 windows searched" win.log || fail "the road was not searched on a window: $(cat win.log)"
for f in "" _s _c; do cmp -s "whole$f.geojson" "win$f.geojson" || fail "win$f.geojson differs from the whole grid's"; done

# Zion (SRTM 3", geographic) cut into 3 x 3 tiles and read through a VRT.
for i in 0 1 2; do
  for j in 0 1 2; do
    gdal_translate -q -srcwin $((j * 155)) $((i * 152)) 155 $((i == 2 ? 153 : 152)) "$zion" "z_${i}_$j.tif"
  done
done
gdalbuildvrt -q zion.vrt z_*.tif
zends=(--from -113.15,37.45 --to -112.93,37.2)
"$TP" -q path "$zion" "${zends[@]}" zwhole.geojson --corridor zwhole_c.geojson
"$TP" -q path zion.vrt "${zends[@]}" zwin.geojson --corridor zwin_c.geojson --memory-limit $limit
cmp -s zwhole.geojson zwin.geojson || fail "the road on the VRT's windows differs from the whole grid's"
cmp -s zwhole_c.geojson zwin_c.geojson || fail "the corridor on the VRT's windows differs from the whole grid's"
# A forest layer in UTM 12N at 30 m (downsampled onto the 3" grid: GDAL's kernel wider than a
# cell), warped onto each window with the whole grid's kernel: the same road, corridor and clearing.
# (On the file itself: the VRT's geotransform differs from the file's in its last bits, which
# moves the warped positions by as much.)
gdalwarp -q -t_srs EPSG:32612 -tr 30 30 -r bilinear "$zion" zutm.tif
gdal_calc.py --quiet -A zutm.tif --outfile forest.tif --type Float32 --calc "clip((A - 1500) / 800.0, 0, 1)"
"$TP" -q path "$zion" "${zends[@]}" fwhole.geojson --corridor fwhole_c.geojson --vegetation forest.tif
"$TP" -q path "$zion" "${zends[@]}" fwin.geojson --corridor fwin_c.geojson --vegetation forest.tif --memory-limit $limit
cmp -s fwhole.geojson fwin.geojson || fail "--vegetation: the road on windows differs from the whole grid's"
cmp -s fwhole_c.geojson fwin_c.geojson || fail "--vegetation: the corridor on windows differs from the whole grid's"
cmp -s fwhole.geojson zwhole.geojson && fail "--vegetation changed nothing: the test compares nothing it prices"
# A map of side angles (50 deg above 1700 m, loose ground at 10 deg below), read on the road's
# last window, whose margin counts the map's shallowest angle: the whole grid's corridor.
gdal_calc.py --quiet -A "$zion" --outfile angles.tif --type Float32 --calc "where(A > 1700, 50, 10)"
"$TP" -q path "$zion" "${zends[@]}" awhole.geojson --corridor awhole_c.geojson --side-angles angles.tif
"$TP" -q path "$zion" "${zends[@]}" awin.geojson --corridor awin_c.geojson --side-angles angles.tif --memory-limit $limit
cmp -s awhole_c.geojson awin_c.geojson || fail "--side-angles: the corridor on windows differs from the whole grid's"
cmp -s awhole_c.geojson zwhole_c.geojson && fail "--side-angles changed nothing: the test compares nothing it reads"
no_leftovers .
[[ ! -e .inland_water ]] || fail "the inland water's tiles were left behind"

refuse() { expect_refused bad.geojson "$1" "$TP" -q path zion.vrt "${zends[@]}" bad.geojson --memory-limit $limit "${@:2}"; }
refuse "--earthworks: reads the whole DEM" --earthworks bad.tif
refuse "--evaluate: reads the whole DEM" --evaluate zwhole.geojson
refuse "--router bezier: reads the whole DEM" --router bezier
expect_refused bad.geojson "--from: the point is in the sea" \
  "$TP" -q path "$corsica" --from 9.0,43.15 --to 9.42,42.70 bad.geojson --memory-limit $limit
# (Under AddressSanitizer the process alone holds more than 90 MB: the inland water's tiles are refused first.)
[[ -n ${ASAN_OPTIONS:-} ]] ||
  expect_refused bad.geojson "cannot be searched within .* the memory limit allows windows of" \
    "$TP" -q path zion.vrt "${zends[@]}" bad.geojson --memory-limit 90
no_leftovers .
