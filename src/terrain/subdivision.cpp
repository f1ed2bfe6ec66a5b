// Constrained midpoint displacement and DMMC (Belhadj 2007, ch. 1 and 3): the subdivision tree of any grid.
// SPDX-License-Identifier: MIT
#include "terrain/subdivision.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include "core/error.hpp"
#include "core/random.hpp"

namespace terrapolis::terrain {
namespace {

/// Splits 0..n-1 recursively at integer midpoints; returns the number of levels.
int build_axis(int n, SubdivisionTree::Axis& axis) {
  axis.depth.assign(std::size_t(n), -1);
  axis.lo.assign(std::size_t(n), -1);
  axis.hi.assign(std::size_t(n), -1);
  axis.depth[0] = 0;
  axis.depth[std::size_t(n - 1)] = 0;
  axis.created.clear();
  axis.created.push_back(n > 1 ? std::vector<int>{0, n - 1} : std::vector<int>{0});
  std::vector<std::pair<int, int>> intervals;
  if (n > 2) intervals.emplace_back(0, n - 1);
  int level = 0;
  while (!intervals.empty()) {
    ++level;
    std::vector<std::pair<int, int>> next;
    std::vector<int> made;
    for (const auto& [a, b] : intervals) {
      const int m = a + (b - a) / 2;
      axis.depth[std::size_t(m)] = level;
      axis.lo[std::size_t(m)] = a;
      axis.hi[std::size_t(m)] = b;
      made.push_back(m);
      if (m - a >= 2) next.emplace_back(a, m);
      if (b - m >= 2) next.emplace_back(m, b);
    }
    axis.created.push_back(std::move(made));
    intervals = std::move(next);
  }
  return level;
}

void build_neighbours(int n, int levels, SubdivisionTree::Axis& axis) {
  axis.created.resize(std::size_t(levels) + 1);
  axis.prev.assign(std::size_t(levels) + 1, std::vector<int>(std::size_t(n), -1));
  axis.next.assign(std::size_t(levels) + 1, std::vector<int>(std::size_t(n), -1));
  for (int level = 0; level <= levels; ++level) {
    auto& prev = axis.prev[std::size_t(level)];
    auto& next = axis.next[std::size_t(level)];
    int last = -1;
    for (int c = 0; c < n; ++c) {
      prev[std::size_t(c)] = last;
      if (axis.depth[std::size_t(c)] <= level) last = c;
    }
    last = -1;
    for (int c = n - 1; c >= 0; --c) {
      next[std::size_t(c)] = last;
      if (axis.depth[std::size_t(c)] <= level) last = c;
    }
  }
}

/// Belhadj eq. 3.4 / 3.5: a (1 - sigma(I) (1 - (1 - d/dmax)^|I|)).
double shape_curve(double a, double d, double d_max, double shape) {
  if (shape == 0.0) return a;
  const double sigma = shape >= 0 ? 1.0 : -1.0;
  return a * (1.0 - sigma * (1.0 - std::pow(std::max(0.0, 1.0 - d / d_max), std::abs(shape))));
}

}  // namespace

double position_noise(std::uint64_t seed, int col, int row) {
  // SplitMix64 finaliser of (seed, position): one number per cell, whatever the order of work.
  const std::uint64_t z = splitmix64(seed * 0x9E3779B97F4A7C15ull + (std::uint64_t(std::uint32_t(col)) << 32 | std::uint32_t(row)));
  return double(z >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

SubdivisionGrid SubdivisionGrid::from_raster(const Raster<float>& raster) {
  SubdivisionGrid grid;
  grid.cols = raster.cols();
  grid.rows = raster.rows();
  grid.z = raster.values();
  grid.state.resize(raster.size());
  for (std::size_t i = 0; i < raster.size(); ++i) {
    const bool known = std::isfinite(raster[i]);
    grid.state[i] = known ? CellState::constrained : CellState::unknown;
    if (!known) grid.z[i] = 0.0f;
  }
  return grid;
}

SubdivisionTree::SubdivisionTree(int cols, int rows) {
  levels_ = std::max(build_axis(cols, x_), build_axis(rows, y_));
  build_neighbours(cols, levels_, x_);
  build_neighbours(rows, levels_, y_);
}

int SubdivisionTree::level(int col, int row) const {
  return std::max(x_.depth[std::size_t(col)], y_.depth[std::size_t(row)]);
}

int SubdivisionTree::parents(Subdivision scheme, int col, int row, int (&pc)[4], int (&pr)[4], double (&w)[4]) const {
  const int dx = x_.depth[std::size_t(col)], dy = y_.depth[std::size_t(row)];
  if (dx == 0 && dy == 0) return 0;
  if (dx == dy) {  // centre of a rectangle: its four corners, bilinear weights
    const int a = x_.lo[std::size_t(col)], b = x_.hi[std::size_t(col)];
    const int c = y_.lo[std::size_t(row)], d = y_.hi[std::size_t(row)];
    const double fx = double(col - a) / double(b - a), fy = double(row - c) / double(d - c);
    pc[0] = a; pr[0] = c; w[0] = (1 - fx) * (1 - fy);
    pc[1] = b; pr[1] = c; w[1] = fx * (1 - fy);
    pc[2] = a; pr[2] = d; w[2] = (1 - fx) * fy;
    pc[3] = b; pr[3] = d; w[3] = fx * fy;
    return 4;
  }
  // Midpoint of an edge: along x when dx > dy (the row is already on the lattice), else along y.
  const bool along_x = dx > dy;
  const Axis& axis = along_x ? x_ : y_;
  const Axis& across = along_x ? y_ : x_;
  const int u = along_x ? col : row, v = along_x ? row : col;
  const int level = along_x ? dx : dy;
  const int a = axis.lo[std::size_t(u)], b = axis.hi[std::size_t(u)];
  int n = 0;
  auto add = [&](int pu, int pv, double weight) {
    pc[n] = along_x ? pu : pv;
    pr[n] = along_x ? pv : pu;
    w[n] = weight;
    ++n;
  };
  if (scheme == Subdivision::triangle_edge) {
    add(a, v, double(b - u) / double(b - a));
    add(b, v, double(u - a) / double(b - a));
    return n;
  }
  // Diamond step: the edge ends and the centres of the two rectangles the edge separates,
  // weighted by inverse distance (so an odd split still interpolates linearly along the edge).
  add(a, v, 1.0 / double(u - a));
  add(b, v, 1.0 / double(b - u));
  const int p = across.prev[std::size_t(level - 1)][std::size_t(v)];
  const int q = across.next[std::size_t(level - 1)][std::size_t(v)];
  // Both centres or none: one centre alone (at the grid border, or beside a rectangle too thin to
  // have a centre) would pull the edge off the plane through its parents.
  if (p >= 0 && v - p >= 2 && q >= 0 && q - v >= 2) {
    add(u, p + (v - p) / 2, 1.0 / double(v - (p + (v - p) / 2)));
    add(u, v + (q - v) / 2, 1.0 / double((q - v) / 2));
  }
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += w[i];
  for (int i = 0; i < n; ++i) w[i] /= sum;
  return n;
}

void for_each_created_cell(const SubdivisionTree& tree, const std::function<void(int, int)>& visit,
                           const std::function<void(int)>& level_done) {
  const auto rows_of = [&](const std::vector<int>& ys, const std::vector<int>& xs) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ys.size()), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t j = r.begin(); j != r.end(); ++j)
        for (const int col : xs) visit(col, ys[j]);
    });
  };
  // Lattice coordinates (created at or before a level) per axis, grown level by level.
  std::vector<int> lattice_x = tree.x().created[0], lattice_y = tree.y().created[0];
  for (int level = 1; level <= tree.levels(); ++level) {
    const auto& new_x = tree.x().created[std::size_t(level)];
    const auto& new_y = tree.y().created[std::size_t(level)];
    rows_of(new_y, new_x);      // square step: rectangle centres
    rows_of(new_y, lattice_x);  // edge step: midpoints of the edges
    rows_of(lattice_y, new_x);
    lattice_x.insert(lattice_x.end(), new_x.begin(), new_x.end());
    std::sort(lattice_x.begin(), lattice_x.end());
    lattice_y.insert(lattice_y.end(), new_y.begin(), new_y.end());
    std::sort(lattice_y.begin(), lattice_y.end());
    if (level_done) level_done(level);
  }
}

