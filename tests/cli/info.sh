# `terrapolis info` on real samples: georeferencing, units and JSON output.
source "$(dirname "$0")/lib.sh" "$@"
out=$("$TP" info "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc")
grep -q "175 x 175 cells" <<<"$out" || fail "size: $out"
grep -q "WGS 84 (EPSG:4326), geographic" <<<"$out" || fail "crs: $out"
grep -q "Extent:     lon 8.712500 .. 9.441667, lat 42.479167 .. 43.208333" <<<"$out" || fail "extent: $out"
grep -q "Elevation:  -2601.00 .. 1829.00 m" <<<"$out" || fail "elevation: $out"
# 15 arc-seconds at 42.84 N: about 340.6 m east-west and 462.9 m north-south.
grep -Eq "Cell size:  340\.[56][0-9] m east-west x 462\.[89][0-9] m north-south" <<<"$out" || fail "cell size: $out"

json=$("$TP" info --json "$SAMPLES/spDataLarge_srtm_zion.tif")
/usr/bin/python3 - "$json" <<'PY'
import json, sys
j = json.loads(sys.argv[1])
assert j["crs"]["epsg"] == 4326, j["crs"]
assert j["elevation_m"]["min"] == 1024 and j["elevation_m"]["max"] == 2892, j["elevation_m"]
assert j["nodata"]["value"] == 65535, j["nodata"]
PY
grep -q "83.42 % of cells" <("$TP" info "$SAMPLES/spDataLarge_nz_elev.tif") || fail "NaN nodata share"
grep -q "(no EPSG code), projected" <("$TP" info "$SAMPLES/spDataLarge_nz_elev.tif") || fail "nz crs"
grep -q "terrapolis" <("$TP" --version) || fail "--version"
echo "info: ok"
