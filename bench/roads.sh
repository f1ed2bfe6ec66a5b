#!/usr/bin/env bash
# Roads benchmark: one long road on the SRTM3 Alps tile (k = 5, m = 8), surface only and with
# bridges and tunnels, by A* (relaxed-distance heuristic), A* with the straight-line bound and
# bidirectional A*, against GRASS r.walk + r.drain between the same
# points; prints time, nodes expanded, long-arc rings priced, peak memory and each path's cost under
# the Terrapolis cost model. Then a shorter road in the same tile, and a network on an island.
# Usage: bench/roads.sh [BUILD_DIR]   (run from the repository root)
set -euo pipefail
build=${1:-build}
bin=$build/src/cli/terrapolis
dem=../shared/dems/N47E009.hgt
from=9.2,47.5; to=9.6,47.3          # Toggenburg (Thur valley) to the Rhine valley near Feldkirch
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT

run() {  # label, extra arguments (the end points are $from and $to)
  local label=$1; shift
  /usr/bin/time -f "%e %U %M" -o "$out/time" "$bin" -v --progress none path "$dem" --from $from --to $to "$out/$label.geojson" "$@" 2>"$out/$label.log"
  read -r secs user kb <"$out/time"
  echo "$label: $(grep -o 'galin:.*' "$out/$label.log") | wall ${secs} s, CPU ${user} s, peak ${kb} kB"
  grep -o 'corners:.*' "$out/$label.log" | sed "s/^/  $label /"
}
run surface_astar --no-bridges --no-tunnels
run surface_astar_distance --no-bridges --no-tunnels --search astar-distance
run surface_bidir --no-bridges --no-tunnels --search bidir
run structures_astar
run structures_astar_distance --search astar-distance
run structures_bidir --search bidir
# By windows (path --memory-limit): the tile as a 3 x 3 VRT of its tiles, the road searched on a
# window around its ends; the same road, byte for byte.
for i in 0 1 2; do
  for j in 0 1 2; do
    gdal_translate -q -srcwin $((j * 400)) $((i * 400)) $((j == 2 ? 401 : 400)) $((i == 2 ? 401 : 400)) "$dem" "$out/tile_${i}_$j.tif"
  done
done
gdalbuildvrt -q "$out/tiles.vrt" "$out"/tile_*.tif
whole_dem=$dem; dem=$out/tiles.vrt
run by_windows --memory-limit 200
dem=$whole_dem
grep -o 'path by windows:.*' "$out/by_windows.log" | sed "s/^/  /"
cmp -s "$out/structures_astar.geojson" "$out/by_windows.geojson" && echo "  by_windows: the whole grid's road, byte for byte" ||
  echo "  by_windows: NOT the whole grid's road"

