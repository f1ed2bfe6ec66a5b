#!/usr/bin/env bash
# Generator benchmark: `terrapolis generate --method M` for each method, median wall time of REPEAT
# whole-process runs (/usr/bin/time), the phase times the command logs with --verbose (median), and
# the figures of its report next to the documents' (Belhadj 2007 §2.2.2.2 and §2.2.3: a 513² skeleton
# in 0.35-0.5 s, its DMMC in 0.1-0.15 s on 2007 hardware; Horton's ranges of real basins; Génévaux
# et al. Tab. 2: 0.42-0.46 km of river per km²). window (Belhadj §2.1, Alg. 1) runs on fig. 2.3's
# sketch (crossed diagonals at 1000 m, the counter-diagonal shifted one cell, borders at 0; the
# thesis: 110 ms on 513² for fig. 2.2's), its phase in the dmmc_s column. river (§1.2.3): the necklace
# in the skeleton_s column, the terrain in dmmc_s (the thesis: 1,447 ms for both on 513²), and its
# own D8 shares below the table.
# Usage: bench/generate.sh [SIZE]   (default 513: the thesis's grid)
# Env: TERRAPOLIS_BIN (default build/src/cli/terrapolis), REPEAT (default 5), METHODS (default "dmmc flow tectonic coast planar window river"), TABLE1 (1: also the coast method at the sizes of Génévaux et al. Tab. 1), SEED (default 1),
#      ARGS (more options of generate for the method table, e.g. "--subdivision triangle-edge --bottom-up mean")
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=$(realpath "${TERRAPOLIS_BIN:-build/src/cli/terrapolis}")
SIZE=${1:-513}
REPEAT=${REPEAT:-5}
METHODS=${METHODS:-dmmc flow tectonic coast planar window river}
TABLE1=${TABLE1:-1}
SEED=${SEED:-1}
read -r -a ARGS <<<"${ARGS:-}"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# Fig. 2.3's sketch for --method window, on a UTM grid (a sketch without CRS must match the grid's pixels).
/usr/bin/python3 - "$WORK/cross.tif" "$SIZE" <<'PY'
import sys
import numpy as np
from osgeo import gdal, osr
n = int(sys.argv[2]); a = np.full((n, n), -9999, np.float32)
for i in range(n):
    a[i, i] = 1000
    if i > 0: a[i, n - i] = 1000
