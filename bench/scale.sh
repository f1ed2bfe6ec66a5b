#!/usr/bin/env bash
# Tile engine benchmark: `terrapolis hydro` whole-grid vs tile by tile (--tile-size, --memory-limit)
# on the shared SRTM tiles: wall and CPU time (medians), peak resident memory, and a check that
# the tiled outputs hold the whole-grid cells. Then, when terrapolis-mpi was built, the tiles on
# 1, 2 and 4 MPI ranks against TauDEM 5.4 (PitRemove + D8FlowDir + AreaD8) on the same ranks:
# TauDEM is built here from ../shared/peers/taudem-*.tar.gz, once, into $TAUDEM_BUILD.
# Run from the repository root: bench/scale.sh [path/to/terrapolis] [runs]
# Needs GNU time (/usr/bin/time), gdal-bin, python3, cmake and Open MPI (mpirun); the DEMs in
# ../shared/dems. BENCH_RANKS="1 2 4", BENCH_MPI_TILE (tile side on ranks; default: a third of the
# DEM's side, 9 tiles), TAUDEM_TIMEOUT (CPU s a rank and step, default 600: a TauDEM step past it is reported as such).
# WEAK=1: weak scaling instead, on a synthetic continent streamed from disk: WEAK_DEM (default
# N47E009, the Alps) written once in its four mirror images, placed by a VRT as a mirror-tiled
# mosaic (seamless edges) of WEAK_COPIES tiles a rank (default 360: 5.2e8 cells a rank, 1.04e9 on 2 ranks),
# run by `terrapolis hydro --memory-limit WEAK_MEMORY` (MB, default 400) on one process and by
# terrapolis-mpi on WEAK_RANKS (default "1 2"), one thread a rank: cells/s a rank, CPU, peak
# resident memory of each rank (GNU time), the engine's reported state, disk written. WEAK_DIR:
# where the mosaic and outputs go (default a temporary folder; removed at the end).
# RUN=1: a run to the network stage (RUN_UNTIL) on such a continent, whole grid vs input.memory_limit_mb (RUN_COPIES, RUN_MEMORY, RUN_PRESET).
# DENSITY=1: the density stage instead, whole grid vs tile by tile (DENSITY_OPTIONS, ";"-separated).
# SPDX-License-Identifier: MIT
set -euo pipefail
bin=$(realpath "${1:-build/src/cli/terrapolis}")
runs=${2:-3}
dems=(${BENCH_DEMS:-../shared/dems/N47E009.hgt ../shared/dems/S46W066.hgt})
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
outputs=filled,flowdir,accumulation
mpi_bin=$(dirname "$bin")/terrapolis-mpi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# run LABEL CMD...: median wall and CPU seconds and the largest peak resident MB over $runs runs.
run() {
  local label=$1; shift
  local log=$work/time.log
  : >"$work/times"
  for _ in $(seq "$runs"); do
    rm -rf "$work/out"
    /usr/bin/time -f "%e %U %S %M" -o "$log" "$@" >/dev/null 2>"$work/stderr" || { cat "$work/stderr"; return 1; }
    cat "$log" >>"$work/times"
  done
  python3 - "$label" "$work/times" <<'PY'
import statistics, sys
rows = [list(map(float, l.split())) for l in open(sys.argv[2]) if l.strip()]
wall = statistics.median(r[0] for r in rows)
cpu = statistics.median(r[1] + r[2] for r in rows)
peak = max(r[3] for r in rows) / 1024
print(f"  {sys.argv[1]:<40} wall {wall:7.2f} s  cpu {cpu:7.2f} s  peak {peak:7.0f} MB")
PY
  python3 -c "import statistics,sys; r=[l.split() for l in open(sys.argv[1])]; print(statistics.median(float(x[0]) for x in r), statistics.median(float(x[1]) + float(x[2]) for x in r))" "$work/times" >"$work/last"
}

