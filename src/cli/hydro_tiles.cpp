// The tiled hydro command: the tile engine between a mosaic reader and per-tile GeoTIFFs + VRTs.
// SPDX-License-Identifier: MIT
#include "cli/hydro_tiles.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <algorithm>
#include <fstream>
#include <mutex>

#include "core/error.hpp"
#include "hydro/tiled/tiled_hydro.hpp"

namespace terrapolis::cli {
namespace {

namespace fs = std::filesystem;

/// Peak resident memory of this process (Linux VmHWM), MB; 0 elsewhere.
double peak_resident_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

}  // namespace

std::string run_tiled_hydro_command(const TiledHydroRequest& q, Context& context) {
  const DemWindowReader reader(q.dem_path, q.read);
  const RasterHeader& h = reader.header();
  const fs::path out(q.out_dir);  // a fresh staging folder (OutputSet): no earlier tiles in it
  struct Layer {
    std::string name;
    bool wanted;
    const WriteOptions* options;
    std::vector<std::string> tiles;
  };
  Layer layers[3] = {{"filled", q.filled, &q.filled_file, {}},
                     {"flowdir", q.flowdir, &q.flowdir_file, {}},
                     {"accumulation", q.accumulation, &q.accumulation_file, {}}};
  hydro::tiled::TiledOptions o;
  o.tile_size = q.tile_size;
  o.memory_limit_mb = q.memory_limit_mb;
  o.sea_level = q.sea_level;
  o.unit = q.unit;
  const int threads = context.threads > 0 ? context.threads : int(std::max(1L, sysconf(_SC_NPROCESSORS_ONLN)));
  o.concurrent_tiles = threads;
  std::mutex tiles_mutex;
  for (Layer& l : layers)
    if (l.wanted) fs::create_directory(out / l.name);
  const fs::path scratch = out / (".scratch-" + std::to_string(getpid()));
  fs::create_directory(scratch);
  o.scratch_dir = scratch.string();
  o.tile_size = q.tile_size > 0 ? q.tile_size : hydro::tiled::tile_size_for(h.cols, h.rows, q.memory_limit_mb, threads);
  const int across = hydro::tiled::TileGrid(h.cols, h.rows, o.tile_size).across();
  auto tile_path = [&](Layer& l, int t) {
    char name[64];
    std::snprintf(name, sizeof name, "tile_%04d_%04d.tif", t / across, t % across);
    const std::string p = (out / l.name / name).string();
    std::lock_guard lock(tiles_mutex);
    l.tiles.push_back(p);
    return p;
  };
  hydro::tiled::TileSinks sinks;
  if (q.filled) sinks.filled = [&](int t, const Dem& z) { write_raster(tile_path(layers[0], t), z, q.filled_file); };
  if (q.flowdir)
    sinks.d8 = [&](int t, const Raster<std::uint8_t>& d8) { write_raster(tile_path(layers[1], t), hydro::encode_d8(d8, q.codes), q.flowdir_file); };
  if (q.accumulation)
    sinks.accumulation = [&](int t, const Raster<double>& acc) {
      Raster<float> v = acc.like<float>(NAN);
      for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(acc[i] * q.accumulation_scale);
      write_raster(tile_path(layers[2], t), v, q.accumulation_file);
    };
  const hydro::tiled::TiledReport report = hydro::tiled::run_tiled_hydro(
      h.cols, h.rows, h.georef, [&](int c0, int r0, int c, int r) { return reader.read(c0, r0, c, r); }, o, sinks,
      context.progress);
  fs::remove_all(scratch);
  for (Layer& l : layers)
    if (l.wanted) {
      std::sort(l.tiles.begin(), l.tiles.end());
      const std::string vrt = (out / (l.name + ".vrt")).string();
      write_vrt(vrt, l.tiles, false);
    }
  char line[400];
  std::snprintf(line, sizeof line,
                "tiles: %d of %d cells a side, %d at once; %llu spill labels, %llu edges; %llu cells of flats across tiles; "
                "%llu links; state %.1f MB a tile + %.1f MB global; peak resident %.0f MB",
                report.tiles, report.tile_size, report.concurrent_tiles, (unsigned long long)report.labels,
                (unsigned long long)report.spill_edges, (unsigned long long)report.flat_cells_shared,
                (unsigned long long)report.links, report.tile_state_bytes / 1e6, report.global_state_bytes / 1e6,
                peak_resident_mb());
  context.log.detail(line);
  return "hydro: wrote " + q.out_name + " (" + std::to_string(report.tiles) + " tiles)";
}

}  // namespace terrapolis::cli
