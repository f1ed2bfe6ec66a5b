# SIGINT and SIGTERM stop a command at its next progress tick, remove its temporary outputs and exit
# 130 / 143; an old output it was replacing stays whole; what a SIGKILL leaves, the next run of the
# same output removes (docs/safety.md, "Interrupts").
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/spDataLarge_srtm_zion.tif
# Belhadj's hydrometry to a threshold it never reaches: a long run with a progress tick per iteration.
long=(--iterations 100000 --threshold 1e-300)  # the schema's largest count

# start_and_signal SIGNAL OUT CMD...: starts CMD, waits for its staging folder OUT.tmp-PID, sends
# SIGNAL, and sets rc to the exit code.
start_and_signal() {
  local signal=$1 out=$2; shift 2
  "$@" 2> "$WORK/stderr" &
  local pid=$!
  for _ in $(seq 100); do [[ -e $out.tmp-$pid ]] && break; sleep 0.1; done
  [[ -e $out.tmp-$pid ]] || fail "'$*' did not start its outputs"
  sleep 0.5
  kill "-$signal" "$pid"
  rc=0
  wait "$pid" || rc=$?
}

start_and_signal INT h1 "$TP" -q hydro "$dem" h1 "${long[@]}"
[[ $rc -eq 130 ]] || fail "SIGINT: exit $rc, expected 130 ($(cat stderr))"
grep -q "interrupted (SIGINT)" stderr || fail "SIGINT: no message ($(cat stderr))"
[[ ! -e h1 ]] || fail "SIGINT left h1"
start_and_signal TERM h2 "$TP" -q hydro "$dem" h2 "${long[@]}"
[[ $rc -eq 143 ]] || fail "SIGTERM: exit $rc, expected 143 ($(cat stderr))"
[[ ! -e h2 ]] || fail "SIGTERM left h2"

# The whole pipeline, interrupted while it replaces an earlier run: the earlier run is untouched.
"$TP" -q run --set dem="$SAMPLES/terra_elev_luxembourg.tif" -o r --set outputs.preview=false
sums=$(cd r && md5sum ./* .terrapolis-outputs.json | sort)
start_and_signal TERM r "$TP" -q run --set dem="$dem" -o r --overwrite --set hydro.iterations=100000 --set hydro.threshold=1e-300
[[ $rc -eq 143 ]] || fail "run, SIGTERM: exit $rc ($(cat stderr))"
[[ $(cd r && md5sum ./* .terrapolis-outputs.json | sort) == "$sums" ]] || fail "an interrupted --overwrite changed the old run"
no_leftovers "$WORK"
[[ -z $(find "$WORK" -name '*.tmp-*') ]] || fail "an interrupt left $(find "$WORK" -name '*.tmp-*')"

# SIGKILL cannot be handled: its staging folder stays until the next command writing that output.
start_and_signal KILL h3 "$TP" -q hydro "$dem" h3 "${long[@]}"
[[ $rc -eq 137 ]] || fail "SIGKILL: exit $rc"
stale=$(ls -d h3.tmp-*)
[[ -d $stale ]] || fail "expected the killed command's staging folder"
# A folder of that name without our marker is left alone.
mkdir "h3.tmp-999999999"
"$TP" -q hydro "$dem" h3 --outputs filled 2> stderr
[[ ! -e $stale ]] || fail "the next run did not remove $stale"
grep -q "warning: removed .*$stale, the temporary folder of a terrapolis command that was killed" stderr || fail "no line about $stale ($(cat stderr))"
[[ -d h3.tmp-999999999 ]] || fail "removed a folder without the staging marker"
[[ -f h3/filled.tif ]] || fail "the next run did not write h3"
[[ -z $(find "$WORK" -name '.*terrapolis-lock') ]] || fail "a lock file stayed: $(find "$WORK" -name '.*terrapolis-lock')"

# A live command's staging folder is never touched: a second command writing the same output is
# refused at once, names the live command, and the live one ends as if alone.
"$TP" -q hydro "$dem" h4 "${long[@]}" 2> /dev/null & live=$!
for _ in $(seq 100); do [[ -e h4.tmp-$live ]] && break; sleep 0.1; done
rc=0; "$TP" -q hydro "$dem" h4 --outputs filled 2> stderr || rc=$?
[[ $rc -eq 2 ]] || fail "a second command on a live output: exit $rc, expected 2"
grep -q "h4: another terrapolis command (pid $live) is writing this output" stderr || fail "refusal does not name the live command: $(cat stderr)"
[[ $(wc -l < stderr) -eq 1 ]] || fail "the refusal is not one line: $(cat stderr)"
[[ -d h4.tmp-$live && -f h4.tmp-$live/.terrapolis-staging ]] || fail "the refused command touched the live staging folder"
kill -INT "$live"; wait "$live" || true
echo "safety_interrupts: ok"
