# `terrapolis access` and the run's access stage on the bundled Cap Corse DEM (docs/access.md):
# travel-time rasters in the DEM's CRS, the sea unreachable, figures that add up, bad inputs refused.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
dem=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
"$TP" -q run -o run --set dem="$dem" --set outputs.preview=false --set sites.population=400000

# The run's stage: rasters per level, figures in run.json that grow with the threshold.
for f in access_minutes.tif access_minutes_10000.tif access_nearest.tif access_minutes.qml; do [[ -f run/$f ]] || fail "run: no $f"; done
/usr/bin/python3 - <<'PY' || fail "run.json access figures"
import json
a = json.load(open("run/run.json"))["summary"]["access"]
assert a["people"] == 400000, a
for level, v in a["levels"].items():
    w = list(v["share_within"].values())
    assert w == sorted(w) and 0 < w[0] and w[-1] <= 1, (level, w)
    assert 0 < v["mean_minutes"] <= v["p90_minutes"], v
assert a["levels"]["all"]["share_within"]["60_min"] >= a["levels"]["10000"]["share_within"]["60_min"], a
PY
/usr/bin/python3 - <<'PY' || fail "access rasters"
from osgeo import gdal
import math
m = gdal.Open("run/access_minutes.tif")
d = gdal.Open("run/elevation.tif")
assert m.GetProjection() == d.GetProjection() and m.GetGeoTransform() == d.GetGeoTransform()
t = m.GetRasterBand(1).ReadAsArray()
z = d.GetRasterBand(1).ReadAsArray()
assert all(math.isnan(t[i, j]) for i in range(z.shape[0]) for j in range(z.shape[1]) if z[i, j] < -50), "the sea has a travel time"
assert (t == 0).sum() >= 30, "every settlement's cell is 0 minutes away"
PY
# The catchments: one per settlement reached, with the nearest raster's cells; their people add
# up to the region's (less those who reach none) and their areas to the reached land.
/usr/bin/python3 - <<'PY' || fail "access_catchments.geojson"
import json
import numpy as np
from osgeo import gdal
m = json.load(open("run/run.json"))
a = m["summary"]["access"]
features = json.load(open("run/access_catchments.geojson"))["features"]
per_id = {f["properties"]["id"]: f["properties"] for f in features}
nearest = gdal.Open("run/access_nearest.tif").ReadAsArray()
assert sorted(per_id) == sorted(int(v) for v in np.unique(nearest) if v >= 0), "catchment ids are not the nearest raster's"
people = sum(p["people"] for p in per_id.values())
expected = a["people"] - a["levels"]["all"]["unreachable_people"]
assert abs(people - expected) <= 0.001 * expected, (people, expected)
cities = {f["properties"]["id"]: f["properties"]["population"] for f in json.load(open("run/cities.geojson"))["features"]}
assert all(p["population"] == cities[i] for i, p in per_id.items()), "a catchment's population is not its city's"
assert all(p["area_km2"] > 0 and p["mean_minutes"] is None or p["mean_minutes"] >= 0 for p in per_id.values())
PY
grep -q '"access_minutes.tif"' run/.terrapolis-outputs.json || fail "not in the manifest"
grep -q 'access_minutes.tif' run/project.qgs || fail "not in the QGIS project"

# The command on the run's layers, with the roads and without: the roads bring people closer.
"$TP" -q access "$dem" with --to run/cities.geojson --roads run/roads.geojson
"$TP" -q access "$dem" without --to run/cities.geojson
/usr/bin/python3 - <<'PY' || fail "access.json"
import json
w = json.load(open("with/access.json")); o = json.load(open("without/access.json"))
assert w["unit"] == "land_km2" and abs(w["total"] - o["total"]) < 1e-6, (w["total"], o["total"])
a, b = w["levels"]["all"], o["levels"]["all"]
assert a["within"]["60_min"] > b["within"]["60_min"] and a["mean_minutes"] < b["mean_minutes"], (a, b)
assert w["settlements"] >= 30 and w["outside_the_dem"] == 0, w
PY

# --water-mask (water.water_mask, as in a run): masked land is water, walked on by no one.
/usr/bin/python3 - "$dem" <<'PY'
import sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1])
band = np.zeros((src.RasterYSize, src.RasterXSize), np.uint8)
band[:, 150:153] = 1
out = gdal.GetDriverByName("GTiff").Create("band.tif", src.RasterXSize, src.RasterYSize, 1, gdal.GDT_Byte)
out.SetGeoTransform(src.GetGeoTransform())
out.SetProjection("EPSG:4326")
out.GetRasterBand(1).WriteArray(band)
PY
"$TP" -q access "$dem" wet --to run/cities.geojson --water-mask band.tif
/usr/bin/python3 - <<'PY' || fail "--water-mask"
import numpy as np
from osgeo import gdal
dry = gdal.Open("without/access_minutes.tif").ReadAsArray(); wet = gdal.Open("wet/access_minutes.tif").ReadAsArray()
assert np.isfinite(dry[:, 150:153]).sum() > 50 and not np.isfinite(wet[:, 150:153]).any(), "masked cells still walked on"
PY

# A people raster on the DEM's grid: the figures are people.
gdal_calc.py --quiet -A run/density.tif --outfile people.tif --type Float32 --calc "(A>0)*100" --NoDataValue -1
"$TP" -q access "$dem" counted --to run/cities.geojson --people people.tif
grep -q '"unit": "people"' counted/access.json || fail "--people: not counted in people"
grep -q '"people":' counted/access_catchments.geojson || fail "--people: catchments not counted in people"
grep -q '"land_km2":' with/access_catchments.geojson || fail "catchments not counted in land km2"

# What a scenario changes: more links kept (network.k 1.3) bring some cells closer.
cp -r run denser
"$TP" -q run -o denser --from network --set network.k=1.3 --set outputs.preview=false --set dem="$dem" --set sites.population=400000
"$TP" compare run denser --changes changes > cmp.txt
grep -Eq "^access_minutes_change.tif: [1-9][0-9]* cells over a minute closer in B" cmp.txt || fail "compare --changes: $(tail -3 cmp.txt)"
/usr/bin/python3 - <<'PY' || fail "access_minutes_change.tif"
from osgeo import gdal
import numpy as np
a = gdal.Open("run/access_minutes.tif").ReadAsArray(); b = gdal.Open("denser/access_minutes.tif").ReadAsArray()
c = gdal.Open("changes/access_minutes_change.tif").ReadAsArray()
ok = ~np.isnan(a) & ~np.isnan(b)
assert np.allclose(c[ok], (b - a)[ok]) and np.isnan(c[~ok]).all() and (c[ok] < -1).any()
PY
expect_refused nochanges "--changes: compares two runs" "$TP" compare run denser run --changes nochanges

# Bad inputs: exit 2, one line, nothing written.
expect_refused bad "run/roads.geojson: --to: the settlements must be points" "$TP" access "$dem" bad --to run/roads.geojson
expect_refused bad "no/such.geojson" "$TP" access "$dem" bad --to no/such.geojson
gdal_translate -q -outsize 50% 50% people.tif small.tif
expect_refused bad "small.tif: --people: is 87x87 cells, the DEM 175x175" "$TP" access "$dem" bad --to run/cities.geojson --people small.tif
expect_refused bad "--walk-factor" "$TP" access "$dem" bad --to run/cities.geojson --walk-factor 0
expect_refused bad2 "/access/thresholds_minutes: a threshold is given twice" "$TP" run -o bad2 --set 'access.thresholds_minutes=[15,15]'
no_leftovers "$WORK"
echo "access: ok"