# TauDEM 5.4 from the shared source archive, built once (Release, its own CMake files).
taudem=${TAUDEM_BUILD:-$HOME/.cache/terrapolis-bench/taudem}
build_taudem() {
  [[ -x $taudem/src/aread8 ]] && return 0
  local archive
  archive=$(ls ../shared/peers/taudem-*-src.tar.gz 2>/dev/null | head -1)
  [[ -n $archive ]] || { echo "no TauDEM source in ../shared/peers: TauDEM skipped"; return 1; }
  mkdir -p "$taudem.src" && tar xzf "$archive" -C "$taudem.src"
  cmake -S "$taudem.src" -B "$taudem" -DCMAKE_BUILD_TYPE=Release >/dev/null &&
    cmake --build "$taudem" -j2 --target pitremove d8flowdir aread8 >/dev/null
}

# taudem_chain NP DEM.tif: PitRemove, D8FlowDir and AreaD8 on NP ranks, each rank within
# TAUDEM_TIMEOUT CPU seconds a step (CPU, not wall: fair on a loaded machine).
taudem_chain() {
  local np=$1 dem=$2 d=$work/tau
  rm -rf "$d" && mkdir "$d"
  ulimit -t "${TAUDEM_TIMEOUT:-600}"
  mpirun -q --oversubscribe -np "$np" "$taudem/src/pitremove" -z "$dem" -fel "$d/fel.tif" >/dev/null 2>&1 &&
    mpirun -q --oversubscribe -np "$np" "$taudem/src/d8flowdir" -fel "$d/fel.tif" -p "$d/p.tif" -sd8 "$d/sd8.tif" >/dev/null 2>&1 &&
    mpirun -q --oversubscribe -np "$np" "$taudem/src/aread8" -p "$d/p.tif" -ad8 "$d/ad8.tif" -nc >/dev/null 2>&1
}
export -f taudem_chain
export taudem work

same_cells() {  # raw copies compared byte for byte
  rm -f "$work"/[ab].*
  GDAL_PAM_ENABLED=NO gdal_translate -q -of ENVI "$1" "$work/a.bin"
  GDAL_PAM_ENABLED=NO gdal_translate -q -of ENVI "$2" "$work/b.bin"
  if cmp -s "$work/a.bin" "$work/b.bin"; then echo "    $(basename "$2"): same cells"; else echo "    $(basename "$2"): DIFFERENT"; fi
}

# The four mirror images of DEM in DIR, once (Int16), for mosaic.
mirror_images() {
  /usr/bin/python3 - "$1" "$2" <<'PY'
import sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1])
z = src.GetRasterBand(1).ReadAsArray()
for name, a in (("id", z), ("lr", z[:, ::-1]), ("ud", z[::-1, :]), ("both", z[::-1, ::-1])):
    out = gdal.GetDriverByName("GTiff").Create(f"{sys.argv[2]}/{name}.tif", a.shape[1], a.shape[0], 1, gdal.GDT_Int16,
                                               ["TILED=YES", "COMPRESS=DEFLATE", "PREDICTOR=2"])
    out.SetGeoTransform(src.GetGeoTransform())
    out.SetProjection(src.GetProjection())
    band = out.GetRasterBand(1)
    band.SetNoDataValue(-32768)
    band.WriteArray(a)
PY
}

# mosaic N DIR: DIR/continent-N.vrt, N copies about as many across as down, each mirrored where it
# meets its neighbours (seamless edges).
mosaic() {
  /usr/bin/python3 - "$1" "$2" <<'PY'
import math, sys
from osgeo import gdal
n, d = int(sys.argv[1]), sys.argv[2]
tile = gdal.Open(f"{d}/id.tif")
side, step = tile.RasterXSize, tile.GetGeoTransform()[1]
across = next(a for a in range(math.isqrt(n), 0, -1) if n % a == 0)
down = n // across
sources = "".join(
    f"""<SimpleSource><SourceFilename relativeToVRT="1">{("id", "lr", "ud", "both")[(i % 2) + 2 * (j % 2)]}.tif</SourceFilename>
<SourceBand>1</SourceBand><SrcRect xOff="0" yOff="0" xSize="{side}" ySize="{side}"/>
<DstRect xOff="{i * side}" yOff="{j * side}" xSize="{side}" ySize="{side}"/></SimpleSource>"""
    for j in range(down) for i in range(across))
open(f"{d}/continent-{n}.vrt", "w").write(f"""<VRTDataset rasterXSize="{side * across}" rasterYSize="{side * down}">
<SRS>EPSG:4326</SRS><GeoTransform>0.0, {step!r}, 0, 60.0, 0, {-step!r}</GeoTransform>
<VRTRasterBand dataType="Int16" band="1"><NoDataValue>-32768</NoDataValue>{sources}</VRTRasterBand></VRTDataset>
""")
PY
}

