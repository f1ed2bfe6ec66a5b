# Bad georeferencing is refused by the raster reader, for every command that reads a DEM: one line
# naming the file and the problem, exit code 2, no signal, no output left (the density stage used
# to crash with SIGSEGV on a zero cell size).
source "$(dirname "$0")/lib.sh" "$@"
good=$SAMPLES/spDataLarge_dem_mongon.tif

# vrt NAME "GEOTRANSFORM" [SRS]: a 64 x 48 VRT over the good DEM's pixels with another georeferencing.
vrt() {
  cat > "$WORK/$1.vrt" <<VRT
<VRTDataset rasterXSize="64" rasterYSize="48">
  <SRS>${3:-EPSG:4326}</SRS>
  <GeoTransform>$2</GeoTransform>
  <VRTRasterBand dataType="Float32" band="1">
    <SimpleSource><SourceFilename relativeToVRT="0">$good</SourceFilename><SourceBand>1</SourceBand>
      <SrcRect xOff="0" yOff="0" xSize="64" ySize="48"/><DstRect xOff="0" yOff="0" xSize="64" ySize="48"/></SimpleSource>
  </VRTRasterBand>
</VRTDataset>
VRT
}
vrt zero "9.0, 0, 0, 43.0, 0, -0.01"
vrt nan "9.0, nan, 0, 43.0, 0, -0.01"
vrt inf "9.0, 0.01, 0, 43.0, 0, -inf"
vrt parallel "500000, 30, 30, 4000000, 30, 30" EPSG:32632
vrt pixels "0, 1, 0, 240, 0, -5"
vrt wide "-200, 0.5, 0, 40, 0, -0.5"
vrt earth "0, 1000000, 0, 0, 0, -1000" EPSG:32632
# A UTM zone labelling coordinates 19,000 km east of its meridian: PROJ cannot invert them.
vrt domain "19000000, 1000, 0, 5000000, 0, -1000" EPSG:32631

# check NAME PATTERN: every command that reads a DEM refuses it the same way.
check() {
  local name=$1 pattern=$2
  for cmd in info hydro density fill; do
    local args=("$WORK/$name.vrt")
    [[ $cmd == info ]] || args+=("$WORK/out-$cmd-$name")
    [[ $cmd == fill ]] && args[1]="$WORK/out-$cmd-$name.tif"
    expect_refused "${args[1]:-$WORK/none}" "$name.vrt: .*$pattern" "$TP" --quiet "$cmd" "${args[@]}"
    [[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "$cmd $name: more than one line: $(cat "$WORK/stderr")"
  done
}
check zero "zero cell size"
check nan "NaN or infinite"
check inf "NaN or infinite"
check parallel "degenerate"
check pixels "outside \[-180, 360\] x \[-90, 90\]"
check wide "outside \[-180, 360\] x \[-90, 90\]"
check earth "larger than the Earth"
check domain "cannot be transformed to WGS 84"

# The same through a scenario: refused before the run folder is made.
expect_refused "$WORK/run-zero" "zero.vrt: .*zero cell size" "$TP" --quiet run --set dem="$WORK/zero.vrt" -o "$WORK/run-zero"

# A bad --assume-crs: our one line only, no GDAL "ERROR 1:" before it.
cp "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" "$WORK/nocrs.asc"
expect_fail 2 "nocrs.asc: unknown CRS 'EPSG:99999999'" "$TP" info "$WORK/nocrs.asc" --assume-crs EPSG:99999999
[[ $(grep -c . "$WORK/stderr") -eq 1 ]] || fail "--assume-crs printed more than one line: $(cat "$WORK/stderr")"
grep -q "ERROR 1" "$WORK/stderr" && fail "GDAL's own error line was printed"

# A row centred on a pole has no width: refused by name. Edges less than half a cell past the pole pass.
vrt pole "-180.25, 0.5, 0, 90.25, 0, -0.5"
check pole "centred on a pole"
vrt past "-180.1, 0.5, 0, 90.1, 0, -0.5"
"$TP" --quiet info "$WORK/past.vrt" >/dev/null 2>"$WORK/stderr" || fail "a grid just past the pole was refused: $(cat "$WORK/stderr")"
no_leftovers "$WORK"
echo "bad georeferencing cases: ok"
