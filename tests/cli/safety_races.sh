# Commands racing for one output (docs/safety.md, "Commands running at once"): of two runs started
# together into one folder exactly one succeeds, the other is refused with one line naming the
# folder and exits 2, and the folder holds the winner's run; the same for two commands writing one
# file. 20 races of each, with the two commands swapped every other time.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
zion=$SAMPLES/spDataLarge_srtm_zion.tif
lux=$SAMPLES/terra_elev_luxembourg.tif
quick=(--until hydro --set outputs.preview=false)

for i in $(seq 20); do
  a=$zion b=$lux
  (( i % 2 )) || { a=$lux; b=$zion; }
  "$TP" -q run --set dem="$a" --seed "$i" -o same "${quick[@]}" 2> err_a & pa=$!
  "$TP" -q run --set dem="$b" --seed "$((i + 100))" -o same "${quick[@]}" 2> err_b & pb=$!
  ra=0 rb=0
  wait "$pa" || ra=$?
  wait "$pb" || rb=$?
  if [[ $ra -eq 0 && $rb -eq 2 ]]; then winner=$a loser=err_b
  elif [[ $ra -eq 2 && $rb -eq 0 ]]; then winner=$b loser=err_a
  else fail "race $i: exit codes $ra and $rb, expected one 0 and one 2 ($(cat err_a err_b))"
  fi
  [[ $(wc -l < "$loser") -eq 1 ]] && grep -Eq "error: same: (another terrapolis command( \(pid [0-9]+\))? is writing this output|output folder exists)" "$loser" \
    || fail "race $i: the loser's message: $(cat "$loser")"
  grep -q "\"dem\": \"$winner\"" same/run.json || fail "race $i: same/ does not hold the winner's run ($winner)"
  [[ -z $(find . -maxdepth 1 -name 'same.tmp-*' -o -maxdepth 1 -name '.same.terrapolis-lock') ]] || fail "race $i left $(ls -a)"
  rm -rf same
done

# Two commands writing one file.
for i in $(seq 20); do
  "$TP" -q convert "$zion" out.tif 2> err_a & pa=$!
  "$TP" -q convert "$lux" out.tif 2> err_b & pb=$!
  ra=0 rb=0
  wait "$pa" || ra=$?
  wait "$pb" || rb=$?
  [[ $((ra + rb)) -eq 2 && $((ra * rb)) -eq 0 ]] || fail "file race $i: exit codes $ra and $rb ($(cat err_a err_b))"
  winner=$zion; [[ $ra -eq 0 ]] || winner=$lux
  [[ $(gdalinfo out.tif | grep -c "Size is $(gdalinfo "$winner" | grep -o 'Size is .*' | cut -c9-)") -eq 1 ]] || fail "file race $i: out.tif is not the winner's"
  rm -f out.tif .terrapolis-outputs.json
done
no_leftovers "$WORK"
echo "safety_races: ok"
