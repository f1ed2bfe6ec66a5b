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
  Box united(const Box& o) const { return {std::min(c0, o.c0), std::min(r0, o.r0), std::max(c1, o.c1), std::max(r1, o.r1)}; }
};

/// A lower bound of the metres per cell across (w) and along (h) every row of the grid: a path
/// from a to b is at least |(dcol w, drow h)| long.
struct Scale {
  double w = 1, h = 1;
};
Scale smallest_cells(const TerrainGrid& g) {
  const CellMetrics m = cell_metrics(g.georef, g.cols, g.rows);
  return {*std::min_element(m.width_m.begin(), m.width_m.end()), *std::min_element(m.height_m.begin(), m.height_m.end())};
}

/// The shortest a path from a to b can be (m) through a cell outside `area`: such a cell lies
/// beyond one of the lines just outside the area's sides, and |a - y| + |y - b| >= |a - b'| for any y
/// beyond a line, b' the reflection of b across it (in metres, scaled by `s`). Infinity when the
/// area is the whole grid.
double detour_m(Cell a, Cell b, const Box& area, const TerrainGrid& g, Scale s) {
  double best = kInfinity;
  auto through = [&](double dc, double dr) { best = std::min(best, std::hypot(dc * s.w, dr * s.h)); };
  if (area.c0 > 0) through(double(a.col) + b.col - 2.0 * (area.c0 - 1), b.row - a.row);
  if (area.c1 < g.cols - 1) through(2.0 * (area.c1 + 1) - a.col - b.col, b.row - a.row);
  if (area.r0 > 0) through(b.col - a.col, double(a.row) + b.row - 2.0 * (area.r0 - 1));
  if (area.r1 < g.rows - 1) through(b.col - a.col, 2.0 * (area.r1 + 1) - a.row - b.row);
  return best;
}

/// The cells around the ellipse of the points y with |a - y| + |y - b| <= length_m (m, scaled by
/// `s`), one more on each side: the detour through any cell outside is longer than length_m.
Box ellipse_box(Cell a, Cell b, double length_m, const TerrainGrid& g, Scale s) {
  const double ax = a.col * s.w, ay = a.row * s.h, bx = b.col * s.w, by = b.row * s.h;
  const double focal = 0.5 * std::hypot(bx - ax, by - ay), major = 0.5 * length_m;
  const double minor = std::sqrt(std::max(0.0, major * major - focal * focal));
  const double cos_t = focal > 0 ? (bx - ax) / (2 * focal) : 1, sin_t = focal > 0 ? (by - ay) / (2 * focal) : 0;
  const double hx = std::hypot(major * cos_t, minor * sin_t), hy = std::hypot(major * sin_t, minor * cos_t);
  const double cx = 0.5 * (ax + bx), cy = 0.5 * (ay + by);
  const auto cell = [](double v, double size, double grid_max) { return std::clamp(v / size, -1.0, grid_max + 1); };
  return {std::max(0, int(std::floor(cell(cx - hx, s.w, g.cols))) - 1), std::max(0, int(std::floor(cell(cy - hy, s.h, g.rows))) - 1),
          std::min(g.cols - 1, int(std::ceil(cell(cx + hx, s.w, g.cols))) + 1), std::min(g.rows - 1, int(std::ceil(cell(cy + hy, s.h, g.rows))) + 1)};
}

std::string cell_text(Cell c) { return "(" + std::to_string(c.col) + ", " + std::to_string(c.row) + ")"; }

}  // namespace

int window_margin_cells(double road_radius_m, double reach_m, double min_cell_m) {
  return int(std::ceil(std::max(road_radius_m, reach_m) / min_cell_m)) + 2;
}

