# The shared regions with 10 or more GeoNames places (CC BY 4.0) on their land, for bench/realism.sh
# and bench/density_terms.sh. Sourced with DEMS and PLACES set, in the folder the runs write to:
# sets `regions` (DEM file names), `dems`, `places` and `scenarios` (a --scenario per DEM; NZ's sea
# is nodata, NaN), and `default_fit`, the calibrate options the schema's default density weights
# were fitted with (docs/density.md, "Presets, terrain terms and calibration").
regions=(N47E009.hgt N57E011.hgt demcompare_reduced_gironde_topobathy.tif osmtransform_heidelberg_mannheim_srtm3.tif
         pyflwdir_rhine_elv0.tif spDataLarge_nz_elev.tif terra_elev_luxembourg.tif gebco2022_15s_la_palma.asc
         gebco2022_15s_north_corsica_capcorse.asc gebco2022_15s_tenerife_east.asc)
default_fit=(--terms altitude,slope,coast_near,position_5km --ridge 0.1)
echo '{}' > plain.json
echo '{"water": {"nodata_is_sea": true}}' > sea_nodata.json
# The scenario of a region's runs.
region_scenario() { [[ $1 == spDataLarge_nz_elev.tif ]] && echo sea_nodata.json || echo plain.json; }
dems=() places=() scenarios=()
for f in "${regions[@]}"; do
  dems+=("$DEMS/$f")
  places+=("$PLACES/${f%.*}.geojson")
  scenarios+=(--scenario "$(region_scenario "$f")")
done
