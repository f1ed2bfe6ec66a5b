# One rule for every command that writes: an output whose parent folder does not exist is refused
# (exit 2, nothing created), never made with its parents (docs/safety.md, "Outputs and --overwrite").
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/terra_elev_luxembourg.tif
"$TP" -q run --set dem="$dem" -o r1 --set outputs.preview=false --set outputs.qgis=false
"$TP" -q sites "$dem" s
"$TP" -q network s/cities.geojson n
echo "x,y,z" > samples.csv
missing="no/such"
check() {  # check OUTPUT CMD...: refused, naming the output and its missing folder; nothing made.
  local out=$1; shift
  expect_fail 2 "$out: output folder no/such does not exist" "$@"
  [[ ! -e no ]] || fail "'$*' created no/"
}
check "$missing/run" "$TP" run --set dem="$dem" -o "$missing/run"
check "$missing/h" "$TP" hydro "$dem" "$missing/h"
check "$missing/d" "$TP" density "$dem" "$missing/d"
check "$missing/s" "$TP" sites "$dem" "$missing/s"
check "$missing/n" "$TP" network s/cities.geojson "$missing/n"
check "$missing/r" "$TP" roads "$dem" n/network.geojson "$missing/r"
check "$missing/e.tif" "$TP" roads "$dem" n/network.geojson r --earthworks "$missing/e.tif"
check "$missing/p.geojson" "$TP" path "$dem" --from 6.0,49.7 --to 6.2,49.8 "$missing/p.geojson"
check "$missing/f.tif" "$TP" fill "$dem" "$missing/f.tif"
check "$missing/c.tif" "$TP" convert "$dem" "$missing/c.tif"
check "$missing/g.tif" "$TP" generate "$missing/g.tif" --size 64x64 --cell 100 --crs EPSG:32632
check "$missing/rec.tif" "$TP" reconstruct samples.csv "$missing/rec.tif" --like "$dem"
check "$missing/c.geojson" "$TP" catchment "$dem" --outlet 6.1,49.7 "$missing/c.geojson"
check "$missing/cmp.txt" "$TP" compare r1 r1 --save "$missing/cmp.txt"
[[ ! -e r ]] || fail "roads wrote its folder although --earthworks was refused"
no_leftovers "$WORK"
echo "safety_missing_parent: ok"
