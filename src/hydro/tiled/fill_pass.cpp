// Pass 1 of the tile engine (Barnes 2016): each tile filled with its edges as outlets, its frame
// and spill edges shared, and the spill graph of the whole mosaic solved.
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <deque>

#include "core/error.hpp"
#include "hydro/flood_queue.hpp"
#include "hydro/tiled/tile_bytes.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {

TileFill fill_tile(const Dem& window, const std::optional<double>& sea_level) {
  const int cols = window.cols() - 2, rows = window.rows() - 2;
  TileFill f;
  f.z = Dem(cols, rows, shifted(window.georef(), 1, 1));
  for (int r = 0; r < rows; ++r) std::copy_n(&window(1, r + 1), cols, &f.z(0, r));
  f.label.assign(f.z.size(), kOpen);
  Dem& z = f.z;
  RadixQueue open;
  std::deque<std::uint32_t> pit;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = z.index(c, r);
      if (std::isnan(z[i])) {
        f.label[i] = kVoid;
        continue;
      }
      bool outlet = is_sea(z[i], sea_level);
      for (int k = 0; k < 8 && !outlet; ++k) outlet = std::isnan(window(c + 1 + dcol[k], r + 1 + drow[k]));
      if (outlet) {
        f.label[i] = 0;
      } else if (r == 0 || c == 0 || r == rows - 1 || c == cols - 1) {
        f.label[i] = f.labels++;
      } else {
        continue;
      }
      open.push(flood_key(z[i], std::uint32_t(i)));
    }
  while (!open.empty() || !pit.empty()) {
    const std::uint32_t i = next_cell(open, pit);
    flood_neighbours(i, cols, 0, rows, z, f.label.data(), kOpen, kVoid, open, pit,
                     [&](std::uint32_t a, std::uint32_t b, float spill) { f.edges.push_back({a, b, spill}); });
    if (f.edges.size() > (std::size_t(1) << 20)) keep_lowest_edges(f.edges);
  }
  keep_lowest_edges(f.edges);
  f.edges.shrink_to_fit();  // kept until the spill graph is solved: the lowest edges only, not the 2^20 before
  return f;
}

// 1. Each tile filled with its edges as outlets; its frame and spill edges kept (Barnes 2016).
void TiledRun::fill_tiles() {
  frames_.resize(static_cast<std::size_t>(tiles_));
  tile_edges_.resize(static_cast<std::size_t>(tiles_));
  tile_labels_.resize(static_cast<std::size_t>(tiles_));
  std::exception_ptr failure = for_tiles("fill tiles", [&](int t, const TileRect& r) {
    TileFill f = fill_tile(read_tile(r), options_.sea_level);
    Frame frame(r);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c)
        if (frame.contains(c, row)) {
          const std::size_t i = f.z.index(c, row), j = frame.index(c, row);
          frame.z[j] = f.z[i];
          frame.label[j] = f.label[i];  // local for now
        }
    frames_[std::size_t(t)] = std::move(frame);
    tile_edges_[std::size_t(t)] = std::move(f.edges);
    tile_labels_[std::size_t(t)] = f.labels;
  });
  exchange(
      failure,
      [&](int t, std::vector<char>& out) {
        put(out, frames_[std::size_t(t)].z);
        put(out, frames_[std::size_t(t)].label);
        put(out, tile_edges_[std::size_t(t)]);
        put(out, std::vector<std::uint32_t>{tile_labels_[std::size_t(t)]});
      },
      [&](int t, Unpack& in) {
        Frame& frame = frames_[std::size_t(t)] = Frame(grid_.rect(t), false);
        frame.z = in.take<float>();
        frame.label = in.take<std::uint32_t>();
        tile_edges_[std::size_t(t)] = in.take<SpillEdge>();
        tile_labels_[std::size_t(t)] = in.take<std::uint32_t>().at(0);
      });
}

/// The tiles' labels made global, the spill edges across tile edges added, and the spill graph
/// solved: the level each label fills to.
void TiledRun::solve_spill_graph() {
  base_.resize(static_cast<std::size_t>(tiles_));
  std::uint64_t nodes = 1;
  for (int t = 0; t < tiles_; ++t) {
    base_[std::size_t(t)] = std::uint32_t(nodes - 1);
    nodes += tile_labels_[std::size_t(t)] - 1;
  }
  if (nodes >= kOpen) throw bad_input("tiles: too many tile-edge labels; use larger tiles (--tile-size)");
  std::vector<SpillEdge> edges;
  for (int t = 0; t < tiles_; ++t) {
    for (SpillEdge e : tile_edges_[std::size_t(t)]) edges.push_back({global(t, e.a), global(t, e.b), e.spill});
    release(tile_edges_[std::size_t(t)]);
    for (auto& l : frames_[std::size_t(t)].label) l = global(t, l);
  }
  add_edges_across_tiles(edges);
  report_.labels = nodes;
  report_.spill_edges = edges.size();
  for (const auto& f : frames_) frame_bytes_ += double(f.z.size()) * 12;  // frame values + edge exits
  report_.global_state_bytes = frame_bytes_ + double(nodes) * 12 + double(edges.size()) * 28;
  level_ = spill_levels(std::uint32_t(nodes), edges);
}

/// Spill edges across tile edges, each pair of cells once (from the lower-numbered tile).
void TiledRun::add_edges_across_tiles(std::vector<SpillEdge>& edges) const {
  for (int t = 0; t < tiles_; ++t) {
    const TileRect r = grid_.rect(t);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c) {
        if (row != 0 && c != 0 && row != r.rows - 1 && c != r.cols - 1) continue;
        float za;
        std::uint32_t la;
        frame_cell(r.col0 + c, r.row0 + row, za, la);
        if (la == kVoid) continue;
        for (int k = 0; k < 8; ++k) {
          const int gc = r.col0 + c + dcol[k], gr = r.row0 + row + drow[k];
          if (off_mosaic(gc, gr) || grid_.tile_of(gc, gr) <= t) continue;
          float zb;
          std::uint32_t lb;
          frame_cell(gc, gr, zb, lb);
          if (lb != kVoid && lb != la) edges.push_back({la, lb, std::max(za, zb)});
        }
      }
  }
}

}  // namespace terrapolis::hydro::tiled
