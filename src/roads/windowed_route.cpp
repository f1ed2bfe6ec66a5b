// One road by windows of the grid (see windowed_route.hpp).
// SPDX-License-Identifier: MIT
#include "roads/windowed_route.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace terrapolis::roads {
namespace {

/// Cells [c0, c1] x [r0, r1] of the grid, bounds included.
struct Box {
  int c0 = 0, r0 = 0, c1 = 0, r1 = 0;
  std::size_t cells() const { return std::size_t(c1 - c0 + 1) * std::size_t(r1 - r0 + 1); }
  Box grown(int by, const TerrainGrid& g) const {
    return {std::max(0, c0 - by), std::max(0, r0 - by), std::min(g.cols - 1, c1 + by), std::min(g.rows - 1, r1 + by)};
  }
  bool holds(int col, int row) const { return col >= c0 && col <= c1 && row >= r0 && row <= r1; }
};

/// The shortest a path from a to b can be, in cells, through a cell outside `area`: such a cell lies
/// beyond one of the lines just outside the area's sides, and |a - y| + |y - b| >= |a - b'| for any y
/// beyond a line, b' the reflection of b across it. Infinity when the area is the whole grid.
double detour_cells(Cell a, Cell b, const Box& area, const TerrainGrid& g) {
  double best = kInfinity;
  auto through = [&](double dc, double dr) { best = std::min(best, std::hypot(dc, dr)); };
  if (area.c0 > 0) through(double(a.col) + b.col - 2.0 * (area.c0 - 1), b.row - a.row);
  if (area.c1 < g.cols - 1) through(2.0 * (area.c1 + 1) - a.col - b.col, b.row - a.row);
  if (area.r0 > 0) through(b.col - a.col, double(a.row) + b.row - 2.0 * (area.r0 - 1));
  if (area.r1 < g.rows - 1) through(b.col - a.col, 2.0 * (area.r1 + 1) - a.row - b.row);
  return best;
}

std::string cell_text(Cell c) { return "(" + std::to_string(c.col) + ", " + std::to_string(c.row) + ")"; }

}  // namespace

int window_margin_cells(double road_radius_m, double reach_m, double min_cell_m) {
  return int(std::ceil(std::max(road_radius_m, reach_m) / min_cell_m)) + 2;
}

WindowedRoad route_by_windows(const TerrainGrid& grid, const ReadTerrainWindow& read, const CostModel& model, const GraphOptions& graph,
                              Cell from, Cell to, const RoutingOptions& options, const WindowOptions& window, Progress* progress) {
  if (options.router != Router::galin) throw bad_input("roads by windows: the Bézier router reads the whole grid; use the Galin router");
  const Box whole{0, 0, grid.cols - 1, grid.rows - 1};
  if (!whole.holds(from.col, from.row) || !whole.holds(to.col, to.row)) throw bad_input("path: an end point lies outside the DEM");
  const int side = std::max(std::abs(to.col - from.col), std::abs(to.row - from.row));
  Box area = Box{std::min(from.col, to.col), std::min(from.row, to.row), std::max(from.col, to.col), std::max(from.row, to.row)}
                 .grown(std::max(window.pad_cells, options.snap_cells) + side / 4, grid);
  WindowedRoad out;
  for (;;) {
    const Box read_box = area.grown(window.margin_cells, grid);
    const bool is_whole = area.c0 == 0 && area.r0 == 0 && area.c1 == whole.c1 && area.r1 == whole.r1;
    const auto refuse = [&](const std::string& why) {
      return bad_input("roads by windows: the road from cell " + cell_text(from) + " to " + cell_text(to) + " " + why + " within " +
                       std::to_string(read_box.c1 - read_box.c0 + 1) + " x " + std::to_string(read_box.r1 - read_box.r0 + 1) +
                       " cells; the memory limit allows windows of " + std::to_string(window.max_cells) + " cells");
    };
    if (window.max_cells > 0 && read_box.cells() > window.max_cells) throw refuse("cannot be searched");
    out.terrain.reset();
    out.terrain.emplace(read(read_box.c0, read_box.r0, read_box.c1 - read_box.c0 + 1, read_box.r1 - read_box.r0 + 1));
    ++out.windows;
    out.largest_cells = std::max(out.largest_cells, read_box.cells());
    const TerrainField& t = *out.terrain;
    const RoadGraph g(t, model, graph);
    out.road = route_road(t, g, from, to, options, progress);
    if (is_whole || (out.road && out.road->over_budget)) return out;
    if (out.road && !out.road->ferry && out.road->cost) {
      const std::vector<std::uint32_t>& cells = out.road->chain.cells;
      bool inside = true;
      for (std::uint32_t i : cells) inside = inside && area.holds(t.col_of(i), t.row_of(i));
      if (inside && !cells.empty()) {
        const Cell a{t.col_of(cells.front()), t.row_of(cells.front())}, b{t.col_of(cells.back()), t.row_of(cells.back())};
        const double leaving = g.model().cheapest_per_metre() * 0.995 * t.min_cell_m() * detour_cells(a, b, area, grid);
        if (*out.road->cost < leaving) {
          out.proved = true;
          return out;
        }
      }
    }
    // Double the area, or grow it as far as the limit allows.
    int by = std::max(area.c1 - area.c0, area.r1 - area.r0) / 2 + 1;
    while (by > 1 && window.max_cells > 0 && area.grown(by, grid).grown(window.margin_cells, grid).cells() > window.max_cells) by /= 2;
    const Box next = area.grown(by, grid);
    if (window.max_cells > 0 && next.grown(window.margin_cells, grid).cells() > window.max_cells)
      throw refuse(out.road && !out.road->ferry ? "was not proved the grid's shortest" : "was not found");
    area = next;
  }
}

}  // namespace terrapolis::roads
