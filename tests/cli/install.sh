# `cmake --install` into a fresh prefix: the installed terrapolis finds its PNG module and its
# plugins in the installed tree (lib/terrapolis), not in the build tree, and writes a whole run.
source "$(dirname "$0")/lib.sh" "$@"
BUILD=$(cd "$(dirname "$TP")/../.." && pwd)
PREFIX=$WORK/prefix
cmake --install "$BUILD" --prefix "$PREFIX" > /dev/null || fail "cmake --install failed"
for f in bin/terrapolis lib/terrapolis/terrapolis_png.so lib/terrapolis/plugins/terrapolis_distance.so \
         lib/terrapolis/plugins/terrapolis_landcover.so share/terrapolis/qgis/terrapolis_provider/provider.py; do
  [[ -e $PREFIX/$f ]] || fail "not installed: $f"
done
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
cat > "$WORK/reserve.geojson" <<'JSON'
{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
 "geometry": {"type": "Polygon", "coordinates": [[[9.355, 42.675], [9.385, 42.675], [9.385, 42.705], [9.355, 42.705], [9.355, 42.675]]]}}]}
JSON
# The dynamic loader says which files it opened (glibc's LD_DEBUG).
LD_DEBUG=files "$PREFIX/bin/terrapolis" -q run --set dem="$DEM" --set sites.quota_scale=0.01 --output "$WORK/run" \
  --set 'plugins=[{"id": "distance", "params": {"vector": "'"$WORK"'/reserve.geojson", "density": {"exclude_within_m": 0}, "road": {"forbidden_within_m": 0}}}]' \
  2> "$WORK/loader.log" || fail "the installed terrapolis failed: $(grep -v '^ *[0-9]*:' "$WORK/loader.log")"
[[ -s $WORK/run/preview.png && -s $WORK/run/roads.geojson ]] || fail "the installed terrapolis wrote no preview or roads"
grep -Eq "file=$PREFIX/(bin/\.\./)?lib/terrapolis/terrapolis_png.so" "$WORK/loader.log" || fail "the PNG module was not the installed one"
grep -Eq "file=$PREFIX/(bin/\.\./)?lib/terrapolis/plugins/terrapolis_distance.so" "$WORK/loader.log" \
  || fail "the distance plugin was not the installed one: $(grep -o 'file=[^ ]*terrapolis_distance.so' "$WORK/loader.log")"
echo "install: ok"
