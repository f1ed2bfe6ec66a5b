# Plugins: broken ones refused with exit 2 and the file named; --plugin syntax errors; --describe-json.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
BAD=${TERRAPOLIS_BAD_PLUGIN_DIR:?set by ctest: the folder of the test suite\'s broken plugins}
export TERRAPOLIS_PLUGIN_PATH=$BAD

expect_fail 2 "^terrapolis: error: $BAD/terrapolis_bad_abi.so: plugin ABI version 42, this Terrapolis needs version 1" \
  "$TP" density "$DEM" out1 --plugin bad_abi
expect_fail 2 "^terrapolis: error: $BAD/terrapolis_bad_schema.so: invalid parameter schema" \
  "$TP" density "$DEM" out2 --plugin bad_schema
expect_fail 2 "^terrapolis: error: $BAD/terrapolis_no_entry.so: not a Terrapolis plugin \(no terrapolis_plugin_entry symbol\)" \
  "$TP" path "$DEM" --from 9.30,42.68 --to 9.42,42.70 out3.geojson --plugin no_entry
[[ $(wc -l < "$WORK/stderr") -eq 1 ]] || fail "more than one line of error: $(cat "$WORK/stderr")"
expect_fail 2 "plugin example \(.*terrapolis_example.so\): params/value" "$TP" density "$DEM" out4 --plugin 'example:{"value":"high"}'
expect_fail 2 "error: --plugin Example: expected ID" "$TP" density "$DEM" out5 --plugin Example
expect_fail 2 "nofile.json: no such parameter file" "$TP" path "$DEM" --from 9.30,42.68 --to 9.42,42.70 out6 --plugin example:2:nofile.json
for o in out1 out2 out3.geojson out4 out5 out6; do [[ ! -e $o ]] || fail "$o left behind"; done

# The example plugin through the command line: its exclusion above 300 m shows in buildable.tif.
"$TP" -q density "$DEM" ok --plugin 'example:1:{"value":0.5,"max_altitude_m":300}' --weights 1,0,1.5,0
/usr/bin/python3 -c "
from osgeo import gdal
z = gdal.Open('$DEM').ReadAsArray(); b = gdal.Open('ok/buildable.tif').ReadAsArray()
assert ((z > 300) & (b == 1)).sum() == 0 and (b == 1).sum() > 1000" || fail "example plugin exclusions"
grep -q "WEIGHTS_COAST_HYDROMETRY_PLATEAU_PLAIN=1,0,1.5,0;plugin example:1" <(gdalinfo ok/density.tif) || fail "plugin missing from provenance"

# --describe-json: valid JSON with every command, --plugin where it belongs, typed options.
"$TP" --describe-json > describe.json
/usr/bin/python3 - <<'PY' || fail "--describe-json"
import json
d = json.load(open("describe.json"))
commands = {c["name"]: {o["name"]: o for o in c["options"]} for c in d["commands"]}
for name in ("density", "path", "roads"):
    assert commands[name]["--plugin"]["repeatable"], name
assert commands["density"]["DEM"] == {**commands["density"]["DEM"], "positional": True, "required": True, "kind": "raster_in"}
assert commands["density"]["OUTDIR"]["kind"] == "folder_out"
assert commands["path"]["--k"]["minimum"] == 1 and commands["path"]["--k"]["maximum"] == 16 and commands["path"]["--k"]["default"] == 5
assert commands["path"]["--router"]["choices"] == ["galin", "bezier"]
assert commands["path"]["--bridges"]["type"] == "boolean" and commands["path"]["--bridges"]["default"] is True
assert commands["density"]["--r-min"]["default"] == 500.0 and commands["density"]["--r-min"]["type"] == "number"
assert commands["hydro"]["--fill"]["default"] == "priority-flood"
assert [o["name"] for o in d["global_options"]] == ["--quiet", "--verbose", "--progress", "--threads"]
PY
echo "plugins refused and described: ok"