a[0, :] = a[-1, :] = a[:, 0] = a[:, -1] = 0
ds = gdal.GetDriverByName("GTiff").Create(sys.argv[1], n, n, 1, gdal.GDT_Float32)
ds.SetGeoTransform((500000, 30, 0, 5000000, 0, -30))
s = osr.SpatialReference(); s.ImportFromEPSG(32632); ds.SetProjection(s.ExportToWkt())
b = ds.GetRasterBand(1); b.SetNoDataValue(-9999); b.WriteArray(a); ds = None
PY
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
printf "%-9s %9s %10s %9s %9s %7s %6s %6s %9s\n" method wall_s skeleton_s dmmc_s d8_share pits Rb Rl km/km2
for m in $METHODS; do
  : >"$WORK/wall" ; : >"$WORK/skel"; : >"$WORK/dmmc"
  extra=()
  [ "$m" = window ] && extra=(--crs EPSG:32632 --origin 500000,5000000 --constraints "$WORK/cross.tif")
  for i in $(seq "$REPEAT"); do
    rm -f "$WORK/$m".*
    /usr/bin/time -f %e -o "$WORK/t" "$BIN" --verbose generate "$WORK/$m.tif" --method "$m" --size "${SIZE}x${SIZE}" --cell 30 \
      --seed "$SEED" "${extra[@]}" "${ARGS[@]}" 2>"$WORK/log"
    cat "$WORK/t" >>"$WORK/wall"
    sed -n 's/.*generate: \(skeleton\|tectonic\|necklace\) in \([0-9.]*\) s.*/\2/p' "$WORK/log" >>"$WORK/skel"
    sed -n 's/.*generate: \(dmmc\|growing window\|river terrain\) in \([0-9.]*\) s.*/\2/p' "$WORK/log" >>"$WORK/dmmc"
  done
  skel=$( [ -s "$WORK/skel" ] && median <"$WORK/skel" || echo -)
  dmmc=$( [ -s "$WORK/dmmc" ] && median <"$WORK/dmmc" || echo -)
  if [ -f "$WORK/$m.report.json" ]; then
    read -r share pits rb rl dd < <(/usr/bin/python3 -c "
import json; r = json.load(open('$WORK/$m.report.json')); c, h = r['d8_consistency'], r['horton']
print(c['share_within_2_cells'], c['mouths_ending_in_pit'], h['bifurcation_ratio'], h['length_ratio'], r['drainage_density_km_per_km2'])")
  else
    share=- pits=- rb=- rl=- dd=-
  fi
  printf "%-9s %9s %10s %9s %9s %7s %6s %6s %9s\n" "$m" "$(median <"$WORK/wall")" "$skel" "$dmmc" "$share" "$pits" "$rb" "$rl" "$dd"
  [ "$m" = river ] && river_note=$(/usr/bin/python3 -c "
import json; f = json.load(open('$WORK/river.report.json'))['figures']
print('river: %d river cells, %.3f of them drain into the river, %.3f of the line within 1 cell of a D8 stream (>= 0.1 km2)' % (
    f['river_cells'], f['river_cells_draining_into_river_share'], f['river_line_within_1_cell_of_d8_stream_share']))")
done
[ -n "${river_note:-}" ] && echo "$river_note"
echo "documents: flow skeleton 513² 0.35-0.5 s, DMMC 0.1-0.15 s (Belhadj 2007, 2007 hardware); Rb 3-5, Rl 1.5-3.5 (Horton 1945,"
echo "Strahler 1957); drainage density 0.42-0.46 km/km² (Génévaux et al., Tab. 2). dmmc alone has no skeleton."
echo "growing window (dmmc_s column): 110 ms on 513² (Belhadj 2007 §2.1.1, fig. 2.2); river (skeleton_s + dmmc_s): 1,447 ms (§1.2.3.2)."
# Génévaux et al. Tab. 1-2: the coast method on islands of the paper's land areas (the seeded island
# covers about 41 % of its grid), 100 m cells; the three phases the command logs with --verbose.
if [ "$TABLE1" = 1 ]; then
  printf "\n%-7s %6s %9s %9s %8s %9s %8s %10s %8s   %s\n" region cells land_km2 wall_s graph_s analysis_s terrain_s km/km2 prim/km2 "paper Tab. 1 (graph, analysis, tree s)"
  for spec in "Mini:487:0.9,0.2,0.6" "Lambda:819:3.4,1.3,1.7" "Hoya:909:4.5,1.7,2.3" "Imbros:1332:39.2,8.7,5.1"; do
    IFS=: read -r region n paper <<<"$spec"
    : >"$WORK/wall"; : >"$WORK/graph"; : >"$WORK/analysis"; : >"$WORK/terrain"
    for i in $(seq "$REPEAT"); do
      rm -f "$WORK"/coast.*
      /usr/bin/time -f %e -o "$WORK/t" "$BIN" --verbose generate "$WORK/coast.tif" --method coast --size "${n}x${n}" --cell 100 --seed "$SEED" 2>"$WORK/log"
      cat "$WORK/t" >>"$WORK/wall"
      for phase in graph analysis terrain; do
        sed -n "s/.*generate: \(grammar \)\{0,1\}$phase in \([0-9.]*\) s.*/\2/p" "$WORK/log" >>"$WORK/$phase"
      done
    done
    read -r land dd prim < <(/usr/bin/python3 -c "
import json; f = json.load(open('$WORK/coast.report.json'))['figures']
print(round(f['land_km2']), f['river_km_per_km2'], f['terrain_primitives_per_km2'])")
    printf "%-7s %6s %9s %9s %8s %9s %8s %10s %8s   %s\n" "$region" "${n}x${n}" "$land" "$(median <"$WORK/wall")" "$(median <"$WORK/graph")" \
      "$(median <"$WORK/analysis")" "$(median <"$WORK/terrain")" "$dd" "$prim" "$paper"
  done
  echo "paper: Intel Core i7 3 GHz; Tab. 2: 0.42-0.46 km of river and about 10 terrain primitives per km²."
fi
