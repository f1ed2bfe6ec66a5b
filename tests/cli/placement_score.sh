# The placement backtest's scoring (bench/placement.py) on a synthetic region whose answers are
# known by hand: shares within 5 km, median distances, uniform and density-weighted baselines.
source "$(dirname "$0")/lib.sh" "$@"
/usr/bin/python3 "$SOURCE/bench/placement.py" self-test | grep -q "placement scoring: ok" || fail "placement scoring self-test"
echo "placement_score: ok"
