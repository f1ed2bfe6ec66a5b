// Each stage's options from a resolved scenario (schemas/scenario.schema.json is the one source of defaults).
// SPDX-License-Identifier: MIT
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "access/access.hpp"
#include "density/density.hpp"
#include "erode/erosion.hpp"
#include "hydro/hydro.hpp"
#include "hydro/river_types.hpp"
#include "io/raster_io.hpp"
#include "lake/lake.hpp"
#include "network/network.hpp"
#include "pipeline/scenario.hpp"
#include "roads/corridor.hpp"
#include "roads/cost_model.hpp"
#include "hydro/flat_water.hpp"
#include "roads/road_network.hpp"
#include "sites/sites.hpp"
#include "skeleton/ridges_valleys.hpp"

namespace terrapolis::pipeline {

/// input.tile_size and input.memory_limit_mb: whether and how the hydro and density stages work
/// tile by tile (docs/scale.md).
struct TileSettings {
  int tile_size = 0;           ///< 0: from memory_limit_mb
  double memory_limit_mb = 0;  ///< 0: none given
  /// Tile by tile: a tile size or a memory limit given, or the DEM is a folder of tiles.
  bool tiled(const std::string& dem_path) const;
  /// A tile size or a memory limit given (a run works tile by tile only then).
  bool given() const { return tile_size > 0 || memory_limit_mb > 0; }
  /// The limit the tiles are sized to: the one given, or 1 GB.
  double limit_mb() const { return memory_limit_mb > 0 ? memory_limit_mb : 1024; }
};
/// Throws bad_input for a tile size under 8 cells.
TileSettings tile_settings(const Scenario& scenario);

/// The hydro section (sea level from the water section). Weights are not part of a scenario.
hydro::HydroOptions hydro_options(const Scenario& scenario);
/// hydro.classify's thresholds, or none when the reaches are not classified.
std::optional<hydro::RiverTypeOptions> river_type_options(const Scenario& scenario);
/// The water section's reservoirs (docs/lakes.md), in the scenario's order, each checked
/// (lake::check_spec; errors name /water/reservoirs/K).
std::vector<lake::LakeSpec> reservoir_specs(const Scenario& scenario);
/// One item of water.reservoirs as a lake, unchecked (what `terrapolis lake` floods from its flags).
lake::LakeSpec reservoir_spec(const nlohmann::ordered_json& item);
/// The skeleton section (terrapolis skeleton, docs/skeleton.md).
skeleton::SkeletonOptions skeleton_options(const Scenario& scenario);
/// The erode section (terrapolis erode, docs/erode.md): the angle of repose from erode.angle_deg, or
/// else erode.material; the files it names (erode.mask, erode.angles, erode.loose, erode.rockfall)
/// are read by the caller.
erode::ErodeOptions erode_options(const Scenario& scenario);
/// Code convention of flowdir.tif.
hydro::D8Codes d8_codes(const Scenario& scenario);
/// The density section, with the water section (its files are read by read_density_files).
density::DensityOptions density_options(const Scenario& scenario);
/// The density's files read onto the DEM's grid: density.layers as factors (ahead of any
/// plugin's), density.exclusions as masks, and `water_mask` (a command: water.water_mask; a run:
/// its inland_water.tif, which holds it) as the water mask, when not empty.
void read_density_files(const Scenario& scenario, const Dem& dem, const std::string& water_mask, density::DensityOptions& options);
/// How the whole grid reads one of density.layers: warped with one kernel scale and rescaled by its
/// range over the grid, so that a window of the grid reads the whole grid's values.
struct LayerOnGrid {
  WarpScale scale;
  density::ValueRange range;
};
/// density.layers over the grid `cols` x `rows` of `grid`, in their order, each read by bands of
/// rows (read_resampled_by_bands).
std::vector<LayerOnGrid> layers_on_grid(const Scenario& scenario, const Georef& grid, int cols, int rows);
/// The same onto a window of the grid (density by tiles), `layers` being layers_on_grid's.
void read_density_files(const Scenario& scenario, const Georef& window, int cols, int rows, const std::vector<LayerOnGrid>& layers,
                        const std::string& water_mask, density::DensityOptions& options);
/// The shallowest angle within (0, 90) of a map of side angles (roads.corridor.side_angles) over the
/// grid, 0 when it holds none: read by bands of rows as the corridors read it (nearest cell), for
/// the reach of corridors read by windows (CorridorOptions::least_side_angle_deg).
double least_side_angle(const std::string& map, const RasterHeader& grid);
/// The files read_density_files reads (the water mask, the layers, the exclusions), as paths.
std::vector<std::string> density_files(const Scenario& scenario);
/// The sites section, with the scenario's seed.
sites::SitesOptions sites_options(const Scenario& scenario);
network::NetworkOptions network_options(const Scenario& scenario);
/// River cells (1) for the density's river_near term: upstream area of hydro.streams_threshold_km2
/// or more, the streams layer's definition, on the km² as accumulation.tif holds them (so that a
/// run, a run resumed from its files and a run by tiles find the same rivers).
Raster<std::uint8_t> river_cells(const Raster<float>& accumulation_km2, const Scenario& scenario);

/// The roads section: the cost model (the paper's defaults, a costs file over them, structures
/// switched off), the routing options with the scenario's seed, and the vegetation raster.
struct RoadsSettings {
  roads::CostModel model;
  roads::RoutingOptions routing;
  std::string vegetation;  ///< resolved path, "" for none
  std::string existing;    ///< roads.existing, resolved path, "" for none
};
RoadsSettings roads_settings(const Scenario& scenario);

/// roads.corridor: the corridor options (the side angle from the material unless given) and the
/// resolved path of the side-angle raster ("" for none; the caller reads it onto the DEM's grid).
struct CorridorSettings {
  roads::CorridorOptions options;
  std::string side_angles;
  bool enabled = false;  ///< the run's roads stage writes corridors.geojson
};
CorridorSettings corridor_settings(const Scenario& scenario);

/// The water section's detection of lakes the DEM flattens (water.flat_water_*, water.sea_level_m).
hydro::FlatWaterOptions flat_water_options(const Scenario& scenario);

/// access.*: the friction surface and what is measured.
struct AccessSettings {
  bool enabled = true;
  access::AccessOptions options;
  std::vector<double> thresholds_minutes;  ///< increasing
  std::vector<double> levels_population;   ///< increasing, distinct
};
AccessSettings access_settings(const Scenario& scenario);

/// The water section's inland water (docs/lakes.md): what pipeline::inland_water reads.
struct InlandWaterSettings {
  hydro::FlatWaterOptions flat_water;
  std::string water_mask;                  ///< water.water_mask (empty: none)
  std::vector<lake::LakeSpec> reservoirs;  ///< in the scenario's order
};
/// Errors name the setting's pointer.
InlandWaterSettings inland_water_settings(const Scenario& scenario);

/// Every stage's typed settings, built by each stage's `prepare` before the first stage runs (as
/// PDAL prepares every stage before executing any): the commands build theirs with the same functions.
struct StageSettings {
  InlandWaterSettings water;
  hydro::HydroOptions hydro;
  std::optional<hydro::RiverTypeOptions> river_types;
  hydro::D8Codes d8_codes{};
  density::DensityOptions density;
  sites::SitesOptions sites;
  network::NetworkOptions network;
  RoadsSettings roads;
  CorridorSettings corridor;
  AccessSettings access;
};
/// A file the scenario names must exist before the run starts (GDAL's /vsi paths are GDAL's to
/// check): throws bad_input "POINTER: PATH: no such file".
void check_file(const std::string& pointer, const std::string& path);

}  // namespace terrapolis::pipeline
