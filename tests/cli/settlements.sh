# Settlements: the thesis's model reproduced byte for byte (pinned before the rank-size default).
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
# cities.geojson of the thesis's quotas and weights on the bundled DEM, seed 1, as of commit f437b48.
PINNED=43f74baa6e097951aaec6a21b7551f6e79e01ce9e7a5837748c3cbc26136780a
# The commands: `density` (the thesis's weights by default), then `sites` on its folder.
"$TP" --quiet density "$DEM" thesis_density
"$TP" --quiet sites thesis_density thesis --quotas belhadj2007 > /dev/null
[[ $(sha256sum < thesis/cities.geojson | cut -d' ' -f1) == "$PINNED" ]] || fail "sites: the thesis's cities changed"
echo "settlements: ok"

# The default run: the population assumed from the land area, a rank-size law, figures against
# the GeoNames places of the tile (tests/data, CC BY 4.0); the thesis's model again through the run.
REF=$SOURCE/tests/data/geonames_capcorse.geojson
"$TP" --quiet run -o run --until sites --set sites.reference="\"$REF\""
/usr/bin/python3 - run/run.json <<'PY' || fail "default run figures"
import json, sys
m = json.load(open(sys.argv[1]))
s, r = m["summary"]["sites"], m["summary"]["realism"]
assert [t["stage"] for t in m["timings"]] == ["terrain", "hydro", "density", "sites"], m["timings"]
assert s["population_source"].startswith("assumed: 60 people/km2"), s
land = m["summary"]["density"]["land_area_km2"]
assert 1400 < land < 1700 and abs(s["target_population"] - round(60 * land)) <= 1, (land, s)
# The settled share (sites.urban_share) lives in the settlements, every one of them placed; sizes by
# the law whose exponent the density's catchments give.
assert s["sizes"] == "catchment" and s["settled_population"] == round(s["urban_share"] * s["target_population"]), s
assert s["population"] == s["settled_population"], s
# Every person accounted for: the settled and the scattered make the region's people.
assert s["settled_population"] + s["scattered_population"] == s["target_population"] and s["scattered_population"] > 0, s
assert 0 <= s["suburbs"] < s["cities"], s  # spaced central places: few in a larger one's reach (Suburbs.* test them)
# Right in magnitude: the total within a factor 3 of the real places' sum (43,093).
assert r["total"]["reference"] == 43093 and 1 / 3 < r["total"]["ratio"] < 3, r["total"]
# A rural cape: the largest town within a factor 2 of the real largest (5,552), the exponent within 0.25.
assert r["largest"]["reference"] == 5552 and 0.5 < r["largest"]["generated"] / 5552 < 2, r["largest"]
assert abs(r["rank_size_exponent"]["generated"] - r["rank_size_exponent"]["reference"]) <= 0.25, r["rank_size_exponent"]
assert r["places"] == 15 and 0 <= r["skill"]["auc"] <= 1 and len(r["top10"]["places"]) == 10, r
PY
"$TP" --quiet run -o thesis_run --until sites --set density.preset='"belhadj2007"' --set sites.quotas='"belhadj2007"' \
  --set sites.reference="\"$REF\""
[[ $(sha256sum < thesis_run/cities.geojson | cut -d' ' -f1) == "$PINNED" ]] || fail "run: the thesis's cities changed"
grep -q "realism.count.generated" <("$TP" compare run thesis_run) || fail "compare does not show the realism figures"
expect_fail 2 "nowhere.geojson: no such file" "$TP" run -o bad --until sites --set sites.reference='"nowhere.geojson"'

# Calibration on the tile: a fragment a scenario takes, a report with the figures.
"$TP" --quiet calibrate "$DEM" --settlements "$REF" --fragment fit.json --report report.json > cal.txt
grep -q "gebco2022_15s_north_corsica_capcorse" cal.txt || fail "calibrate printed no region"
/usr/bin/python3 - report.json <<'PY' || fail "calibrate report"
import json, sys
r = json.load(open(sys.argv[1]))["regions"][0]
assert r["places"] == 15 and set(r["baselines"]) == {"minus_elevation", "minus_slope", "coast_nearness"}, r
assert 0 <= r["cross_validated"]["auc"] <= 1 and r["settlements"]["total"] == 43093, r
PY
"$TP" --quiet run -o fitted --until density --set "density.weights=$(/usr/bin/python3 -c "import json; print(json.dumps(json.load(open('fit.json'))['density']['weights']))")"
expect_fail 2 "fit.json: output exists" "$TP" calibrate "$DEM" --settlements "$REF" --fragment fit.json
echo "run and calibrate: ok"
