#!/usr/bin/env bash
# Roads benchmark: one long road on the SRTM3 Alps tile (k = 5, m = 8), surface only and with
# bridges and tunnels, against GRASS r.walk + r.drain between the same points; prints time, nodes
# expanded, peak memory and each path's cost under the Terrapolis cost model.
# Usage: bench/roads.sh [BUILD_DIR]   (run from the repository root)
set -euo pipefail
build=${1:-build}
bin=$build/src/cli/terrapolis
dem=../shared/dems/N47E009.hgt
from=9.2,47.5; to=9.6,47.3          # Toggenburg (Thur valley) to the Rhine valley near Feldkirch
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

run() {  # label, extra arguments
  local label=$1; shift
  /usr/bin/time -f "%e %U %M" -o "$out/time" "$bin" --progress none path "$dem" --from $from --to $to "$out/$label.geojson" "$@" 2>"$out/$label.log"
  read -r secs user kb <"$out/time"
  echo "$label: $(grep -o 'galin:.*' "$out/$label.log") | wall ${secs} s, CPU ${user} s, peak ${kb} kB"
}
run surface_astar --no-bridges --no-tunnels
run surface_bidir --no-bridges --no-tunnels --search bidir
run structures_astar

if command -v grass >/dev/null; then
  # GRASS: r.walk (anisotropic walking cost, Naismith/Langmuir) from the start, r.drain back from the end.
  gdal_translate -q -of GTiff "$dem" "$out/dem.tif"
  start=$(echo $from | tr , ' '); end=$(echo $to | tr , ' ')
  t0=$(date +%s.%N); c0=$(awk "{print \$14+\$15+\$16+\$17}" /proc/$$/stat)
  grass -c "$out/dem.tif" "$out/loc" --exec bash -c "
    set -e
    r.in.gdal -q input=$out/dem.tif output=dem
    g.region raster=dem
    r.mapcalc --q 'friction = 0'
    r.walk -k --q elevation=dem friction=friction output=cost outdir=dir start_coordinates=${start// /,} stop_coordinates=${end// /,}
    r.drain -d --q input=cost direction=dir output=drain drain=drain_line start_coordinates=${end// /,}
    v.out.ogr --q input=drain_line output=$out/grass.geojson format=GeoJSON
  " >"$out/grass.log" 2>&1 || { echo "GRASS failed:"; tail -5 "$out/grass.log"; exit 1; }
  t1=$(date +%s.%N)
  gsecs=$(echo "$t1 - $t0" | bc)
  gcost=$("$bin" -q path "$dem" --from $from --to $to "$out/unused.geojson" --no-bridges --no-tunnels --evaluate "$out/grass.geojson")
  ourcost=$("$bin" -q path "$dem" --from $from --to $to "$out/unused.geojson" --no-bridges --no-tunnels --evaluate "$out/surface_astar.geojson")
  echo "grass r.walk+r.drain: wall ${gsecs} s; GRASS path under our model: $gcost; our path walked cell by cell: $ourcost"
else
  echo "GRASS not installed (apt-get install -y grass-core): peer skipped"
fi
