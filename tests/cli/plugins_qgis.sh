# The QGIS Processing provider headless with Debian's python3-qgis: load, list, run hydro and density, cancel.
source "$(dirname "$0")/lib.sh" "$@"
/usr/bin/python3 -c "import qgis.core" 2>/dev/null || fail "python3-qgis is not installed (scripts/setup installs it)"
mkdir -m 700 "$WORK/runtime"
TERRAPOLIS_BIN=$TP QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$WORK/runtime \
  /usr/bin/python3 -W error::ResourceWarning "$SOURCE/tests/qgis/check_provider.py" "$SOURCE" \
  "$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc" "$WORK" || fail "QGIS provider"
