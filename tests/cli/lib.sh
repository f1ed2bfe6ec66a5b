# Helpers sourced by the command-line test cases (not a test itself: it has no "case" in its name).
# Usage in a case: source "$(dirname "$0")/lib.sh" "$@"
set -euo pipefail
TP=$1
SAMPLES=$2
SOURCE=${3:-}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

fail() { echo "FAIL: $*" >&2; exit 1; }

# Match a command's output with `grep -q PATTERN <(CMD)`, never `CMD | grep -q PATTERN`: under
# pipefail, grep -q exits at its first match and CMD, still writing past one buffer, dies of SIGPIPE.

# expect_fail CODE PATTERN CMD...: the command exits with CODE and its stderr matches PATTERN (grep -E).
expect_fail() {
  local code=$1 pattern=$2; shift 2
  local rc=0
  "$@" >"$WORK/stdout" 2>"$WORK/stderr" || rc=$?
  [[ $rc -eq $code ]] || fail "expected exit $code, got $rc: $* ($(cat "$WORK/stderr"))"
  grep -Eq -- "$pattern" "$WORK/stderr" || fail "stderr of '$*' does not match '$pattern': $(cat "$WORK/stderr")"
  [[ $(grep -c . "$WORK/stderr") -ge 1 ]] || fail "no error message"
}

# expect_refused OUT PATTERN CMD...: bad input: exit 2, stderr matches PATTERN, OUT not created.
expect_refused() {
  local out=$1 pattern=$2; shift 2
  expect_fail 2 "$pattern" "$@"
  [[ ! -e $out ]] || fail "'$*' left $out behind"
}

# no_leftovers DIR: nothing but what was there before (no partial or temporary outputs).
no_leftovers() {
  local found
  found=$(find "$1" -name '*.tmp-*' -o -name '*.aux.xml' | head -1)
  [[ -z $found ]] || fail "left behind: $found"
}

# stand_in_density DEM DIR: the density stage's two outputs made from the DEM alone (buildable =
# land below 1000 m, density = exp(-z / 400 m)), for cases that test what comes after it.
stand_in_density() {
  mkdir -p "$2"
  gdal_calc.py --quiet -A "$1" --outfile "$2/buildable.tif" --type Byte --calc "(A>0)*(A<1000)" --NoDataValue 255
  gdal_calc.py --quiet -A "$1" --outfile "$2/density.tif" --type Float32 --calc "(A>0)*(A<1000)*exp(-maximum(A,0)/400.0)"
}

# same_cells A B: two rasters (any GDAL format, e.g. a VRT of tiles) hold the same cells, byte for
# byte (both copied to raw ENVI files and compared), on the same grid.
same_cells() {
  rm -f "$WORK"/[ab].*
  GDAL_PAM_ENABLED=NO gdal_translate -q -of ENVI "$1" "$WORK/a.bin" && GDAL_PAM_ENABLED=NO gdal_translate -q -of ENVI "$2" "$WORK/b.bin"
  cmp -s "$WORK/a.bin" "$WORK/b.bin" || { echo "$1 and $2: cells differ"; return 1; }
  [[ $(gdalinfo "$1" | grep -E "^(Size is|Origin|Pixel Size)") == $(gdalinfo "$2" | grep -E "^(Size is|Origin|Pixel Size)") ]] ||
    { echo "$1 and $2: grids differ"; return 1; }
}
