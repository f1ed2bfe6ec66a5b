#!/usr/bin/env bash
# Hydrology benchmark: Terrapolis vs GRASS r.watershed and SAGA on real SRTM tiles.
# Run from the repository root: bench/hydro.sh [path/to/terrapolis] [runs]
# Needs grass (grass-core), saga (saga_cmd), hyperfine, GNU time; the DEMs in ../shared/dems.
# The belhadj part also runs build/bench/bench_hydro (in-process timings) when it was built.
# SPDX-License-Identifier: MIT
set -euo pipefail
bin=$(realpath "${1:-build/src/cli/terrapolis}")
runs=${2:-3}
parts=${BENCH_PARTS:-time,memory,agreement,belhadj}  # e.g. BENCH_PARTS=agreement bench/hydro.sh
has() { [[ ",$parts," == *",$1,"* ]]; }
saga_runs=$(( runs < 2 ? runs : 2 ))  # SAGA is an order of magnitude slower
dems=(../shared/dems/N47E009.hgt ../shared/dems/S46W066.hgt)
for tool in grass saga_cmd hyperfine /usr/bin/time; do
  command -v "$tool" >/dev/null || { echo "missing $tool (apt-get install -y grass-core saga hyperfine time)"; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export GRASS_MESSAGE_FORMAT=silent
grass -c EPSG:4326 "$work/loc" -e >/dev/null 2>&1
gx() { grass "$work/loc/PERMANENT" --exec "$@" >/dev/null 2>&1; }

# Medians of wall time and of CPU time (user + system): on a shared machine the CPU time is the
# steadier measure of the work done.
median() { python3 -c "import json,sys,statistics; print('%.3f' % statistics.median(json.load(open(sys.argv[1]))['results'][0]['times']))" "$1"; }
cpu() { python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['results'][0]; print('%.3f' % (r['user']+r['system']))" "$1"; }
peak_mb() { /usr/bin/time -v "$@" 2>&1 >/dev/null | awk '/Maximum resident/ {printf "%.0f", $6/1024}'; }

printf "%-14s %10s | %-34s %9s %9s %9s | %s\n" dem cells task terrapolis grass saga "ratio (best peer / terrapolis)"
for dem in "${dems[@]}"; do
  name=$(basename "$dem" .hgt)
  cells=$(gdalinfo "$dem" | awk -F'[ ,]+' '/^Size is/ {print $3*$4}')
  # Imports are done once, outside the timings.
  gx r.in.gdal -o input="$(realpath "$dem")" output="$name"
  gx g.region raster="$name"
  if has time || has memory; then saga_cmd io_gdal 0 -GRIDS "$work/$name.sgrd" -FILES "$(realpath "$dem")" >/dev/null 2>&1; fi

  if has time; then
  # 1. Fill + D8 + accumulation.
  hyperfine -N -w 1 -r "$runs" --export-json "$work/tp_d8.json" \
    "$bin -q --threads 2 hydro $dem $work/tp_$name --outputs flowdir,accumulation --overwrite --area-units cells" >/dev/null 2>&1
  hyperfine -N -w 0 -r "$runs" --export-json "$work/grass_d8.json" \
    "grass $work/loc/PERMANENT --exec r.watershed -s --overwrite elevation=$name accumulation=acc_$name drainage=dir_$name memory=4000" >/dev/null 2>&1
  hyperfine -w 0 -r "$saga_runs" --export-json "$work/saga_d8.json" \
    "saga_cmd ta_preprocessor 4 -ELEV $work/$name.sgrd -FILLED $work/f.sgrd -FDIR $work/d.sgrd -WSHED $work/w.sgrd && saga_cmd ta_hydrology 0 -ELEVATION $work/f.sgrd -FLOW $work/a.sgrd -METHOD 0" >/dev/null 2>&1
  t=$(median "$work/tp_d8.json"); g=$(median "$work/grass_d8.json"); s=$(median "$work/saga_d8.json")
  printf "%-14s %10s | %-34s %8ss %8ss %8ss | %.2f\n" "$name" "$cells" "fill+D8+accumulation, wall (median)" "$t" "$g" "$s" \
    "$(python3 -c "print(min($g,$s)/$t)")"
  t=$(cpu "$work/tp_d8.json"); g=$(cpu "$work/grass_d8.json"); s=$(cpu "$work/saga_d8.json")
  printf "%-14s %10s | %-34s %8ss %8ss %8ss | %.2f\n" "$name" "$cells" "fill+D8+accumulation, CPU (mean)" "$t" "$g" "$s" \
    "$(python3 -c "print(min($g,$s)/$t)")"

  # The same pair timed in alternation (per-pair ratios, steadier on a shared machine).
  read -r ta ga wr tc gc cr < <("$(dirname "$0")/paired.py" "$runs" \
    "$bin -q --threads 2 hydro $dem $work/tp_$name --outputs flowdir,accumulation --overwrite --area-units cells" \
    "grass $work/loc/PERMANENT --exec r.watershed -s --overwrite elevation=$name accumulation=acc_$name drainage=dir_$name memory=4000")
  printf "%-14s %10s | %-34s %8ss %8ss %9s | %s (CPU %ss / %ss: %s)\n" "$name" "$cells" "fill+D8+acc, paired wall (median)" "$ta" "$ga" "-" "$wr" "$tc" "$gc" "$cr"

  # 2. MFD against r.watershed's default MFD.
  hyperfine -N -w 1 -r "$runs" --export-json "$work/tp_mfd.json" \
    "$bin -q --threads 2 hydro $dem $work/tpm_$name --flow mfd --outputs accumulation --overwrite --area-units cells" >/dev/null 2>&1
  hyperfine -N -w 0 -r "$runs" --export-json "$work/grass_mfd.json" \
    "grass $work/loc/PERMANENT --exec r.watershed --overwrite elevation=$name accumulation=macc_$name memory=4000" >/dev/null 2>&1
  t=$(median "$work/tp_mfd.json"); g=$(median "$work/grass_mfd.json")
  printf "%-14s %10s | %-34s %8ss %8ss %9s | %.2f\n" "$name" "$cells" "MFD accumulation, wall (median)" "$t" "$g" "-" "$(python3 -c "print($g/$t)")"
  t=$(cpu "$work/tp_mfd.json"); g=$(cpu "$work/grass_mfd.json")
  printf "%-14s %10s | %-34s %8ss %8ss %9s | %.2f\n" "$name" "$cells" "MFD accumulation, CPU (mean)" "$t" "$g" "-" "$(python3 -c "print($g/$t)")"
  read -r ta ga wr tc gc cr < <("$(dirname "$0")/paired.py" "$runs" \
    "$bin -q --threads 2 hydro $dem $work/tpm_$name --flow mfd --outputs accumulation --overwrite --area-units cells" \
    "grass $work/loc/PERMANENT --exec r.watershed --overwrite elevation=$name accumulation=macc_$name memory=4000")
  printf "%-14s %10s | %-34s %8ss %8ss %9s | %s (CPU %ss / %ss: %s)\n" "$name" "$cells" "MFD, paired wall (median)" "$ta" "$ga" "-" "$wr" "$tc" "$gc" "$cr"

  fi

  if has memory; then
  # 3. Peak memory of fill + D8 + accumulation.
  mt=$(peak_mb "$bin" -q --threads 2 hydro "$dem" "$work/tp_$name" --outputs flowdir,accumulation --overwrite --area-units cells)
  mg=$(peak_mb grass "$work/loc/PERMANENT" --exec r.watershed -s --overwrite elevation="$name" accumulation="acc_$name" drainage="dir_$name" memory=4000)
  ms=$(peak_mb saga_cmd ta_preprocessor 4 -ELEV "$work/$name.sgrd" -FILLED "$work/f.sgrd" -FDIR "$work/d.sgrd" -WSHED "$work/w.sgrd")
  printf "%-14s %10s | %-34s %7sMB %7sMB %7sMB | terrapolis %.1f bytes/cell\n" "$name" "$cells" "peak memory (fill+D8+acc)" "$mt" "$mg" "$ms" \
    "$(python3 -c "print($mt*1048576/$cells)")"

  fi

  if has agreement; then
  # 4. Agreement: D8 upstream cells of the 5 largest land catchments (outlet reaches) vs GRASS
  # r.watershed -s. The sea (<= 0 m) is left out of both: Terrapolis with --sea-level 0, GRASS on
  # the DEM with the sea set to null (otherwise both route a flat sea through flat resolution).
  # Both sides count the same thing, the cells whose D8 path reaches the outlet cell: Terrapolis's
  # accumulation, and for GRASS the basin that r.water.outlet traces on r.watershed's own drainage
  # map. r.watershed's accumulation map is not used as the count: it does not pass on the flow of
  # its edge cells (cells on the region's border or next to null, i.e. the sea here), although
  # its drainage map routes them inwards (GRASS 8.2: 5 x 4 cells all draining to one border
  # outlet give accumulation 7, the 6 inner cells and the outlet). It still finds the outlets.
  "$bin" -q hydro "$dem" "$work/agree_$name" --outputs accumulation,streams --area-units cells --streams-threshold 5 \
    --sea-level 0 --overwrite
  gx r.mapcalc --overwrite expression="land_$name = if($name > 0, $name, null())"
  gx r.watershed -s --overwrite elevation="land_$name" accumulation="lacc_$name" drainage="ldir_$name" memory=4000
  gx r.out.gdal -f input="lacc_$name" output="$work/grass_acc_$name.tif" format=GTiff type=Float64
  ogr2ogr -f CSV "$work/reaches_$name.csv" "$work/agree_$name/streams.geojson" -lco GEOMETRY=AS_WKT >/dev/null
  python3 - "$work/reaches_$name.csv" > "$work/outlets_$name.txt" <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["downstream_id"] == "0"]
rows.sort(key=lambda r: -float(r["upstream_km2"]))
for r in rows[:5]:
    pts = r["WKT"].split("(")[1].rstrip(")").split(",")
    last, before = pts[-1].split(), pts[max(0, len(pts) - 2)].split()
    print(last[0], last[1], before[0], before[1], r["upstream_km2"])
PY
  worst=0
  while read -r lon lat lon1 lat1 km2; do
    # A reach that reaches the sea ends in a sea cell, which also gathers every other land cell
    # around it (up to 8 separate outlets); GRASS has no sea cells (null). Both are compared at
    # the reach's last land cell instead (its previous vertex).
    z=$(gdallocationinfo -valonly -wgs84 "$dem" "$lon" "$lat")
    if [[ $z =~ ^-?[0-9.]+$ ]] && python3 -c "import sys; sys.exit(0 if $z <= 0 else 1)"; then lon=$lon1 lat=$lat1; fi
    loc=$(gdallocationinfo -wgs84 "$work/agree_$name/accumulation.tif" "$lon" "$lat" | sed -n 's/.*Location: (\([0-9]*\)P,\([0-9]*\)L).*/\1 \2/p')
    read -r px py <<<"$loc"
    ours=$(gdallocationinfo -valonly "$work/agree_$name/accumulation.tif" "$px" "$py")
    [[ $ours =~ ^[0-9.eE+]+$ ]] || { echo "skipping outlet $lon,$lat: no accumulation value ($ours)"; continue; }
    # GRASS may leave the grid some cells away from Terrapolis's outlet (a flat lake is routed
    # differently: 165 cells on N47E009). Candidates are GRASS's outlet cells within 200 cells
    # (local maxima of |accumulation| over their 8 neighbours: a cell mid-river always has a larger
    # downstream neighbour); the one closest in size to Terrapolis's is its counterpart, and its
    # basin on GRASS's drainage map is GRASS's count (see above).
    gdal_translate -q -of XYZ -srcwin $((px - 200)) $((py - 200)) 401 401 "$work/grass_acc_$name.tif" "$work/win.xyz" 2>/dev/null
    read -r acc gxy <<<"$(awk -v ours="$ours" 'function abs(v) { return v < 0 ? -v : v }
      { v[NR - 1] = ($3 ~ /^-?[0-9]/) ? abs($3 + 0) : 0; x[NR - 1] = $1; y[NR - 1] = $2 }  # nodata ("nan", "-9999"...) counts as 0
      END { w = 401; best = -1
        for (i = 0; i < NR; i++) { r = int(i / w); c = i % w; if (v[i] <= 0) continue; local = 1
          for (dr = -1; dr <= 1; dr++) for (dc = -1; dc <= 1; dc++) {
            rr = r + dr; cc = c + dc; if (rr < 0 || cc < 0 || rr >= NR / w || cc >= w || (dr == 0 && dc == 0)) continue
            if (v[rr * w + cc] > v[i]) local = 0 }
          if (local && (best < 0 || abs(v[i] - ours) < abs(v[best] - ours))) best = i }
        if (best < 0) print 0, "-"; else print v[best], x[best] "," y[best] }' "$work/win.xyz")"
    theirs=0
    if [[ $gxy != - ]]; then
      gx r.water.outlet --overwrite input="ldir_$name" output=basin coordinates="$gxy"
      theirs=$(grass "$work/loc/PERMANENT" --exec r.univar -g map=basin 2>/dev/null | sed -n 's/^n=//p')
    fi
    err=$(python3 -c "print(abs($ours-${theirs:-0})/$ours*100)")
    printf "%-14s %10s | agreement at %.4f,%.4f: terrapolis %.0f cells (%.1f km2), grass %.0f cells (accumulation map %.0f), diff %.3f %%\n" \
      "$name" "$cells" "$lon" "$lat" "$ours" "$km2" "${theirs:-0}" "$acc" "$err"
    worst=$(python3 -c "print(max($worst, $err))")
  done <"$work/outlets_$name.txt"
  printf "%-14s %10s | largest-catchment disagreement with GRASS: %.3f %% (goal < 1 %%)\n" "$name" "$cells" "$worst"

  fi

  if has belhadj; then
  # 5. Belhadj hydrometry throughput on 2 threads.
  bl=$("$bin" -v --threads 2 --progress none hydro "$dem" "$work/bel_$name" --outputs hydrometry --iterations 20 --overwrite 2>&1 \
    | sed -n 's/.*belhadj: \(.*\)/\1/p')
  printf "%-14s %10s | Belhadj hydrometry, 20 iterations: %s\n" "$name" "$cells" "$bl"
  fi
done

has belhadj || exit 0
# The thesis's Corsica-sized case: 256 x 256, 20 iterations (227 ms on a 2.8 GHz Pentium D in 2007).
gdal_translate -q -srcwin 0 0 256 256 "${dems[0]}" "$work/c256.tif"
bl=$("$bin" -v --threads 2 --progress none hydro "$work/c256.tif" "$work/c256" --outputs hydrometry --iterations 20 2>&1 | sed -n 's/.*belhadj: \(.*\)/\1/p')
echo "256x256 (thesis case)     | Belhadj hydrometry, 20 iterations: $bl"
# The same case in process, without start-up, reading and writing (Google Benchmark; built with
# the project when the library is installed): median of 5 repetitions, 2 threads.
micro=$(dirname "$bin")/../../bench/bench_hydro
if [[ -x $micro ]]; then
  TERRAPOLIS_BENCH_DEM=$(realpath "${dems[0]}") TERRAPOLIS_BENCH_THREADS=2 "$micro" --benchmark_filter='Belhadj256x20' \
    --benchmark_repetitions=5 --benchmark_report_aggregates_only=true 2>/dev/null | awk '/_median/ {print "256x256 in process (median) | Belhadj hydrometry, 20 iterations: " $2 " " $3 " wall, " $NF}'
fi