WindowedRoad route_by_windows(const TerrainGrid& grid, const ReadTerrainWindow& read, const CostModel& model, const GraphOptions& graph,
                              Cell from, Cell to, const RoutingOptions& options, const WindowOptions& window, Progress* progress,
                              const WindowDiscount& discount) {
  if (options.router != Router::galin) throw bad_input("roads by windows: the Bézier router reads the whole grid; use the Galin router");
  const Box whole{0, 0, grid.cols - 1, grid.rows - 1};
  if (!whole.holds(from.col, from.row) || !whole.holds(to.col, to.row)) throw bad_input("path: an end point lies outside the DEM");
  const Scale scale = smallest_cells(grid);
  const Box ends = Box{std::min(from.col, to.col), std::min(from.row, to.row), std::max(from.col, to.col), std::max(from.row, to.row)}
                       .grown(std::max(window.pad_cells, options.snap_cells), grid);
  const Box guess = ellipse_box(from, to, window.first_ratio * std::hypot((to.col - from.col) * scale.w, (to.row - from.row) * scale.h), grid, scale);
  Box area = ends.united(guess);
  const auto too_large = [&](const Box& b) { return window.max_cells > 0 && b.grown(window.margin_cells, grid).cells() > window.max_cells; };
  if (too_large(area)) area = ends;
  WindowedRoad out;
  for (;;) {
    std::optional<Box> needed;
    const Box read_box = area.grown(window.margin_cells, grid);
    const bool is_whole = area.c0 == 0 && area.r0 == 0 && area.c1 == whole.c1 && area.r1 == whole.r1;
    const auto refuse = [&](const std::string& why) {
      return bad_input("roads by windows: the road from cell " + cell_text(from) + " to " + cell_text(to) + " " + why + " within " +
                       std::to_string(read_box.c1 - read_box.c0 + 1) + " x " + std::to_string(read_box.r1 - read_box.r0 + 1) +
                       " cells; the memory limit allows windows of " + std::to_string(window.max_cells) + " cells");
    };
    if (too_large(area)) throw refuse("cannot be searched");
    // The previous window's answer stands until this one's search ends: past the nodes the limit
    // allows (processing_error), the previous is the largest window's answer (none on the first).
    std::optional<Road> road;
    double per_metre = 0;  // the bound's cost per metre: the cheapest, times the reuse floor
    auto terrain = std::make_unique<TerrainField>(read(read_box.c0, read_box.r0, read_box.c1 - read_box.c0 + 1, read_box.r1 - read_box.r0 + 1));
    terrain->restrict_search(area.c0, area.r0, area.c1 + 1, area.r1 + 1);  // the margin feeds the costs only
    try {
      const RoadGraph g(*terrain, model, graph);
      const ArcDiscount* reuse = discount ? discount(*terrain) : nullptr;
      per_metre = 0.995 * g.model().cheapest_per_metre() * (reuse ? reuse->floor : 1.0);
      road = route_road(*terrain, g, from, to, options, progress, nullptr, reuse);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::processing) throw;
      out.limited = true;  // the previous window's answer, or none
      return out;
    }
    ++out.windows;
    out.largest_cells = std::max(out.largest_cells, read_box.cells());
    out.road = std::move(road);
    out.terrain = std::move(terrain);
    const TerrainField& t = *out.terrain;
    if (is_whole || (out.road && out.road->over_budget)) return out;
    if (out.road && !out.road->ferry && out.road->cost && !out.road->chain.cells.empty()) {
      const std::vector<std::uint32_t>& cells = out.road->chain.cells;  // all within the area (restrict_search)
      const Cell a{t.col_of(cells.front()), t.row_of(cells.front())}, b{t.col_of(cells.back()), t.row_of(cells.back())};
      if (*out.road->cost < per_metre * detour_m(a, b, area, grid, scale)) {
        out.proved = true;
        return out;
      }
      // The area the bound needs for this cost; the road of a larger window costs no more.
      if (per_metre > 0) needed = ellipse_box(a, b, *out.road->cost / per_metre, grid, scale);
    }
    // At least double the area (the next road may leave it again), and hold what the bound needs,
    // or grow as far as the limit allows; past it, the largest window's answer stands (limited).
    int by = std::max(area.c1 - area.c0, area.r1 - area.r0) / 2 + 1;
    Box next = area.grown(by, grid);
    if (needed) next = next.united(*needed);
    while (too_large(next) && by > 1) next = area.grown(by /= 2, grid);
    if (too_large(next)) {
      out.limited = true;
      return out;
    }
    area = next;
  }
}

}  // namespace terrapolis::roads
