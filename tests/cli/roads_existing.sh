# roads.existing (docs/roads.md, "Existing roads"): the given roads enter the road stage as built
# roads; links along them are not rebuilt (no new km), the others reuse them, and every output
# counts the new roads apart; the same bytes at any thread count; a bad file is refused before any stage.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
run() { "$TP" -q "$@" --set dem="$dem" --set outputs.preview=false --set roads.corridor.enabled=true 2>/dev/null; }

run run -o full
# Every other road of the full run as the existing roads; all of them; a file without a CRS.
/usr/bin/python3 - <<'PY'
import json
g = json.load(open("full/roads.geojson"))
json.dump({"type": "FeatureCollection", "features": g["features"][::2]}, open("half.geojson", "w"))
json.dump({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"highway": "primary"},
           "geometry": {"type": "Point", "coordinates": [9.4, 42.8]}}]}, open("points.geojson", "w"))
json.dump({"type": "FeatureCollection", "features": []}, open("empty.geojson", "w"))
PY
ogr2ogr -q -f "ESRI Shapefile" nocrs.shp half.geojson 2>/dev/null && rm nocrs.prj

run run -o half --set roads.existing="$WORK/half.geojson"
"$TP" -q --threads 1 run -o half1 --set dem="$dem" --set outputs.preview=false --set roads.corridor.enabled=true \
  --set roads.existing="$WORK/half.geojson" 2>/dev/null
for f in roads.geojson sections.geojson existing_roads.geojson corridors.geojson; do
  cmp -s half/$f half1/$f || fail "$f differs between 1 thread and all"
done
run run -o all --set roads.existing="$WORK/full/roads.geojson"
# The printed summary gives the earthworks, of the new roads only, as run.json does.
"$TP" --progress none run -o half_txt --set dem="$dem" --set outputs.preview=false --set roads.corridor.enabled=true \
  --set roads.existing="$WORK/half.geojson" > half.txt 2>/dev/null
/usr/bin/python3 - <<'PY' || fail "no corridor line in the summary: $(grep -A3 '  roads' half.txt)"
import json
c = json.load(open("half/run.json"))["summary"]["roads"]["corridor"]
want = "corridors of the new roads only: land take %.1f ha, cut %.0f m3, fill %.0f m3" % (c["land_take_ha"], c["cut_m3"], c["fill_m3"])
assert want in open("half.txt").read(), want
PY
/usr/bin/python3 - <<'PY' || fail "existing roads in the run"
import json
full = json.load(open("full/run.json"))["summary"]["roads"]
half = json.load(open("half/run.json"))["summary"]["roads"]
every = json.load(open("all/run.json"))["summary"]["roads"]
given = json.load(open("half.geojson"))["features"]
assert "existing" not in full, full
# Every run says what is new, drawn once by class (without given roads: the whole network), so
# that `compare` can put new and existing km side by side.
assert abs(sum(full["new_km"].values()) - full["network_km"]) < 0.05 and full["new_network_km"] == full["network_km"], full
e = half["existing"]
assert e["lines"] == len(given) and e["outside_dem"] == 0, e
km = sum(f["properties"]["length_m"] for f in given) / 1000
assert abs(e["total_km"] - km) < 0.01 * km, (e, km)
for c in ("motorway", "national", "departmental"):
    want = sum(f["properties"]["length_m"] for f in given if f["properties"]["class"] == c) / 1000
    assert abs(e["km"][c] - want) < 0.01 * max(want, 1), (c, e["km"], want)
# The given links are not rebuilt; what is new is about what the full network has beyond them.
roads = json.load(open("half/roads.geojson"))["features"]
# A given link is routed again only as a shortcut: shorter than the given road and on given roads
# for most of its length, yet under roads.redundant_share (0.8) of it, so not redundant.
given_m = {(f["properties"]["from"], f["properties"]["to"]): f["properties"]["length_m"] for f in given}
for f in roads:
    p = f["properties"]
    if (p["from"], p["to"]) in given_m:
        assert p["length_m"] < given_m[(p["from"], p["to"])] and p["existing_m"] > 0.5 * p["length_m"], ("a given road was built again", p)
        assert p["existing_m"] < 0.8 * p["length_m"], ("a redundant link was built", p)
