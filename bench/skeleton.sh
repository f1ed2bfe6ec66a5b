#!/usr/bin/env bash
# Skeleton benchmark (Belhadj 2007 §5.2.2): `terrapolis skeleton` keeps every 3rd cell of its ridge
# and valley lines and a lattice of every 6th cell of every 6th row (the defaults); the DEM is
# rebuilt from the kept cells and, at the same share, from random valid cells (median of 3 seeds)
# and from a regular lattice alone, by `terrapolis reconstruct` (thin-plate), GDAL
# gdal_fillnodata.py, GRASS r.surf.idw and v.surf.rst (its spline, default tension and smoothing),
# in the same run. The `lines` rows are the thesis's literal form (every line cell, no lattice:
# --lattice 0 --line-step 1), `random@l` random cells at its share. Prints the share kept, the RMSE
# against the original (over all valid cells, the thesis's "écart-type", over the hidden cells and
# over the hidden cells of the thesis's lines) and times on the first file of a row: median of REPEAT whole-process runs for terrapolis and GDAL,
# the module's own time (one run) for GRASS.
# Usage: bench/skeleton.sh [DEM...]   (default: the six DEMs of docs/benchmarks.md and N47E009)
# Env: TERRAPOLIS_BIN (default build/src/cli/terrapolis), REPEAT (default 3), CROP (default 600:
#      DEMs wider or taller than this are cut to their central CROP x CROP window first),
#      FILLNULLS_TIMEOUT (s, default 0: r.fillnulls is not run; > 0 adds its rows, capped),
#      SKELETON_ARGS (more `terrapolis skeleton` options for the skeleton rows, e.g. "--line-step 1").
# SPDX-License-Identifier: MIT
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=$(realpath "${TERRAPOLIS_BIN:-build/src/cli/terrapolis}")
REPEAT=${REPEAT:-3}
CROP=${CROP:-600}
FILLNULLS_TIMEOUT=${FILLNULLS_TIMEOUT:-0}
PY=/usr/bin/python3
D=../shared/dems
if [ $# -gt 0 ]; then DEMS=("$@"); else
  DEMS=("$D/whiteboxR_DEM_vermont.tif" "$D/topotoolbox_bigtujunga.tif" "$D/spDataLarge_srtm_zion.tif" "$D/spDataLarge_dem_mongon.tif"
        "$D/spDataLarge_ta_elev_band4.tif" "$D/terra_elev_luxembourg.tif" "$D/N47E009.hgt"); fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
GRASS=1
command -v grass >/dev/null || { GRASS=0; echo "GRASS not found: its rows are skipped" >&2; }

cat >"$WORK/sk.py" <<'EOF'
# random KEPT DEM SEED OUT: as many random valid cells as KEPT holds;
# lattice KEPT DEM OUT: a regular lattice of valid cells of about the same share (spacing 1/sqrt(share));
# score TRUTH SPARSE OUT LINES: RMSE over the valid cells, over the hidden ones and over the hidden
# cells of the thesis's lines (LINES: its sparse raster), where a surface through even cells errs most.
import sys
import numpy as np
from osgeo import gdal
gdal.UseExceptions()

def read(path):
    ds = gdal.Open(path); b = ds.GetRasterBand(1)
    a = b.ReadAsArray().astype(np.float64); nd = b.GetNoDataValue()
    if nd is not None and not np.isnan(nd): a[a == nd] = np.nan
    return ds, a

def write(ds, z, mask, path):
    out = np.where(mask, z, -9999.0)
    o = gdal.GetDriverByName("GTiff").Create(path, ds.RasterXSize, ds.RasterYSize, 1, gdal.GDT_Float32)
    o.SetGeoTransform(ds.GetGeoTransform()); o.SetProjection(ds.GetProjection())
    b = o.GetRasterBand(1); b.SetNoDataValue(-9999); b.WriteArray(out.astype(np.float32)); o = None

what = sys.argv[1]
if what in ("random", "lattice"):
    _, kept = read(sys.argv[2]); ds, z = read(sys.argv[3]); valid = np.isfinite(z)
    n = int(np.isfinite(kept).sum())
    if what == "random":
        pick = np.random.default_rng(int(sys.argv[4])).choice(np.flatnonzero(valid), n, replace=False)
        mask = np.zeros(z.size, bool); mask[pick] = True; mask = mask.reshape(z.shape)
    else:
        step = np.sqrt(valid.sum() / n)
        rows = np.unique(np.floor(np.arange(step / 2, z.shape[0], step)).astype(int))
        cols = np.unique(np.floor(np.arange(step / 2, z.shape[1], step)).astype(int))
        mask = np.zeros(z.shape, bool); mask[np.ix_(rows, cols)] = True; mask &= valid
    write(ds, z, mask, sys.argv[-1])
    print("%.2f" % (100 * mask.sum() / valid.sum()))
else:
    _, t = read(sys.argv[2]); _, s = read(sys.argv[3]); _, lines = read(sys.argv[5])
    try:
        _, o = read(sys.argv[4])
    except Exception:
        print("nan nan nan"); sys.exit()
    valid = np.isfinite(t); hidden = valid & np.isnan(s); on_lines = hidden & np.isfinite(lines)
    if np.isnan(o[valid]).any():  # cells a tool left empty: not scored
        print("unfilled unfilled unfilled"); sys.exit()
    rmse = lambda m: "%.2f" % np.sqrt(np.mean((o[m] - t[m]) ** 2)) if m.any() else "-"
    print(rmse(valid), rmse(hidden), rmse(on_lines))
EOF

timed() {  # median wall time (s) of REPEAT runs of "$@"
  local times=()
  for _ in $(seq "$REPEAT"); do
    /usr/bin/time -f "%e" -o "$WORK/time" "$@" >/dev/null 2>"$WORK/stderr" || { tail -2 "$WORK/stderr" >&2; echo nan; return; }
    times+=("$(cat "$WORK/time")")
  done
  printf '%s\n' "${times[@]}" | sort -g | sed -n "$(( (REPEAT + 1) / 2 ))p"
}

grass_fill() {  # grass_fill MODULE IN OUT: r.surf.idw, v.surf.rst or r.fillnulls; prints the module's time
  local timer="/usr/bin/time -f %e -o $WORK/grass_time" cmd post=""
  case "$1" in
    # r.surf.idw takes integer maps only: heights in centimetres, back to metres after.
    r.surf.idw) cmd="r.mapcalc 'ai = round(a * 100)' --quiet; $timer r.surf.idw input=ai output=bi npoints=12 --quiet"
                post="r.mapcalc 'b = float(bi) / 100' --quiet" ;;
    v.surf.rst) cmd="r.to.vect -z input=a output=p type=point --quiet; $timer v.surf.rst input=p elevation=b --quiet" ;;
    r.fillnulls) cmd="$timer r.fillnulls input=a output=b method=bilinear --quiet" ;;
  esac
  cat >"$WORK/grass.sh" <<EOF