void midpoint_displacement(SubdivisionGrid& grid, const MidpointParams& params, Progress* progress) {
  const int cols = grid.cols, rows = grid.rows;
  if (cols < 1 || rows < 1) return;
  const SubdivisionTree tree(cols, rows);
  const double d_max = std::hypot(double(cols), double(rows));
  std::optional<ProgressStep> step;
  if (progress) step.emplace(*progress, "midpoint displacement");
  auto displacement = [&](int col, int row, int level) {
    if (params.scale_m == 0.0) return 0.0;
    return (position_noise(params.seed, col, row) + params.t) * params.scale_m *
           std::exp2(-double(level) * params.dimension * params.hurst);
  };
  // Level 0: corners the caller left unknown start at the mean of what is known.
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < grid.z.size(); ++i)
    if (grid.state[i] != CellState::unknown) { sum += grid.z[i]; ++count; }
  const double mean = count ? sum / double(count) : 0.0;
  for (const int row : {0, rows - 1})
    for (const int col : {0, cols - 1}) {
      const std::size_t i = std::size_t(row) * std::size_t(cols) + std::size_t(col);
      if (grid.state[i] != CellState::unknown) continue;
      grid.z[i] = float(mean + displacement(col, row, 0));
      grid.state[i] = CellState::known;
    }
  auto compute = [&](int col, int row) {
    const std::size_t i = std::size_t(row) * std::size_t(cols) + std::size_t(col);
    if (grid.state[i] != CellState::unknown) return;
    int pc[4], pr[4];
    double w[4];
    const int n = tree.parents(params.subdivision, col, row, pc, pr, w);
    double a = 0, d = 0;
    for (int k = 0; k < n; ++k) {
      a += w[k] * grid.z[std::size_t(pr[k]) * std::size_t(cols) + std::size_t(pc[k])];
      d += w[k] * std::hypot(double(pc[k] - col), double(pr[k] - row));
    }
    grid.z[i] = float(shape_curve(a, d, d_max, params.shape) + displacement(col, row, tree.level(col, row)));
    grid.state[i] = CellState::known;
  };
  for_each_created_cell(tree, compute, [&](int level) {
    if (step) step->update(double(level) / double(tree.levels()));
  });
}

