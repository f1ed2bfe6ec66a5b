# One source of truth: every command's options that the scenario schema declares (x-cli) show the
# schema's description, unit, default, range and choices in --help and --describe-json; every path
# option states its kind; the command line refuses what a scenario refuses; errors name the flag
# in a command and the scenario file with the JSON pointer in a run.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
"$TP" --describe-json > describe.json
for c in $(/usr/bin/python3 -c "import json; print(' '.join(c['name'] for c in json.load(open('describe.json'))['commands']))"); do
  "$TP" "$c" --help > "help-$c.txt"
done
/usr/bin/python3 - "$SOURCE/schemas/scenario.schema.json" <<'PY' || fail "--help / --describe-json differ from the schema"
import json, re, sys
schema = json.load(open(sys.argv[1]))
described = {c["name"]: {o["name"]: o for o in c["options"]} for c in json.load(open("describe.json"))["commands"]}

def fields(node, pointer=""):
    for key, field in node.get("properties", {}).items():
        yield pointer + "/" + key, field
        yield from fields(field, pointer + "/" + key)
        if isinstance(field.get("items"), dict):  # a list's flags fill its first item
            yield from fields(field["items"], pointer + "/" + key + "/0")

checked = 0
for pointer, field in fields(schema):
    for command, entry in field.get("x-cli", {}).items():
        flag = entry if isinstance(entry, str) else entry["flag"]
        name = flag.split(",")[0]
        default = entry["default"] if isinstance(entry, dict) and "default" in entry else field.get("default")
        o = described[command][name]
        assert o["schema"] == pointer, (command, name, o)
        assert o["help"] == field["description"], (command, name)
        assert o["unit"] == field["x-unit"], (command, name)
        assert o["type"] == field["type"], (command, name)
        assert o["default"] == default, (command, name, o["default"], default)
        assert o.get("choices") == field.get("enum"), (command, name)
        for key, json_key in (("minimum", "minimum"), ("maximum", "maximum"), ("exclusive_minimum", "exclusiveMinimum")):
            assert o.get(key) == field.get(json_key), (command, name, key)
        assert o["kind"] == field.get("x-kind"), (command, name)
        # --help shows the same description (CLI11 wraps nothing; the unit follows in brackets).
        text = open(f"help-{command}.txt").read()
        assert field["description"] in text, (command, name, "help")
        checked += 1
assert checked >= 40, checked
# Every option that names a file or folder says which (no kind guessed from its help wording).
path_words = re.compile(r"^(DEM|OUT|OUTDIR|CITIES|NETWORK|SAMPLES|SCENARIO|RUN_A|RUN_B|DENSITY_DIR_OR_DEM)$")
for command, options in described.items():
    for name, o in options.items():
        if path_words.match(name):
            assert o["kind"], (command, name, "no kind")
assert described["hydro"]["--weights"]["kind"] == "raster_in"
assert described["roads"]["--costs"]["kind"] == "file_in" and described["path"]["--vegetation"]["kind"] == "raster_in"
assert described["density"]["--water-mask"]["kind"] == "raster_in"
assert described["catchment"]["OUT"]["kind"] == "vector_out" and described["calibrate"]["--report"]["kind"] == "file_out"
print("schema options checked:", checked)
PY

# The same range on the command line as in a scenario (2000000 m is over the schema's maximum).
expect_refused d1 "^terrapolis: error: --r-max: .*1e\+?0?6|--r-max: .*1000000" "$TP" density "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" d1 --r-max 2000000
expect_fail 2 "/density/r_max_m" "$TP" run -o r1 --set density.r_max_m=2000000
# A stage's own check names the flag in a command, the scenario and the pointer in a run.
expect_refused d2 "error: --r-max: must be larger than --r-min" "$TP" density "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" d2 --r-max 400
expect_fail 2 "error: \(default scenario\): /density/r_max_m: must be larger than /density/r_min_m" "$TP" run -o r2 --set density.r_max_m=400
[[ ! -e r2 ]] || fail "a refused run left its folder"
# Prepared before any stage: a missing cost model fails at once, naming the pointer, with nothing written.
expect_fail 2 "\(default scenario\): /roads/costs: .*nonexistent.json" "$TP" run -o r3 --set roads.costs=nonexistent.json
[[ ! -e r3 ]] || fail "a missing cost model left a run folder"
expect_fail 2 "/density/layers/0/file: nowhere.tif: no such file" "$TP" run -o r4 --set 'density.layers=[{"file":"nowhere.tif","weight":1}]'
# Schema enums on the command line; a value of the wrong type names the flag.
expect_fail 2 "error: --fill: " "$TP" hydro "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" h1 --fill nonsense
expect_fail 2 "error: --k: " "$TP" network cities.geojson n1 --k abc
no_leftovers "$WORK"
echo "schema options: ok"
