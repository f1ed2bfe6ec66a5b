# `terrapolis run A.json B.json ...` and `run FOLDER`: a batch, --jobs at once, one run folder each,
# a table of outcomes and an exit code saying whether all succeeded (docs/pipeline.md, "Batches").
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
lux=$SAMPLES/terra_elev_luxembourg.tif
mkdir batch out
cat > batch/a.json <<EOF
{"dem": "$lux", "output": "ignored_a", "seed": 7, "outputs": {"preview": false}}
EOF
cat > batch/b.json <<EOF
{"dem": "$lux", "seed": 8, "outputs": {"preview": false}, "sites": {"population": -5}}
EOF
cat > batch/c.json <<EOF
{"dem": "$lux", "seed": 9, "outputs": {"preview": false}, "sites": {"urban_share": 0.65}}
EOF

# A folder of scenarios, two at once, into out/: the invalid one is refused before any run, the
# others succeed; exit 2 (every failure a refusal) and the error line says so.
rc=0
"$TP" run batch --jobs 2 -o out > table 2> stderr || rc=$?
[[ $rc -eq 2 ]] || fail "a batch with one invalid scenario: exit $rc, expected 2 ($(cat stderr))"
grep -q "error: batch: 1 of 3 runs did not succeed" stderr || fail "no batch error line: $(cat stderr)"
grep -Eq "^batch/a.json +out/a +[0-9.]+ s +ok$" table || fail "row of a.json: $(cat table)"
grep -Eq "^batch/b.json +out/b +- +refused: /sites/population: " table || fail "row of b.json: $(cat table)"
grep -Eq "^batch/c.json +out/c +[0-9.]+ s +ok$" table || fail "row of c.json: $(cat table)"
grep -q "^2 of 3 runs succeeded$" table || fail "no count: $(cat table)"
[[ -f out/a/run.json && -f out/c/run.json && ! -e out/b && ! -e ignored_a ]] || fail "run folders: $(ls out)"
grep -q '"urban_share": 0.65' out/c/run.json || fail "out/c is not c.json's run"

# Each run of the batch is the run alone: same bytes.
"$TP" -q run batch/a.json -o alone_a
for f in cities.geojson network.geojson roads.geojson density.tif; do
  cmp -s "out/a/$f" "alone_a/$f" || fail "$f of the batch's a.json differs from its run alone"
done

# The same batch again without --overwrite: every run refused by its own run, exit 2; with it, all
# (but the invalid one) run again.
rc=0
"$TP" -q run batch/a.json batch/c.json -o out 2> stderr || rc=$?
[[ $rc -eq 2 ]] || fail "rerun without --overwrite: exit $rc"
rc=0
"$TP" run batch/c.json batch/a.json -o out --overwrite --jobs 1 > table 2> stderr || rc=$?
[[ $rc -eq 0 ]] || fail "rerun with --overwrite: exit $rc ($(cat stderr))"
grep -q "^2 of 2 runs succeeded$" table || fail "no count: $(cat table)"

# Two scenarios writing one run folder: the second is refused, the first runs.
cp batch/c.json batch/d.json
rc=0
"$TP" run batch/c.json batch/d.json > table 2> stderr || rc=$?
[[ $rc -eq 2 ]] || fail "two scenarios, one folder: exit $rc"
[[ $(grep -c "refused: its run folder is batch/c.json's too" table) -eq 1 ]] || fail "shared folder: $(cat table)"

# A run refused by its own checks once started (its DEM is not a raster): its row gives its exit
# code and error line, the other runs are unaffected. (-o's folder must exist: every run of the
# batch is refused without it, by its own check.)
echo "not a raster" > broken.tif
cat > batch_e.json <<EOF
{"dem": "$WORK/broken.tif", "outputs": {"preview": false}}
EOF
rc=0
"$TP" -q run batch_e.json batch/c.json -o later 2> stderr || rc=$?
[[ $rc -eq 2 && ! -e later ]] || fail "-o without its folder: exit $rc"
mkdir later
rc=0
"$TP" run batch_e.json batch/c.json -o later > table 2> stderr || rc=$?
[[ $rc -eq 2 ]] || fail "a broken DEM: exit $rc ($(cat stderr))"
grep -Eq "^batch_e.json +later/batch_e +[0-9.]+ s +exit 2: .*broken.tif" table || fail "row of the broken DEM: $(cat table)"
grep -Eq "^batch/c.json +later/c +[0-9.]+ s +ok$" table || fail "row beside the broken DEM: $(cat table)"

# SIGTERM to the batch reaches its runs: they stop, leave nothing, and the batch exits 143.
mkdir slow
"$TP" -q run batch/a.json batch/c.json -o slow --jobs 2 --set dem="$SAMPLES/spDataLarge_srtm_zion.tif" --set hydro.iterations=100000 --set hydro.threshold=1e-300 2> stderr & pid=$!
for _ in $(seq 100); do [[ -n $(find slow -maxdepth 1 -name 'c.tmp-*') ]] && break; sleep 0.1; done
sleep 0.5
kill -TERM "$pid"
rc=0; wait "$pid" || rc=$?
[[ $rc -eq 143 ]] || fail "SIGTERM to a batch: exit $rc ($(cat stderr))"
[[ -z $(ls -A slow) ]] || fail "an interrupted batch left $(ls -A slow)"

# compare takes the batch's folders: each against the first.
"$TP" compare out/a out/c alone_a > cmp
[[ $(grep -c "^A: out/a$" cmp) -eq 2 ]] || fail "compare of three runs: $(head -5 cmp)"
"$TP" compare out/a out/c alone_a --json > cmp.json
python3 -c "import json,sys; j=json.load(open('cmp.json')); assert isinstance(j, list) and len(j) == 2, j" || fail "compare --json of three runs"
no_leftovers "$WORK"
echo "run_batch: ok"
