# Refactors change no output: a small run on two sample DEMs gives files whose SHA-256 match the
# goldens in tests/data/golden/ (run.json by its summary and file list: it also holds timings).
# An intended change of outputs regenerates them (and the commit says why):
#   TERRAPOLIS_UPDATE_GOLDEN=1 ctest --test-dir build -R cli.golden_outputs
source "$(dirname "$0")/lib.sh" "$@"
GOLDEN=$SOURCE/tests/data/golden
run_case() {  # NAME DEM: the default scenario on DEM (copied beside the scenario: paths stay relative)
  local name=$1 dem=$2 dir=$WORK/$1
  mkdir -p "$dir"
  cp "$dem" "$dir/"
  for side in "${dem%.*}".prj "$dem".aux.xml; do [[ -e $side ]] && cp "$side" "$dir/"; done
  printf '{"dem": "%s", "output": "out", "outputs": {"preview_width": 128}}\n' "$(basename "$dem")" > "$dir/scenario.json"
  (cd "$dir" && "$TP" --quiet run scenario.json) || fail "$name: run failed"
  (cd "$dir/out" && for f in $(ls | grep -v '^run.json$'); do sha256sum "$f"; done
   /usr/bin/python3 -c "import json; m = json.load(open('run.json')); print(json.dumps({k: m[k] for k in ('summary', 'outputs')}, sort_keys=True))" |
     sha256sum | sed 's/-$/run.json(summary,outputs)/') > "$dir/sha256"
  if [[ -n ${TERRAPOLIS_UPDATE_GOLDEN:-} ]]; then
    cp "$dir/sha256" "$GOLDEN/$name.sha256"
    echo "updated $GOLDEN/$name.sha256"
  else
    diff "$GOLDEN/$name.sha256" "$dir/sha256" >&2 || fail "$name: outputs differ from tests/data/golden/$name.sha256"
  fi
}
run_case corsica "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc"
run_case luxembourg "$SAMPLES/terra_elev_luxembourg.tif"
echo "golden outputs: ok"
