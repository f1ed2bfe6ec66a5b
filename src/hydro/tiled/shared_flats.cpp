// Flats that cross tile edges (Barnes et al. 2014b): the cells the tiles shared grouped into
// flats, each drained whole, and the codes it gives handed back to its tiles as patches.
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <limits>
#include <numeric>

#include "hydro/flow_directions.hpp"
#include "hydro/tiled/tiled_run.hpp"

namespace terrapolis::hydro::tiled {
namespace {

/// Union-find over the cells of flats that cross tile edges.
struct Sets {
  std::vector<std::uint32_t> parent;
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

std::int64_t TiledRun::neighbour(std::int64_t g, int k) const {
  const int gc = int(g % cols_) + dcol[k], gr = int(g / cols_) + drow[k];
  if (off_mosaic(gc, gr)) return -1;
  return std::int64_t(gr) * cols_ + gc;
}

/// Members of each equal-elevation component of shared cells that holds a flat cell, by root.
std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> TiledRun::flat_groups(const SharedFlats& s) const {
  const auto& cells = s.cells;
  Sets sets{std::vector<std::uint32_t>(cells.size())};
  std::iota(sets.parent.begin(), sets.parent.end(), 0u);
  for (std::uint32_t a = 0; a < cells.size(); ++a) {
    if (!cells[a].member) continue;
    for (int k = 0; k < 8; ++k) {
      const std::int64_t n = neighbour(s.cell_of[a], k);
      if (n < 0) continue;
      const auto it = s.slot.find(n);
      if (it != s.slot.end() && cells[it->second].member && cells[it->second].z == cells[a].z) sets.join(a, it->second);
    }
  }
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> groups;  // root -> members holding a flat cell
  std::vector<std::uint8_t> has_flat(cells.size(), 0);
  for (std::uint32_t a = 0; a < cells.size(); ++a)
    if (cells[a].member && cells[a].code == kNoFlow) has_flat[sets.find(a)] = 1;
  for (std::uint32_t a = 0; a < cells.size(); ++a)
    if (cells[a].member && has_flat[sets.find(a)]) groups[sets.find(a)].push_back(a);
  return groups;
}

// Flats that cross tile edges, each gathered whole (its cells and their neighbours) on a
// window of its bounding box and drained there: the same rings, hence the same directions.
void TiledRun::drain_shared_flats() {
  SharedFlats s;
  for (auto& list : shared_) {
    for (const auto& [g, cell] : list) {
      s.slot.emplace(g, std::uint32_t(s.cells.size()));
      s.cell_of.push_back(g);
      s.cells.push_back(cell);
    }
    list = {};
  }
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> groups = flat_groups(s);
  patches_.resize(static_cast<std::size_t>(tiles_));
  std::vector<std::uint32_t> roots;
  for (const auto& [root, members] : groups) roots.push_back(root);
  std::sort(roots.begin(), roots.end());
  for (std::uint32_t root : roots) drain_shared_flat(s, groups[root]);
  report_.global_state_bytes = std::max(report_.global_state_bytes, frame_bytes_ + double(s.cells.size()) * 48);
}

void TiledRun::drain_shared_flat(const SharedFlats& s, const std::vector<std::uint32_t>& members) {
  int c0 = cols_, r0 = rows_, c1 = -1, r1 = -1;
  for (std::uint32_t m : members) {
    const int c = int(s.cell_of[m] % cols_), r = int(s.cell_of[m] / cols_);
    c0 = std::min(c0, c);
    r0 = std::min(r0, r);
    c1 = std::max(c1, c);
    r1 = std::max(r1, r);
  }
  c0 -= 1, r0 -= 1, c1 += 1, r1 += 1;
  Dem z(c1 - c0 + 1, r1 - r0 + 1, {}, std::numeric_limits<float>::quiet_NaN());
  Raster<std::uint8_t> d8 = z.like<std::uint8_t>(kNoData);
  auto copy_cell = [&](std::int64_t g) {
    const auto it = s.slot.find(g);
    if (it == s.slot.end()) return;
    const int c = int(g % cols_) - c0, r = int(g / cols_) - r0;
    z(c, r) = s.cells[it->second].z;
    d8(c, r) = s.cells[it->second].code;
  };
  for (std::uint32_t m : members) {
    copy_cell(s.cell_of[m]);
    for (int k = 0; k < 8; ++k)
      if (const std::int64_t n = neighbour(s.cell_of[m], k); n >= 0) copy_cell(n);
  }
  report_.flat_cells_shared += members.size();
  drain_flats(z, d8);
  for (std::uint32_t m : members) {
    if (s.cells[m].code != kNoFlow) continue;
    const int gc = int(s.cell_of[m] % cols_), gr = int(s.cell_of[m] / cols_);
    const int t = grid_.tile_of(gc, gr);
    const TileRect rt = grid_.rect(t);
    patches_[std::size_t(t)].push_back({std::uint32_t((gr - rt.row0) * rt.cols + (gc - rt.col0)), d8(gc - c0, gr - r0)});
  }
}

}  // namespace terrapolis::hydro::tiled
