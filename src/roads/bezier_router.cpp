// Stochastic refinement of Bézier roads (Belhadj 2007, Algorithm 16).
// SPDX-License-Identifier: MIT
#include "roads/bezier_router.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

namespace terrapolis::roads {
namespace {

constexpr double kForbiddenCost = 10;  // a position on a cell a cost layer forbids (see discretise)

struct Control {
  GridPoint p;
  double t;  ///< parameter of the curve position the control point was drawn at (ends 0 and 1)
};

GridPoint casteljau(std::vector<GridPoint>& work, double t) {
  for (std::size_t n = work.size(); n > 1; --n)
    for (std::size_t i = 0; i + 1 < n; ++i)
      work[i] = {work[i].col + t * (work[i + 1].col - work[i].col), work[i].row + t * (work[i + 1].row - work[i].row)};
  return work[0];
}

struct Discrete {
  std::vector<GridPoint> cells;
  std::vector<double> t, cost;
  double total = 0;
};

class Evaluator {
 public:
  Evaluator(const TerrainField& terrain, const BezierOptions& o) : terrain_(terrain), o_(o) {
    zmin_ = 1e300;
    zmax_ = -1e300;
    for (int r = 0; r < terrain.rows(); ++r)
      for (int c = 0; c < terrain.cols(); ++c) {
        if (terrain.water(c, r)) continue;
        zmin_ = std::min(zmin_, double(terrain.surface(c, r)));
        zmax_ = std::max(zmax_, double(terrain.surface(c, r)));
      }
    if (!(zmax_ > zmin_)) zmax_ = zmin_ + 1;
    tan_max_ = std::tan(o.max_slope_deg * std::numbers::pi / 180);
  }

  Discrete discretise(const std::vector<Control>& ctrl) const {
    std::vector<GridPoint> pts;
    double chord = 0;
    for (std::size_t i = 0; i < ctrl.size(); ++i) {
      pts.push_back(ctrl[i].p);
      if (i) chord += std::hypot(ctrl[i].p.col - ctrl[i - 1].p.col, ctrl[i].p.row - ctrl[i - 1].p.row);
    }
    const int n = std::max(2, int(std::ceil(2 * chord)));
    Discrete d;
    std::vector<GridPoint> work;
    for (int i = 0; i <= n; ++i) {
      const double t = double(i) / n;
      work = pts;
      const GridPoint q = casteljau(work, t);
      const GridPoint cell{std::clamp(std::round(q.col), 0.0, double(terrain_.cols() - 1)),
                           std::clamp(std::round(q.row), 0.0, double(terrain_.rows() - 1))};
      if (!d.cells.empty() && d.cells.back().col == cell.col && d.cells.back().row == cell.row) continue;
      d.cells.push_back(cell);
      d.t.push_back(t);
    }
    d.cost.assign(d.cells.size(), 0.0);
    for (std::size_t i = 1; i + 1 < d.cells.size(); ++i) {  // the two ends cost 0 (thesis)
      const int c = int(d.cells[i].col), r = int(d.cells[i].row);
      double cost = 1.0;
      if (!terrain_.water(c, r)) {
        const int pc = int(d.cells[i - 1].col), pr = int(d.cells[i - 1].row);
        const double l = terrain_.length_m(d.cells[i - 1], d.cells[i]);
        const double s = std::min(1.0, std::fabs(terrain_.surface(c, r) - terrain_.surface(pc, pr)) / l / tan_max_);
        const double a = (terrain_.surface(c, r) - zmin_) / (zmax_ - zmin_);
        cost = std::sqrt((s + o_.altitude_weight * a) / (1 + o_.altitude_weight));
        // Cost layers (plugins), beyond the thesis: e per metre against the flat road's 1 per metre
        // is a share e / (1 + e) of the worst position; a forbidden cell (e infinite) weighs as ten
        // worst positions, so that refinement works on it first and leaving it always pays.
        const double e = terrain_.extra_cost_at(Structure::road, c, r);
        if (e > 0) cost = std::isinf(e) ? kForbiddenCost : std::max(cost, e / (1 + e));
      }
      d.cost[i] = cost;
      d.total += cost;
    }
    return d;
  }

 private:
  const TerrainField& terrain_;
  const BezierOptions& o_;
  double zmin_, zmax_, tan_max_;
};

/// A standard normal variate from two uniforms (Box-Muller), the same on every platform.
double normal(std::mt19937_64& rng) {
  const double u1 = (double((rng() >> 11) + 1)) * 0x1.0p-53, u2 = double(rng() >> 11) * 0x1.0p-53;
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
}

}  // namespace

BezierResult bezier_route(const TerrainField& terrain, GridPoint from, GridPoint to, const BezierOptions& o) {
  Evaluator eval(terrain, o);
  std::mt19937_64 rng(o.seed);
  std::vector<Control> ctrl{{from, 0.0}, {to, 1.0}};
  BezierResult result;
  Discrete d = eval.discretise(ctrl);
  result.evaluations = 1;
  bool improved = true;
  while (improved) {
    improved = false;
    std::vector<std::size_t> order(d.cells.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return d.cost[a] > d.cost[b]; });
    if (d.cost[order[0]] < o.threshold) {
      result.satisfied = true;
      break;
    }
    if (int(ctrl.size()) >= o.max_control_points) break;
    const double sigma = o.sigma_fraction * double(d.cells.size());
    for (std::size_t i : order) {
      if (d.cost[i] < o.threshold || result.evaluations >= o.max_evaluations) break;
      // Normal of the curve at the position, from its neighbours on the discrete curve.
      const GridPoint a = d.cells[i == 0 ? 0 : i - 1], b = d.cells[std::min(i + 1, d.cells.size() - 1)];
      double nx = -(b.row - a.row), ny = b.col - a.col;
      const double len = std::hypot(nx, ny);
      if (len == 0) continue;
      nx /= len;
      ny /= len;
      for (int attempt = 0; attempt < o.tries && result.evaluations < o.max_evaluations; ++attempt) {
        const double off = sigma * normal(rng);
        const GridPoint p{std::clamp(d.cells[i].col + off * nx, 0.0, double(terrain.cols() - 1)),
                          std::clamp(d.cells[i].row + off * ny, 0.0, double(terrain.rows() - 1))};
        std::vector<Control> trial = ctrl;
        const double t = d.t[i];
        auto at = std::upper_bound(trial.begin() + 1, trial.end() - 1, t, [](double v, const Control& c) { return v < c.t; });
        trial.insert(at, Control{p, t});
        Discrete dt = eval.discretise(trial);
        ++result.evaluations;
        if (dt.total < d.total) {
          ctrl = std::move(trial);
          d = std::move(dt);
          improved = true;
          break;
        }
      }
      if (improved) break;
    }
  }
  for (const Control& c : ctrl) result.control.push_back(c.p);
  result.polyline = d.cells;
  result.cost = d.total;
  result.worst = 0;
  for (double c : d.cost) result.worst = std::max(result.worst, c);
  result.satisfied = result.worst < o.threshold;
  return result;
}

}  // namespace terrapolis::roads
