#!/usr/bin/env bash
# Terrain benchmark: rebuild a DEM from 3.3% of its cells, and fill punched voids of 1-10 km2, with
# terrapolis (thin-plate, harmonic, DMMC), GDAL gdal_fillnodata.py and GRASS r.fillnulls (bilinear,
# bicubic, RST) on the same inputs. Prints RMSE and maximum error on the hidden cells, wall time and
# peak memory (median of REPEAT runs).
# Usage: bench/terrain.sh [DEM...]   (default: N47E009.hgt and topotoolbox_bigtujunga.tif)
# Env: TERRAPOLIS_BIN (default build/src/cli/terrapolis), REPEAT (default 3), SKIP_RST=1 to skip RST, GRASS_ONLY=1 to run GRASS alone,
# GRASS_TIMEOUT (s, default 300; GRASS_SPARSE_TIMEOUT for the sparse case) caps each r.fillnulls run (GRASS runs once: its time is r.fillnulls alone).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=$(realpath "${TERRAPOLIS_BIN:-build/src/cli/terrapolis}")
DEMS_DIR=../shared/dems
REPEAT=${REPEAT:-3}
GRASS_TIMEOUT=${GRASS_TIMEOUT:-300}
GRASS_SPARSE_TIMEOUT=${GRASS_SPARSE_TIMEOUT:-$GRASS_TIMEOUT}
PY=/usr/bin/python3
if [ $# -gt 0 ]; then DEMS=("$@"); else DEMS=("$DEMS_DIR/N47E009.hgt" "$DEMS_DIR/topotoolbox_bigtujunga.tif"); fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
command -v grass >/dev/null || { echo "GRASS not found: the GRASS rows are skipped" >&2; }

cat >"$WORK/tb.py" <<'EOF'
# Makes the benchmark inputs and scores the outputs.
import sys, math
import numpy as np
from osgeo import gdal
gdal.UseExceptions()

def read(path):
    ds = gdal.Open(path)
    b = ds.GetRasterBand(1)
    a = b.ReadAsArray().astype(np.float64)
    nd = b.GetNoDataValue()
    if nd is not None:
        a[a == nd] = np.nan
    return ds, a

def write(path, like, a):
    drv = gdal.GetDriverByName("GTiff")
    ds = drv.Create(path, like.RasterXSize, like.RasterYSize, 1, gdal.GDT_Float32, ["TILED=YES", "COMPRESS=DEFLATE"])
    ds.SetGeoTransform(like.GetGeoTransform())
    ds.SetProjection(like.GetProjection())
    b = ds.GetRasterBand(1)
    b.SetNoDataValue(-9999)
    out = np.where(np.isnan(a), -9999, a).astype(np.float32)
    b.WriteArray(out)
    ds = None

def prepare(dem, out):
    ds, z = read(dem)
    rng = np.random.default_rng(20070101)
    write(out + "/truth.tif", ds, z)
    # Sparse: a random 3.3% of the cells (Belhadj §5.2.1).
    keep = rng.random(z.shape) < 0.033
    write(out + "/sparse.tif", ds, np.where(keep, z, np.nan))
    # Voids: blobs of 1 to 10 km2 with a wavy outline, away from the border and from each other.
    gt = ds.GetGeoTransform()
    if ds.GetSpatialRef().IsGeographic():
        lat = gt[3] + gt[5] * z.shape[0] / 2
        cw = abs(gt[1]) * 111320 * math.cos(math.radians(lat)); ch = abs(gt[5]) * 110574
    else:
        cw, ch = abs(gt[1]), abs(gt[5])
    rows, cols = z.shape
    total_km2 = rows * cols * cw * ch / 1e6
    want = max(4, int(total_km2 / 120))
    mask = np.zeros(z.shape, bool)
    yy, xx = np.mgrid[0:rows, 0:cols]
    made = 0; tries = 0
    while made < want and tries < 2000:
        tries += 1
        area = rng.uniform(1e6, 10e6)
        r = math.sqrt(area / math.pi)
        rx, ry = r / cw, r / ch
        cx = rng.uniform(rx * 1.6 + 3, cols - rx * 1.6 - 3); cy = rng.uniform(ry * 1.6 + 3, rows - ry * 1.6 - 3)
        dx = (xx - cx) / rx; dy = (yy - cy) / ry
        rho = np.hypot(dx, dy); th = np.arctan2(dy, dx)
        edge = np.ones_like(rho)
        for k in (2, 3, 5):
            edge += rng.uniform(-0.18, 0.18) * np.cos(k * th + rng.uniform(0, 6.3))
        blob = rho < edge
        grown = np.hypot((xx - cx) / (rx * 1.5), (yy - cy) / (ry * 1.5)) < 1.5
        if (mask & grown).any() or np.isnan(z[blob]).any():
            continue
        mask |= blob
        made += 1
    write(out + "/voids.tif", ds, np.where(mask, np.nan, z))
    print(f"{made} voids, {mask.sum()} cells, {mask.sum() * cw * ch / 1e6:.1f} km2; sparse keeps {keep.sum()} cells")

def score(truth, inp, out):
    _, t = read(truth); _, i = read(inp)
    try:
        _, o = read(out)
    except Exception:
        print("nan nan 0"); return
    hidden = np.isnan(i) & ~np.isnan(t)
    err = o[hidden] - t[hidden]
    filled = ~np.isnan(err)
    e = err[filled]
    # Cells a tool left empty count as failures: report the share filled.
    print(f"{math.sqrt(np.mean(e * e)):.3f} {np.max(np.abs(e)):.1f} {filled.mean():.4f}")

if sys.argv[1] == "prepare":
    prepare(sys.argv[2], sys.argv[3])
else:
    score(sys.argv[2], sys.argv[3], sys.argv[4])
EOF

# Runs "$@" REPEAT times; prints the median wall time (s) and peak memory (MB).
timed() {
  local times=() mems=()
  for _ in $(seq "$REPEAT"); do
    /usr/bin/time -f "%e %M" -o "$WORK/time" "$@" >/dev/null 2>"$WORK/stderr" || { echo "FAILED: $*" >&2; tail -3 "$WORK/stderr" >&2; echo "nan nan"; return; }
    read -r t m <"$WORK/time"
    times+=("$t"); mems+=("$m")
  done
  local mt mm
  mt=$(printf '%s\n' "${times[@]}" | sort -g | sed -n "$(( (REPEAT + 1) / 2 ))p")
  mm=$(printf '%s\n' "${mems[@]}" | sort -g | sed -n "$(( (REPEAT + 1) / 2 ))p")
  echo "$mt $((mm / 1024))"
}

grass_fill() {  # grass_fill METHOD IN OUT TIMEOUT
  cat >"$WORK/grass.sh" <<EOF
set -e
r.in.gdal -o input="$2" output=a --quiet --overwrite
g.region raster=a
/usr/bin/time -f "%e %M" -o "$WORK/grass_time" r.fillnulls input=a output=b method=$1 --quiet --overwrite
r.out.gdal -c -f input=b output="$3" format=GTiff type=Float32 nodata=-9999 --quiet --overwrite
EOF
  rm -f "$3"
  # r.fillnulls can take very long on the sparse case: cap it, and report the cap as its time.
  if ! timeout "$4" grass --tmp-location "$2" --exec bash "$WORK/grass.sh" >/dev/null 2>"$WORK/grass_err"; then
    echo "r.fillnulls $1 on $2 failed or exceeded $4 s" >&2
    echo ">$4 0" >"$WORK/grass_time"
  fi
}

printf '%-28s %-7s %-26s %9s %9s %7s %8s %7s\n' dem case tool rmse_m max_m filled time_s mem_MB
for dem in "${DEMS[@]}"; do
  name=$(basename "$dem"); name=${name%.*}
  d="$WORK/$name"; mkdir -p "$d"
  echo "# $name: $($PY "$WORK/tb.py" prepare "$dem" "$d")"
  for case in sparse voids; do
    in="$d/$case.tif"
    row() {  # row TOOL OUT TIME_MEM
      read -r rmse mx filled < <($PY "$WORK/tb.py" score "$d/truth.tif" "$in" "$2")
      read -r t m <<<"$3"
      printf '%-28s %-7s %-26s %9s %9s %7s %8s %7s\n' "$name" "$case" "$1" "$rmse" "$mx" "$filled" "$t" "$m"
    }
    if [ "$case" = sparse ]; then cmd=(reconstruct "$in"); else cmd=(fill "$in"); fi
    if [ "${GRASS_ONLY:-0}" != 1 ]; then
    for m in thin-plate harmonic dmmc; do
      o="$d/${case}_tp_$m.tif"
      row "terrapolis $m" "$o" "$(timed "$BIN" --quiet "${cmd[@]}" "$o" --method "$m" --overwrite)"
    done
    o="$d/${case}_tp_dmmc_nolp.tif"
    row "terrapolis dmmc no low-pass" "$o" "$(timed "$BIN" --quiet "${cmd[@]}" "$o" --method dmmc --no-low-pass --overwrite)"
    md=100; [ "$case" = voids ] && md=250
    o="$d/${case}_gdal.tif"
    row "gdal_fillnodata -md $md" "$o" "$(timed /usr/bin/python3 /usr/bin/gdal_fillnodata.py -q -md $md "$in" "$o")"
    fi
    if command -v grass >/dev/null; then
      for gm in bilinear bicubic rst; do
        [ "$gm" = rst ] && [ "${SKIP_RST:-0}" = 1 ] && continue
        o="$d/${case}_grass_$gm.tif"
        limit=$GRASS_TIMEOUT; [ "$case" = sparse ] && limit=$GRASS_SPARSE_TIMEOUT
        grass_fill "$gm" "$in" "$o" "$limit"
        read -r t m <"$WORK/grass_time" || true
        row "grass r.fillnulls $gm" "$o" "$t $((m / 1024))"
        rm -f "$WORK/grass_time"
      done
    fi
  done
done