set -e
r.in.gdal -o input="$2" output=a --quiet --overwrite
g.region raster=a
$cmd
$post
r.out.gdal -c -f input=b output="$3" format=GTiff type=Float32 nodata=-9999 --quiet --overwrite
EOF
  rm -f "$3"
  local cap=1200
  [ "$1" = r.fillnulls ] && cap=$FILLNULLS_TIMEOUT
  if timeout "$cap" grass --tmp-location "$2" --exec bash "$WORK/grass.sh" >/dev/null 2>&1; then cat "$WORK/grass_time"
  else echo ">$cap"; fi
}

median() { printf '%s\n' "$@" | sort -g | sed -n "$(( ($# + 1) / 2 ))p"; }

fmt='%-24s %7s %-8s %6s %-26s %9s %11s %10s %8s\n'
printf "$fmt" dem cells samples kept% tool rmse_all rmse_hidden rmse_lines time_s
for dem in "${DEMS[@]}"; do
  name=$(basename "$dem"); name=${name%.*}
  d="$WORK/$name"; mkdir -p "$d"
  read -r w h < <(gdalinfo "$dem" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 \2/p')
  if [ "$w" -gt "$CROP" ] || [ "$h" -gt "$CROP" ]; then  # the central window, so every tool runs in minutes
    cw=$(( w < CROP ? w : CROP )); ch=$(( h < CROP ? h : CROP ))
    gdal_translate -q -srcwin $(( (w - cw) / 2 )) $(( (h - ch) / 2 )) "$cw" "$ch" "$dem" "$d/dem.tif"
    name="$name[${cw}x$ch]"; dem="$d/dem.tif"
  fi
  t_skel=$(timed "$BIN" -q skeleton "$dem" "$d/sk" ${SKELETON_ARGS:-} --overwrite)
  "$BIN" -q skeleton "$dem" "$d/lines" --lattice 0 --line-step 1 --overwrite
  read -r cells < <($PY -c "import json,sys; print(json.load(open(sys.argv[1]))['valid_cells'])" "$d/sk/skeleton.json")
  share() { $PY -c "import json,sys; print('%.2f' % (100*json.load(open(sys.argv[1]))['kept_share']))" "$1"; }
  printf "$fmt" "$name" "$cells" - "$(share "$d/sk/skeleton.json")" "terrapolis skeleton" - - - "$t_skel"
  # Sample sets: name, the kept cells whose share they match, files (several: random seeds, median RMSE).
  cp "$d/sk/skeleton.tif" "$d/skeleton.tif"; cp "$d/lines/skeleton.tif" "$d/lines.tif"
  for seed in 1 2 3; do
    $PY "$WORK/sk.py" random "$d/skeleton.tif" "$dem" "$seed" "$d/random$seed.tif" >/dev/null
    $PY "$WORK/sk.py" random "$d/lines.tif" "$dem" "$seed" "$d/linesrandom$seed.tif" >/dev/null
  done
  lattice_share=$($PY "$WORK/sk.py" lattice "$d/skeleton.tif" "$dem" "$d/lattice.tif")
  declare -A SETS=([skeleton]="skeleton" [random]="random1 random2 random3" [lattice]="lattice"
                   [lines]="lines" [random@l]="linesrandom1 linesrandom2 linesrandom3")
  declare -A SHARE=([skeleton]="$(share "$d/sk/skeleton.json")" [random]="$(share "$d/sk/skeleton.json")" [lattice]="$lattice_share"
                    [lines]="$(share "$d/lines/skeleton.json")" [random@l]="$(share "$d/lines/skeleton.json")")
  for set in skeleton random lattice lines random@l; do
    tools=("terrapolis thin-plate" "gdal_fillnodata -md 100")
    [ "$GRASS" = 1 ] && tools+=("r.surf.idw 12 points" "v.surf.rst defaults")
    [ "$GRASS" = 1 ] && [ "$FILLNULLS_TIMEOUT" -gt 0 ] && tools+=("r.fillnulls bilinear")
    for tool in "${tools[@]}"; do
      alls=(); hids=(); lns=(); t=""
      for f in ${SETS[$set]}; do
        in="$d/$f.tif"; o="$d/${f}_out.tif"; rm -f "$o"
        first=$([ -z "$t" ] && echo 1 || echo 0)
        case "$tool" in
          terrapolis*) if [ "$first" = 1 ]; then t=$(timed "$BIN" -q reconstruct "$in" "$o" --overwrite)
                       else "$BIN" -q reconstruct "$in" "$o" --overwrite; fi ;;
          gdal*) if [ "$first" = 1 ]; then t=$(timed "$PY" /usr/bin/gdal_fillnodata.py -q -md 100 "$in" "$o")
                 else "$PY" /usr/bin/gdal_fillnodata.py -q -md 100 "$in" "$o"; fi ;;
          r.surf*) tt=$(grass_fill r.surf.idw "$in" "$o"); [ "$first" = 1 ] && t=$tt ;;
          v.surf*) tt=$(grass_fill v.surf.rst "$in" "$o"); [ "$first" = 1 ] && t=$tt ;;
          r.fill*) tt=$(grass_fill r.fillnulls "$in" "$o"); [ "$first" = 1 ] && t=$tt ;;
        esac
        read -r a hd ln < <($PY "$WORK/sk.py" score "$dem" "$in" "$o" "$d/lines.tif")
        alls+=("$a"); hids+=("$hd"); lns+=("$ln")
      done
      printf "$fmt" "$name" "$cells" "$set" "${SHARE[$set]}" "$tool" "$(median "${alls[@]}")" "$(median "${hids[@]}")" "$(median "${lns[@]}")" "$t"
    done
  done
  unset SETS SHARE
done
