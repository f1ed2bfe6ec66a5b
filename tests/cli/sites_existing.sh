# sites.existing (docs/sites.md, "Existing settlements"): the real places of a GeoNames extract enter
# the run at their cells with their populations, the model places only the rest of the settled
# people, the network joins them all; places off land are moved within two cells or refused by
# name, places off the DEM left out and counted; a bad file is refused before any stage.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
places=$SOURCE/tests/data/geonames_capcorse.geojson

# A place outside the DEM, one far out at sea, one with a negative population.
/usr/bin/python3 - "$places" <<'PY'
import json, sys
g = json.load(open(sys.argv[1]))
def place(name, pop, lon, lat):
    return {"type": "Feature", "properties": {"name": name, "population": pop}, "geometry": {"type": "Point", "coordinates": [lon, lat]}}
json.dump({"type": "FeatureCollection", "features": g["features"] + [place("Outside", 5000, 12.0, 40.0)]}, open("with_outside.geojson", "w"))
json.dump({"type": "FeatureCollection", "features": g["features"] + [place("Atlantis", 3000, 8.80, 43.10)]}, open("at_sea.geojson", "w"))
json.dump({"type": "FeatureCollection", "features": g["features"] + [place("Negative", -3, 9.4, 42.6)]}, open("negative.geojson", "w"))
PY

"$TP" -q run -o run --set dem="$dem" --set sites.existing="$WORK/with_outside.geojson" --set outputs.preview=false 2> stderr
grep -q "sites.existing: 1 place outside the DEM left out: Outside" stderr || fail "no line naming the place outside: $(cat stderr)"
/usr/bin/python3 - "$places" <<'PY' || fail "existing places in the run"
import json, sys
real = {f["properties"]["name"]: f for f in json.load(open(sys.argv[1]))["features"]}
cities = json.load(open("run/cities.geojson"))["features"]
run = json.load(open("run/run.json"))
given = [c for c in cities if c["properties"]["existing"] == 1]
assert sorted(c["properties"]["name"] for c in given) == sorted(real), [c["properties"]["name"] for c in given]
for c in given:
    p = real[c["properties"]["name"]]
    assert c["properties"]["population"] == p["properties"]["population"], (c, p)
    # The centre of the cell holding the place: within half a cell (15 arc-seconds) of it.
    for a, b in zip(c["geometry"]["coordinates"], p["geometry"]["coordinates"]):
        assert abs(a - b) <= 15 / 3600 / 2 + 1e-6, (c, p)
s = run["summary"]["sites"]
e = s["existing"]
assert e["places"] == len(real) and e["outside_dem"] == 1 and e["people"] == sum(f["properties"]["population"] for f in real.values()), e
# No census figure: the given places are the region as it is, nothing invented beside them.
assert e["generated"] == len(cities) - len(real) == 0, e
assert s["population"] == e["people"] + e["generated_people"] == s["settled_population"], s
assert s["settled_population"] + s["scattered_population"] == s["target_population"], s
# The place left out is named in run.json too.
assert "sites.existing: 1 place outside the DEM left out: Outside" in s["warnings"], s["warnings"]
# Ids run largest first; every settlement, given or generated, is an end of a kept link.
pops = [c["properties"]["population"] for c in cities]
assert pops == sorted(pops, reverse=True), pops
links = [f["properties"] for f in json.load(open("run/network.geojson"))["features"] if f["properties"]["kept"] == 1]
ends = {l["from"] for l in links} | {l["to"] for l in links}
assert ends == {c["properties"]["id"] for c in cities}, (ends, len(cities))
PY

# With the region's people given, the model places the settled people beyond the given places.
"$TP" -q run -o census --set dem="$dem" --set sites.existing="$places" --set sites.population=94347 --set outputs.preview=false --until sites 2>/dev/null ||
  fail "run with sites.population"
/usr/bin/python3 - <<'PY' || fail "existing places with the region's people"
import json
s = json.load(open("census/run.json"))["summary"]["sites"]
e = s["existing"]
assert e["generated"] > 0 and s["population"] == e["people"] + e["generated_people"] == s["settled_population"], s
assert s["settled_population"] == round(0.55 * 94347), s
PY

