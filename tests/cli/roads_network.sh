#!/usr/bin/env bash
# `terrapolis roads` on the Corsica sample with a small hand-made network: roads, a maritime link,
# identical outputs with 1 and 2 threads and with both routers; clean failures on bad input.
set -euo pipefail
bin=$1; samples=$2
dem=$samples/gebco2022_15s_north_corsica_capcorse.asc
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
mkdir "$out/net"
cat > "$out/net/network.geojson" <<'JSON'
{"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"from": 0, "to": 1, "kind": "roots", "kept": 1, "length_m": 10000, "detour_ratio": null},
 "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.42, 42.70]]}},
{"type": "Feature", "properties": {"from": 1, "to": 2, "kind": "parent", "kept": 1, "length_m": 30000, "detour_ratio": 1.2},
 "geometry": {"type": "LineString", "coordinates": [[9.42, 42.70], [9.40, 43.0]]}},
{"type": "Feature", "properties": {"from": 0, "to": 3, "kind": "all", "kept": 0, "length_m": 20000, "detour_ratio": 2.5},
 "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.10, 42.60]]}},
{"type": "Feature", "properties": {"from": 2, "to": 4, "kind": "all", "kept": 1, "length_m": 40000, "detour_ratio": null},
 "geometry": {"type": "LineString", "coordinates": [[9.40, 43.0], [9.0, 43.15]]}}
]}
JSON
cat > "$out/net/cities.geojson" <<'JSON'
{"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"id": 0, "radius_m": 900, "class": 0, "population": 400000, "density": 300, "parent": null, "depth": 0}, "geometry": {"type": "Point", "coordinates": [9.30, 42.68]}},
{"type": "Feature", "properties": {"id": 1, "radius_m": 700, "class": 1, "population": 200000, "density": 200, "parent": 0, "depth": 1}, "geometry": {"type": "Point", "coordinates": [9.42, 42.70]}},
{"type": "Feature", "properties": {"id": 2, "radius_m": 300, "class": 3, "population": 2000, "density": 50, "parent": 1, "depth": 2}, "geometry": {"type": "Point", "coordinates": [9.40, 43.0]}},
{"type": "Feature", "properties": {"id": 3, "radius_m": 300, "class": 3, "population": 2000, "density": 50, "parent": 0, "depth": 1}, "geometry": {"type": "Point", "coordinates": [9.10, 42.60]}},
{"type": "Feature", "properties": {"id": 4, "radius_m": 200, "class": 4, "population": 500, "density": 20, "parent": 2, "depth": 3}, "geometry": {"type": "Point", "coordinates": [9.0, 43.15]}}
]}
JSON
"$bin" -q --threads 1 roads "$dem" "$out/net/network.geojson" "$out/o1"
"$bin" -q --threads 2 roads "$dem" "$out/net/network.geojson" "$out/o2"
cmp "$out/o1/roads.geojson" "$out/o2/roads.geojson"
cmp "$out/o1/road_sections.geojson" "$out/o2/road_sections.geojson"
n=$(grep -o '"type": "Feature"' "$out/o1/roads.geojson" | wc -l)
[[ $n -eq 3 ]] || { echo "expected 3 roads (one edge not kept), got $n"; exit 1; }
grep -q '"class": "motorway"' "$out/o1/roads.geojson"
grep -q '"router": "ferry"' "$out/o1/roads.geojson"
grep -q '"structure": "ferry"' "$out/o1/road_sections.geojson"
# The Bézier router on the same network.
"$bin" -q roads "$dem" "$out/net/network.geojson" "$out/ob" --router bezier
grep -q '"router": "bezier"' "$out/ob/roads.geojson"
# Outputs exist: refused without --overwrite, accepted with it.
if "$bin" -q roads "$dem" "$out/net/network.geojson" "$out/o1" 2>/dev/null; then exit 1; fi
"$bin" -q roads "$dem" "$out/net/network.geojson" "$out/o1" --overwrite --k 3 --angles 1 --no-bridges --no-tunnels
# Bad inputs: missing network, bad costs file, an edge outside the DEM.
set +e
"$bin" -q roads "$dem" "$out/none.geojson" "$out/o3" 2>/dev/null; [[ $? -eq 2 ]] || exit 1
echo '{"road": {"slope": 3}}' > "$out/costs.json"
err=$("$bin" -q roads "$dem" "$out/net/network.geojson" "$out/o4" --costs "$out/costs.json" 2>&1); [[ $? -eq 2 ]] || exit 1
grep -q "costs.json: /road/slope: unknown key" <<<"$err" || { echo "$err"; exit 1; }
sed 's/9.10, 42.60/2.0, 42.60/; s/"kept": 0/"kept": 1/' "$out/net/network.geojson" > "$out/outside.geojson"
err=$("$bin" -q roads "$dem" "$out/outside.geojson" "$out/o5" 2>&1); [[ $? -eq 2 ]] || { echo "$err"; exit 1; }
grep -q "outside the DEM" <<<"$err" || { echo "$err"; exit 1; }
set -e
[[ ! -e "$out/o4" && ! -e "$out/o5" ]] || { echo "a failed run left its folder"; exit 1; }
