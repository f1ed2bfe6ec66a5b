# project.qgs on projected DEMs (one with an EPSG code, one without): every <spatialrefsys> is
# complete, QGIS reads every layer's CRS as valid, and the cities (lon/lat) overlay the rasters (metres).
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
/usr/bin/python3 -c "import qgis.core" 2>/dev/null || fail "python3-qgis is not installed (scripts/setup installs it)"
for dem in whiteboxR_DEM_vermont.tif stars_olinda_dem_utm25s.tif; do
  run=run-${dem%.tif}
  "$TP" --quiet run --set dem="$SAMPLES/$dem" -o "$run" --set outputs.preview_width=200
  /usr/bin/python3 - "$run/project.qgs" <<'PY' || fail "$run/project.qgs: incomplete spatialrefsys"
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
systems = root.findall(".//spatialrefsys")
assert len(systems) >= 2, len(systems)
for s in systems:
    for tag in ("wkt", "proj4", "description", "projectionacronym", "ellipsoidacronym", "geographicflag"):
        assert (s.findtext(tag) or "").strip(), (tag, ET.tostring(s)[:200])
PY
  QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$WORK /usr/bin/python3 "$SOURCE/tests/qgis/check_project.py" "$run" "$run.png" \
    || fail "QGIS check of $run"
done
echo "QGIS CRS: ok"
