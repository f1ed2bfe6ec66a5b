#!/usr/bin/env bash
# Benchmarks of `terrapolis sites` and `terrapolis network`: wall time and peak memory, medians of RUNS.
#   bench/sites_network.sh [TERRAPOLIS] [DEMS_DIR] [RUNS]
# Scenarios: the SRTM tiles S46W066.hgt (3601x3601, 1") and N47E009.hgt (1201x1201, 3") with a
# density model synthesised from the DEM (buildable = land below 1000 m, density = exp(-z / 400 m));
# and 100 000 random cities (60 % roots, 40 % suburbs inside them) for the network alone.
# Peer: the Delaunay triangulation of the same 100 000 points by GEOS (SpatiaLite's
# ST_DelaunayTriangulation through OGR's SQLite dialect), one of the three triangulations the
# network stage computes, without its simplification.
set -euo pipefail
HERE=$(cd "$(dirname "$0")/.." && pwd)
BIN=${1:-$HERE/build/src/cli/terrapolis}
DEMS=${2:-$HERE/../shared/dems}
RUNS=${3:-3}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# Runs a command RUNS times; prints "median_seconds median_peak_MB".
measure() {
  local times=() mems=()
  for ((i = 0; i < RUNS; i++)); do
    /usr/bin/time -f "%e %M" -o "$T/time.txt" "$@" > /dev/null 2> "$T/stderr.txt" || { cat "$T/stderr.txt"; exit 1; }
    read -r s kb < "$T/time.txt"
    times+=("$s")
    mems+=("$kb")
  done
  local ms mm
  ms=$(printf '%s\n' "${times[@]}" | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
  mm=$(printf '%s\n' "${mems[@]}" | sort -g | awk '{ a[NR] = $1 } END { printf "%.0f", a[int((NR + 1) / 2)] / 1024 }')
  echo "$ms $mm"
}

printf "%-28s %10s %10s  %s\n" "scenario" "median s" "peak MB" "result"
for tile in S46W066 N47E009; do
  mkdir -p "$T/$tile/in"
  gdal_calc.py --quiet -A "$DEMS/$tile.hgt" --outfile "$T/$tile/in/buildable.tif" --type Byte --calc "(A>0)*(A<1000)" --NoDataValue 255
  gdal_calc.py --quiet -A "$DEMS/$tile.hgt" --outfile "$T/$tile/in/density.tif" --type Float32 --calc "(A>0)*(A<1000)*exp(-maximum(A,0)/400.0)"
  read -r s mb < <(measure "$BIN" --progress none sites "$T/$tile/in" "$T/$tile/out" --overwrite)
  summary=$("$BIN" --progress none sites "$T/$tile/in" "$T/$tile/out" --overwrite)
  printf "%-28s %10s %10s  %s\n" "sites $tile" "$s" "$mb" "${summary#sites: }"
  "$BIN" -v --progress none sites "$T/$tile/in" "$T/$tile/out" --overwrite 2>&1 >/dev/null | sed 's/^/  phases (one run): /' 
  read -r s mb < <(measure "$BIN" --progress none network "$T/$tile/out/cities.geojson" "$T/$tile/out" --overwrite)
  summary=$("$BIN" --progress none network "$T/$tile/out/cities.geojson" "$T/$tile/out" --overwrite)
  printf "%-28s %10s %10s  %s\n" "network $tile" "$s" "$mb" "${summary#network: }"
done

# 100 000 random cities over 3 x 2 degrees (about 230 x 220 km at 46 N); suburbs lie inside
# their parent's disc with 0.3 times its radius.
awk 'BEGIN {
  srand(42); n = 100000; roots = int(0.6 * n)
  print "{\"type\": \"FeatureCollection\", \"features\": ["
  for (i = 0; i < n; i++) {
    if (i < roots) { x[i] = 9 + 3 * rand(); y[i] = 45 + 2 * rand(); r[i] = 500 + 2000 * rand(); parent = "null" }
    else {
      p = int(rand() * roots); a = 6.283185307 * rand(); d = r[p] * sqrt(rand()) / 111000
      x[i] = x[p] + d * cos(a) / 0.69; y[i] = y[p] + d * sin(a); r[i] = 0.3 * r[p]; parent = p
    }
    printf "{\"type\": \"Feature\", \"properties\": {\"id\": %d, \"radius_m\": %.1f, \"parent\": %s}, \"geometry\": {\"type\": \"Point\", \"coordinates\": [%.7f, %.7f]}}%s\n", i, r[i], parent, x[i], y[i], (i < n - 1 ? "," : "")
  }
  print "]}"
}' > "$T/random100k.geojson"
read -r s mb < <(measure "$BIN" --progress none network "$T/random100k.geojson" "$T/r" --overwrite)
summary=$("$BIN" --progress none network "$T/random100k.geojson" "$T/r" --overwrite)
printf "%-28s %10s %10s  %s\n" "network 100k random" "$s" "$mb" "${summary#network: }"
"$BIN" -v --progress none network "$T/random100k.geojson" "$T/r" --overwrite 2>&1 >/dev/null | sed 's/^/  phases (one run): /' 
ours=$s
read -r s mb < <(measure ogrinfo -q -dialect sqlite -sql \
  "select ST_NumGeometries(ST_DelaunayTriangulation(ST_Collect(geometry), 1)) as edges from random100k" "$T/random100k.geojson")
printf "%-28s %10s %10s  %s\n" "GEOS Delaunay 100k (peer)" "$s" "$mb" "one triangulation, edges only"
awk -v a="$ours" -v b="$s" 'BEGIN { printf "ratio network (3 triangulations + simplification + I/O) / GEOS Delaunay: %.2f\n", a / b }'
