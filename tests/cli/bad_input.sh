# Every kind of bad input gets one line naming the file and the problem, exit code 2, no output left.
source "$(dirname "$0")/lib.sh" "$@"
good=$SAMPLES/spDataLarge_dem_mongon.tif

expect_fail 2 "nope.tif: no such file" "$TP" info "$WORK/nope.tif"

echo "hello, I am not a raster" > "$WORK/text.tif"
expect_fail 2 "text.tif: not a raster" "$TP" info "$WORK/text.tif"

head -c 20000 "$SAMPLES/whiteboxR_DEM_vermont.tif" > "$WORK/truncated.tif"
expect_fail 2 "truncated.tif: (corrupt or truncated|not a raster)" "$TP" convert "$WORK/truncated.tif" "$WORK/t_out.tif"
[[ ! -e $WORK/t_out.tif ]] || fail "output left after a corrupt input"

# An ESRI ASCII grid without its .prj has no CRS.
cp "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" "$WORK/nocrs.asc"
expect_fail 2 "nocrs.asc: has no CRS.*--assume-crs" "$TP" info "$WORK/nocrs.asc"
grep -q "EPSG:4326" <("$TP" info "$WORK/nocrs.asc" --assume-crs EPSG:4326) || fail "--assume-crs not applied"

# A three-band colour image is not a DEM unless a band is chosen.
gdal_translate -q -b 1 -b 1 -b 1 -ot Byte -scale -co PHOTOMETRIC=RGB "$good" "$WORK/rgb.tif"
expect_fail 2 "rgb.tif: has 3 bands.*--band" "$TP" info "$WORK/rgb.tif"
"$TP" info "$WORK/rgb.tif" --band 2 >/dev/null || fail "--band 2 refused"
expect_fail 2 "band 4 does not exist" "$TP" info "$WORK/rgb.tif" --band 4

printf 'ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 0.01\nNODATA_value -9999\n-9999 -9999 -9999\n-9999 -9999 -9999\n-9999 -9999 -9999\n' > "$WORK/empty.asc"
expect_fail 2 "empty.asc: holds no data" "$TP" info "$WORK/empty.asc" --assume-crs EPSG:4326

printf 'ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 0.01\n5\n' > "$WORK/one.asc"
expect_fail 2 "one.asc: is 1x1 cells" "$TP" info "$WORK/one.asc" --assume-crs EPSG:4326

# A header that claims 10^12 cells: refused before allocating, naming the size.
cat > "$WORK/huge.vrt" <<VRT
<VRTDataset rasterXSize="1000000" rasterYSize="1000000">
  <SRS>EPSG:4326</SRS>
  <GeoTransform>0, 0.0001, 0, 50, 0, -0.0001</GeoTransform>
  <VRTRasterBand dataType="Float32" band="1"/>
</VRTDataset>
VRT
expect_fail 2 "huge.vrt: size 1000000x1000000.*too large" "$TP" info "$WORK/huge.vrt"

# Outputs: unwritable folder, missing folder, existing file.
mkdir "$WORK/ro" && chmod 555 "$WORK/ro"
if [[ $(id -u) -ne 0 ]]; then
  expect_fail 2 "out.tif: output folder .* is not writable" "$TP" convert "$good" "$WORK/ro/out.tif"
fi
expect_fail 2 "out.tif: output folder .* does not exist" "$TP" convert "$good" "$WORK/missing/out.tif"
"$TP" --quiet convert "$good" "$WORK/exists.tif"
expect_fail 2 "exists.tif: output exists.*--overwrite" "$TP" convert "$good" "$WORK/exists.tif"
"$TP" --quiet convert "$good" "$WORK/exists.tif" --overwrite || fail "--overwrite refused"

# Usage errors are exit code 2 too.
expect_fail 2 "" "$TP" info
expect_fail 2 "" "$TP" no-such-command
no_leftovers "$WORK"
[[ ! -e $SAMPLES/spDataLarge_dem_mongon.tif.aux.xml ]] || fail "an input was modified (.aux.xml written beside it)"
echo "bad input cases: ok"