# Weak scaling on a synthetic continent (WEAK=1).
weak() {
  local copies=${WEAK_COPIES:-360} memory=${WEAK_MEMORY:-400} dem=${WEAK_DEM:-../shared/dems/N47E009.hgt} dir
  dir=$(mktemp -d "${WEAK_DIR:-$work}/continent.XXXXXX")
  trap "rm -rf '$work' '$dir'" EXIT  # expanded now: dir is local
  mirror_images "$dem" "$dir"
  local side cells_a_copy
  side=$(gdalinfo "$dir/id.tif" | sed -n 's/^Size is \([0-9]*\),.*/\1/p')
  cells_a_copy=$(( side * side ))
  echo "weak scaling: $copies copies of $(basename "$dem") a rank ($(( copies * cells_a_copy )) cells), --memory-limit $memory, one thread a rank, $(nproc) cores"
  local np
  for np in ${WEAK_RANKS:-1 2}; do
    local n=$(( copies * np )) out=$dir/out
    mosaic "$n" "$dir"
    rm -rf "$out"
    local cmd=("$bin" -v --threads 1 hydro "$dir/continent-$n.vrt" "$out" --outputs $outputs --memory-limit "$memory")
    local start end
    start=$(date +%s.%N)
    if [[ $np == 1 && ${WEAK_SINGLE:-process} == process ]]; then
      /usr/bin/time -f "%e %U %S %M" -o "$dir/time.0" "${cmd[@]}" 2>"$dir/log" >/dev/null || { cat "$dir/log"; return 1; }
    else
      [[ -x $mpi_bin ]] || { echo "  no terrapolis-mpi: np $np skipped"; continue; }
      cmd[0]=$mpi_bin
      mpirun -q --oversubscribe -np "$np" bash -c '/usr/bin/time -f "%e %U %S %M" -o "$0/time.$OMPI_COMM_WORLD_RANK" "$@"' \
        "$dir" "${cmd[@]}" 2>"$dir/log" >/dev/null || { cat "$dir/log"; return 1; }
    fi
    end=$(date +%s.%N)
    local written
    written=$(du -sb "$out" | cut -f1)
    /usr/bin/python3 - "$np" "$n" "$cells_a_copy" "$start" "$end" "$written" "$dir" <<'PY'
import glob, sys
np_, n, per, start, end, written, d = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5]), int(sys.argv[6]), sys.argv[7]
cells = n * per
wall = end - start
ranks = [list(map(float, open(f).read().split())) for f in sorted(glob.glob(f"{d}/time.*"))]
cpu = [r[1] + r[2] for r in ranks]
peak = [r[3] * 1024 / 1e6 for r in ranks]  # kB, as MB like --memory-limit
print(f"  np {np_}: {cells:.3e} cells, wall {wall:.0f} s, CPU a rank {min(cpu):.0f}-{max(cpu):.0f} s, "
      f"{cells / np_ / wall / 1e6:.2f} M cells/s a rank (wall), {cells / sum(cpu) / 1e6:.2f} M cells/CPU s, "
      f"peak {min(peak):.0f}-{max(peak):.0f} MB a rank, written {written / 1e9:.2f} GB ({written / cells:.2f} B a cell)")
PY
    grep "^tiles:" "$dir/log" | sed 's/^/    /'
    rm -rf "$out" "$dir"/time.*
  done
}
if [[ ${WEAK:-0} == 1 ]]; then
  weak
  exit
fi

