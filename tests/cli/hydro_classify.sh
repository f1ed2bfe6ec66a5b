#!/usr/bin/env bash
# `terrapolis hydro --classify` (Génévaux et al. 2013 §5.1-5.2) on a real coast: every reach gets
# discharge, slope, sinuosity and a type, and the types obey the paper's rules.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
bin=$TP samples=$SAMPLES work=$WORK

# The documented example (docs/hydro.md).
"$bin" -q hydro "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$work/corsica" --sea-level 0 --classify \
  --outputs filled,streams
[[ -s $work/corsica/streams.qml ]] || fail "no streams.qml"
/usr/bin/python3 - "$work/corsica" <<'EOF'
import json, sys, xml.dom.minidom
folder = sys.argv[1]
xml.dom.minidom.parse(folder + "/streams.qml")  # well-formed
reaches = json.load(open(folder + "/streams.geojson"))["features"]
assert len(reaches) > 10, len(reaches)
types = {}
for f in reaches:
    p = f["properties"]
    t = p["river_type"]
    types[t] = types.get(t, 0) + 1
    a, q = p["upstream_km2"], p["discharge_m3s"]
    assert abs(q - 0.42 * a ** 0.69) <= 1e-9 * q, p  # the paper's law
    assert p["sinuosity"] >= 1 and p["slope"] >= 0, p
    if t == "delta":  # only on a mouth reach at high discharge
        assert p["downstream_id"] == 0 and p["to_mouth_km"] == 0 and q >= 50, p
    elif t == "D":  # only near a mouth at high discharge
        assert p["to_mouth_km"] is not None and p["to_mouth_km"] <= 10 and q >= 10, p
    elif t == "E":
        assert p["slope"] < 0.02 and p["sinuosity"] >= 1.2, p
    else:
        assert t == "B" and (p["slope"] >= 0.02 or p["sinuosity"] < 1.2), p
    if p["to_mouth_km"] is not None and p["downstream_id"] != 0:
        assert p["to_mouth_km"] > 0, p
# A coast of short, steep streams: straight B reaches dominate, and some reach the sea.
assert types.get("B", 0) > len(reaches) / 2, types
assert any(f["properties"]["to_mouth_km"] == 0 for f in reaches)
print("types:", types)
EOF

# QGIS (headless) opens streams.geojson with streams.qml applied: categories by river type.
chmod 700 "$work"
QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$work /usr/bin/python3 - "$work/corsica" <<'EOF' || fail "QGIS style"
import os, sys
from qgis.core import QgsApplication, QgsVectorLayer
app = QgsApplication([], False)
app.initQgis()
layer = QgsVectorLayer(os.path.join(sys.argv[1], "streams.geojson"), "streams", "ogr")
assert layer.isValid()
r = layer.renderer()  # QGIS loads the .qml of the same base name by itself
assert r.type() == "categorizedSymbol" and r.classAttribute() == "river_type", r.type()
assert sorted(c.value() for c in r.categories()) == ["B", "D", "E", "delta"]
os._exit(0)  # skip QGIS's teardown, which may crash in a headless session
EOF

# Without a sea level there is no coast: no D and no delta, no distance to a mouth.
"$bin" -q hydro "$samples/spDataLarge_srtm_zion.tif" "$work/zion" --classify --outputs streams --streams-threshold 2 \
  --braided-discharge 0.1 --delta-discharge 0.1
/usr/bin/python3 - "$work/zion/streams.geojson" <<'EOF'
import json, sys
for f in json.load(open(sys.argv[1]))["features"]:
    p = f["properties"]
    assert p["river_type"] in ("B", "E") and p["to_mouth_km"] is None, p
EOF

# Refusals: exit 2, nothing written.
expect_refused "$work/none" "needs the streams output" "$bin" -q hydro "$samples/spDataLarge_srtm_zion.tif" "$work/none" \
  --classify --outputs filled
expect_refused "$work/none" "--braided-discharge: must be > 0" "$bin" -q hydro "$samples/spDataLarge_srtm_zion.tif" "$work/none" \
  --classify --braided-discharge 0
# An existing streams.qml is refused like the other outputs.
expect_fail 2 "exists" "$bin" -q hydro "$samples/gebco2022_15s_north_corsica_capcorse.asc" "$work/corsica" --sea-level 0 \
  --classify --outputs streams
no_leftovers "$work"
echo ok
