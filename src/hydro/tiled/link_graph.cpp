// The link graph of the tile engine (Barnes 2017): the links of every tile chained through the
// tiles they flow into, their sums solved in topological order; basin labels from the outlets.
// SPDX-License-Identifier: MIT
#include <algorithm>

#include "core/error.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {

/// The exit (>= 0) or outlet (-3 - j) of the path through mosaic cell `g` of tile `u`.
std::int32_t TiledRun::edge_exit_at(std::int64_t g, int& u) const {
  const int gc = int(g % cols_), gr = int(g / cols_);
  u = grid_.tile_of(gc, gr);
  const TileRect ru = grid_.rect(u);
  return edge_exit_[std::size_t(u)][Frame(ru, false).index(gc - ru.col0, gr - ru.row0)];
}

/// Outlet j of tile u: its basin label, outlets numbered in row-major order of the mosaic.
std::uint32_t TiledRun::basin_of_outlet(int u, std::uint32_t j) const {
  const auto& above = outlets_above_[std::size_t(u)];
  const std::size_t row = std::size_t(std::upper_bound(above.begin(), above.end(), j) - above.begin()) - 1;
  std::uint64_t rank = before_row_[std::size_t(grid_.rect(u).row0) + row] + (j - above[row]);
  for (int v = u - u % grid_.across(); v < u; ++v) rank += outlet_rows_[std::size_t(v)][row];  // on the row, to the west
  return std::uint32_t(rank + 1);
}

// The link graph: each link flows into the tile of its target and leaves it by that cell's
// exit; solved in topological order, the sums exact.
void TiledRun::solve_link_graph() {
  link_base_.assign(static_cast<std::size_t>(tiles_) + 1, 0);
  for (int t = 0; t < tiles_; ++t) link_base_[std::size_t(t) + 1] = link_base_[std::size_t(t)] + std::uint32_t(links_[std::size_t(t)].size());
  const std::uint32_t link_count = link_base_.back();
  report_.links = link_count;
  std::vector<Link> all;
  all.reserve(link_count);
  for (auto& l : links_) {
    all.insert(all.end(), l.begin(), l.end());
    release(l);
  }
  std::vector<std::int64_t> next(link_count, -1);
  std::vector<std::uint32_t> indegree(link_count, 0);
  for (std::uint32_t y = 0; y < link_count; ++y) {
    int u = 0;
    const std::int32_t e = edge_exit_at(all[y].target, u);
    if (e >= 0) {
      next[y] = link_base_[std::size_t(u)] + std::uint32_t(e);
      ++indegree[std::size_t(next[y])];
    }
  }
  number_outlets();
  if (sinks_.basins) label_links(all, next);
  release(edge_exit_);
  std::vector<std::int64_t> total(link_count);
  for (std::uint32_t y = 0; y < link_count; ++y) total[y] = all[y].local;
  std::vector<std::uint32_t> ready;
  for (std::uint32_t y = 0; y < link_count; ++y)
    if (indegree[y] == 0) ready.push_back(y);
  while (!ready.empty()) {
    const std::uint32_t y = ready.back();
    ready.pop_back();
    if (next[y] < 0) continue;
    const std::size_t x = std::size_t(next[y]);
    total[x] += total[y];
    if (--indegree[x] == 0) ready.push_back(std::uint32_t(x));
  }
  // What flows into each tile, by target cell.
  inflow_.resize(static_cast<std::size_t>(tiles_));
  for (std::uint32_t y = 0; y < link_count; ++y) {
    const int gc = int(all[y].target % cols_), gr = int(all[y].target / cols_);
    const int u = grid_.tile_of(gc, gr);
    const TileRect ru = grid_.rect(u);
    inflow_[std::size_t(u)].push_back({std::uint32_t((gr - ru.row0) * ru.cols + (gc - ru.col0)), total[y]});
  }
  report_.global_state_bytes = std::max(report_.global_state_bytes, frame_bytes_ + double(link_count) * 60 + double(rows_) * 16);
}

// Basins: outlets numbered in row-major order of the mosaic (drainage_basins), from the tiles'
// outlets by row.
void TiledRun::number_outlets() {
  before_row_.assign(std::size_t(rows_) + 1, 0);  // outlets of the mosaic's rows above
  outlets_above_.resize(static_cast<std::size_t>(tiles_));  // a tile's, above each row
  for (int t = 0; t < tiles_; ++t) {
    const TileRect r = grid_.rect(t);
    auto& above = outlets_above_[std::size_t(t)];
    above.assign(std::size_t(r.rows) + 1, 0);
    for (int row = 0; row < r.rows; ++row) {
      const std::uint32_t n = outlet_rows_[std::size_t(t)][std::size_t(row)];
      above[std::size_t(row) + 1] = above[std::size_t(row)] + n;
      before_row_[std::size_t(r.row0 + row) + 1] += n;
    }
  }
  for (int row = 0; row < rows_; ++row) before_row_[std::size_t(row) + 1] += before_row_[std::size_t(row)];
  if (sinks_.basins && before_row_.back() >= 0xFFFFFFFFu) throw bad_input("basins: more than 2^32 - 2 outlets");
}

/// Each link labelled with the basin its chain of links ends in.
void TiledRun::label_links(const std::vector<Link>& all, const std::vector<std::int64_t>& next) {
  link_basin_.assign(all.size(), 0);
  std::vector<std::uint32_t> chain;
  for (std::uint32_t y = 0; y < link_basin_.size(); ++y) {
    chain.clear();
    std::uint32_t z = y;
    for (; link_basin_[z] == 0 && next[z] >= 0; z = std::uint32_t(next[z])) chain.push_back(z);
    if (link_basin_[z] == 0) {
      int u = 0;
      const std::int32_t e = edge_exit_at(all[z].target, u);
      link_basin_[z] = basin_of_outlet(u, std::uint32_t(-3 - e));
    }
    for (std::uint32_t x : chain) link_basin_[x] = link_basin_[z];
  }
}

}  // namespace terrapolis::hydro::tiled