sections = json.load(open("full/sections.geojson"))["features"]
kept = set(range(0, len(json.load(open("full/roads.geojson"))["features"]), 2))
rest = sum(s["properties"]["length_m"] for s in sections if not {int(r) for r in s["properties"]["roads"].split(",")} & kept) / 1000
# (less: the other links reuse the given roads, all built before them, more than the full run's order let them)
assert 0.6 * rest < half["new_network_km"] < 1.1 * rest, (half["new_network_km"], rest)
assert abs(sum(half["new_km"].values()) - half["new_network_km"]) < 0.05, half
assert abs(half["new_network_km"] + half["on_existing_km"] - half["network_km"]) < 0.05, half
# roads.geojson splits each road's length; the sections say which are on the given roads.
for f in roads:
    p = f["properties"]
    assert abs(p["new_m"] + p["existing_m"] - p["length_m"]) < 0.02 and p["new_m"] >= 0, p
new = json.load(open("half/sections.geojson"))["features"]
assert {s["properties"]["existing"] for s in new} == {0, 1}, "sections.geojson: no existing field"
assert len(json.load(open("half/existing_roads.geojson"))["features"]) >= len(given)
# Earthworks of the new roads only: fewer than the full run's.
assert half["corridor"]["cut_m3"] < full["corridor"]["cut_m3"] and half["corridor"]["land_take_ha"] < full["corridor"]["land_take_ha"], (half, full)
# Every road of the full run given: every link runs along them and adds no new km.
assert every["new_network_km"] == 0 and every["roads"] == 0 and every["redundant"] == full["roads"] + full["redundant"], every
PY

# compare puts the new and the existing road km by class side by side, with the change of the new.
"$TP" compare full half --json > compare.json
"$TP" compare full half > compare.txt
/usr/bin/python3 - <<'PY' || fail "compare: new and existing road km: $(cat compare.txt)"
import json
full = json.load(open("full/run.json"))["summary"]["roads"]
half = json.load(open("half/run.json"))["summary"]["roads"]
rows = {r["class"]: r for r in json.load(open("compare.json"))["roads"]}
t = rows["total"]
assert t["a_new_km"] == full["network_km"] and t["a_existing_km"] == 0, t
assert t["b_new_km"] == half["new_network_km"] and t["b_existing_km"] == half["existing"]["total_km"], t
assert abs(t["new_change_km"] - (half["new_network_km"] - full["network_km"])) < 1e-6, t
d = rows["departmental"]
assert d["b_new_km"] == half["new_km"]["departmental"] and d["b_existing_km"] == half["existing"]["km"]["departmental"] > 0, d
text = open("compare.txt").read()
head = "Roads, new and existing, km"
assert head in text, text
line = [l for l in text[text.index(head):].splitlines() if l.split()[:1] == ["departmental"]][0].split()
assert [float(v) for v in line[1:5]] == [round(x, 2) for x in (d["a_new_km"], d["a_existing_km"], d["b_new_km"], d["b_existing_km"])], line
PY

# The roads command takes them too.
"$TP" roads "$dem" full/network.geojson cmd --existing "$WORK/half.geojson" > out.txt 2>&1 || fail "roads --existing: $(cat out.txt)"
given=$(/usr/bin/python3 -c "import json; print(len(json.load(open('$WORK/half.geojson'))['features']))")
grep -Eq "existing roads: [0-9.]+ km given \($given lines, 0 outside the DEM\)" out.txt || fail "roads --existing: $(cat out.txt)"
[[ -s cmd/existing_roads.geojson ]] || fail "roads --existing wrote no existing_roads.geojson"

# Bad files: refused with exit 2 before any stage, naming the option; nothing written.
expect_refused bad "/roads/existing: .*no/such.geojson: no such file" "$TP" run -o bad --set dem="$dem" --set roads.existing=no/such.geojson
expect_refused bad "/roads/existing: .*nocrs.shp: has no CRS" "$TP" run -o bad --set dem="$dem" --set roads.existing="$WORK/nocrs.shp"
[[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "a file without a CRS was not refused before the stages: $(cat "$WORK/stderr")"
expect_refused bad "/roads/existing: .*points.geojson: roads must be line strings" \
  "$TP" run -o bad --set dem="$dem" --set roads.existing="$WORK/points.geojson"
[[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "a point file was not refused before the stages: $(cat "$WORK/stderr")"
expect_refused bad "/roads/existing: .*empty.geojson: holds no line" "$TP" run -o bad --set dem="$dem" --set roads.existing="$WORK/empty.geojson"
no_leftovers "$WORK"
echo "roads_existing: ok"
