#!/usr/bin/env bash
# `terrapolis path --earthworks`: the DEM after cut-and-fill, on the DEM's grid; no outputs on failure.
set -euo pipefail
bin=$1; samples=$2
dem=$samples/gebco2022_15s_north_corsica_capcorse.asc
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

"$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/road.geojson" --earthworks "$out/levelled.tif"
info=$(gdalinfo "$out/levelled.tif")
grep -q "Size is 175, 175" <<<"$info" || { echo "not on the DEM's grid: $info"; exit 1; }
grep -q "cut-and-fill" <<<"$info" || { echo "no band description"; exit 1; }
# An existing earthworks file without --overwrite: refused before any work, the road not written.
set +e; err=$("$bin" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$out/road2.geojson" --earthworks "$out/levelled.tif" 2>&1); rc=$?; set -e
[[ $rc -eq 2 ]] || { echo "exit $rc: $err"; exit 1; }
[[ ! -e "$out/road2.geojson" ]] || { echo "output left behind"; exit 1; }
# The network command takes the option too.
printf '%s' '{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"from": 0, "to": 1, "kept": 1}, "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.42, 42.70]]}}]}' >"$out/network.geojson"
"$bin" -q roads "$dem" "$out/network.geojson" "$out/net" --earthworks "$out/net_levelled.tif"
[[ -s "$out/net_levelled.tif" && -s "$out/net/roads.geojson" ]]
