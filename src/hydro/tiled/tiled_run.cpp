// One run of the tile engine: its passes in order, the D8 codes kept between them on scratch
// files, and run_tiled_hydro.
// SPDX-License-Identifier: MIT
#include "hydro/tiled/tiled_run.hpp"

#include <algorithm>
#include <fstream>

#include "core/error.hpp"

namespace terrapolis::hydro::tiled {

void write_codes(const std::string& path, const Raster<std::uint8_t>& d8) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(d8.data()), std::streamsize(d8.size()));
  if (!out) throw bad_input(path + ": cannot write scratch data (disk full?)");
}

void read_codes(const std::string& path, Raster<std::uint8_t>& d8) {
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(d8.data()), std::streamsize(d8.size()));
  if (!in) throw bad_input(path + ": cannot read scratch data back");
}

namespace {

TiledReport sized_report(int cols, int rows, const TiledOptions& options) {
  TiledReport report;
  report.concurrent_tiles = options.concurrent_tiles > 0 ? options.concurrent_tiles : allowed_threads();
  report.tile_size = options.tile_size > 0 ? std::max(options.tile_size, 8)
                                           : tile_size_for(cols, rows, options.memory_limit_mb, report.concurrent_tiles, options.reserved_mb);
  report.tile_state_bytes = kTileBytesPerCell * double(report.tile_size + 4) * double(report.tile_size + 4);
  return report;
}

}  // namespace

TiledRun::TiledRun(int cols, int rows, const Georef& georef, const ReadWindow& read, const TiledOptions& options, const TileSinks& sinks,
                   Progress& progress, TileDriver& driver)
    : cols_(cols), rows_(rows), georef_(georef), read_(read), options_(options), sinks_(sinks), progress_(progress), driver_(driver),
      report_(sized_report(cols, rows, options)), grid_(cols, rows, report_.tile_size), tiles_(grid_.count()),
      metrics_(cell_metrics(georef, cols, rows)), arena_(report_.concurrent_tiles),
      scratch_(options.scratch_dir.empty() ? std::filesystem::temp_directory_path() : std::filesystem::path(options.scratch_dir)) {
  report_.tiles = tiles_;
  for (int t = 0; t < tiles_; ++t)
    if (driver.owns(t)) own_.push_back(t);
}

TiledRun::~TiledRun() {
  std::error_code ec;
  for (int t = 0; t < tiles_; ++t) {
    std::filesystem::remove(codes_path(t), ec);
    std::filesystem::remove(flats_path(t), ec);
  }
}

TiledReport TiledRun::run() {
  fill_tiles();
  solve_spill_graph();
  direct_tiles();
  solve_shared_flats();
  accumulate_tiles();
  solve_link_graph();
  if (!final_accumulation()) return report_;
  gather_streams();
  return report_;
}

TiledReport run_tiled_hydro(int cols, int rows, const Georef& georef, const ReadWindow& read, const TiledOptions& options,
                            const TileSinks& sinks, Progress& progress, TileDriver& driver) {
  TiledRun run(cols, rows, georef, read, options, sinks, progress, driver);
  return run.run();
}

}  // namespace terrapolis::hydro::tiled
