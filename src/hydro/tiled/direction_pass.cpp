// Pass 2 of the tile engine: each tile filled again to its labels' levels, first-pass D8 on it and
// a one-cell halo, the flats inside it drained; the cells of flats that reach the halo shared.
// SPDX-License-Identifier: MIT
#include <limits>

#include "hydro/flow_directions.hpp"
#include "hydro/tiled/tile_bytes.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {
namespace {

bool out_code(std::uint8_t v) { return v == kNoData || v == kTerminal; }  // drain_flats' "outside" cells

}  // namespace

// The equal-elevation components are drain_flats' flats and the draining cells that join them.
std::vector<std::uint8_t> flats_reaching_halo(const Dem& near, const Raster<std::uint8_t>& first) {
  std::vector<std::uint8_t> member(near.size(), 0);
  std::vector<std::size_t> stack;
  for (int row = 0; row < near.rows(); ++row)
    for (int c = 0; c < near.cols(); ++c) {
      if (row != 0 && c != 0 && row != near.rows() - 1 && c != near.cols() - 1) continue;
      const std::size_t i = near.index(c, row);
      if (out_code(first[i])) continue;
      member[i] = 1;
      stack.push_back(i);
    }
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const int c = int(i % std::size_t(near.cols())), row = int(i / std::size_t(near.cols()));
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[k], nr = row + drow[k];
      if (!near.inside(nc, nr)) continue;
      const std::size_t n = near.index(nc, nr);
      if (member[n] || out_code(first[n]) || near[n] != near[i]) continue;
      member[n] = 1;
      stack.push_back(n);
    }
  }
  return member;
}

// 2. Filled tiles (the flood again, each cell raised to its label's level), first-pass D8 on
// the tile and a one-cell halo, flats inside the tile drained; cells of flats reaching the halo
// handed on: the pieces of them in the tile and its outer ring's cells in them.
void TiledRun::direct_tiles() {
  ring_.resize(static_cast<std::size_t>(tiles_));
  pieces_.resize(static_cast<std::size_t>(tiles_));
  flat_cells_.assign(static_cast<std::size_t>(tiles_), 0);
  std::exception_ptr failure = for_tiles("flow directions of tiles", [&](int t, const TileRect& r) { direct_tile(t, r); });
  exchange(
      failure,
      [&](int t, std::vector<char>& out) {
        put(out, ring_[std::size_t(t)]);
        put(out, pieces_[std::size_t(t)]);
        put(out, std::vector<std::uint64_t>{flat_cells_[std::size_t(t)]});
      },
      [&](int t, Unpack& in) {
        ring_[std::size_t(t)] = in.take<RingCell>();
        pieces_[std::size_t(t)] = in.take<FlatPiece>();
        const std::vector<std::uint64_t> cells = in.take<std::uint64_t>();
        flat_cells_[std::size_t(t)] = cells.empty() ? 0 : cells[0];
      });
}

void TiledRun::direct_tile(int t, const TileRect& r) {
  TileFill f = fill_tile(read_tile(r), options_.sea_level);
  for (std::size_t i = 0; i < f.z.size(); ++i) f.z[i] = final_z(f.z[i], global(t, f.label[i]));
  release(f.label);
  f.z.georef() = shifted(georef_, r.col0, r.row0);
  if (sinks_.filled) sinks_.filled(t, f.z);
  Dem wide = with_halo(r, f.z);
  f.z = Dem();
  // The tile with a halo of one cell: filled values and first-pass codes.
  Dem near(r.cols + 2, r.rows + 2, shifted(georef_, r.col0 - 1, r.row0 - 1));
  Raster<std::uint8_t> first = near.like<std::uint8_t>(kNoData);
  bool any_flat = false;
  for (int row = 0; row < near.rows(); ++row) {
    const int gr = r.row0 - 1 + row;
    double step[8];
    if (gr >= 0 && gr < rows_)
      for (int k = 0; k < 8; ++k) step[k] = metrics_.step_m(gr, k);
    for (int c = 0; c < near.cols(); ++c) {
      near(c, row) = wide(c + 1, row + 1);
      if (gr < 0 || gr >= rows_) continue;
      first(c, row) = d8_first_pass(wide, step, options_.sea_level, c + 1, row + 1);
      any_flat |= first(c, row) == kNoFlow;
    }
  }
  wide = Dem();
  Raster<std::uint8_t> drained = first;
  if (any_flat) drain_flats(near, drained);
  const std::vector<std::uint8_t> member = flats_reaching_halo(near, first);
  Raster<std::uint8_t> d8 = tile_codes(r);
  d8.nodata = kNoData;
  bool any_member = false;
  for (int row = 0; row < r.rows; ++row)
    for (int c = 0; c < r.cols; ++c) {
      const std::size_t i = near.index(c + 1, row + 1);
      d8(c, row) = member[i] ? first[i] : drained[i];  // shared flats: drained by tiles later
      any_member |= member[i] != 0;
    }
  if (any_member) share_tile_flats(t, r, near, first, member);
  write_codes(codes_path(t), d8);
}

/// The filled tile `filled` with a halo of two cells (from the neighbours' frames), NaN off the mosaic.
Dem TiledRun::with_halo(const TileRect& r, const Dem& filled) const {
  Dem wide(r.cols + 4, r.rows + 4, shifted(georef_, r.col0 - 2, r.row0 - 2), std::numeric_limits<float>::quiet_NaN());
  for (int row = 0; row < wide.rows(); ++row)
    for (int c = 0; c < wide.cols(); ++c) {
      const int gc = r.col0 - 2 + c, gr = r.row0 - 2 + row;
      if (off_mosaic(gc, gr)) continue;
      if (gc >= r.col0 && gr >= r.row0 && gc < r.col0 + r.cols && gr < r.row0 + r.rows) {
        wide(c, row) = filled(gc - r.col0, gr - r.row0);
      } else {
        float z;
        std::uint32_t label;
        frame_cell(gc, gr, z, label);
        wide(c, row) = final_z(z, label);
      }
    }
  return wide;
}

}  // namespace terrapolis::hydro::tiled
