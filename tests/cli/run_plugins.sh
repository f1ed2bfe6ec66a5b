# A scenario with the distance plugin: a protected area that cities avoid and roads skirt, recorded
# in run.json; a broken plugin list is refused before anything is written.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
PY=/usr/bin/python3
cat > protected.geojson <<'JSON'
{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"name": "reserve"},
 "geometry": {"type": "Polygon", "coordinates": [[[9.28, 42.52], [9.33, 42.52], [9.33, 42.56], [9.28, 42.56], [9.28, 42.52]]]}}]}
JSON
cat > scenario.json <<JSON
{"dem": "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc", "output": "run",
 "outputs": {"preview_width": 300},
 "sites": {"quotas": "belhadj2007"}, "density": {"preset": "belhadj2007"},
 "plugins": [{"id": "distance", "params": {"vector": "protected.geojson", "density": {"exclude_within_m": 0},
              "road": {"forbidden_within_m": 0, "structures": ["road", "bridge", "tunnel"]}}}]}
JSON
"$TP" --quiet run scenario.json
"$TP" --quiet run scenario.json -o free --set 'plugins=[]'
$PY - <<'PY' || fail "protected area in a scenario run"
import json
from osgeo import ogr
# Keep every OGR object referenced while its children are used (the bindings do not).
source = ogr.Open("protected.geojson")
feature = source.GetLayer(0).GetNextFeature()
reserve = feature.GetGeometryRef().Clone()
def crossing(path):
    ds = ogr.Open(path)
    n = 0
    for f in ds.GetLayer(0):
        g = f.GetGeometryRef()
        n += g.Intersects(reserve)
    return n
assert crossing("free/cities.geojson") > 0 and crossing("free/roads.geojson") > 0, "test set-up: the reserve should hold cities and roads without the plugin"
assert crossing("run/cities.geojson") == 0, "a city centre lies in the protected area"
assert crossing("run/city_extents.geojson") == 0, "a city disc overlaps the protected area"
assert crossing("run/roads.geojson") == 0, "a road enters the protected area"
m = json.load(open("run/run.json"))
assert m["scenario"]["plugins"][0]["id"] == "distance" and m["scenario"]["plugins"][0]["weight"] == 1, m["scenario"]["plugins"]
PY
# Refused before any work, nothing left: an unknown plugin, parameters its schema rejects.
expect_refused bad1 "nosuch" "$TP" run scenario.json -o bad1 --set 'plugins=[{"id":"nosuch"}]'
expect_refused bad2 "distance" "$TP" run scenario.json -o bad2 --set 'plugins=[{"id":"distance","params":{"vector":3}}]'
expect_refused bad3 "/plugins/0/id" "$TP" run scenario.json -o bad3 --set 'plugins=[{"id":"Bad Id"}]'
no_leftovers "$WORK"
echo "run with plugins: ok"
