# A switch means what it says or is refused: a negative seed is refused (never replaced), and
# roads.bridges=false with roads.tunnels=false builds no structure at all (the smoothed road used
# to be labelled a bridge where it crossed water or rose above the ground).
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"

# Seeds: refused out of range, honoured in range, on the command line and in --set.
expect_fail 2 "seed" "$TP" run --seed -1 --print-scenario
expect_fail 2 "seed" "$TP" run --seed -7 --print-scenario
[[ $(wc -l <"$WORK/stderr") -eq 1 ]] || fail "a refused option takes more than one line: $(cat "$WORK/stderr")"
grep -q "^terrapolis: error: --seed: must be >= 0$" "$WORK/stderr" || fail "unexpected refusal: $(cat "$WORK/stderr")"
expect_fail 2 "seed" "$TP" run --seed 9007199254740992 --print-scenario
expect_fail 2 "/seed" "$TP" run --set seed=-1 --print-scenario
grep -q '"seed": 5' <("$TP" run --seed 5 --print-scenario) || fail "--seed 5 not honoured"
grep -q '"seed": 0' <("$TP" run --seed 0 --print-scenario) || fail "--seed 0 not honoured"
expect_fail 2 "seed" "$TP" sites "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" out --seed -1

# count_structures FILE: "bridge tunnel" section counts of a road_sections.geojson.
count_structures() {
  /usr/bin/python3 -c '
import json, sys
f = json.load(open(sys.argv[1]))["features"]
print(sum(x["properties"]["structure"] == "bridge" for x in f), sum(x["properties"]["structure"] == "tunnel" for x in f))' "$1"
}
# The thesis's dense network on the Corsica sample (its coast and valleys: bridges), with and without structures.
"$TP" --quiet run -o with --set sites.quotas=belhadj2007
read -r bridges tunnels < <(count_structures with/road_sections.geojson)
[[ $bridges -gt 0 ]] || fail "the thesis run builds no bridge: this case would not test the switch"
"$TP" --quiet run -o without --set sites.quotas=belhadj2007 --set roads.bridges=false --set roads.tunnels=false
read -r bridges tunnels < <(count_structures without/road_sections.geojson)
[[ $bridges -eq 0 && $tunnels -eq 0 ]] || fail "roads.bridges=false, roads.tunnels=false built $bridges bridges and $tunnels tunnels"
/usr/bin/python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))["summary"]["roads"]
assert s["roads"] > 0, s' without/run.json || fail "no road was built without structures"
# The roads command's --no-bridges --no-tunnels, on the same network.
"$TP" --quiet roads "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" with/network.geojson roads-cmd --no-bridges --no-tunnels
read -r bridges tunnels < <(count_structures roads-cmd/road_sections.geojson)
[[ $bridges -eq 0 && $tunnels -eq 0 ]] || fail "roads --no-bridges --no-tunnels built $bridges bridges and $tunnels tunnels"
no_leftovers "$WORK"
echo "switches: ok"
