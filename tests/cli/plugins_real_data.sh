# The landcover and distance plugins on the Corsica sample: streams from `terrapolis hydro` as
# "existing roads", a land-cover raster and a protected area made here; cities avoid, roads skirt.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
PY=/usr/bin/python3
$PY -c 'from osgeo import gdal' 2>/dev/null || fail "python3-gdal is needed to build the test layers"

"$TP" -q hydro "$DEM" hydro
"$TP" -q density "$DEM" base --hydrometry hydro/hydrometry.tif

# ---- distance to streams: with a huge weight the density is the curve of the distance --------
"$TP" -q density "$DEM" near --hydrometry hydro/hydrometry.tif \
  --plugin 'distance:1000:{"vector":"hydro/streams.geojson","density":{"points":[[0,1],[3000,0]]}}'
$PY - <<'PY' || fail "distance factor"
from osgeo import gdal, ogr
import numpy as np
d = gdal.Open("near/density.tif"); dens = d.ReadAsArray(); ok = gdal.Open("near/buildable.tif").ReadAsArray() == 1
mem = gdal.GetDriverByName("MEM").Create("", d.RasterXSize, d.RasterYSize, 1, gdal.GDT_Byte)
mem.SetGeoTransform(d.GetGeoTransform()); mem.SetProjection(d.GetProjection())
src = ogr.Open("hydro/streams.geojson")
gdal.RasterizeLayer(mem, [1], src.GetLayer(0), burn_values=[1], options=["ALL_TOUCHED=TRUE"])
on = (mem.ReadAsArray() == 1) & ok
assert on.sum() > 50, on.sum()
# On a stream the distance is 0, the factor 1: (3.5 d0 + 1000) / 1003.5 >= 0.996.
assert dens[on].min() > 0.996, dens[on].min()
# Far from every stream (> 3 km: at least 3 cells of 15" away in both axes) the factor is 0.
assert dens[ok & ~on].min() < 0.01
PY
# Same bytes whatever the thread count.
"$TP" -q --threads 1 density "$DEM" near1 --hydrometry hydro/hydrometry.tif \
  --plugin 'distance:1000:{"vector":"hydro/streams.geojson","density":{"points":[[0,1],[3000,0]]}}'
for f in density buildable; do cmp -s near/$f.tif near1/$f.tif || fail "$f.tif differs with 1 thread"; done
# Weight 0 changes nothing.
"$TP" -q density "$DEM" zero --hydrometry hydro/hydrometry.tif --plugin 'distance:0:{"vector":"hydro/streams.geojson","density":{"points":[[0,1]]}}'
$PY -c "
from osgeo import gdal; import numpy as np
a=gdal.Open('base/density.tif').ReadAsArray(); b=gdal.Open('zero/density.tif').ReadAsArray()
assert np.array_equal(a, b, equal_nan=True)" || fail "weight 0 changed the density"

# ---- a protected area across the road of path_corsica.sh --------------------------------------
"$TP" -q path "$DEM" --from 9.30,42.68 --to 9.42,42.70 free.geojson
cat > protected.geojson <<'JSON'
{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"name": "reserve"},
 "geometry": {"type": "Polygon", "coordinates": [[[9.355, 42.675], [9.385, 42.675], [9.385, 42.705], [9.355, 42.705], [9.355, 42.675]]]}}]}
JSON
PROTECT='{"vector":"protected.geojson","density":{"exclude_within_m":0},"road":{"forbidden_within_m":0,"structures":["road","bridge","tunnel"]}}'
"$TP" -q path "$DEM" --from 9.30,42.68 --to 9.42,42.70 skirt.geojson --plugin "distance:$PROTECT"
"$TP" -q path "$DEM" --from 9.30,42.68 --to 9.42,42.70 bezier_free.geojson --router bezier
"$TP" -q path "$DEM" --from 9.30,42.68 --to 9.42,42.70 bezier_skirt.geojson --router bezier --plugin "distance:$PROTECT"
"$TP" -q density "$DEM" protected --hydrometry hydro/hydrometry.tif --plugin "distance:$PROTECT"
$PY - <<'PY' || fail "protected area"
from osgeo import gdal, ogr
def line(path):  # the first geometry of a file (the dataset must outlive the feature)
    ds = ogr.Open(path)
    feature = ds.GetLayer(0).GetNextFeature()
    return feature.GetGeometryRef().Clone()
reserve = line("protected.geojson")
assert line("free.geojson").Intersects(reserve), "the free road should cross the reserve (test set-up)"
assert not line("skirt.geojson").Intersects(reserve), "the road enters the protected area"
assert line("bezier_free.geojson").Intersects(reserve), "the free Bezier road should cross the reserve (test set-up)"
assert not line("bezier_skirt.geojson").Intersects(reserve), "the Bezier road enters the protected area"
b = gdal.Open("protected/buildable.tif"); gt = b.GetGeoTransform(); a = b.ReadAsArray()
col, row = int((9.37 - gt[0]) / gt[1]), int((42.69 - gt[3]) / gt[5])
assert a[row, col] == 0, "a cell inside the reserve is buildable"
base = gdal.Open("base/buildable.tif").ReadAsArray()
assert base[row, col] == 1 and (a == 1).sum() < (base == 1).sum()
# Without a curve the plugin only excludes: elsewhere the density hardly moves (the characteristics
# are divided by their maximum over habitable land, which the reserve may have held).
dens, base_dens = gdal.Open("protected/density.tif").ReadAsArray(), gdal.Open("base/density.tif").ReadAsArray()
both = (a == 1) & (base == 1)
assert abs(dens[both] - base_dens[both]).max() < 0.05, abs(dens[both] - base_dens[both]).max()
PY

