# Every command that reads a DEM reads it the same way (cli/dem_input.hpp): --band 2 on a
# one-band file is refused, naming the file (exit 2, one line, no output left), and --assume-crs
# reads a DEM that carries no CRS (refused without it) with the same cells as the file that has one.
# `run` takes the same two settings from the scenario (input.band, input.assume_crs).
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
gdal_translate -q "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" one.tif  # WGS 84, one band
cp one.tif nocrs.tif
gdal_edit.py -a_srs "" nocrs.tif
rm -f nocrs.tif.aux.xml
grep -q GEOGCRS <(gdalinfo nocrs.tif) && fail "nocrs.tif still has a CRS"
cat > net.geojson <<'EOF'
{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"from": 1, "to": 2, "kept": true},
 "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.42, 42.70]]}}]}
EOF
printf 'lon,lat,z\n9.3,42.7,100\n9.4,42.9,300\n9.2,42.8,50\n' > samples.csv
places=$SOURCE/tests/data/geonames_capcorse.geojson

# args COMMAND DEM OUT: the command's arguments reading DEM and writing OUT.
args() {
  local dem=$2 out=$3
  case $1 in
    info) echo "$dem" ;;
    convert | fill) echo "$dem $out.tif" ;;
    hydro | density | skeleton | sites) echo "$dem $out" ;;
    lake) echo "$dem $out --at 9.40,42.95 --depth 5" ;;
    catchment) echo "$dem $out.geojson --outlet 9.40,42.95" ;;
    path) echo "$dem $out.geojson --from 9.30,42.68 --to 9.42,42.70" ;;
    roads) echo "$dem net.geojson $out" ;;
    calibrate) echo "$dem --settlements $places --report $out.json" ;;
    reconstruct) echo "samples.csv $out.tif --like $dem" ;;
    *) fail "no arguments for $1" ;;
  esac
}
commands="info convert fill hydro density skeleton sites lake catchment path roads calibrate reconstruct"
for cmd in $commands; do
  read -r -a a <<<"$(args "$cmd" one.tif "band-$cmd")"
  expect_fail 2 "^terrapolis: error: one\.tif: band 2 does not exist \(the file has 1\)$" "$TP" --quiet "$cmd" "${a[@]}" --band 2
  [[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "$cmd --band 2: more than one line: $(cat "$WORK/stderr")"
  compgen -G "band-$cmd*" >/dev/null && fail "$cmd --band 2 left band-$cmd behind"

  read -r -a a <<<"$(args "$cmd" nocrs.tif "nocrs-$cmd")"
  expect_fail 2 "nocrs\.tif: has no CRS; give one with --assume-crs" "$TP" --quiet "$cmd" "${a[@]}"
  read -r -a a <<<"$(args "$cmd" nocrs.tif "assumed-$cmd")"
  "$TP" --quiet "$cmd" "${a[@]}" --assume-crs EPSG:4326 >"$WORK/stdout" 2>"$WORK/stderr" ||
    fail "$cmd --assume-crs EPSG:4326 failed: $(cat "$WORK/stderr")"
  [[ $cmd == info ]] || compgen -G "assumed-$cmd*" >/dev/null || fail "$cmd --assume-crs wrote nothing"
done
# The assumed CRS is the file's: the same cells and georeferencing as from the file that has it.
"$TP" --quiet convert one.tif crs.tif
same_cells crs.tif assumed-convert.tif || fail "--assume-crs: convert's cells differ from the georeferenced file's"
[[ $(gdalsrsinfo -o epsg assumed-convert.tif) == "$(gdalsrsinfo -o epsg crs.tif)" ]] || fail "--assume-crs: the CRS was not written"
"$TP" --quiet info nocrs.tif --assume-crs EPSG:4326 | grep -v "^File:" > assumed.txt
"$TP" --quiet info one.tif | grep -v "^File:" > crs.txt
diff crs.txt assumed.txt >&2 || fail "--assume-crs: info differs from the georeferenced file's"

# sites takes --band / --assume-crs for a DEM only, not for a density folder.
mkdir density
expect_fail 2 "--band, --assume-crs: only for a DEM, and density is a density folder" "$TP" --quiet sites density out-sites --band 2

# run: the scenario's input.band and input.assume_crs, refused before the run folder is made.
expect_refused run-band "one\.tif: band 2 does not exist \(the file has 1\)" "$TP" --quiet run --set dem="$WORK/one.tif" --set input.band=2 -o run-band
expect_refused run-nocrs "nocrs\.tif: has no CRS" "$TP" --quiet run --set dem="$WORK/nocrs.tif" -o run-nocrs --until hydro
"$TP" --quiet run --set dem="$WORK/nocrs.tif" --set input.assume_crs=EPSG:4326 -o run-assumed --until hydro || fail "run with input.assume_crs failed"
[[ -f run-assumed/run.json ]] || fail "run with input.assume_crs wrote no run.json"
no_leftovers "$WORK"
echo "dem input: ok"
