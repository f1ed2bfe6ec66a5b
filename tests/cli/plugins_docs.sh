# The examples of docs/plugins.md, run as printed: the example plugin built by hand, the streams,
# the reserve and the land cover, with the figures the page quotes.
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
expect_line() {  # PATTERN FILE: the file has a line matching PATTERN (grep -E)
  grep -Eq "$1" "$2" || fail "expected '$1' in $(cat "$2")"
}

# Writing a plugin: the example compiles on its own with the public header only.
mkdir my_plugins
cc -shared -fPIC -fvisibility=hidden -Wall -Wextra -Werror -I "$SOURCE/src/plugin" "$SOURCE/plugins/example/example.c" \
  -o my_plugins/terrapolis_example.so -lm || fail "the example plugin does not compile"
TERRAPOLIS_PLUGIN_PATH=my_plugins "$TP" -v --progress none density "$DEM" ex --plugin 'example:2:{"value":0.9,"max_altitude_m":600}' \
  --weights 1,0,1.5,0 2>log
expect_line "^plugin example: my_plugins/terrapolis_example.so \(Constant density factor" log

# Streams as existing roads.
"$TP" -q hydro "$DEM" hydro
"$TP" --progress none density "$DEM" base --hydrometry hydro/hydrometry.tif 2>log
expect_line "density: 9941 buildable cells \(100.0 % of land\), mean density 0.321" log
"$TP" --progress none density "$DEM" near --hydrometry hydro/hydrometry.tif \
  --plugin 'distance:2:{"vector":"hydro/streams.geojson","density":{"points":[[0,1],[3000,0]]}}' 2>log
expect_line "density: 9941 buildable cells \(100.0 % of land\), mean density 0.360" log

# The reserve.
cat > protected.geojson <<'JSON'
{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"name": "reserve"},
 "geometry": {"type": "Polygon", "coordinates": [[[9.355, 42.675], [9.385, 42.675], [9.385, 42.705], [9.355, 42.705], [9.355, 42.675]]]}}]}
JSON
cat > reserve.json <<'JSON'
{"vector": "protected.geojson",
 "density": {"exclude_within_m": 0},
 "road": {"forbidden_within_m": 0, "points": [[0, 2], [1000, 0]], "structures": ["road", "bridge", "tunnel"]}}
JSON
# (The road figures depend on the road search's cost model: only their order is checked.)
"$TP" --progress none path "$DEM" --from 9.30,42.68 --to 9.42,42.70 free.geojson 2>log
expect_line "^galin: [0-9]+ m, cost [0-9.]+, " log
free=$(grep -o "^galin: [0-9]*" log | grep -o "[0-9]*$")
"$TP" --progress none path "$DEM" --from 9.30,42.68 --to 9.42,42.70 skirt.geojson --plugin distance:reserve.json 2>log
skirt=$(grep -o "^galin: [0-9]*" log | grep -o "[0-9]*$")
(( skirt > free )) || fail "the road round the reserve ($skirt m) is not longer than the free one ($free m)"
"$TP" --progress none density "$DEM" protected --hydrometry hydro/hydrometry.tif --plugin distance:reserve.json 2>log
expect_line "density: 9875 buildable cells \(99.3 % of land\), mean density 0.321" log

# The land cover (the raster of plugins_real_data.sh).
/usr/bin/python3 "$SOURCE/tests/cli/corsica_landcover.py" || fail "could not write the land-cover raster"
cat > landcover.json <<'JSON'
{"raster": "landcover.tif",
 "classes": [{"codes": [10], "name": "forest", "density": 0.2, "road_cost": 1.5},
             {"codes": [20], "name": "grassland", "density": 0.8, "road_cost": 0},
             {"codes": [80], "name": "wetland", "density": "excluded", "road_cost": "forbidden"}],
 "structures": ["road", "bridge"]}
JSON
"$TP" --progress none density "$DEM" cover --hydrometry hydro/hydrometry.tif --plugin landcover:2:landcover.json 2>log
expect_line "density: 9885 buildable cells \(99.4 % of land\), mean density 0.391" log
echo "docs/plugins.md examples: ok"
