# Every JSON input (scenario, --set value, cost model, plugin parameters, run.json) is bounded before
# it is parsed: depth, size, numbers out of range. One line naming the input and the field, exit 2.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc

# one_line: the last command's stderr is a single line without the JSON library's exception names.
one_line() {
  [[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "more than one line: $(cat "$WORK/stderr")"
  grep -q "json.exception" "$WORK/stderr" && fail "raw JSON library text: $(cat "$WORK/stderr")"
  return 0
}

# Nested 100,000 levels deep (crashed the serializer), and just past the limit.
/usr/bin/python3 -c 'print("[" * 100000 + "]" * 100000)' > deep.json
expect_refused out "deep.json: JSON nests deeper than 64 levels" "$TP" run deep.json -o out; one_line
/usr/bin/python3 -c 'print("{\"a\": " * 65 + "1" + "}" * 65)' > deep65.json
expect_refused out "deep65.json: JSON nests deeper than 64 levels at /a/a" "$TP" run deep65.json -o out; one_line
expect_refused out "--set x: JSON nests deeper" "$TP" run --set "x=$(/usr/bin/python3 -c 'print("[" * 1000 + "]" * 1000)')" -o out; one_line
expect_refused out "nests deeper" "$TP" run --set "$(/usr/bin/python3 -c 'print(".".join(["a"] * 100))')=1" -o out; one_line
# Larger than 16 MB: refused before reading.
/usr/bin/python3 -c 'import sys; sys.stdout.write("{\"pad\": \"" + "x" * (17 << 20) + "\"}")' > big.json
expect_refused out "big.json: JSON file of 17 MB is larger than the 16 MB accepted" "$TP" run big.json -o out; one_line

# Numbers out of range name the file and the field.
echo '{"density": {"r_min_m": 1e400}}' > huge.json
expect_refused out "huge.json: /density/r_min_m: number 1e400 is out of range" "$TP" run huge.json -o out; one_line
echo '{"density": {"weights": [1, -1e400, 0, 0]}}' > huge2.json
expect_refused out "huge2.json: /density/weights/1: number -1e400 is out of range" "$TP" run huge2.json -o out; one_line
expect_refused out "--set density.r_min_m: /: number 1e400 is out of range" "$TP" run --set density.r_min_m=1e400 -o out; one_line
echo '{"road": {"slope_deg": {"points": [[0, 1e999]]}}}' > costs.json
cat > net.geojson <<'JSON'
{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"from": 0, "to": 1, "kind": "roots", "kept": 1},
 "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.42, 42.70]]}}]}
JSON
expect_refused out "costs.json: /road/slope_deg/points/0/1: number 1e999" "$TP" --quiet roads "$dem" net.geojson out --costs costs.json; one_line
echo '{"seed": 1,' > cut.json
expect_refused out "cut.json: not valid JSON" "$TP" run cut.json -o out; one_line

# An empty output or DEM is refused by the schema, not by a filesystem error.
expect_refused out "/output" "$TP" run -o ""; one_line
echo '{"output": ""}' > empty_out.json
expect_refused out "empty_out.json: /output" "$TP" run empty_out.json; one_line
expect_refused out "/dem" "$TP" run --set 'dem=""' -o out; one_line

# run.json of a compared run: bounded too.
mkdir fake && cp deep.json fake/run.json
expect_fail 2 "run.json: JSON nests deeper" "$TP" compare fake fake; one_line
no_leftovers "$WORK"
echo "bad JSON cases: ok"
