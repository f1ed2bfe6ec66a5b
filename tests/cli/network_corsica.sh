# `terrapolis network` on the cities of the Corsica sample and on a planner's own file; clean failures.
source "$(dirname "$0")/lib.sh" "$@"
BIN=$TP
T=$WORK
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
stand_in_density "$DEM" "$T/in"
"$BIN" --quiet sites "$T/in" "$T/s" --seed 5 --quotas belhadj2007

# The thesis's detour factor by its preset (the default, 1.5, is tested below).
"$BIN" --quiet network "$T/s/cities.geojson" "$T/n" --preset belhadj2007 | tee "$T/out.txt"
grep -q "k 1.80" "$T/out.txt"
info=$(ogrinfo -so -al "$T/n/network.geojson")
grep -q "Geometry: Line String" <<< "$info"
for f in "from: Integer" "to: Integer" "kind: String" "kept: Integer" "length_m: Real" "detour_ratio: Real"; do
  grep -q "$f" <<< "$info" || { echo "missing field $f"; exit 1; }
done
q() { ogrinfo -q -dialect sqlite -sql "$1" "$T/n/network.geojson" | grep -o "n (Integer) = [0-9]*" | grep -o "[0-9]*$"; }
# Every suburb has its parent-child edge, kept; removed edges carry their detour ratio in [1, k)
# (1 when a third city lies on the segment), kept ones none.
suburbs=$(ogrinfo -q -dialect sqlite -sql "select count(*) as n from cities where parent is not null" "$T/s/cities.geojson" | grep -o "n (Integer) = [0-9]*" | grep -o "[0-9]*$")
test "$(q "select count(*) as n from network where kind = 'parent_child' and kept = 1")" -eq "$suburbs"
test "$(q "select count(*) as n from network where kept = 0 and (detour_ratio is null or detour_ratio >= 1.8 or detour_ratio < 0.999999)")" -eq 0
test "$(q "select count(*) as n from network where kept = 1 and detour_ratio is not null")" -eq 0
test "$(q "select count(*) as n from network where kind = 'inter_urban'")" -gt 0
test "$(q "select count(*) as n from network where kept = 0")" -gt 0
# A smaller k removes fewer edges; same input, same bytes.
"$BIN" --quiet network "$T/s/cities.geojson" "$T/n2" --k 1.2
kept18=$(q "select count(*) as n from network where kept = 1")
kept12=$(ogrinfo -q -dialect sqlite -sql "select count(*) as n from network where kept = 1" "$T/n2/network.geojson" | grep -o "n (Integer) = [0-9]*" | grep -o "[0-9]*$")
test "$kept12" -gt "$kept18"
"$BIN" --quiet network "$T/s/cities.geojson" "$T/n3" --preset belhadj2007
cmp "$T/n/network.geojson" "$T/n3/network.geojson"
# The default k (1.5) keeps more links than the thesis's, and still every parent-child link.
"$BIN" --quiet network "$T/s/cities.geojson" "$T/n4" | grep -q "k 1.50"
kept15=$(ogrinfo -q -dialect sqlite -sql "select count(*) as n from network where kept = 1" "$T/n4/network.geojson" | grep -o "n (Integer) = [0-9]*" | grep -o "[0-9]*$")
test "$kept15" -gt "$kept18"
pc15=$(ogrinfo -q -dialect sqlite -sql "select count(*) as n from network where kind = 'parent_child' and kept = 1" "$T/n4/network.geojson" | grep -o "n (Integer) = [0-9]*" | grep -o "[0-9]*$")
test "$pc15" -eq "$suburbs"
# A --k given stands over the preset's.
"$BIN" --quiet network "$T/s/cities.geojson" "$T/n5" --preset belhadj2007 --k 1.2 | grep -q "k 1.20"

# A planner's own cities: ids of their choosing, one suburb.
cat > "$T/plan.geojson" <<'JSON'
{"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"id": 10, "radius_m": 2000}, "geometry": {"type": "Point", "coordinates": [9.40, 42.70]}},
{"type": "Feature", "properties": {"id": 20, "radius_m": 800, "parent": 10}, "geometry": {"type": "Point", "coordinates": [9.41, 42.71]}},
{"type": "Feature", "properties": {"id": 30, "radius_m": 1500}, "geometry": {"type": "Point", "coordinates": [9.45, 42.80]}},
{"type": "Feature", "properties": {"id": 40, "radius_m": 1000}, "geometry": {"type": "Point", "coordinates": [9.30, 42.75]}}
]}
JSON
"$BIN" --quiet network "$T/plan.geojson" "$T/p"
grep -q '"from": 10, "to": 20, "kind": "parent_child", "kept": 1' "$T/p/network.geojson"

refuse() { expect_refused "$1" "$2" "$BIN" --quiet network "${@:3}" "$1"; }
sed 's/"radius_m": 800, //' "$T/plan.geojson" > "$T/noradius.geojson"
refuse "$T/x1" "radius_m" "$T/noradius.geojson"
sed 's/"parent": 10/"parent": 99/' "$T/plan.geojson" > "$T/orphan.geojson"
refuse "$T/x2" "parent 99" "$T/orphan.geojson"
refuse "$T/x3" "no such file" "$T/missing.geojson"
refuse "$T/x4" "k" "$T/plan.geojson" --k 1
# Existing output refused unless --overwrite.
set +e
"$BIN" --quiet network "$T/plan.geojson" "$T/p" 2> /dev/null
rc=$?
set -e
test $rc -eq 2
"$BIN" --quiet network "$T/plan.geojson" "$T/p" --overwrite
echo OK
