# --overwrite replaces only what terrapolis wrote (docs/safety.md, "Outputs and --overwrite"):
# the folders it refuses, the files it keeps, and a replaced run that stays whole.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
cp "$SAMPLES/terra_elev_luxembourg.tif" mydem.tif
small=(--set outputs.preview=false --set outputs.qgis=false)

# `-o .` and `-o ..` (issue 14: they emptied the folder, the DEM included): refused, nothing removed.
mkdir -p sub
cp mydem.tif sub/
(cd sub && expect_fail 2 "'?\.'?: is the current folder" "$TP" run --set dem=mydem.tif -o . --overwrite)
(cd sub && expect_fail 2 "is the current folder" "$TP" run --set dem=mydem.tif -o .. --overwrite)
(cd sub && expect_fail 2 "is the current folder" "$TP" hydro mydem.tif .. --overwrite)
[[ -f sub/mydem.tif && -f mydem.tif ]] || fail "-o . / -o .. removed the DEM"
expect_fail 2 "is the root folder" "$TP" hydro mydem.tif / --overwrite
mkdir home
echo keep > home/precious.txt
expect_fail 2 "is the home folder" env HOME="$WORK/home" "$TP" density mydem.tif "$WORK/home" --overwrite

# A folder that no command of ours wrote (issue 14: precious.txt was gone, exit 0).
mkdir mydata
echo keep > mydata/precious.txt
for cmd in "run --set dem=mydem.tif -o mydata" "hydro mydem.tif mydata" "density mydem.tif mydata" "sites mydem.tif mydata"; do
  # shellcheck disable=SC2086
  expect_fail 2 "mydata: is not an output folder of terrapolis" "$TP" $cmd --overwrite
  # shellcheck disable=SC2086
  expect_fail 2 "mydata: output folder exists.*--overwrite" "$TP" $cmd
done
[[ $(cat mydata/precious.txt) == keep && $(ls -A mydata) == precious.txt ]] || fail "mydata was changed"
# An empty folder is as good as a new one.
mkdir empty
"$TP" -q hydro mydem.tif empty --outputs filled
[[ -f empty/filled.tif && -f empty/.terrapolis-outputs.json ]] || fail "hydro into an empty folder"

# The DEM (or any input) inside the output folder, or below it: refused, the input kept.
"$TP" -q run --set dem=mydem.tif -o r1 "${small[@]}"
cp mydem.tif r1/dem.tif
expect_fail 2 "r1: holds the input .*r1/dem.tif" "$TP" run --set dem=r1/dem.tif -o r1 --overwrite "${small[@]}"
[[ -f r1/dem.tif ]] || fail "the DEM inside the run folder was removed"
mkdir -p deep/a
cp mydem.tif deep/a/d.tif
"$TP" -q hydro deep/a/d.tif deep/h --outputs filled
expect_fail 2 "deep: holds the input" "$TP" hydro deep/a/d.tif deep --overwrite
expect_fail 2 "deep/h: holds the input" "$TP" hydro deep/h/filled.tif deep/h --overwrite
expect_fail 2 "d.tif: is an input of this command" "$TP" fill deep/a/d.tif deep/a/d.tif --overwrite
[[ -f deep/a/d.tif && -f deep/h/filled.tif ]] || fail "an input was removed"

# Replacing a run of ours: its files are replaced, a file the user added stays, a file the new run
# does not write any more goes.
rm r1/dem.tif
echo "my notes" > r1/notes.txt
"$TP" -q run --set dem=mydem.tif -o r2 --set outputs.preview=true --set outputs.preview_width=200 --set outputs.qgis=false
[[ -f r2/preview.png ]] || fail "no preview.png"
cp r1/notes.txt r2/
"$TP" -q run --set dem=mydem.tif -o r2 --overwrite "${small[@]}" --seed 7
[[ ! -e r2/preview.png ]] || fail "a file of the previous run that this one does not write was kept"
[[ $(cat r2/notes.txt) == "my notes" ]] || fail "--overwrite removed a file the user added"
grep -q '"seed": 7' r2/run.json || fail "r2 was not replaced"
grep -q 'notes.txt' r2/.terrapolis-outputs.json && fail "the user's file was recorded as ours"
# A user's file with the name of one of the new outputs: refused before anything moves.
"$TP" -q hydro mydem.tif h --outputs filled
echo mine > h/streams.geojson
before=$(md5sum h/filled.tif)
expect_fail 2 "h/streams.geojson: exists and was not written by terrapolis" "$TP" hydro mydem.tif h --overwrite
[[ $(cat h/streams.geojson) == mine && $(md5sum h/filled.tif) == "$before" ]] || fail "the refused overwrite changed h"

# A failed rerun keeps the old run whole (here the new DEM is not a raster: it fails after the
# new run folder was started beside the old one).
sums=$(cd r1 && md5sum ./* | sort)
echo "not a raster" > broken.tif
expect_fail 2 "broken.tif: not a raster" "$TP" run --set dem=broken.tif -o r1 --overwrite "${small[@]}"
[[ $(cd r1 && md5sum ./* | sort) == "$sums" ]] || fail "a failed --overwrite changed the old run"

# Single files: replaced only when terrapolis wrote them.
gdal_translate -q mydem.tif theirs.tif
expect_fail 2 "theirs.tif: was not written by terrapolis" "$TP" convert mydem.tif theirs.tif --overwrite
"$TP" -q convert mydem.tif ours.tif
"$TP" -q convert mydem.tif ours.tif --overwrite --cog
grep -q "LAYOUT=COG" <(gdalinfo ours.tif) || fail "convert --overwrite did not replace its own file"
echo keep > report.txt
expect_fail 2 "report.txt: was not written by terrapolis" "$TP" compare r1 r2 --save report.txt --overwrite
[[ $(cat report.txt) == keep ]] || fail "compare --save replaced a user's file"
"$TP" compare r1 r2 --save cmp.txt > /dev/null
"$TP" compare r1 r2 --save cmp.txt --overwrite > /dev/null

no_leftovers "$WORK"
[[ -z $(find "$WORK" -name '*.tmp-*') ]] || fail "temporary outputs left: $(find "$WORK" -name '*.tmp-*')"
echo "safety_overwrite: ok"
