#!/usr/bin/env bash
# Skeleton benchmark (Belhadj 2007 §5.2.2): `terrapolis skeleton` keeps the ridge and valley cells
# of a DEM; the DEM is rebuilt from them and from as many random cells (same share, fixed seed) by
# `terrapolis reconstruct` (thin-plate, dmmc), GDAL gdal_fillnodata.py and GRASS r.fillnulls, in
# the same run. Prints the share kept, the RMSE against the original (over all valid cells, as the
# thesis's "écart-type", and over the hidden cells) and whole-process wall times (median of REPEAT).
# Usage: bench/skeleton.sh [DEM...]  (default: N47E009.hgt, a GEBCO grid, Vermont and Big Tujunga)
# Env: TERRAPOLIS_BIN (default build/src/cli/terrapolis), REPEAT (default 3), GRASS_TIMEOUT (s, default 120).
# SPDX-License-Identifier: MIT
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=$(realpath "${TERRAPOLIS_BIN:-build/src/cli/terrapolis}")
REPEAT=${REPEAT:-3}
GRASS_TIMEOUT=${GRASS_TIMEOUT:-120}
PY=/usr/bin/python3
D=../shared/dems
if [ $# -gt 0 ]; then DEMS=("$@"); else
  DEMS=("$D/N47E009.hgt" "$D/gebco2022_15s_la_palma.asc" "$D/whiteboxR_DEM_vermont.tif" "$D/topotoolbox_bigtujunga.tif"); fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
command -v grass >/dev/null || echo "GRASS not found: the r.fillnulls rows are skipped" >&2

cat >"$WORK/sk.py" <<'EOF'
# random SKELETON DEM OUT: as many random valid cells as the skeleton kept; score TRUTH SPARSE OUT.
import sys
import numpy as np
from osgeo import gdal
gdal.UseExceptions()

def read(path):
    ds = gdal.Open(path); b = ds.GetRasterBand(1)
    a = b.ReadAsArray().astype(np.float64); nd = b.GetNoDataValue()
    if nd is not None and not np.isnan(nd): a[a == nd] = np.nan
    return ds, a

if sys.argv[1] == "random":
    _, kept = read(sys.argv[2]); ds, z = read(sys.argv[3])
    idx = np.flatnonzero(np.isfinite(z))
    pick = np.random.default_rng(20070101).choice(idx, int(np.isfinite(kept).sum()), replace=False)
    out = np.full(z.size, -9999.0); out[pick] = z.flat[pick]
    o = gdal.GetDriverByName("GTiff").Create(sys.argv[4], ds.RasterXSize, ds.RasterYSize, 1, gdal.GDT_Float32)
    o.SetGeoTransform(ds.GetGeoTransform()); o.SetProjection(ds.GetProjection())
    b = o.GetRasterBand(1); b.SetNoDataValue(-9999); b.WriteArray(out.reshape(z.shape).astype(np.float32)); o = None
else:
    _, t = read(sys.argv[2]); _, s = read(sys.argv[3])
    try:
        _, o = read(sys.argv[4])
    except Exception:
        print("nan nan"); sys.exit()
    valid = np.isfinite(t); hidden = valid & np.isnan(s)
    e_all = o[valid] - t[valid]; e_hid = o[hidden] - t[hidden]
    if np.isnan(e_all).any():  # cells a tool left empty: not scored
        print("unfilled unfilled"); sys.exit()
    print(f"{np.sqrt(np.mean(e_all ** 2)):.2f} {np.sqrt(np.mean(e_hid ** 2)):.2f}")
EOF

timed() {  # median wall time (s) of REPEAT runs of "$@"
  local times=()
  for _ in $(seq "$REPEAT"); do
    /usr/bin/time -f "%e" -o "$WORK/time" "$@" >/dev/null 2>"$WORK/stderr" || { tail -2 "$WORK/stderr" >&2; echo nan; return; }
    times+=("$(cat "$WORK/time")")
  done
  printf '%s\n' "${times[@]}" | sort -g | sed -n "$(( (REPEAT + 1) / 2 ))p"
}

grass_fill() {  # grass_fill IN OUT: r.fillnulls bilinear, capped; prints its own time
  cat >"$WORK/grass.sh" <<EOF
set -e
r.in.gdal -o input="$1" output=a --quiet --overwrite
g.region raster=a
/usr/bin/time -f "%e" -o "$WORK/grass_time" r.fillnulls input=a output=b method=bilinear --quiet --overwrite
r.out.gdal -c -f input=b output="$2" format=GTiff type=Float32 nodata=-9999 --quiet --overwrite
EOF
  rm -f "$2"
  if timeout "$GRASS_TIMEOUT" grass --tmp-location "$1" --exec bash "$WORK/grass.sh" >/dev/null 2>&1; then cat "$WORK/grass_time"
  else echo ">$GRASS_TIMEOUT"; fi
}

printf '%-26s %7s %6s %-9s %-26s %9s %11s %8s\n' dem cells kept% samples tool rmse_all rmse_hidden time_s
for dem in "${DEMS[@]}"; do
  name=$(basename "$dem"); name=${name%.*}
  d="$WORK/$name"
  t_skel=$(timed "$BIN" -q skeleton "$dem" "$d" --overwrite)
  read -r share cells < <($PY -c "import json,sys; r=json.load(open(sys.argv[1])); print('%.1f' % (100*r['kept_share']), r['valid_cells'])" "$d/skeleton.json")
  printf '%-26s %7s %6s %-9s %-26s %9s %11s %8s\n' "$name" "$cells" "$share" - "terrapolis skeleton" - - "$t_skel"
  $PY "$WORK/sk.py" random "$d/skeleton.tif" "$dem" "$d/random.tif"
  for samples in skeleton random; do
    in="$d/$samples.tif"
    row() { read -r a h < <($PY "$WORK/sk.py" score "$dem" "$in" "$2")
            printf '%-26s %7s %6s %-9s %-26s %9s %11s %8s\n' "$name" "$cells" "$share" "$samples" "$1" "$a" "$h" "$3"; }
    for m in thin-plate dmmc; do
      o="$d/${samples}_$m.tif"
      row "terrapolis reconstruct $m" "$o" "$(timed "$BIN" -q reconstruct "$in" "$o" --method $m --overwrite)"
    done
    o="$d/${samples}_gdal.tif"
    row "gdal_fillnodata -md 100" "$o" "$(timed "$PY" /usr/bin/gdal_fillnodata.py -q -md 100 "$in" "$o")"
    if command -v grass >/dev/null; then
      o="$d/${samples}_grass.tif"
      t=$(grass_fill "$in" "$o")
      row "r.fillnulls bilinear" "$o" "$t"
    fi
  done
done
