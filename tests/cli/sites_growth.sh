# sites.growth (docs/sites.md, "Growth scenarios"): the region as it is (the GeoNames places of
# Cap Corse) grown by a fifth; the new people go to the existing places in proportion to their
# size and, for growth_new_share of them, to new settlements; the places keep their cells; the
# figures add up and `compare` lines each place's gain up against the region as it is.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
places=$SOURCE/tests/data/geonames_capcorse.geojson
common=(--set dem="$dem" --set sites.existing="$places" --set outputs.preview=false --set access.enabled=false)

"$TP" -q run -o today "${common[@]}" --set sites.growth=0 2> /dev/null  # no census figure: the places alone, growth 0 adds nothing
"$TP" -q run -o gibrat "${common[@]}" --set sites.growth=0.2 2> /dev/null
"$TP" run -o mixed "${common[@]}" --set sites.growth=0.2 --set sites.growth_new_share=0.5 > mixed.txt 2>&1
/usr/bin/python3 - "$places" <<'PY' || fail "growth scenarios"
import json, sys
real = {f["properties"]["name"]: f for f in json.load(open(sys.argv[1]))["features"]}
E = sum(f["properties"]["population"] for f in real.values())
def run(name):
    cities = json.load(open(name + "/cities.geojson"))["features"]
    return cities, json.load(open(name + "/run.json"))["summary"]["sites"]
today, s0 = run("today")
assert len(today) == len(real) and s0["existing"]["generated"] == 0, s0["existing"]  # the region as it is: nothing invented
for name in ("gibrat", "mixed"):
    cities, s = run(name)
    g = s["growth"]
    assert g["people"] == round(0.2 * E) and g["to_existing"] + g["to_new_settlements"] == g["people"], g
    assert s["population"] == E + g["people"] == s["settled_population"], (s["population"], E, g)
    assert s["target_population"] == round(94347 * 1.2), s["target_population"]
    given = {c["properties"]["name"]: c for c in cities if c["properties"]["existing"] == 1}
    assert sorted(given) == sorted(real) and sum(c["properties"]["gained"] for c in cities) == g["people"]
    for n, c in given.items():
        p = real[n]["properties"]["population"]
        assert c["geometry"]["coordinates"] == next(t for t in today if t["properties"]["name"] == n)["geometry"]["coordinates"], n
        assert c["properties"]["population"] == p + c["properties"]["gained"] == p + g["gained"][n], (n, c["properties"])
        share = g["to_existing"] / E  # proportionate growth: every place within a person of its share
        assert abs(c["properties"]["gained"] - share * p) < 1, (n, c["properties"]["gained"], share * p)
    created = [c for c in cities if c["properties"]["existing"] == 0]
    assert len(created) == g["new_settlements"] and all(c["properties"]["gained"] == c["properties"]["population"] for c in created)
    assert sum(c["properties"]["population"] for c in created) == g["to_new_settlements"]
    if name == "gibrat":
        assert g["to_existing"] == g["people"] and not created, g
    else:
        assert g["to_new_settlements"] == round(0.5 * g["people"]) and len(created) >= 2, g
        assert all(v["near"] in real and v["near_km"] > 0 for v in g["new_largest"].values()), g["new_largest"]
PY
grep -Eq "growth \+20%: 8619 new settled people, 4309 to the existing places, 4310 in [0-9]+ new settlements" mixed.txt \
  || fail "the summary's growth line: $(grep growth mixed.txt)"

# compare: each place's gain beside the region as it is.
"$TP" compare today mixed > compare.txt
grep -Eq "^  sites\.growth\.gained\.Biguglia +- +[0-9]+" compare.txt || fail "compare has no per-place gain: $(grep growth compare.txt | head -3)"
# Its columns line up in characters, not bytes: a name with an accent (L'Île-Rousse) is not a column off.
/usr/bin/python3 - <<'PY' || fail "compare: columns off after a name with an accent: $(grep -a "Rousse\|Biguglia" compare.txt)"
rows = [l for l in open("compare.txt", encoding="utf-8").read().splitlines() if l.startswith("  sites.growth.gained.")]
assert any("Île-Rousse" in r for r in rows) and len({len(r) for r in rows}) == 1, [(len(r), r) for r in rows]
PY

# The sites command takes it too.
"$TP" sites "$dem" s --existing "$places" --growth 0.2 > out.txt
grep -q "^sites: growth +20%: 8619 new settled people, 8619 to the existing places, 0 in new settlements" out.txt || fail "sites --growth: $(cat out.txt)"

# Growth needs the places that grow, and the rank-size quotas: refused before any stage.
expect_refused bad "/sites/growth: needs /sites/existing" "$TP" run -o bad --set dem="$dem" --set sites.growth=0.2
[[ $(wc -l < "$WORK/stderr") -eq 1 ]] || fail "growth without places not refused at once: $(cat "$WORK/stderr")"
expect_refused bad "/sites/growth: needs /sites/quotas rank_size" \
  "$TP" run -o bad "${common[@]}" --set sites.growth=0.2 --set sites.quotas=belhadj2007
expect_refused bad "growth_new_share" "$TP" run -o bad "${common[@]}" --set sites.growth=0.2 --set sites.growth_new_share=1.5
no_leftovers "$WORK"
echo "sites_growth: ok"
