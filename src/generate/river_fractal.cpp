// Belhadj 2007 §1.2.3: a fractal terrain crossed by one river, the Mandelbrot necklace (§1.2.3.1,
// fig. 1.4) refined with the midpoint displacement and eq. 1.2-1.3 (§1.2.3.2). See river_fractal.hpp.
// SPDX-License-Identifier: MIT
#include "generate/river_fractal.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "core/error.hpp"
#include "core/neighbours.hpp"
#include "core/progress.hpp"
#include "core/random.hpp"
#include "generate/distance_field.hpp"
#include "generate/generators.hpp"
#include "hydro/hydro.hpp"

namespace terrapolis::generate {
namespace {

/// An axis-aligned edge between two lattice cells, (xa, ya) <= (xb, yb).
struct Segment {
  int xa, ya, xb, yb;
};

/// §1.2.3.1's node id: from the low bytes up, the larger abscissa, the larger ordinate, the smaller
/// abscissa, the smaller ordinate, 16 bits each, so an edge has one key whichever way it is read.
std::uint64_t edge_key(const Segment& s) {
  return std::uint64_t(std::max(s.xa, s.xb)) | std::uint64_t(std::max(s.ya, s.yb)) << 16 |
         std::uint64_t(std::min(s.xa, s.xb)) << 32 | std::uint64_t(std::min(s.ya, s.yb)) << 48;
}

/// A rectangle of the path with the two river edges on its sides.
struct PathRect {
  int x0, x1, y0, y1;
  Segment in, out;
};

int split_of(int a, int b) { return b - a >= 2 ? a + (b - a) / 2 : -1; }

class NecklaceBuilder {
 public:
  NecklaceBuilder(int cols, int rows, std::uint64_t seed) : cols_(cols), rows_(rows), tree_(cols, rows), rng_(seed) {}

  Necklace build() {
    Necklace out;
    out.river_vertex_level.assign(std::size_t(cols_) * std::size_t(rows_), -1);
    // Level 0: two distinct sides of the grid, at random: the first is the source's.
    const int w = cols_ - 1, h = rows_ - 1;
    const std::array<Segment, 4> sides = {Segment{0, 0, w, 0}, Segment{w, 0, w, h}, Segment{0, h, w, h}, Segment{0, 0, 0, h}};
    const int a = int(rng_.next() % 4);
    const int b = (a + 1 + int(rng_.next() % 3)) % 4;
    std::vector<PathRect> path = {PathRect{0, w, 0, h, sides[std::size_t(a)], sides[std::size_t(b)]}};
    labels_[edge_key(path[0].in)] = true;
    labels_[edge_key(path[0].out)] = true;
    for (int level = 1;; ++level) {
      std::vector<PathRect> next;
      bool split = false;
      for (const PathRect& r : path) split = subdivide(r, next) || split;
      if (!split) break;
      path = std::move(next);
      for (const PathRect& r : path) mark_vertices(r, level, out.river_vertex_level);
    }
    // River cells: both ends of every crossed unit edge, listed by the last edge that touches them
    // (the order in which the river leaves them).
    std::vector<std::int64_t> last(out.river_vertex_level.size(), -1);
    auto add_edge = [&](const Segment& s) {
      out.line.push_back({0.5 * (s.xa + s.xb), 0.5 * (s.ya + s.yb)});
      for (const auto& [x, y] : {std::pair{s.xa, s.ya}, {s.xb, s.yb}})
        last[std::size_t(y) * std::size_t(cols_) + std::size_t(x)] = std::int64_t(out.line.size() - 1);
    };
    add_edge(path.front().in);
    for (const PathRect& r : path) add_edge(r.out);
    for (std::size_t i = 0; i < last.size(); ++i)
      if (last[i] >= 0) out.cells.push_back(i);
    std::stable_sort(out.cells.begin(), out.cells.end(), [&](std::size_t a, std::size_t b) { return last[a] < last[b]; });
    for (const std::size_t i : out.cells) out.edge_of_cell.push_back(std::size_t(last[i]));
    out.tree_nodes = labels_.size();
    return out;
  }

