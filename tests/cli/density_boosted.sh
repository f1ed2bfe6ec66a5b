# A boosted density model (docs/density.md, "Boosted trees"): `calibrate --model boosted` writes a
# fragment naming its trees; a run and the density command read them in place of the weights, the
# same bytes at any thread count; a file that is not such a model is refused before any stage.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
places=$SOURCE/tests/data/geonames_capcorse.geojson

"$TP" -q calibrate "$dem" --settlements "$places" --model boosted --trees 40 --depth 2 --fragment fit.json --report fit_report.json > table.txt
/usr/bin/python3 - <<'PY' || fail "calibrate --model boosted"
import json
fragment = json.load(open("fit.json"))
assert fragment == {"density": {"model": "fit.boosted.json"}}, fragment
model = json.load(open("fit.boosted.json"))
assert model["format"] == "terrapolis-boosted-density" and len(model["terms"]) == 10, model["terms"]
assert len(model["xgboost"]["learner"]["gradient_booster"]["model"]["trees"]) == 40
lo, hi = model["margin_bounds"]
assert lo < 0 < hi, (lo, hi)
report = json.load(open("fit_report.json"))
region = report["regions"][0]
assert report["model"] == "boosted" and region["logistic_held_out"]["auc"] is not None, report
assert 0.5 < region["fitted_in_sample"]["auc"] <= 1, region  # the trees rank the places above the land they were fitted on
PY
grep -q "logit" table.txt || fail "the table does not compare with the logistic fit"
# auto: on Cap Corse's 15 places the weights rank the held-out places better (5-fold), so the
# fragment is theirs and no trees are written.
"$TP" -q calibrate "$dem" --settlements "$places" --model auto --fragment auto.json > auto.txt
grep -q "^chosen: logistic" auto.txt || fail "auto: $(cat auto.txt)"
grep -q '"weights"' auto.json && [[ ! -e auto.boosted.json ]] || fail "auto: the fragment is not the weights'"

# A run reads the fragment's trees (the scenario merges it; its path is relative to the scenario).
/usr/bin/python3 -c "
import json; s = json.load(open('fit.json')); s['dem'] = '$dem'; s['outputs'] = {'preview': False}; s['access'] = {'enabled': False}
json.dump(s, open('boosted.json', 'w'))"
"$TP" -q --threads 1 run boosted.json -o one 2> /dev/null
"$TP" -q --threads 2 run boosted.json -o two 2> /dev/null
cmp -s one/density.tif two/density.tif || fail "the boosted density depends on the thread count"
"$TP" -q run -o weighted --set dem="$dem" --set outputs.preview=false --set access.enabled=false 2> /dev/null
! cmp -s one/density.tif weighted/density.tif || fail "the boosted model did not change the density"
/usr/bin/python3 - <<'PY' || fail "run with a boosted model"
import json
m = json.load(open("one/run.json"))
assert m["scenario"]["density"]["model"] == "fit.boosted.json", m["scenario"]["density"]
assert m["summary"]["sites"]["cities"] > 0
PY

# By tiles: the trees read the terms ranked and measured over the whole grid.
"$TP" -q run boosted.json -o by_tiles --set input.tile_size=60 2> /dev/null
same_cells one/density.tif by_tiles/density.vrt || fail "the boosted density differs on tiles"
cmp -s one/cities.geojson by_tiles/cities.geojson || fail "the boosted run's settlements differ on tiles"
# The density command does not find the rivers on tiles (their river_near term).
expect_refused dtiles "river_near: this command does not find the rivers on tiles" "$TP" density "$dem" dtiles --model fit.boosted.json --tile-size 60

# Refitted trees under the same name: a rerun does not reuse the density made with the old ones.
"$TP" -q calibrate "$dem" --settlements "$places" --model boosted --trees 41 --depth 2 --fragment fit.json --overwrite > /dev/null
expect_fail 2 "/density/model names a file changed since the saved run; rerun from density" "$TP" run boosted.json -o one --from sites
"$TP" -q run boosted.json -o one --from density 2> /dev/null

# The density command takes it as --model.
"$TP" -q density "$dem" d --model fit.boosted.json
"$TP" -q density "$dem" d_weighted
! cmp -s d/density.tif d_weighted/density.tif || fail "density --model changed nothing"

# Not a model: refused at once, by the setting's name, nothing written.
echo '{"density": {"weights": {}}}' > not_a_model.json
expect_refused bad "^terrapolis: error: \(default scenario\): /density/model: .*not_a_model.json: not a boosted density model" \
  "$TP" run -o bad --set dem="$dem" --set density.model=not_a_model.json
[[ $(wc -l < "$WORK/stderr") -eq 1 ]] || fail "not one line: $(cat "$WORK/stderr")"
expect_refused dbad "^terrapolis: error: --model: .*not a boosted density model" "$TP" density "$dem" dbad --model not_a_model.json
no_leftovers "$WORK"
echo "density_boosted: ok"
