#!/usr/bin/env bash
# roads.corridor.enabled: the run's roads stage writes corridors.geojson (styled in project.qgs) and
# the summary's land take and volumes, the land take polygons' area equal to the summary's.
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
"$TP" --quiet run -o run --set outputs.preview_width=200 --set roads.corridor.enabled=true --set roads.corridor.material=rock 2>/dev/null
[[ -s run/corridors.geojson && -s run/corridors.qml ]] || fail "no corridors.geojson"
grep -q 'corridors.geojson' run/project.qgs || fail "corridors not in project.qgs"
/usr/bin/python3 - run <<'PY' || fail "corridor figures"
import json, sys
run = sys.argv[1]
s = json.load(open(run + "/run.json"))["summary"]["roads"]["corridor"]
assert s["land_take_ha"] > 0 and s["cut_m3"] >= 0 and s["fill_m3"] >= 0, s
corr = [f["properties"] for f in json.load(open(run + "/corridors.geojson"))["features"]]
taken = sum(p["area_ha"] for p in corr if p["part"] == "land_take")
zones = sum(p["area_ha"] for p in corr if p["part"] == "earthworks")
assert abs(taken - s["land_take_ha"]) < 0.01, (taken, s)
assert taken <= zones + 1e-3, (taken, zones)  # the union never exceeds the sum
# Per-class widths: a zone is at least its class's platform (the local road's 7 m at the least).
assert all(p["area_ha"] >= 0.98 * p["length_m"] * 7 / 1e4 for p in corr if p["part"] == "earthworks" and p["length_m"] > 0), "narrow zone"
PY
echo ok
