# A full disk fails the command (exit 1, naming the file and "no space left") and leaves nothing
# behind: rasters (GDAL), vectors (OGR), text files and a whole run (docs/safety.md, "Full disks").
source "$(dirname "$0")/lib.sh" "$@"
[[ $(id -u) -eq 0 ]] || { echo "SKIP: mounting a small tmpfs needs root (CI runs as root)"; exit 77; }
disk=$WORK/disk
mkdir "$disk"
mount -t tmpfs -o size=4m tmpfs "$disk" 2>/dev/null || { echo "SKIP: cannot mount a tmpfs here"; exit 77; }
trap 'cd /; umount "$disk"; rm -rf "$WORK"' EXIT
cd "$disk"
# fill_to KB: leaves about KB kilobytes free on the tmpfs.
fill_to() {
  rm -f filler
  local free
  free=$(df -k --output=avail . | tail -1)
  if (( free > $1 )); then dd if=/dev/zero of=filler bs=1k count=$((free - $1)) status=none; fi
}
empty_but() {  # nothing but the listed names on the disk
  local left
  left=$(ls -A | grep -vxF -e filler "${@/#/-e}" || true)
  [[ -z $left ]] || fail "left behind on the full disk: $left"
}

# Rasters: hydro's GeoTIFFs do not fit.
dem=$SAMPLES/spDataLarge_nz_elev.tif
expect_fail 1 "error: h/[a-z_]+\.(tif|geojson): cannot write output \(no space left on the device\)" "$TP" -q hydro "$dem" h
empty_but

# Vectors: the streams layer alone, on a disk with a few kilobytes left.
"$TP" -q hydro "$SAMPLES/whiteboxR_DEM_vermont.tif" "$WORK/vt" --outputs streams --streams-threshold 0.2
size=$(du -k "$WORK/vt/streams.geojson" | cut -f1)
fill_to $((size / 2))
expect_fail 1 "error: s/streams.geojson: cannot write output \(no space left on the device\)" \
  "$TP" -q hydro "$SAMPLES/whiteboxR_DEM_vermont.tif" s --outputs streams --streams-threshold 0.2
empty_but
rm -f filler

# Text: compare --save on a disk with nothing left.
"$TP" -q run --set dem="$SAMPLES/terra_elev_luxembourg.tif" -o "$WORK/r1" --set outputs.preview=false
fill_to 0
expect_fail 1 "error: cmp.txt.*: cannot write output \(no space left on the device\)" "$TP" compare "$WORK/r1" "$WORK/r1" --save cmp.txt
empty_but
rm -f filler

# A whole run that fits once but not twice: the rerun fails and the first one stays whole.
"$TP" -q run --set dem="$SAMPLES/terra_elev_luxembourg.tif" -o r --set outputs.preview=false
used=$(du -sk r | cut -f1)
fill_to $((used / 2))
sums=$(cd r && md5sum ./* | sort)
expect_fail 1 "no space left on the device" "$TP" -q run --set dem="$SAMPLES/terra_elev_luxembourg.tif" -o r --overwrite \
  --set outputs.preview=false --seed 3
[[ $(cd r && md5sum ./* | sort) == "$sums" ]] || fail "a run that failed on a full disk changed the previous run"
empty_but r
echo "safety_full_disk: ok"
