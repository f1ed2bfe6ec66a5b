// Pass 3 of the tile engine (Barnes 2017): each tile's final directions (its own and those of the
// shared flats' cells in it), the accumulation inside it, and the links by which its flow leaves it.
// SPDX-License-Identifier: MIT
#include "hydro/exact_accumulation.hpp"
#include "hydro/tiled/tile_bytes.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {
namespace {

/// For each edge cell of a tile (Frame order, first ring only used), the end of its path as in
/// `down` (filled in along the way).
std::vector<std::int32_t> edge_exits(const TileRect& r, const Raster<std::uint8_t>& d8, std::vector<std::int32_t>& down) {
  std::vector<std::size_t> path;
  const Frame frame(r, false);
  std::vector<std::int32_t> exits(frame.size(), -1);
  for (int row = 0; row < r.rows; ++row)
    for (int c = 0; c < r.cols; ++c) {
      if (row != 0 && c != 0 && row != r.rows - 1 && c != r.cols - 1) continue;
      std::size_t i = d8.index(c, row);
      path.clear();
      std::int32_t exit = -1;
      for (;;) {
        if (down[i] != -2) {
          exit = down[i];
          break;
        }
        path.push_back(i);
        const std::uint8_t k = d8[i];
        const int nc = int(i % std::size_t(r.cols)) + (k < 8 ? dcol[k] : 0), nr = int(i / std::size_t(r.cols)) + (k < 8 ? drow[k] : 0);
        if (k >= 8 || !d8.inside(nc, nr) || d8(nc, nr) == kNoData) break;
        i = d8.index(nc, nr);
      }
      for (std::size_t p : path) down[p] = exit;
      exits[frame.index(c, row)] = exit;
    }
  return exits;
}

}  // namespace

std::vector<std::int64_t> TiledRun::own_units(const Raster<std::uint8_t>& d8, const TileRect& r) const {
  std::vector<std::int64_t> acc(d8.size(), 0);
  for (int row = 0; row < r.rows; ++row)
    for (int c = 0; c < r.cols; ++c)
      if (d8(c, row) != kNoData) acc[d8.index(c, row)] = units_.per_row[std::size_t(r.row0 + row)];
  return acc;
}

/// Target of the D8 code of mosaic cell (gc, gr) when it lies in another tile on valid data, else -1.
std::int64_t TiledRun::crossing(int t, int gc, int gr, std::uint8_t k) const {
  if (k >= 8) return -1;
  const int nc = gc + dcol[k], nr = gr + drow[k];
  if (off_mosaic(nc, nr) || grid_.tile_of(nc, nr) == t) return -1;
  float z;
  std::uint32_t label;
  frame_cell(nc, nr, z, label);
  return label == kVoid ? -1 : std::int64_t(nr) * cols_ + nc;
}

TiledRun::PathEnds TiledRun::path_ends(int t, const TileRect& r, const Raster<std::uint8_t>& d8) const {
  PathEnds ends;
  for (int row = 0; row < r.rows; ++row)
    for (int c = 0; c < r.cols; ++c) {
      const std::uint8_t k = d8(c, row);
      if (k == kNoData) continue;
      const std::uint32_t i = std::uint32_t(d8.index(c, row));
      const int nc = c + (k < 8 ? dcol[k] : 0), nr = row + (k < 8 ? drow[k] : 0);
      if (k < 8 && d8.inside(nc, nr)) {
        if (d8(nc, nr) == kNoData) ends.outlets.push_back(i);
        continue;
      }
      if (const std::int64_t target = crossing(t, r.col0 + c, r.row0 + row, k); target >= 0) {
        ends.exits.push_back(i);
        ends.targets.push_back(target);
      } else {
        ends.outlets.push_back(i);
      }
    }
  return ends;
}

// 3. Final directions; accumulation inside each tile; the links between tiles (Barnes 2017).
void TiledRun::accumulate_tiles() {
  units_ = fixed_point_units(metrics_, cols_, options_.unit);
  links_.resize(static_cast<std::size_t>(tiles_));
  outlet_rows_.resize(static_cast<std::size_t>(tiles_));
  edge_exit_.resize(static_cast<std::size_t>(tiles_));
  std::exception_ptr failure = for_tiles("accumulation of tiles", [&](int t, const TileRect& r) { accumulate_tile(t, r); });
  exchange(
      failure,
      [&](int t, std::vector<char>& out) {
        put(out, links_[std::size_t(t)]);
        put(out, edge_exit_[std::size_t(t)]);
        put(out, outlet_rows_[std::size_t(t)]);
      },
      [&](int t, Unpack& in) {
        links_[std::size_t(t)] = in.take<Link>();
        edge_exit_[std::size_t(t)] = in.take<std::int32_t>();
        outlet_rows_[std::size_t(t)] = in.take<std::uint32_t>();
      });
  release(ring_);
  release(pieces_);
}

void TiledRun::accumulate_tile(int t, const TileRect& r) {
  Raster<std::uint8_t> d8 = tile_codes(r);
  d8.nodata = kNoData;
  read_codes(codes_path(t), d8);
  if (flat_cells_[std::size_t(t)] > 0) direct_tile_flats(t, r, d8);
  if (sinks_.d8) sinks_.d8(t, d8);
  write_codes(codes_path(t), d8);
  std::vector<std::int64_t> acc = own_units(d8, r);
  accumulate_d8_units(d8, acc);
  // Exits and outlets, then for each edge cell where its path ends: exit e >= 0, outlet j of the
  // tile (row-major) as -3 - j, -1 on nodata.
  std::vector<std::int32_t> down(d8.size(), -2);
  const PathEnds ends = path_ends(t, r, d8);
  auto& out = links_[std::size_t(t)];
  for (std::size_t e = 0; e < ends.exits.size(); ++e) {
    const std::uint32_t i = ends.exits[e];
    down[i] = std::int32_t(e);
    out.push_back({std::int64_t(r.row0) * cols_ + r.col0 + std::int64_t(i / std::uint32_t(r.cols)) * cols_ + i % std::uint32_t(r.cols),
                   ends.targets[e], acc[i]});
  }
  std::vector<std::uint32_t>& per_row = outlet_rows_[std::size_t(t)];
  per_row.assign(std::size_t(r.rows), 0);
  for (std::size_t j = 0; j < ends.outlets.size(); ++j) {
    down[ends.outlets[j]] = -3 - std::int32_t(j);
    ++per_row[ends.outlets[j] / std::uint32_t(r.cols)];
  }
  edge_exit_[std::size_t(t)] = edge_exits(r, d8, down);
}

}  // namespace terrapolis::hydro::tiled
