# Settlements: the thesis's model reproduced byte for byte (pinned before the rank-size default).
source "$(dirname "$0")/lib.sh" "$@"
cd "$WORK"
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
# cities.geojson of the thesis's quotas and weights on the bundled DEM, seed 1, as of commit f437b48.
PINNED=43f74baa6e097951aaec6a21b7551f6e79e01ce9e7a5837748c3cbc26136780a
"$TP" --quiet sites "$DEM" thesis > /dev/null
[[ $(sha256sum < thesis/cities.geojson | cut -d' ' -f1) == "$PINNED" ]] || fail "sites: the thesis's cities changed"
echo "settlements: ok"
