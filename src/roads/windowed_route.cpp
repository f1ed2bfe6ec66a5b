// One road by windows of the grid (see windowed_route.hpp).
// SPDX-License-Identifier: MIT
#include "roads/windowed_route.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "roads/radix_heap.hpp"

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
Scale smallest_cells(const CellMetrics& m) {
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

/// Each factor becomes the least within `reach` cells of it (a square), so that every arc starting
/// at a cell is priced at no more than its own discount.
void least_within(std::vector<float>& factor, const Box& box, int reach) {
  const int cols = box.c1 - box.c0 + 1, rows = box.r1 - box.r0 + 1;
  std::vector<float> line;
  for (int pass = 0; pass < 2; ++pass) {  // along rows, then along columns
    const int n = pass == 0 ? cols : rows, lines = pass == 0 ? rows : cols;
    const std::size_t step = pass == 0 ? 1 : std::size_t(cols), next = pass == 0 ? std::size_t(cols) : 1;
    line.resize(std::size_t(n));
    for (int l = 0; l < lines; ++l) {
      float* v = factor.data() + std::size_t(l) * next;
      for (int i = 0; i < n; ++i) line[std::size_t(i)] = v[std::size_t(i) * step];
      bool any = false;
      for (float f : line) any = any || f < 1;
      if (!any) continue;
      for (int i = 0; i < n; ++i) {
        float least = 1;
        for (int j = std::max(0, i - reach); j <= std::min(n - 1, i + reach); ++j) least = std::min(least, line[std::size_t(j)]);
        v[std::size_t(i) * step] = least;
      }
    }
  }
}

std::string cell_text(Cell c) { return "(" + std::to_string(c.col) + ", " + std::to_string(c.row) + ")"; }

/// A road is proved when it costs less than this times the bound: a margin for the costs' rounding.
constexpr double kMargin = 0.995;

/// The reach bound under road reuse: what a road must pay to pass through each cell of `region`,
/// read from no terrain. A metre costs at least the cheapest cost per metre times the factor of
/// the roads built within an arc's reach of it (`factor`: the region's cells, the least factor
/// within `reach` cells, 1 off the roads), and an arc costs at least its 8-connected steps over
/// octile_slack (of the region's cells); so the two Dijkstra distances D_a(x) + D_b(x) bound every road through x within
/// the region, far above the straight line times the smallest factor when most of the way is off
/// the roads.
struct Reach {
  double outside = kInfinity;  ///< the least bound over the region's cells outside `area`; the others' are at least the limit
  Box needed;                  ///< `area` and every cell whose bound is below the limit
};
Reach reach_bound(const CellMetrics& m, const Box& region, const Box& area, Cell a, Cell b, double per_metre, double limit,
                  const std::vector<float>& factor, std::vector<std::uint8_t>& read) {
  const int cols = region.c1 - region.c0 + 1, rows = region.r1 - region.r0 + 1;
  const std::size_t n = std::size_t(cols) * std::size_t(rows);
  const auto at = [&](int col, int row) { return std::size_t(row - region.r0) * std::size_t(cols) + std::size_t(col - region.c0); };
  struct Entry {
    double f;
    std::uint32_t i;
  };
  // The region's cells: widths, heights and diagonals between their extremes over its rows.
  double w_min = kInfinity, w_max = 0, h_min = kInfinity, h_max = 0, d_max = 0;
  for (int r = region.r0; r <= region.r1; ++r) {
    w_min = std::min(w_min, m.width_m[std::size_t(r)]), w_max = std::max(w_max, m.width_m[std::size_t(r)]);
    if (r == region.r0) continue;
    h_min = std::min(h_min, m.height_m[std::size_t(r)]), h_max = std::max(h_max, m.height_m[std::size_t(r)]);
    d_max = std::max(d_max, m.diagonal_m[std::size_t(r)]);
  }
  if (region.r0 == region.r1) h_min = h_max = m.height_m[std::size_t(region.r0)], d_max = std::hypot(w_max, h_max);
  const double slack = octile_slack(w_min, w_max, h_min, h_max, d_max);
  std::vector<float> from_a(n, float(kInfinity)), from_b(n, float(kInfinity));
  Reach out;
  out.needed = area;
  read.assign(n, 0);  // bits: settled from a, from b, reached
  for (const bool second : {false, true}) {
    std::vector<float>& g = second ? from_b : from_a;
    const Cell start = second ? b : a;
    RadixHeap<Entry> heap;
    g[at(start.col, start.row)] = 0;
    heap.push({0.0, std::uint32_t(at(start.col, start.row))});
    while (!heap.empty()) {
      const Entry e = heap.pop();
      if (e.f >= limit) break;  // every cell left costs at least the limit
      if (e.f > double(g[e.i]) || (read[e.i] & (second ? 2 : 1))) continue;
      read[e.i] |= second ? 2 : 1;
      const int col = region.c0 + int(e.i % std::size_t(cols)), row = region.r0 + int(e.i / std::size_t(cols));
      if (second) {
        const double through = double(from_a[e.i]) + e.f;
        // Past the limit here, past it beyond: a cell y reached through this one has
        // D_a(y) + D_b(y) >= D_a(here) + D_b(here) (the steps cost the same both ways).
        if (through >= limit) continue;
        out.needed = out.needed.united({col, row, col, row});
        if (!area.holds(col, row)) out.outside = std::min(out.outside, through);
      }
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          if ((dc == 0 && dr == 0) || !region.holds(col + dc, row + dr)) continue;
          // height_m[r] and diagonal_m[r] join rows r - 1 and r.
          const std::size_t lower = std::size_t(std::max(row, row + dr));
          const double length = dr == 0 ? m.width_m[std::size_t(row)] : dc == 0 ? m.height_m[lower] : m.diagonal_m[lower];
          const std::size_t j = at(col + dc, row + dr);
          const double d = e.f + length / slack * per_metre * std::min(factor[e.i], factor[j]);
          // Stored as floats rounded down: still lower bounds.
          float stored = float(d);
          if (double(stored) > d) stored = std::nextafter(stored, 0.0f);
          if (stored < g[j]) {
            g[j] = stored;
            read[j] |= 4;  // its factor was read
            heap.push({double(stored), std::uint32_t(j)});
          }
        }
    }
  }
  return out;
}

}  // namespace

