# `terrapolis run`: a whole run folder, byte-identical twice, clean failures, and QGIS opens it.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
"$TP" --quiet run -o run1 --set outputs.preview_width=400
"$TP" --quiet --threads 1 run -o run2 --set outputs.preview_width=400
for f in run1/*; do
  name=$(basename "$f")
  [[ $name == run.json ]] && continue  # holds timings and memory of the run
  cmp -s "$f" "run2/$name" || fail "$name differs between two runs of the same scenario"
done
for f in elevation.tif hillshade.tif filled.tif flowdir.tif accumulation.tif hydrometry.tif streams.geojson \
         coast.tif plateau.tif plain.tif buildable.tif density.tif cities.geojson city_extents.geojson \
         network.geojson roads.geojson road_sections.geojson sections.geojson junctions.geojson elevation.qml roads.qml project.qgs preview.png run.json; do
  [[ -s run1/$f ]] || fail "run1/$f missing"
done
# Every stage ran and the summary holds its figures; the kept network is connected and each kept
# link has its road (or is reported as not routable).
/usr/bin/python3 - run1/run.json <<'PY' || fail "run.json figures"
import json, sys
m = json.load(open(sys.argv[1]))
assert [t["stage"] for t in m["timings"]] == ["terrain", "hydro", "density", "sites", "network", "roads", "access"], m["timings"]
s = m["summary"]
assert s["hydro"]["stream_reaches"] > 0 and s["sites"]["cities"] > 0, s
assert sum(c["cities"] for c in s["sites"]["per_class"].values()) == s["sites"]["cities"], s["sites"]
assert 0 < s["density"]["mean_density"] <= 1, s["density"]
assert s["roads"]["roads"] + s["roads"]["failed"] + s["roads"]["redundant"] == s["network"]["kept_edges"], (s["roads"], s["network"])
assert sum(s["roads"]["length_km"].values()) > 0, s["roads"]
# Road density: the network drawn once over the land the density stage measured (as the sites read it).
r = s["roads"]
assert r["land_km2"] == s["density"]["land_area_km2"] > 1000, (r, s["density"])
assert abs(r["network_km_per_km2"] - r["network_km"] / r["land_km2"]) < 1e-3, r
PY
grep -q "LAYOUT=COG" <(gdalinfo run1/elevation.tif) || fail "elevation.tif is not a COG"
grep -q "TERRAPOLIS_INPUT_SHA256=" <(gdalinfo run1/elevation.tif) || fail "no provenance in elevation.tif"
/usr/bin/python3 -c "import json,sys; m=json.load(open('run1/run.json')); assert m['input']['sha256'] and m['timings'], m" || fail "run.json"

# Existing folder refused; invalid scenarios fail with the pointer and leave nothing.
expect_fail 2 "run1: output folder exists.*--overwrite" "$TP" run -o run1
expect_fail 2 "/outputs/cog" "$TP" run -o bad --set outputs.cog=3
[[ ! -e bad ]] || fail "an invalid scenario left a folder"
echo '{"dem": "nowhere.tif", "output": "bad2"}' > s.json
expect_fail 2 "nowhere.tif: no such file" "$TP" run s.json
[[ ! -e bad2 ]] || fail "a missing DEM left a folder"
no_leftovers "$WORK"
grep -q "tmp-" <(ls -a) && fail "temporary run folder left behind"

# The real client: QGIS opens project.qgs headless, every layer valid and styled, and renders it.
if /usr/bin/python3 -c "import qgis.core" 2>/dev/null; then
  QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$WORK /usr/bin/python3 "$SOURCE/tests/qgis/check_project.py" run1 qgis.png
else
  fail "python3-qgis is not installed (scripts/setup installs it)"
fi
# outputs.geopackage: every vector layer in run.gpkg, styled by default in QGIS, the same bytes at
# any thread count and from a rerun that reuses the saved stages.
"$TP" --quiet run -o gpkg1 --set outputs.geopackage=true --set outputs.preview=false
"$TP" --quiet --threads 1 run -o gpkg2 --set outputs.geopackage=true --set outputs.preview=false
cmp -s gpkg1/run.gpkg gpkg2/run.gpkg || fail "run.gpkg differs between two runs of the same scenario"
"$TP" --quiet run -o gpkg1 --from network --set outputs.geopackage=true --set outputs.preview=false
cmp -s gpkg1/run.gpkg gpkg2/run.gpkg || fail "run.gpkg differs after a rerun --from network"
[[ ! -e run1/run.gpkg ]] || fail "run.gpkg written by default"
QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$WORK /usr/bin/python3 "$SOURCE/tests/qgis/check_geopackage.py" gpkg1
echo "run: ok"

# Reruns from saved results: --from reads the earlier stages back, --only reruns just some.
# Read back exactly: an unchanged rerun from the network rewrites the network and roads byte for byte.
cp -r run1 same
"$TP" --quiet run -o same --from network --set outputs.preview_width=400
for f in network.geojson roads.geojson road_sections.geojson; do
  cmp -s "run1/$f" "same/$f" || fail "--from network with nothing changed rewrote $f differently"
done
cp -r run1 rerun
"$TP" --quiet run -o rerun --from network --set network.k=1.3
/usr/bin/python3 - run1/run.json rerun/run.json <<'PY' || fail "--from network"
import json, sys
old, m = (json.load(open(f)) for f in sys.argv[1:3])
assert m["rerun"] == {"ran": ["network", "roads", "access"], "reused": ["terrain", "hydro", "density", "sites"], "stale": []}, m["rerun"]
assert m["scenario"]["network"]["k"] == 1.3
# The same candidates as the full run (the cities read back are the same); a smaller detour
# factor removes fewer links (fewer detours are short enough).
assert m["summary"]["network"]["candidate_edges"] == old["summary"]["network"]["candidate_edges"], m["summary"]["network"]
assert m["summary"]["network"]["kept_edges"] > old["summary"]["network"]["kept_edges"], (m["summary"], old["summary"])
assert m["summary"]["sites"] == old["summary"]["sites"]
PY
cmp -s run1/cities.geojson rerun/cities.geojson || fail "--from network rewrote the cities"
"$TP" --quiet run -o rerun --only density --set density.weights.plain=1
/usr/bin/python3 -c "import json; r=json.load(open('rerun/run.json'))['rerun']; assert r['stale']==['sites','network','roads','access'], r" || fail "--only"
cmp -s run1/density.tif rerun/density.tif && fail "--only density did not change density.tif"
expect_fail 2 "other 'density' parameters; rerun from density" "$TP" run -o rerun --from sites --set density.r_max_m=6000
# The flow-direction style follows the run's code convention (GRASS: east is 8).
cp -r run1 grass
"$TP" --quiet run -o grass --only hydro --set hydro.d8_codes=grass
grep -q 'value="8" color="#e41a1c" alpha="255" label="E"' grass/flowdir.qml || fail "flowdir.qml does not use the GRASS codes"
# Water looks like water in QGIS: the density is transparent where it is 0 (the sea, as in the
# preview) and the terrain is blue up to the sea level (water.sea_level_m).
grep -q '<pixelListEntry min="0" max="0" percentTransparent="100"/>' run1/density.qml || fail "density.qml draws the sea"
grep -q 'value="0" label="sea level" color="#9ecae1"' run1/elevation.qml || fail "elevation.qml: no sea level"
"$TP" --quiet run -o sea50 --until terrain --set water.sea_level_m=50
grep -q 'value="50" label="sea level" color="#9ecae1"' sea50/elevation.qml || fail "elevation.qml ignores water.sea_level_m"
expect_fail 2 "other 'density' parameters" "$TP" run -o rerun --only hydro roads --set density.r_max_m=6000
# A run that stopped early (--until) can rerun its last stage: the stages it never made stay absent.
"$TP" --quiet run -o short --until sites
"$TP" --quiet run -o short --only sites --set sites.influence_factor=2
/usr/bin/python3 -c "import json; m=json.load(open('short/run.json')); assert m['rerun']['stale']==[] and 'network' not in m['summary'], m['rerun']" || fail "--only sites after --until sites"
[[ ! -e short/network.geojson ]] || fail "--only sites made a network"
expect_fail 2 "dunes" "$TP" run -o rerun --from dunes
expect_fail 2 "nosuch: not a run folder" "$TP" run -o nosuch --from roads
no_leftovers "$WORK"
echo "rerun: ok"

# compare: two runs differing in one parameter.
cp -r run1 run3
"$TP" --quiet run -o run3 --only terrain --set outputs.preview_width=500
"$TP" compare run1 run3 > cmp.txt
grep -Eq "outputs.preview_width +400 +500" cmp.txt || fail "compare does not show the changed parameter: $(cat cmp.txt)"
"$TP" compare --json run1 run1 | /usr/bin/python3 -c "import json,sys; c=json.load(sys.stdin); assert c['parameters']==[], c" || fail "compare of a run with itself"
expect_fail 2 "nowhere: not a run folder" "$TP" compare run1 nowhere
# --save: the same text in a file, written whole; an existing file is refused without --overwrite.
"$TP" compare run1 run3 --save saved.txt > shown.txt
cmp -s saved.txt shown.txt || fail "compare --save wrote something else than it printed"
expect_fail 2 "saved.txt: output exists" "$TP" compare run1 run3 --save saved.txt
"$TP" compare --json run1 run3 --save saved.txt --overwrite > /dev/null
/usr/bin/python3 -c "import json; json.load(open('saved.txt'))" || fail "compare --json --save did not write JSON"
echo "compare: ok"
