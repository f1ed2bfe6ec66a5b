// The inland water and the hydrometry by tiles (see by_tiles.hpp).
// SPDX-License-Identifier: MIT
#include "pipeline/by_tiles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "core/error.hpp"
#include "hydro/tiled/tiled_hydro.hpp"
#include "io/mask_io.hpp"
#include "pipeline/density_folder.hpp"
#include "pipeline/inland_water.hpp"
#include "pipeline/stage_options.hpp"

namespace terrapolis::pipeline {

WindowReservoirs::WindowReservoirs(const DemWindowReader& dem, const InlandWaterSettings& water, double budget_mb, Progress& progress,
                                   const Log& log) {
  const RasterHeader& h = dem.header();
  const std::size_t max_cells = std::size_t(std::max(0.0, budget_mb) * 1e6 / kFloodBytesPerCell);
  for (std::size_t k = 0; k < water.reservoirs.size(); ++k) {
    const std::string pointer = "/water/reservoirs/" + std::to_string(k);
    lake::WindowLake w;
    try {
      w = lake::flood_by_windows(
          h.georef, h.cols, h.rows, [&](int c0, int r0, int cols, int rows) { return dem.read(c0, r0, cols, rows); }, water.reservoirs[k],
          max_cells, progress);
    } catch (const Error& e) {
      throw bad_input(pointer + e.what());
    }
    figures_.push_back(reservoir_figures(w.lake, pointer, log));
    log.detail(pointer + ": flooded on " + std::to_string(w.windows) + " window" + (w.windows > 1 ? "s" : "") + ", the last " +
               std::to_string(w.lake.mask.cols()) + " x " + std::to_string(w.lake.mask.rows()) + " cells");
    const Raster<std::uint8_t>& m = w.lake.mask;
    int x0 = m.cols(), y0 = m.rows(), x1 = -1, y1 = -1;  // the flooded cells' bounding box
    for (int y = 0; y < m.rows(); ++y)
      for (int x = 0; x < m.cols(); ++x)
        if (m(x, y) == 1) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    Water& kept = water_.emplace_back();
    kept.col0 = w.col0 + x0, kept.row0 = w.row0 + y0;
    kept.mask = hydro::tiled::crop(m, x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  }
}

void WindowReservoirs::add_to(Raster<std::uint8_t>& tile, int col0, int row0) const {
  for (const Water& w : water_)
    for (int y = std::max(0, w.row0 - row0); y < std::min(tile.rows(), w.row0 + w.mask.rows() - row0); ++y)
      for (int x = std::max(0, w.col0 - col0); x < std::min(tile.cols(), w.col0 + w.mask.cols() - col0); ++x)
        if (w.mask(x + col0 - w.col0, y + row0 - w.row0) == 1) tile(x, y) = 1;
}

double WindowReservoirs::held_mb() const {
  double bytes = 0;
  for (const Water& w : water_) bytes += double(w.mask.size());
  return bytes / 1e6;
}

hydro::tiled::TiledFlatWaterReport inland_water_by_tiles(const DemWindowReader& dem, const InlandWaterSettings& water, const TileSettings& tiles,
                                                         const WindowReservoirs& reservoirs, double reserved_mb,
                                                         const WriteTile<std::uint8_t>& write, Progress& progress) {
  const RasterHeader& h = dem.header();
  reserved_mb += reservoirs.held_mb();
  const int side = tiles.tile_size > 0 ? tiles.tile_size : hydro::tiled::flat_water_tile_size_for(h.cols, h.rows, tiles.limit_mb(), reserved_mb);
  const hydro::tiled::TileGrid grid(h.cols, h.rows, side);
  return hydro::tiled::run_tiled_flat_water(
      h.cols, h.rows, h.georef, [&](int c0, int r0, int cols, int rows) { return dem.read(c0, r0, cols, rows); }, water.flat_water, side,
      [&](int t, int across, const Raster<std::uint8_t>& lakes) {
        if (water.water_mask.empty() && water.reservoirs.empty()) return write(t, across, lakes);
        Raster<std::uint8_t> mask = water.water_mask.empty() ? lakes.like<std::uint8_t>(0)
                                                             : read_mask(water.water_mask, lakes.georef(), lakes.cols(), lakes.rows());
        for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = mask[i] || lakes[i];  // as inland_water: 1 water, 0 not
        const hydro::tiled::TileRect r = grid.rect(t);
        reservoirs.add_to(mask, r.col0, r.row0);
        write(t, across, mask);
      },
      progress);
}

std::string describe(const hydro::tiled::TiledFlatWaterReport& r) {
  char line[300];
  std::snprintf(line, sizeof line, "inland water tiles: %d of %d cells a side, %zu lakes the DEM flattens, %.2f km2 (%zu level surfaces on tile edges "
                "or large enough, joined across tiles)", r.tiles, r.tile_size, r.lakes, r.area_km2, r.surfaces);
  return line;
}

std::string inland_water_mosaic(const DemWindowReader& dem, const InlandWaterSettings& water, const TileSettings& tiles,
                                const std::string& dir, Progress& progress, const Log& log) {
  const MosaicFiles mosaic{dir, "inland_water"};
  mosaic.create();
  const double reserved_mb = reserve_reader_memory(tiles.limit_mb());
  const WindowReservoirs reservoirs(dem, water, tiles.limit_mb() - reserved_mb, progress, log);
  const hydro::tiled::TiledFlatWaterReport report = inland_water_by_tiles(
      dem, water, tiles, reservoirs, reserved_mb,
      [&](int t, int across, const Raster<std::uint8_t>& tile) { write_raster(mosaic.tile(t, across), tile, WriteOptions{}); }, progress);
  mosaic.finish(report.tiles, report.across);
  log.detail(describe(report));
  return mosaic.vrt();
}

hydro::tiled::TiledBelhadjReport hydrometry_by_tiles(const DemWindowReader& dem, const hydro::HydroOptions& hydro, const TileSettings& tiles,
                                                     double reserved_mb, const std::string& scratch_dir, const WriteTile<float>& write,
                                                     Progress& progress) {
  const hydro::HydrometryOptions h = hydro::hydrometry_options(hydro);
  if (h.method != hydro::HydrometryMethod::belhadj)
    throw bad_input("/hydro/hydrometry: the accumulation hydrometry is not computed on tiles yet (Belhadj's is)");
  const RasterHeader& g = dem.header();
  return hydro::tiled::run_tiled_belhadj(
      g.cols, g.rows, g.georef, [&](int c0, int r0, int cols, int rows) { return dem.read(c0, r0, cols, rows); }, hydro::belhadj_options(h),
      tiles.tile_size, tiles.limit_mb(), scratch_dir, write, progress, reserved_mb);
}

std::string describe(const hydro::tiled::TiledBelhadjReport& b) {
  char line[300];
  std::snprintf(line, sizeof line,
                "hydrometry tiles: %d of %d cells a side, %d Belhadj iterations (mean %.3g) found in %d pass%s, halo %d cells; state %.1f MB a window",
                b.tiles, b.tile_size, b.iterations, b.final_mean, b.searches, b.searches > 1 ? "es" : "", b.halo, b.window_bytes / 1e6);
  return line;
}

double density_file_bytes_per_cell(const Scenario& scenario) {
  const auto& d = scenario.resolved["density"];
  return 8.0 * double(d["layers"].size()) + 2.0 * double(d["exclusions"].size());
}

density::ReadWindowInputs density_windows(const DemWindowReader& dem, const Scenario& scenario, const density::DensityOptions& options,
                                          const std::string& inland_water, const ReadHydrometry& hydrometry,
                                          const std::string& accumulation_km2) {
  std::shared_ptr<const DemWindowReader> accumulation;
  if (!accumulation_km2.empty() && density::needs_terrain_terms(options)) accumulation = std::make_shared<const DemWindowReader>(accumulation_km2);
  const RasterHeader& h = dem.header();
  std::vector<LayerOnGrid> layers = layers_on_grid(scenario, h.georef, h.cols, h.rows);
  return [&dem, &scenario, &options, inland_water, hydrometry, accumulation, layers = std::move(layers)](int c0, int r0, int cols, int rows,
                                                                                                         bool dem_only) {
    density::WindowInputs in;
    in.dem = dem.read(c0, r0, cols, rows);
    in.options = options;
    const Georef& grid = in.dem.georef();
    in.options.water_mask = read_mask(inland_water, grid, cols, rows);
    if (dem_only) {
      if (accumulation) in.options.rivers = river_cells(accumulation->read(c0, r0, cols, rows), scenario);  // for the distances' bands
      return in;
    }
    read_density_files(scenario, grid, cols, rows, layers, "", in.options);
    in.hydrometry = hydrometry ? hydrometry(in.dem, c0, r0) : in.dem.like<float>(0.0f);
    return in;
  };
}

RunDensityWindows::RunDensityWindows(const std::string& dem_path, const ReadOptions& read, const std::string& run_folder, const Scenario& scenario,
                                     density::DensityOptions options)
    : options_(std::move(options)), dem_(dem_path, read), hydrometry_(run_folder + "/hydrometry.vrt") {
  read_ = density_windows(
      dem_, scenario, options_, run_folder + "/inland_water.vrt",
      [this](const Dem& w, int c0, int r0) { return hydrometry_.read(c0, r0, w.cols(), w.rows()); }, run_folder + "/accumulation.vrt");
}

// A window's cells hold 13 bytes while read (a raster read as floats, 4, and GDAL's copy of it, 4;
// the view's density and buildable, 5); a band's 4 more (the catchments' owner), a block's 2 (the
// disc test's row gaps). Measured, the process grows by about 1.5 times that (the VRT's buffers,
// freed chunks the allocator keeps): 25 and 21 bytes a cell are counted, and a band or a block
// holds at most a third of the budget (2.3e7 cells peaked at 311 MB against a 300 MB limit at 17
// and 15 bytes and half the budget; 288 MB now).
constexpr double kBandBytes = 25, kBlockBytes = 21, kShare = 1.0 / 3;

namespace {
std::unique_ptr<DemWindowReader> open_reader(const std::string& path) { return std::make_unique<DemWindowReader>(path); }
}  // namespace

LandTiles::LandTiles(const std::string& density, const std::string& buildable, const std::optional<Georef>& grid, const TileSettings& tiles,
                     double reserved_mb)
    : LandTiles(open_reader(density), open_reader(buildable), grid, tiles, reserved_mb) {}

LandTiles::LandTiles(std::unique_ptr<DemWindowReader> density, std::unique_ptr<DemWindowReader> buildable, const std::optional<Georef>& grid,
                     const TileSettings& tiles, double reserved_mb)
    : Land(grid.value_or(density->header().georef), density->header().cols, density->header().rows), density_(std::move(density)),
      buildable_(std::move(buildable)) {
  check_same_grid(density_->header(), buildable_->path(), buildable_->header());
  const double least = 2 * kBandBytes * cols() / kShare;  // a band of two rows
  bytes_ = (tiles.limit_mb() - reserved_mb) * 1e6;
  if (tiles.memory_limit_mb > 0 && bytes_ < least)
    throw bad_input(hydro::tiled::too_little(tiles.limit_mb(), reserved_mb) + " for the sites' bands of " + std::to_string(cols()) + " columns");
  bytes_ = std::max(bytes_, least);  // a tile size without a limit
  band_rows_ = int(std::clamp(bytes_ * kShare / (kBandBytes * cols()), 1.0, double(rows())));
  tile_size_ = tiles.tile_size;
}

int LandTiles::block_side(int margin_cols, int margin_rows) const {
  // The largest side whose window, grown by the margins, holds a third of the budget (at least 16
  // cells: a window of the largest disc and 16 cells then holds more); a tile size given is kept
  // when smaller.
  const double a = 2.0 * margin_cols, b = 2.0 * margin_rows, c = bytes_ * kShare / kBlockBytes;  // (s + a)(s + b) = c
  const int side = std::max(16, int((-(a + b) + std::sqrt((a - b) * (a - b) + 4 * c)) / 2));
  return tile_size_ > 0 ? std::min(tile_size_, side) : side;
}

sites::LandView LandTiles::window(int col0, int row0, int cols, int rows) const {
  sites::LandView v;
  v.col0 = col0, v.row0 = row0, v.cols = cols, v.rows = rows;
  v.stride = std::size_t(cols);
  Dem d = density_->read(col0, row0, cols, rows);
  check_density_values(density_->path(), d.data(), d.size());
  v.own_density = std::move(d.values());
  const Dem b = buildable_->read(col0, row0, cols, rows);
  v.own_buildable.resize(b.size());
  for (std::size_t i = 0; i < b.size(); ++i) v.own_buildable[i] = b[i] == 1 ? 1 : 0;  // nodata (NaN) is not buildable
  v.density = v.own_density.data();
  v.buildable = v.own_buildable.data();
  return v;
}


}  // namespace terrapolis::pipeline
