#!/usr/bin/env bash
# Plugins benchmark: the `distance` plugin's exact distance transform (streams of the SRTM3 Alps
# tile as features) against GRASS r.grow.distance (geodesic metric) on the same streams; prints
# times and how far the two distance rasters agree.
# Usage: bench/plugins.sh [BUILD_DIR]   (run from the repository root)
set -euo pipefail
build=$(realpath "${1:-build}")
bin=$build/src/cli/terrapolis
dem=$(realpath ../shared/dems/N47E009.hgt)
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
cd "$out"
"$bin" -q hydro "$dem" hydro --outputs streams
echo "features: $(ogrinfo -so hydro/streams.geojson streams | grep -o 'Feature Count: [0-9]*')"

# Terrapolis: the factor is distance / 1e6 (weights 0 elsewhere), so density.tif * 1e6 = metres.
params='{"vector":"hydro/streams.geojson","density":{"points":[[0,0],[1000000,1]]}}'
for i in 1 2 3 4 5; do
  "$bin" -v --progress none density "$dem" tp$i --weights 0,0,0,0 --plugin "distance:$params" 2>&1 | grep -o 'density factor in [0-9.]* s'
done | sort -t' ' -k4 -n | awk '{t[NR]=$4} END {print "terrapolis distance plugin (rasterise + transform): median " t[3] " s of 5"}'
/usr/bin/time -f "terrapolis density with the plugin, whole process: %e s, peak %M kB" "$bin" -q density "$dem" tp --weights 0,0,0,0 --plugin "distance:$params"

if command -v grass >/dev/null; then
  gdal_translate -q -of GTiff "$dem" dem.tif
  grass -c dem.tif loc --exec bash -c "
    set -e
    r.in.gdal --quiet input=dem.tif output=dem
    g.region raster=dem
    v.in.ogr --quiet input=hydro/streams.geojson output=streams
    v.to.rast --quiet -d input=streams output=streams use=val value=1
    for i in 1 2 3 4 5; do
      /usr/bin/time -f '%e' -a -o grow.times r.grow.distance --quiet --overwrite input=streams distance=dist metric=geodesic -m
    done
    r.out.gdal --quiet -f input=dist output=grass.tif type=Float32
  " >grass.log 2>&1 || { echo "GRASS failed:"; tail -5 grass.log; exit 1; }
  echo "grass r.grow.distance -m metric=geodesic: median $(sort -n grow.times | sed -n 3p) s of 5 (process time in the GRASS session)"
  /usr/bin/python3 - <<'PY'
from osgeo import gdal
import numpy as np
tp = gdal.Open("tp/density.tif").ReadAsArray().astype(np.float64) * 1e6
gr = gdal.Open("grass.tif").ReadAsArray().astype(np.float64)
ok = np.isfinite(tp) & np.isfinite(gr)
d = np.abs(tp[ok] - gr[ok])
print("agreement over %d cells: mean |diff| %.1f m, 99th percentile %.1f m, max %.1f m; mean distance %.0f m"
      % (ok.sum(), d.mean(), np.percentile(d, 99), d.max(), gr[ok].mean()))
PY
fi
