// Pass 4 of the tile engine: each tile's accumulation again with what flows in from the other
// tiles, its basins labelled, the outputs handed to the sinks; the stream cells gathered on rank 0.
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "hydro/catchment.hpp"
#include "hydro/exact_accumulation.hpp"
#include "hydro/tiled/tile_bytes.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {

// 4. The accumulation again, with what flows in from the other tiles; the stream cells kept.
// False when there are no streams to gather (every process's tiles written).
bool TiledRun::final_accumulation() {
  if (sinks_.streams && options_.unit != AccumulationUnit::area_m2)
    throw bad_input("tiles: streams need the accumulation as an area (--area-units m2 or km2)");
  stream_cells_.resize(static_cast<std::size_t>(tiles_));
  std::exception_ptr failure = nullptr;
  if (sinks_.accumulation || sinks_.streams || sinks_.basins)
    failure = for_tiles("accumulation", [&](int t, const TileRect& r) { finish_tile(t, r); });
  if (!sinks_.streams) {
    driver_.check(failure);
    return false;
  }
  exchange(
      failure, [&](int t, std::vector<char>& out) { put(out, stream_cells_[std::size_t(t)]); },
      [&](int t, Unpack& in) { stream_cells_[std::size_t(t)] = in.take<StreamCell>(); });
  return true;
}

void TiledRun::finish_tile(int t, const TileRect& r) {
  Raster<std::uint8_t> d8 = tile_codes(r);
  read_codes(codes_path(t), d8);
  if (sinks_.basins) {
    Raster<std::uint32_t> basins = d8.like<std::uint32_t>(0);
    basins.nodata = 0;
    const PathEnds ends = path_ends(t, r, d8);
    for (std::size_t e = 0; e < ends.exits.size(); ++e) basins[ends.exits[e]] = link_basin_[link_base_[std::size_t(t)] + e];
    for (std::size_t j = 0; j < ends.outlets.size(); ++j) basins[ends.outlets[j]] = basin_of_outlet(t, std::uint32_t(j));
    label_by_descent(d8, basins);
    sinks_.basins(t, basins);
  }
  if (!sinks_.accumulation && !sinks_.streams) return;
  std::vector<std::int64_t> acc = own_units(d8, r);
  for (const auto& [i, v] : inflow_[std::size_t(t)]) acc[i] += v;
  release(inflow_[std::size_t(t)]);
  accumulate_d8_units(d8, acc);
  Raster<double> out = d8.like<double>(0.0);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = d8[i] == kNoData ? NAN : units_.value(acc[i]);
  if (sinks_.streams)
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c)
        if (const double a = out(c, row); d8(c, row) != kNoData && a >= options_.streams_threshold_m2)
          stream_cells_[std::size_t(t)].push_back({std::int64_t(r.row0 + row) * cols_ + r.col0 + c, a, d8(c, row)});
  if (sinks_.accumulation) sinks_.accumulation(t, out);
}

/// The stream cells of every tile, in mosaic order, handed to the streams sink on rank 0.
void TiledRun::gather_streams() {
  if (driver_.rank() != 0) return;
  std::vector<StreamCell> network;
  for (auto& part : stream_cells_) {
    network.insert(network.end(), part.begin(), part.end());
    release(part);
  }
  std::sort(network.begin(), network.end(), [](const StreamCell& a, const StreamCell& b) { return a.index < b.index; });
  StreamCells streams{cols_, rows_, {}, {}, {}};
  for (const StreamCell& cell : network) {
    streams.index.push_back(cell.index);
    streams.code.push_back(cell.code);
    streams.area_m2.push_back(cell.area_m2);
  }
  report_.stream_cells = network.size();
  report_.global_state_bytes = std::max(report_.global_state_bytes, frame_bytes_ + double(network.size()) * 40);
  release(network);
  sinks_.streams(streams);
}

}  // namespace terrapolis::hydro::tiled
