// What the stages of one run share: the scenario, the DEM, each stage's typed results, the files written.
// SPDX-License-Identifier: MIT
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "io/raster_io.hpp"
#include "io/vector_io.hpp"
#include "pipeline/descriptions.hpp"
#include "pipeline/scenario.hpp"
#include "pipeline/stage_options.hpp"
#include "plugin/plugin.hpp"
#include "sites/sites.hpp"

namespace terrapolis::pipeline {

/// How a layer is drawn in QGIS and in the preview.
enum class Style { elevation, hillshade, unit_ramp, density, mask, water, flow_direction, accumulation,
                   streams, cities, city_extents, network, roads, road_sections, sections, junctions, corridors, access_minutes,
                   existing_roads, access_catchments };

/// Style names as recorded in run.json ("elevation", "road_sections"...), and back.
const char* style_name(Style style);
Style style_from_name(const std::string& name);

/// One file of the run folder.
struct OutputFile {
  std::string name;         ///< file name inside the run folder
  std::string stage;        ///< stage that wrote it
  std::string description;  ///< what it is
  Style style;
  bool raster = true;
  std::size_t features = 0;  ///< vector layers: number of features
};

/// How a run reads its DEM when it works tile by tile (input.tile_size, input.memory_limit_mb).
struct TiledInput {
  std::string dem_path;
  ReadOptions read;
  TileSettings tiles;
  double reserved_mb = 0;  ///< what the process and the mosaic's reader hold of the memory limit
  /// At the start of a stage: what the process holds now (reserve_reader_memory).
  void reserve();
};

struct RunState {
  RunState(const Scenario& s, std::filesystem::path run_folder, std::string sha256, Dem elevation, RasterHeader dem_grid)
      : scenario(s), folder(std::move(run_folder)), dem_sha256(std::move(sha256)), dem(std::move(elevation)), grid(std::move(dem_grid)),
        terms(description_terms(s)) {}

  const Scenario& scenario;
  StageSettings settings;  ///< every stage's settings, prepared before the first stage runs
  std::filesystem::path folder;  ///< the run folder being written (a temporary name until the end)
  std::string dem_sha256;
  Dem dem;            ///< the whole DEM; empty when the run works tile by tile
  RasterHeader grid;  ///< the DEM's grid and georeferencing
  std::optional<TiledInput> by_tiles;  ///< set: the stages read the DEM by windows and write their rasters by tiles
  plugin::PluginSet plugins;  ///< the scenario's plugins, loaded and checked before any work
  // Typed results of the stages, filled in data-flow order.
  std::optional<Raster<float>> hydrometry;        ///< hydro: [0,1]
  std::optional<Raster<std::uint8_t>> rivers;     ///< hydro: 1 on river cells (upstream area over the streams threshold)
  std::optional<Raster<float>> density;           ///< density: [0,1]
  std::optional<Raster<std::uint8_t>> buildable;  ///< density: 1 habitable, 0 not, 255 nodata
  std::vector<sites::Site> sites;                 ///< sites: sorted by radius, decreasing
  std::optional<VectorLayer> cities, network;     ///< sites and network layers, in the DEM's CRS
  DescriptionTerms terms;  ///< what the scenario decides of the outputs' descriptions
  std::vector<OutputFile> outputs;
  std::vector<std::pair<Style, VectorLayer>> vectors;  ///< vector layers written, kept for the preview
  nlohmann::ordered_json summary = nlohmann::ordered_json::object();  ///< per-stage figures for the summary and compare

  /// Writes a raster of the run with provenance metadata and its description (describe_output of
  /// the scenario's terms, the one a command writing the same file gives), and records it.
  template <class T>
  void write(const std::string& stage, const std::string& name, const Raster<T>& raster, Style style,
             const std::vector<std::pair<std::string, std::string>>& metadata = {});
  /// Writes tile t of a raster of the run written by tiles (`mosaic.name` the file's name without
  /// .tif), with the provenance and description write() gives the whole file.
  template <class T>
  void write_tile(const std::string& stage, const MosaicFiles& mosaic, int t, int across, const Raster<T>& raster,
                  const std::vector<std::pair<std::string, std::string>>& metadata = {}) const;
  /// Writes the VRT over a raster's tiles and records it (NAME.vrt).
  void write_mosaic(const std::string& stage, const MosaicFiles& mosaic, int tiles, int across, Style style);
  /// Where the run writes raster NAME by tiles.
  MosaicFiles mosaic(const std::string& name) const { return {folder.string(), name}; }
  /// Writes a vector layer of the run and records it with its description.
  void write(const std::string& stage, const std::string& name, const VectorLayer& layer, Style style);

 private:
  /// The file options of a raster of the run: provenance without timestamps, its description.
  WriteOptions file_options(const std::string& stage, const std::string& name,
                            const std::vector<std::pair<std::string, std::string>>& metadata) const;
};

}  // namespace terrapolis::pipeline
