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
for f in elevation.tif hillshade.tif elevation.qml project.qgs preview.png run.json; do
  [[ -s run1/$f ]] || fail "run1/$f missing"
done
gdalinfo run1/elevation.tif | grep -q "LAYOUT=COG" || fail "elevation.tif is not a COG"
gdalinfo run1/elevation.tif | grep -q "TERRAPOLIS_INPUT_SHA256=" || fail "no provenance in elevation.tif"
/usr/bin/python3 -c "import json,sys; m=json.load(open('run1/run.json')); assert m['input']['sha256'] and m['timings'], m" || fail "run.json"

# Existing folder refused; invalid scenarios fail with the pointer and leave nothing.
expect_fail 2 "run1: run folder exists.*--overwrite" "$TP" run -o run1
expect_fail 2 "/outputs/cog" "$TP" run -o bad --set outputs.cog=3
[[ ! -e bad ]] || fail "an invalid scenario left a folder"
echo '{"dem": "nowhere.tif", "output": "bad2"}' > s.json
expect_fail 2 "nowhere.tif: no such file" "$TP" run s.json
[[ ! -e bad2 ]] || fail "a missing DEM left a folder"
no_leftovers "$WORK"
ls -a | grep -q "tmp-" && fail "temporary run folder left behind"

# The real client: QGIS opens project.qgs headless, every layer valid and styled, and renders it.
if /usr/bin/python3 -c "import qgis.core" 2>/dev/null; then
  QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$WORK /usr/bin/python3 "$SOURCE/tests/qgis/check_project.py" run1 qgis.png
else
  fail "python3-qgis is not installed (scripts/setup installs it)"
fi
echo "run: ok"

# compare: two runs differing in one parameter.
"$TP" --quiet run -o run3 --set outputs.preview_width=500
"$TP" compare run1 run3 > cmp.txt
grep -Eq "outputs.preview_width +400 +500" cmp.txt || fail "compare does not show the changed parameter: $(cat cmp.txt)"
"$TP" compare --json run1 run1 | /usr/bin/python3 -c "import json,sys; c=json.load(sys.stdin); assert c['parameters']==[], c" || fail "compare of a run with itself"
expect_fail 2 "nowhere: not a run folder" "$TP" compare run1 nowhere
echo "compare: ok"