if command -v grass >/dev/null; then
  # GRASS: r.walk (anisotropic walking cost, Naismith/Langmuir) from the start, r.drain back from the end.
  gdal_translate -q -of GTiff "$dem" "$out/dem.tif"
  /usr/bin/time -f "%e %U %M" -o "$out/time" grass -c "$out/dem.tif" "$out/loc" --exec bash -c "
    set -e
    r.in.gdal --quiet input=$out/dem.tif output=dem
    g.region raster=dem
    r.mapcalc --quiet 'friction = 0'
    r.walk -k --quiet elevation=dem friction=friction output=cost outdir=dir start_coordinates=$from stop_coordinates=$to
    r.drain -d --quiet input=cost direction=dir output=drain drain=drain_line start_coordinates=$to
    v.out.ogr --quiet input=drain_line output=$out/grass.geojson format=GeoJSON
  " >"$out/grass.log" 2>&1 || { echo "GRASS failed:"; grep -i error "$out/grass.log" | head -5; exit 1; }
  read -r secs user kb <"$out/time"
  echo "grass r.walk+r.drain: wall ${secs} s, CPU ${user} s (GRASS session included), peak ${kb} kB"
  # Paired: the default road (A*, bridges and tunnels) and GRASS in turn, 3 times each; medians of
  # wall and CPU (user) seconds and their ratios (the machine is shared: wall times drift with the
  # load, pairs see the same load; CPU seconds drift less).
  ours=(); peer=(); ours_cpu=(); peer_cpu=()
  for i in 1 2 3; do
    /usr/bin/time -f "%e %U" -o "$out/t_ours" "$bin" --progress none path "$dem" --from $from --to $to "$out/paired.geojson" --overwrite 2>/dev/null
    /usr/bin/time -f "%e %U" -o "$out/t_peer" grass "$out/loc/PERMANENT" --exec bash -c "
      r.walk -k --quiet --overwrite elevation=dem friction=friction output=cost outdir=dir start_coordinates=$from stop_coordinates=$to
      r.drain -d --quiet --overwrite input=cost direction=dir output=drain drain=drain_line start_coordinates=$to" >/dev/null 2>&1
    read -r w u <"$out/t_ours"; ours+=("$w"); ours_cpu+=("$u")
    read -r w u <"$out/t_peer"; peer+=("$w"); peer_cpu+=("$u")
  done
  median() { printf '%s\n' "$@" | sort -g | sed -n 2p; }
  ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }
  mo=$(median "${ours[@]}"); mp=$(median "${peer[@]}"); co=$(median "${ours_cpu[@]}"); cp=$(median "${peer_cpu[@]}")
  echo "paired x3, wall: terrapolis ${ours[*]} s (median $mo), grass ${peer[*]} s (median $mp), ratio $(ratio "$mo" "$mp")"
  echo "paired x3, CPU: terrapolis ${ours_cpu[*]} s (median $co), grass ${peer_cpu[*]} s (median $cp), ratio $(ratio "$co" "$cp")"
  echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
  # Both paths priced by our model, walked cell by cell (8-neighbour steps, curvature with m = 8);
  # then without the slope and water thresholds, so that a path breaking them still gets a number.
  echo '{"road": {"slope_deg": {"threshold": null}, "water_depth_m": {"threshold": null}}}' >"$out/open.json"
  for label in grass surface_astar; do
    strict=$("$bin" -q path "$dem" --from $from --to $to "$out/unused.geojson" --no-bridges --no-tunnels --evaluate "$out/$label.geojson")
    open=$("$bin" -q path "$dem" --from $from --to $to "$out/unused.geojson" --no-bridges --no-tunnels --costs "$out/open.json" --evaluate "$out/$label.geojson")
    echo "$label path under our model: $strict; without thresholds: $open"
  done
else
  echo "GRASS not installed (apt-get install -y grass-core): peer skipped"
fi

# A shorter road in the same tile (18 km), surface only and with bridges and tunnels.
from=9.3,47.4; to=9.45,47.3
run short_surface_astar --no-bridges --no-tunnels
run short_structures_astar
from=9.2,47.5; to=9.6,47.3

# A whole network on an island: Corsica (GEBCO 15", bundled sample), 200 land sites every few
# cells, each joined to its two nearest neighbours (about 200 roads), both routers.
island=sample_dems/gebco2022_15s_north_corsica_capcorse.asc
mkdir -p "$out/net"
gdal_translate -q -of XYZ "$island" "$out/island.xyz"
awk '$3 > 20 && (NR % 27) == 0 && n++ < 200 {print $1, $2}' "$out/island.xyz" > "$out/sites.txt"
awk '{x[NR]=$1; y[NR]=$2} END {
  printf "{\"type\": \"FeatureCollection\", \"features\": ["; sep = "";
  for (i = 1; i <= NR; i++) {
    b1 = 0; b2 = 0; d1 = 1e9; d2 = 1e9;
    for (j = 1; j <= NR; j++) { if (j == i) continue; d = (x[i]-x[j])^2 + (y[i]-y[j])^2;
      if (d < d1) { d2 = d1; b2 = b1; d1 = d; b1 = j } else if (d < d2) { d2 = d; b2 = j } }
    for (k = 1; k <= 2; k++) { j = (k == 1 ? b1 : b2); if (j < i && (j == 0 || seen[j "," i])) continue; seen[i "," j] = 1;
      printf "%s{\"type\": \"Feature\", \"properties\": {\"from\": %d, \"to\": %d, \"kept\": 1}, \"geometry\": {\"type\": \"LineString\", \"coordinates\": [[%s, %s], [%s, %s]]}}", sep, i, j, x[i], y[i], x[j], y[j]; sep = ", " } }
  print "]}" }' "$out/sites.txt" > "$out/net/network.geojson"
edges=$(grep -o '"from"' "$out/net/network.geojson" | wc -l)
for router in galin bezier; do
  /usr/bin/time -f "%e %U %M" -o "$out/time" "$bin" --progress none roads "$island" "$out/net/network.geojson" "$out/net_$router" --router $router 2>"$out/net_$router.log"
  read -r secs user kb <"$out/time"
  echo "network of $edges edges on Corsica, router $router: $(grep -o '[0-9]* roads.*' "$out/net_$router.log") | wall ${secs} s, CPU ${user} s, peak ${kb} kB"
done