namespace {

/// I_-1 of eq. 3.5 for a child labelled `label` (Belhadj §5.1.1: rivière up, crête down).
double child_shape(ExtrapolationLabel label, double shape) {
  switch (label) {
    case ExtrapolationLabel::river: return -std::abs(shape);
    case ExtrapolationLabel::ridge: return std::abs(shape);
    case ExtrapolationLabel::global: break;
  }
  return shape;
}

/// The label a parent takes from its children links[g, h): theirs if they all agree, else global,
/// so a chain of river cells keeps rising up the tree and a river beside a ridge follows the rule.
ExtrapolationLabel parent_label(const SubdivisionGrid& grid, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& links,
                                std::size_t g, std::size_t h) {
  const ExtrapolationLabel first = grid.label[links[g].second];
  for (std::size_t k = g + 1; k < h; ++k)
    if (grid.label[links[k].second] != first) return ExtrapolationLabel::global;
  return first;
}

/// The altitude of unknown parent p from its children links[g, h) (all known at the start of the round).
double extrapolate(const SubdivisionGrid& grid, const std::vector<std::pair<std::uint32_t, std::uint32_t>>& links,
                   std::size_t g, std::size_t h, double d_max, const BottomUpParams& params, std::uint64_t seed) {
  const std::uint32_t cols = std::uint32_t(grid.cols), p = links[g].first;
  const double px = double(p % cols), py = double(p / cols);
  double a = 0, weight_sum = 0, distance_sum = 0;
  for (std::size_t k = g; k < h; ++k) {
    const std::uint32_t e = links[k].second;
    const double d = std::hypot(px - double(e % cols), py - double(e / cols));
    if (params.rule == BottomUpRule::mean) {
      a += grid.z[e];
      distance_sum += d;
      continue;
    }
    const double weight = params.weight_by_distance ? d : 1.0 / d;
    a += weight * shape_curve(grid.z[e], d, d_max, grid.label.empty() ? params.shape : child_shape(grid.label[e], params.shape));
    weight_sum += weight;
  }
  if (params.rule == BottomUpRule::weighted) return a / weight_sum;
  // Belhadj Alg. 10 (§3.1.1.3, applied in §3.1.2): T.a <- Ex.a / Ex.n + (Ex.d x s / Ex.n) x X, with Ex.a the sum
  // of the children's altitudes, Ex.n their count, Ex.d the sum of their Euclidean distances to the
  // parent (cells), s the scale factor of eq. 1.1 and X uniform in [-1,1]. X is the position's hash,
  // so the result does not depend on the order of work.
  const double n = double(h - g);
  if (params.noise_m_per_cell == 0.0) return a / n;
  return a / n + distance_sum * params.noise_m_per_cell / n * position_noise(seed, int(px), int(py));
}

}  // namespace