# A run by tiles (RUN=1): `terrapolis run --until network` (RUN_UNTIL; density.preset RUN_PRESET, the default fitted)
# on the mirror-tiled continent of RUN_COPIES copies of WEAK_DEM (default 36: 5.2e7 cells), on the
# whole grid and with input.memory_limit_mb RUN_MEMORY (default 400): wall, CPU, peak resident
# memory, each stage's time and peak, and the tiled outputs checked against the whole grid's.
run_bench() {
  local copies=${RUN_COPIES:-36} memory=${RUN_MEMORY:-400} dem=${WEAK_DEM:-../shared/dems/N47E009.hgt} dir
  dir=$(mktemp -d "${WEAK_DIR:-$work}/continent.XXXXXX")
  trap "rm -rf '$work' '$dir'" EXIT
  mirror_images "$dem" "$dir"
  mosaic "$copies" "$dir"
  local set=(--set dem="$dir/continent-$copies.vrt" --set density.preset="${RUN_PRESET:-fitted}" --set outputs.preview=false --until "${RUN_UNTIL:-network}")
  echo "run by tiles: $copies copies of $(basename "$dem"), $(gdalinfo "$dir/continent-$copies.vrt" | sed -n 's/^Size is //p') cells, $(nproc) cores"
  local label out
  for label in whole tiled; do
    out=$dir/$label
    local extra=()
    [[ $label == tiled ]] && extra=(--set input.memory_limit_mb="$memory")
    /usr/bin/time -f "%e %U %S %M" -o "$dir/time" "$bin" -q run "${set[@]}" "${extra[@]}" -o "$out" >/dev/null 2>"$dir/log" ||
      { cat "$dir/log"; return 1; }
    /usr/bin/python3 - "$label" "$dir/time" "$out/run.json" "$memory" <<'PY'
import json, sys
wall, user, sys_, kb = map(float, open(sys.argv[2]).read().split())
timings = json.load(open(sys.argv[3]))["timings"]
stages = ", ".join(f"{t['stage']} {t['seconds']:.0f} s (peak {t['peak_memory_mb']:.0f} MB)" for t in timings)
limit = f" (limit {sys.argv[4]} MB)" if sys.argv[1] == "tiled" else ""
print(f"  {sys.argv[1]:<6} wall {wall:6.0f} s  cpu {user + sys_:6.0f} s  peak {kb * 1024 / 1e6:6.0f} MB{limit}: {stages}")
PY
  done
  for r in elevation filled accumulation hydrometry inland_water buildable density; do same_cells "$dir/whole/$r.tif" "$dir/tiled/$r.vrt"; done
  for l in streams cities city_extents network; do
    [[ -f $dir/whole/$l.geojson ]] || continue
    cmp -s "$dir/whole/$l.geojson" "$dir/tiled/$l.geojson" && echo "  $l.geojson: the same bytes" || echo "  $l.geojson DIFFERS"
  done
  /usr/bin/python3 -c 'import json, sys; s = json.load(open(sys.argv[1]))["summary"]; print("  sites:", s.get("sites", {}).get("cities"), "settlements,", s.get("sites", {}).get("population"), "people; network:", s.get("network"))' "$dir/tiled/run.json"
}
if [[ ${RUN:-0} == 1 ]]; then
  run_bench
  exit
fi

# The density stage by tiles (DENSITY=1): `terrapolis density` whole-grid vs --tile-size and
# --memory-limit on each DEM, with the hydrometry of the whole-grid hydro command (Belhadj): wall,
# CPU, peak memory, the engine's report, and a check that the tiled outputs hold the whole-grid cells.
density_bench() {
  local dem name
  for dem in "${dems[@]}"; do
    name=$(basename "$dem" .hgt)
    local sea=() side
    [[ $name == S46W066 ]] && sea=(--sea-level 0)
    side=$(gdalinfo "$dem" | sed -n 's/^Size is \([0-9]*\),.*/\1/p')
    "$bin" -q hydro "$dem" "$work/hydro" --outputs hydrometry "${sea[@]}" --overwrite
    local h=(--hydrometry "$work/hydro/hydrometry.tif")
    echo "$name density ($side x $side cells), $runs runs, $(nproc) cores, hydrometry from the whole-grid hydro command"
    run "whole grid" "$bin" -q density "$dem" "$work/out" "${h[@]}" "${sea[@]}"
    "$bin" -q density "$dem" "$work/whole" "${h[@]}" "${sea[@]}" --overwrite
    IFS=";" read -ra options <<<"${DENSITY_OPTIONS:---tile-size 1201;--tile-size 600;--tile-size 300;--memory-limit 128;--memory-limit 64}"
    for option in "${options[@]}"; do
      run "tiled $option" "$bin" -q density "$dem" "$work/out" "${h[@]}" "${sea[@]}" $option
      "$bin" -v density "$dem" "$work/tiled" "${h[@]}" "${sea[@]}" $option --overwrite 2>&1 | grep "^density tiles:" | sed 's/^/    /'
      for o in plain coast plateau buildable density; do same_cells "$work/whole/$o.tif" "$work/tiled/$o.vrt"; done
    done
  done
}
if [[ ${DENSITY:-0} == 1 ]]; then
  density_bench
  exit