 private:
  /// The river half of river edge `s` split at the rectangle's split: read from the tree when the
  /// rectangle on its other side was subdivided first, else drawn and stored (§1.2.3.1).
  Segment river_half(const Segment& s) {
    const bool horizontal = s.ya == s.yb;
    const int m = horizontal ? split_of(s.xa, s.xb) : split_of(s.ya, s.yb);
    if (m < 0) return s;
    const Segment lo = horizontal ? Segment{s.xa, s.ya, m, s.yb} : Segment{s.xa, s.ya, s.xb, m};
    const Segment hi = horizontal ? Segment{m, s.ya, s.xb, s.yb} : Segment{s.xa, m, s.xb, s.yb};
    const auto found = labels_.find(edge_key(lo));
    if (found != labels_.end()) return found->second ? lo : hi;
    const bool take_lo = rng_.uniform() < 0.5;
    labels_[edge_key(lo)] = take_lo;
    labels_[edge_key(hi)] = !take_lo;
    return take_lo ? lo : hi;
  }

  /// Splits `r` into its 2 or 4 sub-rectangles and appends those on the path, in order. Returns
  /// false (and appends `r`) when `r` is too small to split.
  bool subdivide(const PathRect& r, std::vector<PathRect>& next) {
    const int mx = split_of(r.x0, r.x1), my = split_of(r.y0, r.y1);
    if (mx < 0 && my < 0) {
      next.push_back(r);
      return false;
    }
    const std::vector<int> xs = mx < 0 ? std::vector<int>{r.x0, r.x1} : std::vector<int>{r.x0, mx, r.x1};
    const std::vector<int> ys = my < 0 ? std::vector<int>{r.y0, r.y1} : std::vector<int>{r.y0, my, r.y1};
    const int nx = int(xs.size()) - 1, ny = int(ys.size()) - 1;
    // The sub-rectangle (i, j) a side's half lies on.
    auto holder = [&](const Segment& s) {
      const int i = s.xa == s.xb ? (s.xa == r.x0 ? 0 : nx - 1) : (nx == 2 && s.xa >= mx ? 1 : 0);
      const int j = s.ya == s.yb ? (s.ya == r.y0 ? 0 : ny - 1) : (ny == 2 && s.ya >= my ? 1 : 0);
      return std::pair{i, j};
    };
    const Segment in = river_half(r.in), out = river_half(r.out);
    const auto first = holder(in), last = holder(out);
    std::vector<std::pair<int, int>> walk = {first};
    if (first != last) {
      if (nx * ny == 2) {
        walk.push_back(last);
      } else {
        // Around the four quarters, one way or the other: the first inner side is drawn at random,
        // after which only one side is still unknown (fig. 1.4).
        const std::array<std::pair<int, int>, 4> ring = {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        int at = int(std::find(ring.begin(), ring.end(), first) - ring.begin());
        const int step = rng_.uniform() < 0.5 ? 1 : 3;
        while (ring[std::size_t(at)] != last) {
          at = (at + step) % 4;
          walk.push_back(ring[std::size_t(at)]);
        }
      }
    }
    for (std::size_t k = 0; k < walk.size(); ++k) {
      const auto [i, j] = walk[k];
      PathRect sub{xs[std::size_t(i)], xs[std::size_t(i) + 1], ys[std::size_t(j)], ys[std::size_t(j) + 1], in, out};
      if (k > 0) sub.in = next.back().out;
      if (k + 1 < walk.size()) {
        const auto [i2, j2] = walk[k + 1];
        sub.out = i2 != i ? Segment{mx, sub.y0, mx, sub.y1} : Segment{sub.x0, my, sub.x1, my};
        labels_[edge_key(sub.out)] = true;
      }
      next.push_back(sub);
    }
    return true;
  }

  void mark_vertices(const PathRect& r, int level, std::vector<std::int8_t>& marks) const {
    for (const Segment& s : {r.in, r.out})
      for (const auto& [x, y] : {std::pair{s.xa, s.ya}, {s.xb, s.yb}})
        if (tree_.level(x, y) == level) marks[std::size_t(y) * std::size_t(cols_) + std::size_t(x)] = std::int8_t(level);
  }

  int cols_, rows_;
  terrain::SubdivisionTree tree_;
  Rng rng_;
  std::map<std::uint64_t, bool> labels_;  ///< the binary search tree of edge labels: true = river
};

/// The project's D8 on the generated DEM: the share of river cells whose water goes to another river
/// cell or off the grid, and the share of the river line's points with a D8 stream cell (at least
/// `stream_m2` upstream) within one cell. The report's check asks for Strahler orders within one of
/// the river's, which a single river (order 1) collecting every slope cannot meet.
std::pair<double, double> river_d8_shares(const Raster<float>& dem, const Necklace& necklace, double stream_m2) {
  hydro::HydroOptions options;
  options.with_hydrometry = false;
  options.with_streams = false;
  SilentProgress progress;
  const hydro::HydroResult d8 = hydro::run_hydro(dem, options, progress);
  const int cols = dem.cols();
  std::vector<char> river(dem.size(), 0);
  for (const std::size_t i : necklace.cells) river[i] = 1;
  std::size_t stays = 0;
  for (const std::size_t i : necklace.cells) {
    const int k = d8.d8[i];
    if (k >= 8) continue;
    const int u = int(i % std::size_t(cols)) + dcol[std::size_t(k)], v = int(i / std::size_t(cols)) + drow[std::size_t(k)];
    stays += !dem.inside(u, v) || river[dem.index(u, v)];
  }
  std::size_t near = 0;
  for (const auto& p : necklace.line) {
    bool found = false;
    for (int v = int(std::floor(p[1])) - 1; v <= int(std::ceil(p[1])) + 1 && !found; ++v)
      for (int u = int(std::floor(p[0])) - 1; u <= int(std::ceil(p[0])) + 1 && !found; ++u)
        found = dem.inside(u, v) && d8.accumulation(u, v) >= stream_m2;
    near += found;
  }
  return {double(stays) / double(necklace.cells.size()), double(near) / double(necklace.line.size())};
}

}  // namespace

Necklace mandelbrot_necklace(int cols, int rows, std::uint64_t seed) {
  if (cols < 3 || rows < 3 || cols > 65535 || rows > 65535)
    throw bad_input("--size: the river method needs 3 to 65535 cells a side (16-bit edge keys), got " + std::to_string(cols) + "x" +
                    std::to_string(rows));
  return NecklaceBuilder(cols, rows, seed).build();
}

void river_fractal(Raster<float>& raster, const Necklace& necklace, const RiverFractalParams& params) {
  const int cols = raster.cols(), rows = raster.rows();
  const std::size_t n = raster.size();
  terrain::SubdivisionGrid grid;
  grid.cols = cols;
  grid.rows = rows;
  grid.z.assign(n, 0.0f);
  grid.state.assign(n, terrain::CellState::unknown);
  auto fix = [&](std::size_t i, double z) {
    grid.z[i] = float(z);
    grid.state[i] = terrain::CellState::constrained;
  };
  // The bed falls along the river from the last edge touching each river cell: every river cell but
  // the mouth's has a lower river cell beside it (an end of the next edge), so water in the river
  // runs down it to the mouth. The thesis's bed is 0 everywhere (its rivers do not need to drain).
  const double edges = double(std::max<std::size_t>(1, necklace.line.size() - 1));
  std::vector<char> river(n, 0);
  for (std::size_t k = 0; k < necklace.cells.size(); ++k) {
    fix(necklace.cells[k], params.bed_drop_m * (1.0 - double(necklace.edge_of_cell[k]) / edges));
    river[necklace.cells[k]] = 1;
  }
  const double relief = params.relief_m;
  const std::array<std::pair<std::size_t, double>, 4> corners = {
      std::pair{std::size_t(0), relief}, {std::size_t(cols - 1), 0.1 * relief},
      {std::size_t(rows - 1) * std::size_t(cols), 0.1 * relief}, {n - 1, 0.5 * relief}};
  for (const auto& [i, z] : corners)
    if (!river[i]) fix(i, z);
  // Bed under every cell: that of the nearest river cell.
  std::vector<double> dist;
  std::vector<std::size_t> nearest;
  distance_to(river, cols, rows, dist, nearest);
  // A bank is no lower than the river cells beside it, so no water leaves the river through it
  // (the necklace folds on itself: a bank between two folds would else drain one into the other).
  std::vector<float> bank(n, -std::numeric_limits<float>::infinity());
  for (const std::size_t i : necklace.cells) {
    const int x = int(i % std::size_t(cols)), y = int(i / std::size_t(cols));
    for (int k = 0; k < 8; ++k) {
      const int u = x + dcol[std::size_t(k)], v = y + drow[std::size_t(k)];
      if (u < 0 || v < 0 || u >= cols || v >= rows) continue;
      const std::size_t j = std::size_t(v) * std::size_t(cols) + std::size_t(u);
      if (!river[j]) bank[j] = std::max(bank[j], grid.z[i]);
    }
  }

  const terrain::MidpointParams& p = params.top_down;
  const terrain::SubdivisionTree tree(cols, rows);
  const double r_max = std::ceil(std::log2(double(std::max(cols, rows))));  // §1.2.3.2 note 13
  auto compute = [&](int col, int row) {
    const std::size_t i = std::size_t(row) * std::size_t(cols) + std::size_t(col);
    if (grid.state[i] != terrain::CellState::unknown) return;
    int pc[4], pr[4];
    double w[4];
    const int k = tree.parents(p.subdivision, col, row, pc, pr, w);
    double m = 0;
    for (int q = 0; q < k; ++q) m += w[q] * grid.z[std::size_t(pr[q]) * std::size_t(cols) + std::size_t(pc[q])];
    const int r = tree.level(col, row);
    const double x = terrain::position_noise(p.seed, col, row);
    double z;
    if (necklace.river_vertex_level[i] == r) {
      // Eq. 1.3 with the bed b in place of 0: b + p (m - b) + delta-, delta- of eq. 1.2, never
      // below the bed (the thesis's bed is its lowest altitude).
      const double b = grid.z[nearest[i]];
      const double pull = std::pow(std::max(0.0, 1.0 - r / r_max), params.convergence);
      const double down = -0.5 * (x + 1.0) * p.scale_m * std::exp2(std::pow(double(r), params.power) - r * p.dimension * p.hurst);
      z = std::max(b, b + pull * (m - b) + down);
    } else {
      z = m + (x + p.t) * p.scale_m * std::exp2(-r * p.dimension * p.hurst);  // eq. 1.1
    }
    grid.z[i] = std::max(float(z), bank[i]);
    grid.state[i] = terrain::CellState::known;
  };
  terrain::for_each_created_cell(tree, compute);  // as terrain::midpoint_displacement
  raster.values() = std::move(grid.z);
}

GeneratedTerrain generate_river(const GenerateRequest& request) {
  GeneratedTerrain out;
  out.dem = request.grid;
  const auto t0 = std::chrono::steady_clock::now();
  const Necklace necklace = mandelbrot_necklace(out.dem.cols(), out.dem.rows(), request.seed ^ 0x6e65636b6c616365ull);
  const auto t1 = std::chrono::steady_clock::now();
  RiverFractalParams params = request.river;
  params.top_down = request.dmmc.top_down;
  params.relief_m = request.relief_m;
  river_fractal(out.dem, necklace, params);
  const auto t2 = std::chrono::steady_clock::now();
  out.timings.emplace_back("necklace", std::chrono::duration<double>(t1 - t0).count());
  out.timings.emplace_back("river terrain", std::chrono::duration<double>(t2 - t1).count());
  RiverReach reach;
  reach.line = necklace.line;
  reach.width_m = request.cell_m;
  out.plan.rivers.push_back(std::move(reach));
  assign_strahler(out.plan);
  // The river starts on the border, where D8 drains nothing: the check's D8 streams start from the
  // tectonic method's 0.1 km2 rather than from the area at the source.
  out.channel_head_m2 = 1e5;
  out.figures.emplace_back("river_cells", double(necklace.cells.size()));
  out.figures.emplace_back("edge_tree_nodes", double(necklace.tree_nodes));
  const auto [stays, near] = river_d8_shares(out.dem, necklace, *out.channel_head_m2);
  out.figures.emplace_back("river_cells_draining_into_river_share", stays);
  out.figures.emplace_back("river_line_within_1_cell_of_d8_stream_share", near);
  out.timings.emplace_back("D8 shares", std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count());
  return out;
}

}  // namespace terrapolis::generate