# A place on a sea cell next to the coast is moved to the nearest buildable cell.
/usr/bin/python3 - <<'PY'
import json
from osgeo import gdal
d = gdal.Open("run/elevation.tif"); z = d.ReadAsArray(); t = d.GetGeoTransform()
b = gdal.Open("run/buildable.tif").ReadAsArray()
r, c = next((r, c) for r in range(2, z.shape[0] - 2) for c in range(2, z.shape[1] - 2)
            if z[r, c] <= 0 and b[r, c + 1] == 1 and b[r, c - 1] != 1)
lon, lat = t[0] + (c + 0.5) * t[1], t[3] + (r + 0.5) * t[5]
json.dump({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"name": "Harbour", "population": 2000},
           "geometry": {"type": "Point", "coordinates": [lon, lat]}}]}, open("harbour.geojson", "w"))
PY
"$TP" -q run -o moved --set dem="$dem" --set sites.existing="$WORK/harbour.geojson" --set outputs.preview=false 2> /dev/null
/usr/bin/python3 -c "
import json; s = json.load(open('moved/run.json'))['summary']['sites']; e = s['existing']
assert e['places'] == 1 and e['moved_to_land'] == 1, e
assert s['warnings'][0] == 'sites.existing: 1 place on water or unbuildable land moved to the nearest free buildable cell: Harbour', s" \
  || fail "a place on a coastal sea cell was not moved to land, by name"

# The given places hold more than the settled share, or more people than the population given:
# the settlements hold them all, the region at least them, and run.json says so.
"$TP" run -o over --until sites --set dem="$dem" --set sites.existing="$places" --set sites.urban_share=0.3 --set outputs.preview=false \
  > over.txt 2>/dev/null
"$TP" -q run -o below --until sites --set dem="$dem" --set sites.existing="$places" --set sites.population=30000 --set outputs.preview=false \
  2>/dev/null
grep -q "existing 15 places, 43093 people (0 moved to land, 0 outside the DEM left out, 0 without people); 0 generated, 0 people" over.txt \
  || fail "no summary line for the given places: $(cat over.txt)"
grep -q "scattered over the land (hamlets and houses, spread by the density): 43093 settled + 51254 = 94347" over.txt \
  || fail "no line for the scattered people: $(cat over.txt)"
/usr/bin/python3 - <<'PY' || fail "given places above the settled share or the population"
import json
over = json.load(open("over/run.json"))["summary"]["sites"]
assert over["population"] == over["settled_population"] == 43093 and over["target_population"] == 94347, over
assert over["scattered_population"] == 94347 - 43093 and over["existing"]["generated"] == 0, over
assert any("the settled share (28304) or more: no settlement generated" in w for w in over["warnings"]), over["warnings"]
below = json.load(open("below/run.json"))["summary"]["sites"]
assert below["population"] == below["settled_population"] == below["target_population"] == 43093, below
assert below["scattered_population"] == 0, below
assert any(w.startswith("sites.population (30000) is below the 43093 people of sites.existing") for w in below["warnings"]), below["warnings"]
assert json.load(open("below/run.json"))["summary"].get("access", {"people": 43093})["people"] == 43093
PY

# The sites command on a DEM takes them too.
"$TP" sites "$dem" s --existing "$places" > out.txt
grep -Eq "^sites: 15 existing places \(43093 people; 0 moved to land, 0 outside the DEM left out\), [0-9]+ generated" out.txt || fail "sites --existing: $(cat out.txt)"

# Far out at sea: refused by name, nothing written; a negative population: refused before any stage.
expect_refused bad "at_sea.geojson: Atlantis: lies on water, nodata or unbuildable land with no free buildable cell within two cells" \
  "$TP" run -o bad --set dem="$dem" --set sites.existing="$WORK/at_sea.geojson"
expect_refused bad "/sites/existing: .*negative.geojson: Negative: the population must be a number of people >= 0" \
  "$TP" run -o bad --set dem="$dem" --set sites.existing="$WORK/negative.geojson"
[[ $(wc -l < "$WORK/stderr") -eq 1 ]] || fail "a bad places file was not refused before the stages: $(cat "$WORK/stderr")"
expect_refused bad "/sites/existing: .*no/such.geojson" "$TP" run -o bad --set dem="$dem" --set sites.existing=no/such.geojson
expect_refused bad "/sites/existing: needs /sites/quotas rank_size" \
  "$TP" run -o bad --set dem="$dem" --set sites.existing="$places" --set sites.quotas=belhadj2007
no_leftovers "$WORK"
echo "sites_existing: ok"