fi

for dem in "${dems[@]}"; do
  name=$(basename "$dem" .hgt)
  size=$(gdalinfo "$dem" | sed -n 's/^Size is //p')
  echo "$name ($size cells), $runs runs, $(nproc) cores"
  sea=()
  [[ $name == S46W066 ]] && sea=(--sea-level 0)
  run "whole grid" "$bin" -q hydro "$dem" "$work/out" --outputs $outputs "${sea[@]}"
  "$bin" -q hydro "$dem" "$work/whole" --outputs $outputs "${sea[@]}" --overwrite
  IFS=";" read -ra options <<<"${BENCH_OPTIONS:---tile-size 1201;--tile-size 600;--tile-size 300;--memory-limit 64;--memory-limit 32}"
  for option in "${options[@]}"; do
    run "tiled $option" "$bin" -q hydro "$dem" "$work/out" "${sea[@]}" $option
    "$bin" -v hydro "$dem" "$work/tiled" "${sea[@]}" $option --overwrite 2>&1 | grep "^tiles:" | sed 's/^/    /'
    for o in filled flowdir accumulation; do same_cells "$work/whole/$o.tif" "$work/tiled/$o.vrt"; done
  done
done

# Terrapolis tiles on MPI ranks vs TauDEM on the same ranks (one thread a rank for both).
[[ -x $mpi_bin ]] || { echo "no terrapolis-mpi (MPI not found at build time): ranks skipped"; exit 0; }
have_taudem=1
build_taudem || have_taudem=0
for dem in "${dems[@]}"; do
  name=$(basename "$dem" .hgt)
  side=$(gdalinfo "$dem" | sed -n 's/^Size is \([0-9]*\),.*/\1/p')
  tile=${BENCH_MPI_TILE:-$(( (side + 2) / 3 ))}
  sea=()
  [[ $name == S46W066 ]] && sea=(--sea-level 0)
  gdal_translate -q -ot Float32 "$dem" "$work/$name.tif"
  echo "$name on MPI ranks: Terrapolis tiles of $tile, --threads 1 a rank; TauDEM PitRemove + D8FlowDir + AreaD8 (timeout ${TAUDEM_TIMEOUT:-600} s a step)"
  for np in ${BENCH_RANKS:-1 2 4}; do
    run "terrapolis-mpi np $np" mpirun --oversubscribe -np "$np" "$mpi_bin" -q hydro "$dem" "$work/out" "${sea[@]}" --tile-size "$tile" --threads 1
    ours=$(cat "$work/last")
    if (( have_taudem )); then
      if run "taudem np $np" bash -c 'taudem_chain "$0" "$1"' "$np" "$work/$name.tif"; then
        python3 -c "import sys; a, b = sys.argv[1].split(), sys.argv[2].split(); print(f'    TauDEM / Terrapolis: wall {float(b[0]) / float(a[0]):.1f}x, CPU {float(b[1]) / float(a[1]):.1f}x')" "$ours" "$(cat "$work/last")"
      else
        echo "  taudem np $np: a step did not finish within ${TAUDEM_TIMEOUT:-600} CPU s a rank"
      fi
    fi
  done
done