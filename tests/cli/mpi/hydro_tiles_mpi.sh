#!/usr/bin/env bash
# `mpirun -np N terrapolis-mpi hydro --tile-size`: tiles dealt to 1, 2 and 4 ranks give the cells of
# the whole grid and of the single-process tiled run, byte for byte (basins included); a depression and a flat that
# span four tiles each; the exchanges in rounds when they exceed what one call carries; a bad input
# is one error line from rank 0, exit 2, nothing left behind.
# Usage: hydro_tiles_mpi.sh TERRAPOLIS SAMPLES SOURCE TERRAPOLIS_MPI MPIRUN (registered when MPI is found)
# SPDX-License-Identifier: MIT
source "$(dirname "$0")/../lib.sh" "$@"
bin=$TP mpi_bin=$4 mpirun=${5:-mpirun} work=$WORK
mpi() { local np=$1; shift; "$mpirun" -q --oversubscribe -np "$np" "$mpi_bin" "$@"; }  # -q: no notice of a non-zero exit
outputs=(filled flowdir accumulation basins)
all=filled,flowdir,accumulation,streams,basins

# 300 x 300 cells of SRTM 1" (Zion), 3 x 3 tiles of 100: a pit 40 m deep on the corner where tiles
# 0, 1, 3, 4 meet (filled, it is a lake flat on four tiles) and a plateau on the corner of 4, 5, 7, 8.
dem=$work/zion_cut.tif
gdal_translate -q -srcwin 80 80 300 300 "$SAMPLES/spDataLarge_srtm_zion.tif" "$work/cut.tif"
/usr/bin/python3 - "$work/cut.tif" "$dem" <<'PY'
import sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1])
z = src.GetRasterBand(1).ReadAsArray().astype(np.float32)
rows, cols = np.mgrid[0:300, 0:300]
pit = (rows - 100) ** 2 + (cols - 100) ** 2 <= 12 ** 2
z[pit] -= 40
plateau = (abs(rows - 200) <= 10) & (abs(cols - 200) <= 10)
z[plateau] = z[plateau].max()
out = gdal.GetDriverByName("GTiff").Create(sys.argv[2], 300, 300, 1, gdal.GDT_Float32)
out.SetGeoTransform(src.GetGeoTransform())
out.SetProjection(src.GetProjection())
out.GetRasterBand(1).WriteArray(z)
PY
"$bin" -q hydro "$dem" "$work/whole" --outputs $all --streams-threshold 0.5
"$bin" -v hydro "$dem" "$work/tiled" --tile-size 100 --streams-threshold 0.5 --outputs $all 2>"$work/tiled.log"
grep "^tiles: 9 of 100" "$work/tiled.log" | grep -Eq "; [1-9][0-9]* cells of flats across tiles" ||
  fail "expected 9 tiles and flats across tile edges: $(cat "$work/tiled.log")"
for o in "${outputs[@]}"; do same_cells "$work/whole/$o.tif" "$work/tiled/$o.vrt" || fail "tiled $o differs from the whole grid"; done
cmp -s "$work/whole/streams.geojson" "$work/tiled/streams.geojson" || fail "tiled streams differ from the whole grid"
# Reaches stitched: some reach runs through three tiles or more, one feature (not one per tile).
/usr/bin/python3 - "$work/tiled/streams.geojson" <<'PY' || fail "no reach crosses two tile edges"
import json, sys
from osgeo import gdal
gt = gdal.Open(sys.argv[1].replace("streams.geojson", "filled.vrt")).GetGeoTransform()
tiles = lambda line: {(int((y - gt[3]) / gt[5]) // 100, int((x - gt[0]) / gt[1]) // 100) for x, y in line}
sys.exit(0 if max(len(tiles(f["geometry"]["coordinates"])) for f in json.load(open(sys.argv[1]))["features"]) >= 3 else 1)
PY
# A basin crossing tiles: the pit's lake drains on, so the basin holding the pit corner (100, 100)
# spreads over the four tiles around it at least, under one label.
/usr/bin/python3 - "$work/tiled/basins.vrt" <<'PY' || fail "no basin over four tiles"
import sys
from osgeo import gdal
b = gdal.Open(sys.argv[1]).ReadAsArray()
rows, cols = (b == b[100, 100]).nonzero()
sys.exit(0 if b[100, 100] > 0 and len({(r // 100, c // 100) for r, c in zip(rows, cols)}) >= 4 else 1)
PY
for np in 1 2 4; do
  mpi "$np" -v hydro "$dem" "$work/np$np" --tile-size 100 --streams-threshold 0.5 --outputs $all --threads 1 2>"$work/np$np.log" ||
    fail "np $np: $(cat "$work/np$np.log")"
  cmp -s "$work/whole/streams.geojson" "$work/np$np/streams.geojson" || fail "np $np: streams differ from the whole grid"
  grep -q "^tiles: 9 of 100.*; $np process" "$work/np$np.log" || fail "np $np: no tile report: $(cat "$work/np$np.log")"
  # Bytes exchanged between passes: none on one rank, both ways on more.
  read -r sent received < <(sed -n 's/^tiles: .*exchanged \([0-9.]*\) MB sent, \([0-9.]*\) MB received$/\1 \2/p' "$work/np$np.log")
  awk -v np="$np" -v s="$sent" -v r="$received" 'BEGIN { exit !(s != "" && (np == 1 ? s + r == 0 : s > 0 && r > 0)) }' ||
    fail "np $np: bytes exchanged: $(grep '^tiles' "$work/np$np.log")"
  for o in "${outputs[@]}"; do
    same_cells "$work/whole/$o.tif" "$work/np$np/$o.vrt" || fail "np $np: $o differs from the whole grid"
    cmp -s "$work/tiled/$o/tile_0001_0001.tif" "$work/np$np/$o/tile_0001_0001.tif" || fail "np $np: $o tile files differ from the tiled run's"
    [[ $(ls "$work/np$np/$o"/tile_*.tif | wc -l) -eq 9 ]] || fail "np $np: expected 9 $o tiles"
  done
  [[ -z $(ls -A "$work/np$np" | grep scratch) ]] || fail "np $np: scratch folder left behind"
done
# An exchange larger than one MPI call carries (2 GB) goes in rounds: rounds of at most 1000 bytes
# here (each rank sending its next 500 or 250), hundreds of them, the same bytes.
for np in 2 4; do
  TERRAPOLIS_MPI_EXCHANGE_BYTES=1000 mpi "$np" -v hydro "$dem" "$work/rounds$np" --tile-size 100 --streams-threshold 0.5 --outputs $all \
    --threads 1 2>"$work/rounds$np.log" || fail "np $np in rounds: $(cat "$work/rounds$np.log")"
  cmp -s "$work/whole/streams.geojson" "$work/rounds$np/streams.geojson" || fail "np $np in rounds: streams differ from the whole grid"
  for o in "${outputs[@]}"; do same_cells "$work/whole/$o.tif" "$work/rounds$np/$o.vrt" || fail "np $np in rounds: $o differs"; done
done
no_leftovers "$work"

# Bad input and an existing output: one line from rank 0 (no MPI abort), exit 2, nothing written.
# The memory limit is refused inside the tiled run, on every rank: they agree, rank 0 prints.
expect_refused "$work/bad" "too little" mpi 4 hydro "$dem" "$work/bad" --memory-limit 0.1
[[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "expected one error line: $(cat "$WORK/stderr")"
expect_fail 2 "exists" mpi 2 hydro "$dem" "$work/np2" --tile-size 100
[[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "expected one error line: $(cat "$WORK/stderr")"
no_leftovers "$work"
echo ok