std::size_t bottom_up(SubdivisionGrid& grid, Subdivision scheme, const BottomUpParams& params, std::uint64_t seed) {
  const int cols = grid.cols;
  const SubdivisionTree tree(cols, grid.rows);
  const double d_max = std::hypot(double(cols), double(grid.rows));
  std::vector<std::uint32_t> active;
  for (std::size_t i = 0; i < grid.z.size(); ++i)
    if (grid.state[i] != CellState::unknown) active.push_back(std::uint32_t(i));
  std::size_t set = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> links;  // (parent, child)
  while (!active.empty()) {
    links.clear();
    for (const std::uint32_t e : active) {
      const int col = int(e % std::uint32_t(cols)), row = int(e / std::uint32_t(cols));
      int pc[4], pr[4];
      double w[4];
      const int n = tree.parents(scheme, col, row, pc, pr, w);
      for (int k = 0; k < n; ++k) {
        const std::uint32_t p = std::uint32_t(pr[k]) * std::uint32_t(cols) + std::uint32_t(pc[k]);
        if (grid.state[p] == CellState::unknown) links.emplace_back(p, e);
      }
    }
    // Sorting makes the groups (and so the floating-point sums) independent of the order of work.
    // Each parent is set, and queued for the next round, once (Alg. 10 queues it once per child).
    std::sort(links.begin(), links.end());
    active.clear();
    for (std::size_t g = 0; g < links.size();) {
      const std::uint32_t p = links[g].first;
      std::size_t h = g;
      while (h < links.size() && links[h].first == p) ++h;
      grid.z[p] = float(extrapolate(grid, links, g, h, d_max, params, seed));
      if (!grid.label.empty()) grid.label[p] = parent_label(grid, links, g, h);
      grid.state[p] = CellState::known;
      active.push_back(p);
      ++set;
      g = h;
    }
  }
  return set;
}

void low_pass(SubdivisionGrid& grid) {
  const int cols = grid.cols, rows = grid.rows;
  const std::vector<float> source = grid.z;
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& r) {
    for (int row = r.begin(); row != r.end(); ++row)
      for (int col = 0; col < cols; ++col) {
        const std::size_t i = std::size_t(row) * std::size_t(cols) + std::size_t(col);
        if (grid.state[i] == CellState::constrained) continue;
        double sum = 0;
        int n = 0;
        for (int y = std::max(0, row - 1); y <= std::min(rows - 1, row + 1); ++y)
          for (int x = std::max(0, col - 1); x <= std::min(cols - 1, col + 1); ++x) {
            sum += source[std::size_t(y) * std::size_t(cols) + std::size_t(x)];
            ++n;
          }
        grid.z[i] = float(sum / n);
      }
  });
}

namespace {

void run_dmmc(SubdivisionGrid& grid, const DmmcParams& params, Progress* progress) {
  bottom_up(grid, params.top_down.subdivision, params.bottom_up, params.top_down.seed);
  midpoint_displacement(grid, params.top_down, progress);
}

}  // namespace

int dmmc(Raster<float>& raster, const DmmcParams& params, Progress* progress, const std::vector<ExtrapolationLabel>& labels) {
  SubdivisionGrid grid = SubdivisionGrid::from_raster(raster);
  if (!labels.empty()) {
    if (labels.size() != raster.size()) throw processing_error("dmmc: " + std::to_string(labels.size()) + " labels for " + std::to_string(raster.size()) + " cells");
    grid.label = labels;
  }
  int passes = 0;
  if (params.low_pass) {
    // §5.2.1 smooths while the error falls; the true error is unknown in practice, so a share of the
    // constraints is held out, rebuilt, and the pass count that minimises their error is kept.
    SubdivisionGrid held = grid;
    std::vector<std::size_t> hidden;
    for (int row = 0; row < grid.rows; ++row)
      for (int col = 0; col < grid.cols; ++col) {
        const std::size_t i = std::size_t(row) * std::size_t(grid.cols) + std::size_t(col);
        if (grid.state[i] != CellState::constrained) continue;
        if ((position_noise(params.top_down.seed ^ 0x5bd1e995u, col, row) + 1.0) * 0.5 >= params.holdout_share) continue;
        hidden.push_back(i);
        held.state[i] = CellState::unknown;
      }
    if (!hidden.empty()) {
      run_dmmc(held, params, nullptr);
      auto error = [&] {
        double s = 0;
        for (const std::size_t i : hidden) s += (double(held.z[i]) - grid.z[i]) * (double(held.z[i]) - grid.z[i]);
        return s;
      };
      double best = error();
      while (passes < params.max_low_pass) {
        low_pass(held);
        const double e = error();
        if (!(e < best)) break;
        best = e;
        ++passes;
      }
    }
  }
  run_dmmc(grid, params, progress);
  for (int k = 0; k < passes; ++k) low_pass(grid);
  raster.values() = std::move(grid.z);
  return passes;
}

}  // namespace terrapolis::terrain
