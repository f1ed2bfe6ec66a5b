# `terrapolis sites` on the Corsica sample: outputs and fields, quota report, seeds, modes, clean failures.
source "$(dirname "$0")/lib.sh" "$@"
BIN=$TP
T=$WORK
DEM=$SAMPLES/gebco2022_15s_north_corsica_capcorse.asc
stand_in_density "$DEM" "$T/in"

"$BIN" --quiet sites "$T/in" "$T/a" --seed 5 --report --quotas belhadj2007 > "$T/report.txt"
cat "$T/report.txt"
grep -q "^class  radius_m   quota  placed    kept" "$T/report.txt"
# 15" cells are 462.9 m north-south: dr = 462, classes 462 .. 2310 m. Class 0 (2310 m, 924000 people):
# floor(4 + 1068 * 0.076^4) = 4; class 4 (462 m): floor(4 + 1068 * 0.8152^4) = 475.
grep -Eq "^ +0 +2310.0 +4 " "$T/report.txt"
grep -Eq "^ +4 +462.0 +475 " "$T/report.txt"
grep -q "seed 5" "$T/report.txt"
test -s "$T/a/cities.geojson"
test -s "$T/a/city_extents.geojson"
fields=$(ogrinfo -so -al "$T/a/cities.geojson")
for f in "id: Integer" "radius_m: Real" "class: Integer" "population: Integer" "density: Real" "parent: Integer" "depth: Integer" "seed: Integer"; do
  grep -q "$f" <<< "$fields" || { echo "missing field $f"; exit 1; }
done
grep -q "Geometry: Polygon" <(ogrinfo -so -al "$T/a/city_extents.geojson")
grep -q '"seed": 5' "$T/a/cities.geojson"
# Roots have a null parent, suburbs a parent id; every extent has its city.
roots=$(ogrinfo -q -dialect sqlite -sql "select count(*) as n from cities where parent is null and depth = 0" "$T/a/cities.geojson" | grep -o "n (Integer) = [0-9]*")
test "${roots##* }" -gt 0
ncities=$(ogrinfo -so -al "$T/a/cities.geojson" | grep -o "Feature Count: [0-9]*")
nextents=$(ogrinfo -so -al "$T/a/city_extents.geojson" | grep -o "Feature Count: [0-9]*")
test "$ncities" = "$nextents"

# Same seed, same bytes (whatever the thread count); another seed, another placement.
"$BIN" --quiet --threads 1 sites "$T/in" "$T/b" --seed 5 --quotas belhadj2007
cmp "$T/a/cities.geojson" "$T/b/cities.geojson"
cmp "$T/a/city_extents.geojson" "$T/b/city_extents.geojson"
"$BIN" --quiet sites "$T/in" "$T/c" --seed 6
if cmp -s "$T/a/cities.geojson" "$T/c/cities.geojson"; then echo "seed 6 gave the same cities"; exit 1; fi

# Manhattan: no suburbs. Perimeter test: runs.
"$BIN" --quiet sites "$T/in" "$T/m" --mode manhattan --disc-test perimeter
kids=$(ogrinfo -q -dialect sqlite -sql "select count(*) as n from cities where parent is not null" "$T/m/cities.geojson" | grep -o "n (Integer) = [0-9]*")
test "${kids##* }" -eq 0

# Existing outputs are refused (exit 2, untouched) unless --overwrite.
set +e
"$BIN" --quiet sites "$T/in" "$T/a" --seed 9 2> "$T/err.txt"
rc=$?
set -e
test $rc -eq 2
grep -q "a: output folder exists" "$T/err.txt"
cmp "$T/a/cities.geojson" "$T/b/cities.geojson"
"$BIN" --quiet sites "$T/in" "$T/a" --seed 9 --overwrite
grep -q '"seed": 9' "$T/a/cities.geojson"

# A DEM instead of a density folder: the density of a run's stages (tests/cli/stage_commands.sh
# holds it to the run's cities byte for byte), not the thesis's weights of `terrapolis density`.
"$BIN" --quiet sites "$DEM" "$T/from_dem"
"$BIN" --quiet density "$DEM" "$T/model"
"$BIN" --quiet sites "$T/model" "$T/from_model"
cmp -s "$T/from_dem/cities.geojson" "$T/from_model/cities.geojson" && { echo "sites DEM used the thesis's density weights"; exit 1; }

# Bad inputs: exit 2, one line naming the problem, no output folder left.
refuse() { expect_refused "$1" "$2" "$BIN" --quiet sites "${@:3}" "$1"; }
refuse "$T/x1" "no such folder" "$T/missing"
mkdir "$T/half"
cp "$T/in/density.tif" "$T/half/"
refuse "$T/x2" "buildable.tif" "$T/half"
refuse "$T/x3" "r_max" "$T/in" --quotas belhadj2007 --r-min 3000 --r-max 3100
refuse "$T/x3" "--r-min: sets the classes of --quotas belhadj2007" "$T/in" --r-min 3000 --r-max 3100
refuse "$T/x5" "seed" "$T/in" --seed 18446744073709551615
gdal_calc.py --quiet -A "$DEM" --outfile "$T/half/buildable.tif" --type Byte --calc "A*0"
refuse "$T/x4" "no buildable cell" "$T/half"
echo OK
