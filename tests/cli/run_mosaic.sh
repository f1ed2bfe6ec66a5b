#!/usr/bin/env bash
# `terrapolis run` on a region given as a folder of GeoTIFF tiles or a VRT mosaic (docs/pipeline.md):
# the tiles are joined into one grid and the run's layers are those of the run on the whole DEM,
# cell for cell and byte for byte; a folder of tiles that do not share a grid is refused before
# any stage; the same folder run by tiles gives the same layers again.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
zion=$SAMPLES/spDataLarge_srtm_zion.tif

# Zion (465 x 457 cells of SRTM 3") cut into 2 x 2 tiles, and the same tiles as a VRT.
mkdir tiles
for i in 0 1; do for j in 0 1; do
  gdal_translate -q -srcwin $((i * 233)) $((j * 229)) $((i == 0 ? 233 : 232)) $((j == 0 ? 229 : 228)) "$zion" "tiles/z_${j}_${i}.tif"
done; done
gdalbuildvrt -q zion.vrt tiles/*.tif
set_run=(--set sites.population=60000 --until roads)
"$TP" -q run --set dem="$zion" "${set_run[@]}" -o whole
"$TP" -q run --set dem="$WORK/tiles" "${set_run[@]}" -o folder
"$TP" -q run --set dem="$WORK/zion.vrt" "${set_run[@]}" -o vrt
for run in folder vrt; do
  for r in elevation filled accumulation density buildable; do
    same_cells "whole/$r.tif" "$run/$r.tif" || fail "$run: $r differs from the whole DEM's run"
  done
  for v in cities network roads; do
    cmp -s "whole/$v.geojson" "$run/$v.geojson" || fail "$run: $v.geojson differs from the whole DEM's run"
  done
done
/usr/bin/python3 -c 'import json, sys; sys.exit(json.load(open("whole/run.json"))["summary"]["roads"]["roads"] < 2)' ||
  fail "fewer than two roads on Zion: the comparison proves little"

# Tiles of another cell size: refused before any stage, nothing written.
gdal_translate -q -tr 0.002 0.002 tiles/z_0_0.tif odd.tif && cp -r tiles mixed && mv odd.tif mixed/z_0_0.tif
expect_refused mixed_run "mixed/z_0_1.tif: cell size differs" "$TP" run --set dem="$WORK/mixed" -o mixed_run
[[ $(wc -l < "$WORK/stderr") -eq 1 ]] || fail "mixed tiles: not one line: $(cat "$WORK/stderr")"
# The folder by tiles of 128 (the default preset's terrain terms ranked and measured over the whole grid).
"$TP" -q run --set dem="$WORK/tiles" "${set_run[@]}" --set input.tile_size=128 -o tiled_run
for r in density buildable; do same_cells "whole/$r.tif" "tiled_run/$r.vrt" || fail "by tiles: $r differs from the whole DEM's run"; done
for v in cities network roads; do cmp -s "whole/$v.geojson" "tiled_run/$v.geojson" || fail "by tiles: $v.geojson differs from the whole DEM's run"; done
echo "run on a mosaic: ok"