double octile_slack(double w_min, double w_max, double h_min, double h_max, double d_max) {
  // A move of a >= b cells (a across, b along, or the other way) is at least |(a w_min, b h_min)|
  // long; its 8-connected steps at most (a - b) w_max + b d_max. The worst ratio over the
  // directions t = b / a, sampled finely (the ratio is smooth: 1e-3 covers the samples' gaps).
  constexpr int kSamples = 4096;
  double worst = 1;
  for (int k = 0; k <= kSamples; ++k) {
    const double t = double(k) / kSamples;
    worst = std::max(worst, ((1 - t) * w_max + t * d_max) / std::hypot(w_min, t * h_min));
    worst = std::max(worst, ((1 - t) * h_max + t * d_max) / std::hypot(h_min, t * w_min));
  }
  return worst * (1 + 1e-3);
}

int window_margin_cells(double road_radius_m, double reach_m, double min_cell_m) {
  return int(std::ceil(std::max(road_radius_m, reach_m) / min_cell_m)) + 2;
}

WindowedRoad route_by_windows(const TerrainGrid& grid, const ReadTerrainWindow& read, const CostModel& model, const GraphOptions& graph,
                              Cell from, Cell to, const RoutingOptions& options, const WindowOptions& window, Progress* progress,
                              const WindowReuse* reuse) {
  if (options.router != Router::galin) throw bad_input("roads by windows: the Bézier router reads the whole grid; use the Galin router");
  const Box whole{0, 0, grid.cols - 1, grid.rows - 1};
  if (!whole.holds(from.col, from.row) || !whole.holds(to.col, to.row)) throw bad_input("path: an end point lies outside the DEM");
  const CellMetrics metrics = cell_metrics(grid.georef, grid.cols, grid.rows);
  const Scale scale = smallest_cells(metrics);
  const Box ends = Box{std::min(from.col, to.col), std::min(from.row, to.row), std::max(from.col, to.col), std::max(from.row, to.row)}
                       .grown(std::max(window.pad_cells, options.snap_cells), grid);
  const Box guess = ellipse_box(from, to, window.first_ratio * std::hypot((to.col - from.col) * scale.w, (to.row - from.row) * scale.h), grid, scale);
  Box area = ends.united(guess);
  const auto too_large = [&](const Box& b) { return window.max_cells > 0 && b.grown(window.margin_cells, grid).cells() > window.max_cells; };
  if (too_large(area)) area = ends;
  WindowedRoad out;
  // Whether no road leaving `area` costs less than `road`, by the straight line, then by the roads
  // built around it (the reach bound); if not, what area the two bounds need.
  const auto prove = [&](const Road& road, const RoadGraph& g, const ArcDiscount* discount, const Box& area, std::optional<Box>& needed,
                         std::optional<Box>& reached) {
    const TerrainField& t = g.terrain();
    const std::vector<std::uint32_t>& cells = road.chain.cells;  // all within the area (restrict_search)
    const Cell a{t.col_of(cells.front()), t.row_of(cells.front())}, b{t.col_of(cells.back()), t.row_of(cells.back())};
    const double cheapest = g.model().cheapest_per_metre(), floor = discount ? discount->floor : 1.0;
    const double cost = *road.cost, per_metre = cheapest * floor;
    if (!(per_metre > 0)) return false;
    if (cost < kMargin * per_metre * detour_m(a, b, area, grid, scale)) return true;
    needed = ellipse_box(a, b, cost / (kMargin * per_metre), grid, scale);  // the road of a larger window costs no more
    if (floor == 1) return false;
    // Under reuse the straight line prices every metre as a road built: the reach bound knows
    // where the roads are. Its region: the area up to three times as wide, within the memory the
    // search's nodes freed.
    Box region = area;
    for (int by = std::max(area.c1 - area.c0, area.r1 - area.r0) + 1; by > 0 && region.cells() == area.cells(); by /= 2)
      if (const Box r = area.grown(by, grid); double(r.cells()) * kReachBytesPerCell <= double(options.max_nodes) * kSearchBytesPerNode) region = r;
    if (region.cells() == area.cells()) return false;
    int reach_cells = 1;  // the surface arcs' reach
    for (std::size_t k = 0; k < g.surface_arcs(); ++k) reach_cells = std::max({reach_cells, std::abs(g.arcs()[k].dcol), std::abs(g.arcs()[k].drow)});
    if (cost >= kMargin * per_metre * detour_m(a, b, region, grid, scale)) return false;  // a road leaving the region might
    std::vector<float> factor;
    reuse->over_box(region.c0, region.r0, region.c1, region.r1, factor);
    least_within(factor, region, reach_cells);
    std::vector<std::uint8_t> read_cells;
    const Reach r = reach_bound(metrics, region, area, a, b, cheapest, cost / kMargin, factor, read_cells);
    reuse->read(region.c0, region.r0, region.c1, region.r1, read_cells);
    if (cost <= kMargin * r.outside) {
      out.proved_by_reach = true;
      return true;
    }
    reached = r.needed.grown(1, grid);  // no cheaper road leaves it
    return false;
  };
  for (;;) {
    std::optional<Box> needed, reached;  // what the straight-line bound, and the reach bound, need
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
    bool proved = false;
    auto terrain = std::make_unique<TerrainField>(read(read_box.c0, read_box.r0, read_box.c1 - read_box.c0 + 1, read_box.r1 - read_box.r0 + 1));
    terrain->restrict_search(area.c0, area.r0, area.c1 + 1, area.r1 + 1);  // the margin feeds the costs only
    try {
      const RoadGraph g(*terrain, model, graph);
      const ArcDiscount* discount = reuse ? reuse->over_window(*terrain) : nullptr;
      road = route_road(*terrain, g, from, to, options, progress, nullptr, discount);
      if (!is_whole && road && !road->over_budget && !road->ferry && road->cost && !road->chain.cells.empty())
        proved = prove(*road, g, discount, area, needed, reached);
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::processing) throw;
      out.limited = true;  // the previous window's answer, or none
      return out;
    }
    ++out.windows;
    out.largest_cells = std::max(out.largest_cells, read_box.cells());
    out.road = std::move(road);
    out.terrain = std::move(terrain);
    if (is_whole || (out.road && out.road->over_budget)) return out;
    if (proved) {
      out.proved = true;
      return out;
    }
    // Hold what the reach bound needs, or at least double the area (the next road may leave it
    // again) and hold what the straight-line bound needs; or grow as far as the limit allows, if
    // that is a quarter more; past it, the largest window's answer stands (limited).
    if (reached && area.united(*reached).cells() == area.cells()) reached.reset();  // nothing new to hold
    Box next = reached ? area.united(*reached) : area.grown(std::max(area.c1 - area.c0, area.r1 - area.r0) / 2 + 1, grid);
    if (needed && !reached) next = next.united(*needed);
    if (too_large(next)) {
      if (window.give_up_at_limit) {
        out.limited = true;
        out.road.reset();
        return out;
      }
      int fits = 0, over = std::max(area.c1 - area.c0, area.r1 - area.r0) + 1;  // the largest growth that fits
      if (!too_large(area.grown(over, grid))) fits = over;
      while (over - fits > 1) (too_large(area.grown((fits + over) / 2, grid)) ? over : fits) = (fits + over) / 2;
      next = area.grown(fits, grid);
      if (4 * next.cells() < 5 * area.cells()) {
        out.limited = true;
        return out;
      }
    }
    area = next;
  }
}

}  // namespace terrapolis::roads