# `roads` takes the same term: a one-link network across the reserve is laid round it.
mkdir net
cat > net/network.geojson <<'JSON'
{"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"from": 0, "to": 1, "kind": "roots", "kept": 1, "length_m": 10000, "detour_ratio": null},
 "geometry": {"type": "LineString", "coordinates": [[9.30, 42.68], [9.42, 42.70]]}}]}
JSON
cat > net/cities.geojson <<'JSON'
{"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"id": 0, "radius_m": 900, "class": 0, "population": 40000, "density": 300, "parent": null, "depth": 0}, "geometry": {"type": "Point", "coordinates": [9.30, 42.68]}},
{"type": "Feature", "properties": {"id": 1, "radius_m": 700, "class": 1, "population": 20000, "density": 200, "parent": 0, "depth": 1}, "geometry": {"type": "Point", "coordinates": [9.42, 42.70]}}]}
JSON
"$TP" -q roads "$DEM" net/network.geojson roads_out --plugin "distance:$PROTECT"
$PY - <<'PY' || fail "roads with a protected area"
from osgeo import ogr
ds, rs = ogr.Open("protected.geojson"), ogr.Open("roads_out/roads.geojson")
feature = ds.GetLayer(0).GetNextFeature()  # kept alive while its geometry is used
reserve = feature.GetGeometryRef().Clone()
count = 0
for f in rs.GetLayer(0):
    count += 1
    assert not f.GetGeometryRef().Intersects(reserve), "a road of `roads` enters the reserve"
assert count >= 1
PY

# ---- land cover: a raster in another CRS, classes mapped to attractiveness and road cost -------
/usr/bin/python3 "$SOURCE/tests/cli/corsica_landcover.py" || fail "could not write the land-cover raster"
cat > landcover.json <<'JSON'
{"raster": "landcover.tif",
 "classes": [{"codes": [10], "name": "forest", "density": 0.2, "road_cost": 1.5},
             {"codes": [20], "name": "grassland", "density": 0.8, "road_cost": 0},
             {"codes": [80], "name": "wetland", "density": "excluded", "road_cost": "forbidden"}],
 "structures": ["road", "bridge", "tunnel"]}
JSON
"$TP" -q density "$DEM" cover --hydrometry hydro/hydrometry.tif --plugin landcover:1000:landcover.json
"$TP" -q path "$DEM" --from 9.30,42.68 --to 9.42,42.70 cover.geojson --plugin landcover:landcover.json
$PY - <<'PY' || fail "landcover"
from osgeo import gdal, ogr
import numpy as np
d = gdal.Open("cover/density.tif"); dens = d.ReadAsArray(); gt = d.GetGeoTransform()
ok = gdal.Open("cover/buildable.tif").ReadAsArray()
lon = gt[0] + (np.arange(d.RasterXSize) + 0.5) * gt[1]
lat = gt[3] + (np.arange(d.RasterYSize) + 0.5) * gt[5]
LON, LAT = np.meshgrid(lon, lat)
west, east = (ok == 1) & (LON < 9.19), (ok == 1) & (LON > 9.21)
assert west.sum() > 100 and east.sum() > 100
assert abs(dens[west].mean() - 0.2) < 0.01, dens[west].mean()   # (3.5 d0 + 1000 x 0.2) / 1003.5
assert abs(dens[east].mean() - 0.8) < 0.01, dens[east].mean()
inside = (LON > 9.36) & (LON < 9.38) & (LAT > 42.68) & (LAT < 42.70)
assert inside.sum() > 0 and (ok[inside] == 0).all(), "wetland cells are buildable"
def line(path):
    ds = ogr.Open(path)
    feature = ds.GetLayer(0).GetNextFeature()
    return feature.GetGeometryRef().Clone()
assert not line("cover.geojson").Intersects(line("protected.geojson")), "the road crosses the wetland"
PY

# ---- errors: exit 2, one line naming the plugin and the file, nothing written ----------------
expect_fail 2 "plugin landcover .*terrapolis_landcover.so.*nowhere.tif: cannot open the raster" \
  "$TP" -q density "$DEM" bad1 --hydrometry hydro/hydrometry.tif --plugin 'landcover:{"raster":"nowhere.tif","classes":[{"codes":[1]}]}'
expect_fail 2 "params: .*classes" "$TP" -q density "$DEM" bad2 --hydrometry hydro/hydrometry.tif --plugin 'landcover:{"raster":"landcover.tif"}'
expect_fail 2 "params has no \"road\" object" "$TP" -q path "$DEM" --from 9.30,42.68 --to 9.42,42.70 bad3.geojson \
  --plugin 'distance:{"vector":"protected.geojson"}'
expect_fail 2 "plugin nonexistent: no terrapolis_nonexistent.so" "$TP" -q density "$DEM" bad4 --hydrometry hydro/hydrometry.tif --plugin nonexistent
[[ ! -e bad1 && ! -e bad2 && ! -e bad3.geojson && ! -e bad4 ]] || fail "a failed run left an output"
no_leftovers "$WORK"
echo "plugins on real data: ok"
