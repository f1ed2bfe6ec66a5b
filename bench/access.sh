#!/usr/bin/env bash
# Access benchmark: travel time to the nearest settlement over a whole SRTM3 tile (1201 x 1201,
# geographic) from the settlements and roads of a default run, against GRASS r.walk -k (16
# neighbours, Aitken/Langmuir walking cost, friction 0) from the same points on the same grid, in
# the same session: medians of 3 paired runs, wall and CPU seconds, and their ratios.
# Usage: bench/access.sh [BUILD_DIR] [DEM]   (run from the repository root)
set -euo pipefail
build=${1:-build}
dem=${2:-../shared/dems/N47E009.hgt}
bin=$build/src/cli/terrapolis
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

"$bin" -q run -o "$out/run" --set dem="$(realpath "$dem")" --set outputs.preview=false --set access.enabled=false
echo "settlements: $(grep -o '"type": "Feature"' "$out/run/cities.geojson" | wc -l), roads: $(grep -o '"type": "Feature"' "$out/run/roads.geojson" | wc -l)"
access() { "$bin" --progress none access "$dem" "$out/acc" --to "$out/run/cities.geojson" --roads "$out/run/roads.geojson" --overwrite "$@"; }
access -v 2>&1 | grep '^access:' || true

median() { printf '%s\n' "$@" | sort -g | sed -n 2p; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }
if command -v grass >/dev/null; then
  gdal_translate -q -of GTiff "$dem" "$out/dem.tif"
  grass -c "$out/dem.tif" "$out/loc" --exec bash -c "
    set -e
    r.in.gdal --quiet input=$out/dem.tif output=dem
    g.region raster=dem
    r.mapcalc --quiet 'friction = 0'
    v.in.ogr --quiet input=$out/run/cities.geojson output=cities
  " >"$out/grass.log" 2>&1 || { echo "GRASS failed:"; grep -i error "$out/grass.log" | head -5; exit 1; }
  ours=(); peer=(); ours_cpu=(); peer_cpu=()
  for i in 1 2 3; do
    /usr/bin/time -f "%e %U" -o "$out/t_ours" bash -c "$(declare -f access); bin=$bin dem=$dem out=$out access -q"
    /usr/bin/time -f "%e %U" -o "$out/t_peer" grass "$out/loc/PERMANENT" --exec \
      r.walk -k --quiet --overwrite elevation=dem friction=friction output=cost start_points=cities >/dev/null 2>&1
    read -r w u <"$out/t_ours"; ours+=("$w"); ours_cpu+=("$u")
    read -r w u <"$out/t_peer"; peer+=("$w"); peer_cpu+=("$u")
  done
  mo=$(median "${ours[@]}"); mp=$(median "${peer[@]}"); co=$(median "${ours_cpu[@]}"); cp=$(median "${peer_cpu[@]}")
  echo "paired x3, wall: terrapolis access ${ours[*]} s (median $mo), grass r.walk ${peer[*]} s (median $mp), ratio $(ratio "$mo" "$mp")"
  echo "paired x3, CPU: terrapolis access ${ours_cpu[*]} s (median $co), grass r.walk ${peer_cpu[*]} s (median $cp), ratio $(ratio "$co" "$cp")"
else
  echo "GRASS not installed (apt-get install -y grass-core): peer skipped"
fi
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
