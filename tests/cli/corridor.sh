#!/usr/bin/env bash
# `path --corridor` and `roads --corridor` on the bundled DEM (the docs/roads.md example): polygons
# per section, per-road land take and volumes, materials ordered by their angles; bad inputs exit 2.
source "$(dirname "$0")/lib.sh" "$@"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
py=/usr/bin/python3

# The docs' example.
"$TP" path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/road.geojson" --corridor "$WORK/corridor.geojson" \
  --material rock 2>"$WORK/log"
grep -Eq "corridor: land take [0-9.]+ ha, cut [0-9]+ m³, fill [0-9]+ m³" "$WORK/log" || fail "no corridor summary: $(cat "$WORK/log")"
$py - "$WORK/road.geojson" "$WORK/corridor.geojson" <<'EOF' || fail "corridor outputs"
import json, sys
road = json.load(open(sys.argv[1]))["features"][0]["properties"]
corr = json.load(open(sys.argv[2]))["features"]
assert road["land_take_ha"] > 0 and road["cut_m3"] >= 0 and road["fill_m3"] >= 0, road
assert road["cleared_ha"] is None, road  # no vegetation layer
zones = [f for f in corr if f["properties"]["part"] == "earthworks"]
lanes = [f for f in corr if f["properties"]["part"] == "carriageway"]
taken = [f for f in corr if f["properties"]["part"] == "land_take"]
assert zones and len(lanes) >= len(zones) and taken, (len(zones), len(lanes), len(taken))
assert all(f["geometry"]["type"] == "Polygon" for f in corr)
# The road's land take is its sections' zones united (never more than their sum), the run's
# land_take polygons the same ground; cut and fill are the sum of its sections'.
zones_ha = sum(f["properties"]["area_ha"] for f in zones)
assert 0.9 * zones_ha <= road["land_take_ha"] <= zones_ha + 1e-3, (road, zones_ha)
assert abs(sum(f["properties"]["area_ha"] for f in taken) - road["land_take_ha"]) < 1e-3, road
assert abs(sum(f["properties"]["cut_m3"] or 0 for f in zones) - road["cut_m3"]) < 1, road
# A departmental road (path's class): platform 9 m (r = 4.5 m), carriageway 6 m.
for f in zones:
    p = f["properties"]
    assert p["structure"] == "road" and p["half_width_m"] >= 4.5 and p["max_half_width_m"] >= p["half_width_m"], p
    # The zone is at least the platform: length x 2r, in hectares.
    assert p["area_ha"] >= 0.98 * p["length_m"] * 9 / 1e4, p
for f in lanes:
    p = f["properties"]
    assert p["half_width_m"] == 3, p
    assert abs(p["area_ha"] - p["length_m"] * 6 / 1e4) <= 0.05 * p["length_m"] * 6 / 1e4 + 1e-4, p
# Coordinates are lon/lat (RFC 7946) near the two points.
x, y = corr[0]["geometry"]["coordinates"][0][0]
assert 9.2 < x < 9.5 and 42.6 < y < 42.8, (x, y)
EOF

# Softer material, wider zone and more earth moved.
"$TP" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/sand.geojson" --corridor "$WORK/sand_corridor.geojson" --material sand
$py - "$WORK/road.geojson" "$WORK/sand.geojson" <<'EOF' || fail "sand is not wider than rock"
import json, sys
rock, sand = (json.load(open(p))["features"][0]["properties"] for p in sys.argv[1:])
assert sand["land_take_ha"] > rock["land_take_ha"], (sand, rock)
assert sand["cut_m3"] + sand["fill_m3"] > rock["cut_m3"] + rock["fill_m3"], (sand, rock)
EOF

# A side-angle map (45 deg everywhere) gives what --side-angle 45 gives; --earthworks uses the same sides.
gdal_calc.py --quiet -A "$dem" --outfile "$WORK/angles.tif" --type Float32 --calc "A*0+45"
"$TP" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/a.geojson" --corridor "$WORK/a_corr.geojson" --side-angles "$WORK/angles.tif"
"$TP" -q path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/b.geojson" --corridor "$WORK/b_corr.geojson" --side-angle 45 \
  --earthworks "$WORK/levelled.tif"
cmp -s "$WORK/a_corr.geojson" "$WORK/b_corr.geojson" || fail "--side-angles 45 everywhere differs from --side-angle 45"
[[ -s "$WORK/levelled.tif" ]] || fail "no levelled DEM"

# The network command: corridors.geojson in OUTDIR, the figures in roads.geojson; a vegetation layer is cleared.
printf '%s' '{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"from": 0, "to": 1, "kept": 1}, "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.42, 42.70]]}}]}' >"$WORK/network.geojson"
gdal_calc.py --quiet -A "$dem" --outfile "$WORK/forest.tif" --type Float32 --calc "(A>0)*1.0"
"$TP" roads "$dem" "$WORK/network.geojson" "$WORK/net" --corridor --vegetation "$WORK/forest.tif" 2>"$WORK/log"
grep -q "corridors: land take .* vegetation cleared" "$WORK/log" || fail "no corridors summary: $(cat "$WORK/log")"
$py - "$WORK/net/roads.geojson" "$WORK/net/corridors.geojson" <<'EOF' || fail "roads --corridor outputs"
import json, sys
road = json.load(open(sys.argv[1]))["features"][0]["properties"]
zones = [f["properties"] for f in json.load(open(sys.argv[2]))["features"] if f["properties"]["part"] == "earthworks"]
# Forest on all land: every hectare taken on land is cleared.
assert 0 < road["cleared_ha"] <= road["land_take_ha"] + 1e-4, road
assert road["cleared_ha"] <= sum(z["cleared_ha"] or 0 for z in zones) + 1e-3
EOF
no_leftovers "$WORK"

# Bad inputs: exit 2, one line naming the option, nothing written.
expect_refused "$WORK/bad.geojson" "side-angle" "$TP" path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/bad.geojson" --corridor "$WORK/bad_c.geojson" --side-angle 95
expect_refused "$WORK/bad.geojson" "material" "$TP" path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/bad.geojson" --corridor "$WORK/bad_c.geojson" --material clay
expect_refused "$WORK/bad.geojson" "half-width" "$TP" path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/bad.geojson" --corridor "$WORK/bad_c.geojson" --half-width 60
expect_refused "$WORK/bad.geojson" "missing.tif" "$TP" path "$dem" --from 9.30,42.68 --to 9.42,42.70 "$WORK/bad.geojson" --corridor "$WORK/bad_c.geojson" --side-angles "$WORK/missing.tif"
[[ ! -e "$WORK/bad_c.geojson" ]] || fail "corridor written on bad input"
expect_refused "$WORK/net2" "side-angle" "$TP" roads "$dem" "$WORK/network.geojson" "$WORK/net2" --corridor --side-angle -1
echo ok
