// The tiled hydro command: the tile engine between a mosaic reader and per-tile GeoTIFFs + VRTs.
// SPDX-License-Identifier: MIT
#include "cli/hydro_tiles.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "io/text_io.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

TileDistribution* distribution = nullptr;

std::string tiles_of_this_process(const TiledHydroRequest& q, Context& context, hydro::tiled::TileDriver& driver) {
  const double reserved_mb = reserve_reader_memory(q.memory_limit_mb);
  const DemWindowReader reader(q.dem_path, q.read);
  const RasterHeader& h = reader.header();
  const fs::path out(q.out_dir);  // a fresh staging folder (OutputSet, rank 0's): no earlier tiles in it
  struct Layer {
    std::string name;
    bool wanted;
    const WriteOptions* options;
  };
  const Layer layers[4] = {{"filled", q.filled, &q.filled_file},
                           {"flowdir", q.flowdir, &q.flowdir_file},
                           {"accumulation", q.accumulation, &q.accumulation_file},
                           {"basins", q.basins, &q.basins_file}};
  hydro::tiled::TiledOptions o;
  o.memory_limit_mb = q.memory_limit_mb;
  o.reserved_mb = reserved_mb;
  o.sea_level = q.sea_level;
  o.unit = q.unit;
  o.streams_threshold_m2 = q.streams_threshold_km2 * 1e6;
  const int threads = context.threads > 0 ? context.threads : hydro::tiled::allowed_threads();
  o.concurrent_tiles = threads;
  const bool leader = driver.rank() == 0;
  if (leader)  // before the engine's first exchange, hence before any process writes a tile
    for (const Layer& l : layers)
      if (l.wanted) fs::create_directory(out / l.name);
  const ScratchFolder scratch((out / (".scratch-" + std::to_string(driver.rank()) + "-" + std::to_string(getpid()))).string());
  o.scratch_dir = scratch.path();
  o.tile_size = q.tile_size > 0 ? q.tile_size : hydro::tiled::tile_size_for(h.cols, h.rows, o.memory_limit_mb, threads, reserved_mb);
  const hydro::tiled::TileGrid grid(h.cols, h.rows, o.tile_size);
  auto tile_path = [&](const Layer& l, int t) { return MosaicFiles{out.string(), l.name}.tile(t, grid.across()); };
  hydro::tiled::TileSinks sinks;
  if (q.filled) sinks.filled = [&](int t, const Dem& z) { write_raster(tile_path(layers[0], t), z, q.filled_file); };
  if (q.flowdir)
    sinks.d8 = [&](int t, const Raster<std::uint8_t>& d8) {
      write_raster(tile_path(layers[1], t), hydro::encode_d8(d8, q.codes), q.flowdir_file);
    };
  if (q.accumulation)
    sinks.accumulation = [&](int t, const Raster<double>& acc) {
      Raster<float> v = acc.like<float>(NAN);
      for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(acc[i] * q.accumulation_scale);
      write_raster(tile_path(layers[2], t), v, q.accumulation_file);
    };
  if (q.basins)
    sinks.basins = [&](int t, const Raster<std::uint32_t>& b) { write_raster(tile_path(layers[3], t), b, q.basins_file); };
  std::optional<VectorLayer> streams;  // rank 0's, written once the filled tiles are (the river types read them)
  if (q.streams)
    sinks.streams = [&](hydro::StreamCells& cells) {
      streams = hydro::streams_of_cells(cells, h.georef, cell_metrics(h.georef, h.cols, h.rows), context.progress);
      cells = {};
    };
  const hydro::tiled::TiledReport report = hydro::tiled::run_tiled_hydro(
      h.cols, h.rows, h.georef, [&](int c0, int r0, int c, int r) { return reader.read(c0, r0, c, r); }, o, sinks,
      context.progress, driver);
  if (!leader) return {};
  for (const Layer& l : layers)
    if (l.wanted) MosaicFiles{out.string(), l.name}.finish(grid.count(), grid.across());
  const std::size_t reaches = streams ? streams->features.size() : 0;
  if (streams && q.river_types) {  // each reach's ends read from the filled tiles
    hydro::classify_streams(*streams, DemWindowReader(MosaicFiles{out.string(), "filled"}.vrt()), h.georef, q.sea_level, *q.river_types);
    write_text_file((out / "streams.qml").string(), hydro::river_types_qml(), false);
  }
  if (streams) write_vector((out / "streams.geojson").string(), *streams);
  char line[560];
  std::snprintf(line, sizeof line,
                "tiles: %d of %d cells a side, %d at once; %llu spill labels, %llu edges; %llu cells of flats across tiles (%llu rounds); "
                "%llu links; %llu stream cells; state %.1f MB a tile + %.1f MB global + %.0f MB reader and process; peak resident %.0f MB; %d process%s; "
                "exchanged %.2f MB sent, %.2f MB received",
                report.tiles, report.tile_size, report.concurrent_tiles, (unsigned long long)report.labels,
                (unsigned long long)report.spill_edges, (unsigned long long)report.flat_cells_shared, (unsigned long long)report.flat_rounds,
                (unsigned long long)report.links, (unsigned long long)report.stream_cells, report.tile_state_bytes / 1e6, report.global_state_bytes / 1e6,
                reserved_mb, peak_resident_mb(), driver.ranks(), driver.ranks() == 1 ? "" : "es", double(report.bytes_sent) / 1e6,
                double(report.bytes_received) / 1e6);
  context.log.detail(line);
  return "hydro: wrote " + q.out_name + " (" + std::to_string(report.tiles) + " tiles" +
         (q.streams ? ", " + std::to_string(reaches) + " stream reaches)" : ")");
}

}  // namespace

void set_tile_distribution(TileDistribution* d) { distribution = d; }

std::string run_tiled_hydro_command(const TiledHydroRequest& q, Context& context) {
  if (!distribution) {
    hydro::tiled::LocalTiles local;
    return run_tiled_hydro_tiles(q, context, local);
  }
  distribution->start(q, context);
  return run_tiled_hydro_tiles(q, context, distribution->driver());
}

std::string run_tiled_hydro_tiles(const TiledHydroRequest& q, Context& context, hydro::tiled::TileDriver& driver) {
  try {
    return tiles_of_this_process(q, context, driver);
  } catch (...) {
    driver.check(std::current_exception());  // every process learns of it and throws it
    throw;
  }
}

}  // namespace terrapolis::cli
