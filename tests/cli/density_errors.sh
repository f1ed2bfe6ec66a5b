#!/usr/bin/env bash
# `terrapolis density` refuses bad input with exit code 2, a one-line message, and no output.
set -euo pipefail
bin=$1 samples=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
dem="$samples/gebco2022_15s_north_corsica_capcorse.asc"

# expect_error PATTERN ARGS...: exit code 2, PATTERN in the one-line message, no output folder.
expect_error() {
  local pattern=$1; shift
  rm -rf "$tmp/out"
  set +e
  "$bin" --quiet density "$@" 2> "$tmp/err"
  local code=$?
  set -e
  [[ $code == 2 ]] || fail "'$*' exited $code, expected 2"
  grep -q -- "$pattern" "$tmp/err" || fail "'$*' said '$(cat "$tmp/err")', expected '$pattern'"
  [[ $(wc -l < "$tmp/err") == 1 ]] || fail "'$*' printed more than one line"
  [[ ! -e $tmp/out ]] || fail "'$*' left an output folder"
}

expect_error "missing.tif" "$tmp/missing.tif" "$tmp/out" --weights 1,0,1,0
expect_error "every weight is 0" "$dem" "$tmp/out" --weights 0,0,0,0
expect_error "expected 4 numbers" "$dem" "$tmp/out" --weights 1,2
expect_error "is not a number" "$dem" "$tmp/out" --weights 1,x,0,0
expect_error "missing.tif: no such file" "$dem" "$tmp/out" --hydrometry "$tmp/missing.tif"
expect_error "--r-max" "$dem" "$tmp/out" --weights 1,0,1,0 --r-min 2000 --r-max 1000
expect_error "--max-slope" "$dem" "$tmp/out" --weights 1,0,1,0 --max-slope 120
expect_error "expected FILE:WEIGHT" "$dem" "$tmp/out" --weights 1,0,1,0 --layer nolayer
expect_error "not a number" "$dem" "$tmp/out" --weights 1,0,1,0 --layer "$dem:heavy"
gdal_translate -q -ot Float32 -scale -2601 1829 0 7 "$dem" "$tmp/hydro.tif"
expect_error "values must lie in \[0,1\]" "$dem" "$tmp/out" --hydrometry "$tmp/hydro.tif"
expect_error "output folder .*no/such does not exist" "$dem" "$tmp/no/such/out" --weights 1,0,1,0

# Existing outputs are kept unless --overwrite.
"$bin" --quiet density "$dem" "$tmp/done" --weights 1,0,1,0
before=$(md5sum "$tmp/done/density.tif")
set +e
"$bin" --quiet density "$dem" "$tmp/done" --weights 0,0,1,0 2> "$tmp/err"
code=$?
set -e
[[ $code == 2 ]] || fail "existing output: exit $code"
[[ $(md5sum "$tmp/done/density.tif") == "$before" ]] || fail "existing output was changed"
# A module names the setting by its pointer; a command shows its own flag, a run the pointer (and
# refuses it before its first stage: r_min is raised to the cell size, read from the DEM).
expect_error "error: --r-max: must be larger than r_min" "$dem" "$tmp/out" --r-max 100 --r-min 50
set +e
"$bin" -v run -o "$tmp/out" --set dem="$dem" --set density.r_max_m=100 --set density.r_min_m=50 2> "$tmp/err"
code=$?
set -e
[[ $code == 2 ]] && grep -q ": /density/r_max_m: must be larger than r_min" "$tmp/err" || fail "run: exit $code, '$(cat "$tmp/err")'"
[[ ! -e $tmp/out ]] || fail "a refused run left an output"
[[ $(wc -l < "$tmp/err") == 1 ]] || fail "the run started its stages before refusing r_max: $(cat "$tmp/err")"
echo "density error cases passed"
