// Dijkstra, A* and bidirectional A* on the oriented road graph (Galin et al. 2010).
// SPDX-License-Identifier: MIT
#include "roads/anisotropic_search.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "core/random.hpp"

namespace terrapolis::roads {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

int sector_of(double angle_rad, int m) {
  const double w = 2 * std::numbers::pi / m;
  return int(std::floor(angle_rad / w + 0.5)) % m;
}

}  // namespace

RoadGraph::RoadGraph(const TerrainField& terrain, const CostModel& model, const GraphOptions& options)
    : terrain_(terrain), model_(model), options_(options) {
  if (options.angles < 1 || options.angles > 64) throw bad_input("--angles: must be in 1..64, got " + std::to_string(options.angles));
  const int m = options.angles;
  for (int s = 0; s < 3; ++s) salt_[s] = splitmix64(options.seed * 3 + std::uint64_t(s));
  // The road slope cost as a table over the grade (no atan per sample): 4096 steps up to the
  // threshold's grade; the threshold itself is tested exactly on the grade.
  {
    const double thr = model.road.slope_deg.threshold;
    tan_slope_max_ = thr < 90 ? std::tan(thr / kDeg) : kInfinity;
    const double gmax = thr < 90 ? tan_slope_max_ : std::tan(80 / kDeg);
    lut_step_ = gmax / 4096;
    slope_lut_.resize(4098);
    for (std::size_t i = 0; i < slope_lut_.size(); ++i)
      slope_lut_[i] = model.road.slope_deg(std::min(std::atan(double(i) * lut_step_) * kDeg, thr < 90 ? thr : 90.0));
  }
  // The table's lower convex hull (a piecewise-linear table lies above the hull of its points).
  for (std::size_t i = 0; i < slope_lut_.size() && slope_lut_[i] < kInfinity; ++i) {
    const double t = double(i) * lut_step_, c = slope_lut_[i];
    while (road_hull_t_.size() >= 2) {
      const std::size_t k = road_hull_t_.size();
      const double ax = road_hull_t_[k - 2], ay = road_hull_c_[k - 2], bx = road_hull_t_[k - 1], by = road_hull_c_[k - 1];
      if ((bx - ax) * (c - ay) - (by - ay) * (t - ax) <= 0) road_hull_t_.pop_back(), road_hull_c_.pop_back();
      else break;
    }
    road_hull_t_.push_back(t);
    road_hull_c_.push_back(c);
  }
  // Increasing costs give an increasing hull; guard a user's decreasing curve (the bound must not
  // fall with the grade: a path of mean grade t may be steeper in places).
  for (std::size_t i = road_hull_c_.size(); i-- > 1;) road_hull_c_[i - 1] = std::min(road_hull_c_[i - 1], road_hull_c_[i]);
  road_floor_ = model.road.water_depth_m.min_value() + model.road.vegetation.min_value();
  step_m_ = model.sample_step_m > 0 ? model.sample_step_m : 0.5 * terrain.min_cell_m();
  cheapest_ = model.cheapest_per_metre();
  // Orientation layers: one block of m sectors per enabled structure, then the "start" orientation.
  int block[3] = {0, -1, -1};
  int blocks = 1;
  if (model.bridge.enabled) block[1] = blocks++;
  if (model.tunnel.enabled) block[2] = blocks++;
  orientations_ = blocks * m + 1;
  for (const MaskArc& a : segment_mask(options.k)) arcs_.push_back({a.dcol, a.drow, Structure::road, block[0] * m + sector_of(a.angle_rad, m), a.angle_rad});
  surface_arcs_ = arcs_.size();
  const double cell = terrain.typical_cell_m();
  for (Structure s : {Structure::bridge, Structure::tunnel}) {
    const StructureCosts& sc = s == Structure::bridge ? model.bridge : model.tunnel;
    if (!sc.enabled) continue;
    const double rmin = sc.min_length_m ? *sc.min_length_m / cell : sc.min_length_cells;
    // Long arcs start beyond the surface mask: shorter crossings are surface arcs.
    double rmax = sc.max_length_m ? *sc.max_length_m / cell : sc.max_length_cells;
    if (sc.longest_m) rmax = std::min(rmax, *sc.longest_m / cell);
    const auto ring = annulus_mask(std::max(rmin, 1.0), rmax);
    const double keep = ring.empty() ? 0.0 : std::min(1.0, double(sc.samples) / double(ring.size()));
    const std::uint64_t threshold = keep >= 1.0 ? ~std::uint64_t(0) : std::uint64_t(keep * 18446744073709551615.0);
    (s == Structure::bridge ? bridge_keep_ : tunnel_keep_) = threshold;
    period_[int(s)] = keep >= 1.0 ? 1 : kSamplePeriod;
    if (keep <= 0) continue;
    const int b = block[int(s)];
    for (const MaskArc& a : ring) arcs_.push_back({a.dcol, a.drow, s, b * m + sector_of(a.angle_rad, m), a.angle_rad});
  }
  // Heuristic: per-metre cost against the grade t = tan(slope), the cheapest structure at each
  // grade, sampled every 0.05 deg; its lower convex hull bounds every arc from below (an increasing
  // piecewise-linear function of the slope is concave in the grade, so it lies above its chords).
  {
    std::vector<std::array<double, 2>> pts;
    for (double sdeg = 0; sdeg <= 89.5; sdeg += 0.05) {
      double c = model.road.slope_deg(sdeg) + model.road.water_depth_m.min_value() + model.road.vegetation.min_value();
      if (model.bridge.enabled)
        c = std::min(c, model.bridge.slope_deg(sdeg) + model.bridge.water_depth_m.min_value() + model.bridge.height_m.min_value() +
                                model.bridge.vegetation.min_value());
      if (model.tunnel.enabled)
        c = std::min(c, model.tunnel.slope_deg(sdeg) + model.tunnel.water_depth_m.min_value() + model.tunnel.depth_m.min_value() +
                                model.tunnel.vegetation.min_value());
      if (c == kInfinity) continue;
      pts.push_back({std::tan(sdeg / kDeg), 0.99 * c});
    }
    // A path of total grade t may climb steeper in places, so the bound must not decrease with
    // the grade: take the cheapest cost at any steeper grade (a no-op for increasing curves).
    for (std::size_t i = pts.size(); i-- > 1;) pts[i - 1][1] = std::min(pts[i - 1][1], pts[i][1]);
    std::vector<std::array<double, 2>> hull;
    for (const auto& p : pts) {
      while (hull.size() >= 2) {
        const auto& a = hull[hull.size() - 2];
        const auto& b = hull.back();
        if ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) <= 0) hull.pop_back();
        else break;
      }
      hull.push_back(p);
    }
    kappa_ = kInfinity;
    for (const auto& h : hull) {
      hull_t_.push_back(h[0]);
      hull_c_.push_back(h[1]);
      if (h[0] > 0 && h[1] / h[0] < kappa_) {
        kappa_ = h[1] / h[0];
        best_grade_ = h[0];
      }
    }
    if (kappa_ == kInfinity) kappa_ = 0;
    if (!hull_c_.empty()) cheapest_ = std::min(cheapest_, hull_c_.front());
  }
  build_rings();
  // Turn costs: the turn is the angle between the incoming sector and the new arc, less half a
  // sector (the exact incoming direction is only known to within a sector), priced by the stricter
  // of the two structures' curvature functions. m = 1 makes every turn free.
  const StructureCosts* costs[3] = {&model.road, &model.bridge, &model.tunnel};
  turn_.assign(std::size_t(orientations_) * arcs_.size(), 0.0);
  for (int o = 0; o + 1 < orientations_; ++o) {
    const int blk = o / m, sector = o % m;
    Structure in = Structure::road;
    for (int s = 0; s < 3; ++s)
      if (block[s] == blk) in = Structure(s);
    const double centre = sector * 2 * std::numbers::pi / m;
    for (std::size_t a = 0; a < arcs_.size(); ++a) {
      double d = std::fabs(arcs_[a].angle_rad - centre);
      if (d > std::numbers::pi) d = 2 * std::numbers::pi - d;
      const double turn = std::max(0.0, d - std::numbers::pi / m) * kDeg;
      turn_[std::size_t(o) * arcs_.size() + a] =
          std::max(costs[int(in)]->curvature_deg(turn), costs[int(arcs_[a].structure)]->curvature_deg(turn));
    }
  }
  // Arc lists. Surface arcs: out of a node only those with a finite turn, into it every arc of its
  // orientation. Long arcs: the same per ring and per sampling class of the cell (see pair_sampled).
  from_.assign(std::size_t(orientations_), {});
  into_.assign(std::size_t(orientations_), {});
  orientation_structure_.assign(std::size_t(orientations_), Structure::road);
  for (int s = 0; s < 3; ++s)
    if (block[s] >= 0)
      for (int i = 0; i < m; ++i) orientation_structure_[std::size_t(block[s] * m + i)] = Structure(s);
  for (std::size_t a = 0; a < surface_arcs_; ++a) {
    into_[std::size_t(arcs_[a].orientation)].push_back(int(a));
    for (int o = 0; o < orientations_; ++o)
      if (turn_cost(o, int(a)) < kInfinity) from_[std::size_t(o)].push_back(int(a));
  }
  const std::size_t nr = rings_.size(), no = std::size_t(orientations_);
  int classes = 1;
  for (int s = 1; s < 3; ++s) classes = std::max(classes, period_[s] * period_[s]);
  // Built in index order ((class, orientation), ring) straight into the flat arrays; the long arcs
  // are sorted by ring, so a class's kept arcs come out grouped by ring.
  long_from_start_.assign(1, 0);
  long_into_start_.assign(1, 0);
  std::vector<int> kept_from, kept_into;
  std::vector<std::vector<int>> into_by_slot(no * nr);
  for (int cls = 0; cls < classes; ++cls) {
    kept_from.clear();
    for (auto& l : into_by_slot) l.clear();
    for (std::size_t a = surface_arcs_; a < arcs_.size(); ++a) {
      const Arc& arc = arcs_[a];
      const int period = period_[int(arc.structure)];
      if (cls >= period * period) continue;
      const int col = cls % period, row = cls / period;
      if (pair_sampled(int(a), col, row)) kept_from.push_back(int(a));
      // Into a cell of this class: the arc from c - d exists when the pair drawn from there is kept.
      if (pair_sampled(int(a), col - arc.dcol, row - arc.drow))
        into_by_slot[std::size_t(arc.orientation) * nr + std::size_t(ring_of_[a - surface_arcs_])].push_back(int(a));
    }
    std::size_t k = 0;
    for (std::size_t ring = 0; ring < nr; ++ring) {
      for (; k < kept_from.size() && std::size_t(ring_of_[std::size_t(kept_from[k]) - surface_arcs_]) == ring; ++k)
        long_from_.push_back(kept_from[k]);
      long_from_start_.push_back(long_from_.size());
    }
    for (std::size_t o = 0; o < no; ++o) {
      for (std::size_t ring = 0; ring < nr; ++ring) {
        const auto& l = into_by_slot[o * nr + ring];
        long_into_.insert(long_into_.end(), l.begin(), l.end());
        long_into_start_.push_back(long_into_.size());
      }
    }
  }
}

void RoadGraph::build_rings() {
  // Sort the long arcs by structure and length, then cut each structure's arcs into bands of
  // equal length range. Lengths use the narrowest cell of the grid, so no arc is shorter.
  double wmin = kInfinity, hmin = kInfinity;
  for (int r = 0; r < terrain_.rows(); ++r) {
    wmin = std::min(wmin, terrain_.metres_x(r));
    hmin = std::min({hmin, terrain_.metres_y(r - 0.5), terrain_.metres_y(r + 0.5)});
  }
  auto min_length = [&](const Arc& a) { return std::hypot(a.dcol * wmin, a.drow * hmin); };
  std::stable_sort(arcs_.begin() + std::ptrdiff_t(surface_arcs_), arcs_.end(), [&](const Arc& a, const Arc& b) {
    if (a.structure != b.structure) return int(a.structure) < int(b.structure);
    return min_length(a) < min_length(b);
  });
  ring_of_.assign(arcs_.size() - surface_arcs_, -1);
  constexpr int kRings = 10;
  for (Structure s : {Structure::bridge, Structure::tunnel}) {
    std::size_t first = arcs_.size(), last = 0;
    for (std::size_t a = surface_arcs_; a < arcs_.size(); ++a)
      if (arcs_[a].structure == s) first = std::min(first, a), last = a + 1;
    if (first >= last) continue;
    const StructureCosts& sc = s == Structure::bridge ? model_.bridge : model_.tunnel;
    // Per-metre floor of the structure, and its margin over the heuristic's envelope g at every
    // grade it allows: an arc of length L costs at least L (floor) and, since the heuristic is
    // consistent (a subadditive bound of the distance and climb), e + h(target) - h(source) >= L
    // (margin). 0.75 keeps the keys clear of rounding and of the row-to-row change of cell widths
    // on geographic grids.
    const double fixed = sc.water_depth_m.min_value() + sc.vegetation.min_value() +
                         (s == Structure::bridge ? sc.height_m.min_value() : sc.depth_m.min_value());
    double floor = kInfinity, margin = kInfinity;
    for (double sdeg = 0; sdeg <= 89.5; sdeg += 0.05) {
      const double c = sc.slope_deg(sdeg) + fixed;
      if (c == kInfinity) continue;
      floor = std::min(floor, c);
      margin = std::min(margin, c - envelope(std::tan(sdeg / kDeg)) - 0.01);
    }
    if (floor == kInfinity) floor = margin = 0;
    const double lo = min_length(arcs_[first]), hi = min_length(arcs_[last - 1]);
    const int base = int(rings_.size());
    for (std::size_t a = first; a < last; ++a) {
      const double l = min_length(arcs_[a]);
      const int r = hi > lo ? std::min(kRings - 1, int((l - lo) / (hi - lo) * kRings)) : 0;
      ring_of_[a - surface_arcs_] = base + r;
    }
    for (int r = 0; r < kRings; ++r) rings_.push_back({s, kInfinity, 0, 0, -1});
    for (std::size_t a = first; a < last; ++a) {
      Ring& ring = rings_[std::size_t(ring_of_[a - surface_arcs_])];
      ring.min_length_m = std::min(ring.min_length_m, min_length(arcs_[a]));
    }
    // Drop empty rings (renumbering), then link each to the next of its structure.
    std::vector<int> renumber(kRings, -1);
    int kept = base;
    for (int r = 0; r < kRings; ++r) {
      if (rings_[std::size_t(base + r)].min_length_m == kInfinity) continue;
      rings_[std::size_t(kept)] = rings_[std::size_t(base + r)];
      renumber[std::size_t(r)] = kept++;
    }
    rings_.resize(std::size_t(kept));
    for (std::size_t a = first; a < last; ++a) ring_of_[a - surface_arcs_] = renumber[std::size_t(ring_of_[a - surface_arcs_] - base)];
    first_ring_[int(s)] = base;
    for (int r = base; r < kept; ++r) {
      Ring& ring = rings_[std::size_t(r)];
      ring.with_heuristic = 0.75 * std::max(0.0, margin) * ring.min_length_m;
      ring.without_heuristic = 0.75 * floor * ring.min_length_m;
      ring.next = r + 1 < kept ? r + 1 : -1;
    }
  }
}

double RoadGraph::envelope(double grade) const {
  if (hull_t_.empty()) return cheapest_;
  if (hull_t_.size() == 1 || grade <= hull_t_.front()) return hull_c_.front();
  if (grade >= hull_t_.back()) return hull_c_.back();
  const auto it = std::upper_bound(hull_t_.begin(), hull_t_.end(), grade);
  const std::size_t j = std::size_t(it - hull_t_.begin());
  const double f = (grade - hull_t_[j - 1]) / (hull_t_[j] - hull_t_[j - 1]);
  return hull_c_[j - 1] + f * (hull_c_[j] - hull_c_[j - 1]);
}

double RoadGraph::road_slope_cost(double grade) const {
  if (grade > tan_slope_max_) return kInfinity;
  const double x = grade / lut_step_;
  const std::size_t i = std::size_t(x);
  if (i + 1 >= slope_lut_.size()) return model_.road.slope_deg(std::atan(grade) * kDeg);
  const double f = x - double(i);
  return slope_lut_[i] + f * (slope_lut_[i + 1] - slope_lut_[i]);
}

double RoadGraph::surface_arc_bound(Cell from, int arc) const {
  const Arc& a = arcs_[std::size_t(arc)];
  const int c1 = from.col + a.dcol, r1 = from.row + a.drow;
  if (!terrain_.inside(c1, r1)) return kInfinity;
  const double length = terrain_.length_m({double(from.col), double(from.row)}, {double(c1), double(r1)});
  const double grade = std::fabs(double(terrain_.surface(c1, r1)) - double(terrain_.surface(from.col, from.row))) / length;
  // Some step is at least as steep as the mean (1e-9: the steps' own rounding).
  if (grade > tan_slope_max_ * (1 + 1e-9) || road_hull_t_.empty()) return kInfinity;
  // The middle sample exactly as arc_cost takes it: water deeper than the threshold closes the arc.
  const int n = std::max(1, int(std::ceil(length / step_m_))), i = (n + 1) / 2;
  const double dc = double(a.dcol) / n, dr = double(a.drow) / n;
  const double depth = terrain_.depth_at(from.col + dc * (i - 0.5), from.row + dr * (i - 0.5));
  if (depth > 0 && model_.road.water_depth_m(depth) == kInfinity) return kInfinity;
  double h = road_hull_c_.back();
  if (grade <= road_hull_t_.front()) {
    h = road_hull_c_.front();
  } else if (grade < road_hull_t_.back()) {
    const std::size_t j = std::size_t(std::upper_bound(road_hull_t_.begin(), road_hull_t_.end(), grade) - road_hull_t_.begin());
    const double f = (grade - road_hull_t_[j - 1]) / (road_hull_t_[j] - road_hull_t_[j - 1]);
    h = road_hull_c_[j - 1] + f * (road_hull_c_[j] - road_hull_c_[j - 1]);
  }
  return (1 - 1e-6) * length * (h + road_floor_);  // 1e-6: the float rounding of the cached costs
}

double RoadGraph::surface_cost_per_m(double slope_deg, double depth_m) const {
  return model_.road.slope_deg(slope_deg) + model_.road.water_depth_m(depth_m);
}

int RoadGraph::sample_class(Structure s, int col, int row) const {
  const int period = period_[int(s)];
  return ((row % period + period) % period) * period + (col % period + period) % period;
}

bool RoadGraph::pair_sampled(int arc, int from_class_col, int from_class_row) const {
  // The unordered pair {p, p + d} is drawn once, from its end with the canonical offset (south, or
  // due east): the same draw whichever end the search stands on.
  const Arc& a = arcs_[std::size_t(arc)];
  if ((a.structure == Structure::bridge ? bridge_keep_ : tunnel_keep_) == ~std::uint64_t(0)) return true;
  const bool canonical = a.drow > 0 || (a.drow == 0 && a.dcol > 0);
  const int dc = canonical ? a.dcol : -a.dcol, dr = canonical ? a.drow : -a.drow;
  const int period = period_[int(a.structure)];
  const int sc = canonical ? from_class_col : from_class_col + a.dcol, sr = canonical ? from_class_row : from_class_row + a.drow;
  const std::uint64_t cls = std::uint64_t(((sr % period + period) % period) * period + (sc % period + period) % period);
  const std::uint64_t offset = std::uint64_t((dr + 1024) * 2048 + (dc + 1024));
  const std::uint64_t h = splitmix64(salt_[int(a.structure)] ^ (offset * 0x100000001b3ULL + cls));
  return h <= (a.structure == Structure::bridge ? bridge_keep_ : tunnel_keep_);
}

bool RoadGraph::arc_sampled(Cell from, int arc) const {
  if (arcs_[std::size_t(arc)].structure == Structure::road) return true;
  return pair_sampled(arc, from.col, from.row);
}

std::span<const int> RoadGraph::arcs_from(Cell c, int orientation, int slot) const {
  if (slot == 0) return from_[std::size_t(orientation)];
  const std::size_t i = std::size_t(sample_class(rings_[std::size_t(slot - 1)].structure, c.col, c.row)) * rings_.size() + std::size_t(slot - 1);
  return {long_from_.data() + long_from_start_[i], long_from_start_[i + 1] - long_from_start_[i]};
}

std::span<const int> RoadGraph::arcs_into(Cell c, int orientation, int slot) const {
  if (slot == 0) return into_[std::size_t(orientation)];
  const std::size_t i = (std::size_t(sample_class(rings_[std::size_t(slot - 1)].structure, c.col, c.row)) * std::size_t(orientations_) +
                         std::size_t(orientation)) * rings_.size() + std::size_t(slot - 1);
  return {long_into_.data() + long_into_start_[i], long_into_start_[i + 1] - long_into_start_[i]};
}

double RoadGraph::arc_cost(Cell from, int arc) const {
  const Arc& a = arcs_[std::size_t(arc)];
  const int c1 = from.col + a.dcol, r1 = from.row + a.drow;
  if (!terrain_.inside(c1, r1)) return kInfinity;
  const GridPoint p0{double(from.col), double(from.row)}, p1{double(c1), double(r1)};
  const double length = terrain_.length_m(p0, p1);
  const int n = std::max(1, int(std::ceil(length / step_m_)));
  const double dl = length / n;
  const double dc = double(a.dcol) / n, dr = double(a.drow) / n;
  double total = 0;
  if (a.structure == Structure::road) {
    const StructureCosts& sc = model_.road;
    const bool veg = terrain_.has_vegetation();
    const double veg0 = veg ? 0.0 : sc.vegetation(0.0);  // without a layer the density is 0 everywhere
    const double water0 = sc.water_depth_m(0.0);
    double z0 = terrain_.surface(from.col, from.row);
    for (int i = 1; i <= n; ++i) {
      const double z1 = i == n ? terrain_.surface(c1, r1) : terrain_.surface_at(from.col + dc * i, from.row + dr * i);
      const double depth = terrain_.depth_at(from.col + dc * (i - 0.5), from.row + dr * (i - 0.5));
      double c = road_slope_cost(std::fabs(z1 - z0) / dl) + veg0 + (depth > 0 ? sc.water_depth_m(depth) : water0);
      if (veg) c += sc.vegetation(terrain_.vegetation_at(from.col + dc * (i - 0.5), from.row + dr * (i - 0.5)));
      c += terrain_.extra_cost_at(Structure::road, from.col + dc * (i - 0.5), from.row + dr * (i - 0.5));  // cost layers (plugins)
      if (c == kInfinity) return kInfinity;
      total += c * dl;
      z0 = z1;
    }
    return total;
  }
  // Bridges and tunnels join two land cells by a straight deck between their surfaces.
  if (terrain_.water(from.col, from.row) || terrain_.water(c1, r1)) return kInfinity;
  const bool bridge = a.structure == Structure::bridge;
  const StructureCosts& sc = bridge ? model_.bridge : model_.tunnel;
  const double za = terrain_.surface(from.col, from.row), zb = terrain_.surface(c1, r1);
  const double per_m_slope = sc.slope_deg(std::atan(std::fabs(zb - za) / length) * kDeg);
  if (per_m_slope == kInfinity) return kInfinity;
  // Per-metre cost of sample i (infinity when the deck cuts the ground or breaks a threshold).
  auto sample = [&](int i) {
    const double t = (i + 0.5) / n;
    const double col = from.col + dc * (i + 0.5), row = from.row + dr * (i + 0.5);
    const double deck = za + t * (zb - za);
    const double depth = terrain_.depth_at(col, row);
    if (bridge) {
      const double h = deck - terrain_.surface_at(col, row);
      if (h < 0) return kInfinity;  // the deck would cut the ground
      return sc.height_m(h) + sc.water_depth_m(depth) + sc.vegetation(terrain_.vegetation_at(col, row)) +
             terrain_.extra_cost_at(a.structure, col, row);  // cost layers (plugins)
    }
    const double d = terrain_.ground_at(col, row) - deck;
    if (d < 0) return kInfinity;  // the tube would leave the ground (or the sea floor)
    return sc.depth_m(d) + sc.water_depth_m(depth) + sc.vegetation(terrain_.vegetation_at(col, row)) +
           terrain_.extra_cost_at(a.structure, col, row);  // cost layers (plugins)
  };
  // Most long arcs are infeasible somewhere along their span: probe every eighth sample first so
  // that they are rejected early, then sum in order (the same sum as a plain loop, bit for bit).
  thread_local std::vector<double> c;
  c.assign(std::size_t(n), -1.0);
  const int stride = std::max(1, n / 8);
  for (int pass = 0; pass < 2; ++pass)
    for (int i = pass == 0 ? stride / 2 : 0; i < n; i += pass == 0 ? stride : 1) {
      if (c[std::size_t(i)] >= 0) continue;
      c[std::size_t(i)] = sample(i);
      if (c[std::size_t(i)] == kInfinity) return kInfinity;
    }
  for (int i = 0; i < n; ++i) total += (c[std::size_t(i)] + per_m_slope) * dl;
  return total;
}

double RoadGraph::lower_bound(Cell a, Cell b) const {
  // Any path between the two rows is at least |dcol| x the narrowest of their cell widths wide and
  // |drow| x the shortest cell height (cell widths shrink monotonically polewards); 0.995 absorbs
  // the small variation of cell heights with latitude.
  const double w = std::min(terrain_.metres_x(a.row), terrain_.metres_x(b.row));
  const double h = std::min(terrain_.metres_y(a.row), terrain_.metres_y(b.row));
  const double d = 0.995 * std::hypot((b.col - a.col) * w, (b.row - a.row) * h);
  const double z = std::fabs(double(terrain_.surface(b.col, b.row)) - double(terrain_.surface(a.col, a.row)));
  if (hull_t_.size() < 2 || kappa_ <= 0) return cheapest_ * d;
  if (d <= 0 || z >= best_grade_ * d) return std::max(cheapest_ * d, kappa_ * z);
  return d * envelope(z / d);  // below the best grade: cover D at grade z / D along the envelope
}

namespace {

struct Node {
  double g;
  std::uint32_t parent;  ///< forward: predecessor; backward: successor towards the goal
  std::int32_t arc;      ///< arc joining the node and its parent
};

struct QueueItem {
  double f;
  std::uint64_t key;
  std::uint32_t node;
  std::int32_t ring;  ///< -1: expand the node; r >= 0: price the node's long arcs of ring r
  double g;
  bool operator<(const QueueItem& o) const {  // min-heap; ties by key then ring, so the order is fixed
    if (f != o.f) return f > o.f;
    if (key != o.key) return key > o.key;
    return ring > o.ring;
  }
};

/// One direction of the search: its nodes and its queue. Nodes are stored per cell: a dense array
/// of 4 bytes per grid cell points to the cell's block of `orientations` nodes, allocated on first
/// touch, so a lookup is two array reads and memory follows the explored cells (a 3601 x 3601 SRTM
/// tile needs 52 MB for the cell array; a node is 16 bytes).
struct Frontier {
  static constexpr std::uint32_t kNone = 0xffffffffu;
  Frontier(std::size_t cells, std::uint64_t orientations) : orientations(orientations), block(cells, kNone) {}
  std::uint64_t orientations;
  std::vector<std::uint32_t> block;       ///< per grid cell: its block, or kNone
  std::vector<std::uint32_t> block_cell;  ///< per block: its cell
  std::vector<Node> nodes;                ///< block * orientations + orientation
  std::size_t stored = 0;
  std::vector<QueueItem> heap;
  double top() const { return heap.empty() ? kInfinity : heap.front().f; }
  void push(const QueueItem& q) {
    heap.push_back(q);
    std::push_heap(heap.begin(), heap.end());
  }
  QueueItem pop() {
    std::pop_heap(heap.begin(), heap.end());
    QueueItem q = heap.back();
    heap.pop_back();
    return q;
  }
  std::uint64_t key(std::uint32_t idx) const {
    return std::uint64_t(block_cell[idx / orientations]) * orientations + idx % orientations;
  }
  /// Index of the node of `key`, or kNone when it was never reached.
  std::uint32_t find(std::uint64_t k) const {
    const std::uint32_t b = block[std::size_t(k / orientations)];
    if (b == kNone) return kNone;
    const std::uint32_t idx = std::uint32_t(std::uint64_t(b) * orientations + k % orientations);
    return nodes[idx].g == kInfinity ? kNone : idx;
  }
  /// Relaxes `key` to cost g through `parent`/`arc`; returns the node index.
  std::uint32_t relax(std::uint64_t k, double g, std::uint32_t parent, int arc, bool& improved) {
    std::uint32_t& b = block[std::size_t(k / orientations)];
    if (b == kNone) {
      b = std::uint32_t(block_cell.size());
      block_cell.push_back(std::uint32_t(k / orientations));
      nodes.resize(nodes.size() + orientations, Node{kInfinity, kNone, -1});
    }
    const std::uint32_t idx = std::uint32_t(std::uint64_t(b) * orientations + k % orientations);
    Node& n = nodes[idx];
    improved = g < n.g;
    if (improved) {
      if (n.g == kInfinity) ++stored;
      n = {g, parent, arc};
    }
    return idx;
  }
};

/// Surface arc costs of the cells met so far: a node is expanded once per orientation but its
/// arcs cost the same from every orientation, so they are computed once (lazily, NaN = not yet).
class ArcCache {
 public:
  ArcCache(const RoadGraph& graph) : graph_(graph), n_(graph.surface_arcs()), slot_(graph.terrain().cols() * std::size_t(graph.terrain().rows()), kNone) {}
  /// The cached costs of a cell's surface arcs (NaN = not computed yet); valid until the next call.
  float* row(std::size_t cell_index) {
    std::uint32_t& s = slot_[cell_index];
    if (s == kNone) {
      s = std::uint32_t(costs_.size() / n_);
      costs_.resize(costs_.size() + n_, std::numeric_limits<float>::quiet_NaN());
    }
    return costs_.data() + std::size_t(s) * n_;
  }
  double get(Cell c, float* row, int arc) {
    if (std::size_t(arc) >= n_) return graph_.arc_cost(c, arc);
    float& v = row[arc];
    if (std::isnan(v)) v = float(graph_.arc_cost(c, arc));
    return v;
  }
  double get(Cell c, std::size_t cell_index, int arc) {
    if (std::size_t(arc) >= n_) return graph_.arc_cost(c, arc);
    return get(c, row(cell_index), arc);
  }
  std::size_t cells() const { return costs_.size() / std::max<std::size_t>(1, n_); }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  const RoadGraph& graph_;
  std::size_t n_;
  std::vector<std::uint32_t> slot_;
  std::vector<float> costs_;
};

/// Long-arc costs of the rings priced so far, per cell and ring (a cell's ring is priced once per
/// orientation it is expanded in, about 6 times on an Alpine road, but its arcs cost the same from
/// each), computed lazily (NaN = not yet) and kept as floats. Bounded: past `cap` values it stops
/// storing and the costs are recomputed, with the same rounding, so the cache never changes a result.
class LongArcCache {
 public:
  LongArcCache(std::size_t cells, std::size_t rings, std::size_t cap) : rings_(rings), cap_(cap), slot_(rings ? cells : 0, kNone) {}
  /// The costs of ring r of a cell whose list holds n arcs, or nullptr when the cache is full; valid
  /// until the next call.
  float* ring(std::size_t cell, int r, std::size_t n) {
    std::uint32_t& s = slot_[cell];
    if (s == kNone) {
      if (heads_.size() + values_.size() + rings_ > cap_) return nullptr;
      s = std::uint32_t(heads_.size() / rings_);
      heads_.resize(heads_.size() + rings_, kNone);
    }
    std::uint32_t& h = heads_[std::size_t(s) * rings_ + std::size_t(r)];
    if (h == kNone) {
      if (heads_.size() + values_.size() + n > cap_) return nullptr;
      h = std::uint32_t(values_.size());
      values_.resize(values_.size() + n, std::numeric_limits<float>::quiet_NaN());
    }
    return values_.data() + h;
  }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  std::size_t rings_, cap_;
  std::vector<std::uint32_t> slot_, heads_;
  std::vector<float> values_;
};

/// Distances to the target on a relaxed 2-D graph: nodes are cells (the orientation dropped, so no
/// turn is priced), arcs are every surface arc at its exact cost and every sampled bridge or tunnel
/// arc at a lower bound of its cost (its deck slope term exact, the height or depth, water and
/// vegetation terms at their minima). Every arc of the oriented graph costs at least its relaxed
/// arc, so the relaxed distance is an admissible and consistent heuristic for it, and on relief it
/// is far tighter than the straight-line bound: it knows where the valleys and passes are.
/// Computed lazily by a reverse A* from the target guided by the straight-line bound towards the
/// source and resumed on demand (Reverse Resumable A*, Silver 2005): `exact(v)` settles v; `bound(v)`
/// never searches and returns the exact distance when v is settled, else the A* bound
/// F - lower_bound(v, source) (F the smallest key still queued), which only grows.
class RelaxedDistance {
 public:
  RelaxedDistance(const RoadGraph& graph, Cell target, Cell source, ArcCache& cache)
      : graph_(graph), t_(graph.terrain()), source_(source), cache_(cache) {
    if (scratch_in_use_) own_.emplace();  // a nested search on this thread gets its own arrays
    else scratch_in_use_ = true;
    Scratch& s = scratch();
    if (s.g.size() != t_.size()) {
      s.g.assign(t_.size(), kInfinity);
      s.closed.assign(t_.size(), 0);
      s.touched.clear();
    }
    const CostModel& m = graph.model();
    fixed_[1] = m.bridge.height_m.min_value() + m.bridge.water_depth_m.min_value() + m.bridge.vegetation.min_value();
    fixed_[2] = m.tunnel.depth_m.min_value() + m.tunnel.water_depth_m.min_value() + m.tunnel.vegetation.min_value();
    // Deck slope cost against the grade as a table of lower bounds: entry i is the smallest cost at
    // any grade >= i x step. Each piece of the curve is monotone in the grade, so that minimum is at
    // i x step or at a breakpoint beyond it.
    for (int st = 1; st < 3; ++st) {
      const TransferFunction& f = st == 1 ? m.bridge.slope_deg : m.tunnel.slope_deg;
      tan_max_[st] = f.threshold < 90 ? std::tan(f.threshold / kDeg) : kInfinity;
      const double gmax = f.threshold < 90 ? tan_max_[st] : std::tan(89.5 / kDeg);
      constexpr std::size_t kSteps = 2048;
      grade_step_[st] = gmax / kSteps;
      auto& table = slope_floor_[st];
      table.assign(kSteps + 1, kInfinity);
      double beyond = f(std::min(f.threshold, std::atan(gmax) * kDeg));
      for (std::size_t i = kSteps + 1; i-- > 0;) {
        const double lo_deg = std::min(f.threshold, std::atan(double(i) * grade_step_[st]) * kDeg), hi_deg = std::atan(double(i + 1) * grade_step_[st]) * kDeg;
        for (const auto& p : f.points)
          if (p[0] >= lo_deg && (p[0] < hi_deg || i == kSteps) && p[0] <= f.threshold) beyond = std::min(beyond, p[1]);
        beyond = std::min(beyond, f(lo_deg));
        table[i] = beyond;
      }
      if (f.points.empty()) table.assign(kSteps + 1, 0.0);
    }
    relax(t_.index(target.col, target.row), 0.0);
  }
  ~RelaxedDistance() {
    Scratch& s = scratch();
    for (std::size_t i : s.touched) s.g[i] = kInfinity, s.closed[i] = 0;
    s.touched.clear();
    if (!own_) scratch_in_use_ = false;
  }
  RelaxedDistance(const RelaxedDistance&) = delete;
  RelaxedDistance& operator=(const RelaxedDistance&) = delete;

  /// The relaxed distance from v to the target (infinity when none), settling v if needed.
  double exact(Cell v) {
    const std::size_t i = t_.index(v.col, v.row);
    Scratch& s = scratch();
    while (!s.closed[i] && settle_next()) {
    }
    return s.closed[i] ? s.g[i] : kInfinity;
  }
  /// A lower bound of the relaxed distance from v without searching (exact when v is settled).
  double bound(Cell v) {
    const std::size_t i = t_.index(v.col, v.row);
    Scratch& s = scratch();
    if (s.closed[i]) return s.g[i];
    if (heap_.empty()) return kInfinity;
    return std::max(0.0, heap_.front().f - graph_.lower_bound(v, source_));
  }
  bool settled(Cell v) { return scratch().closed[t_.index(v.col, v.row)] != 0; }
  std::size_t settled_cells() const { return settled_; }
  /// Guides the search towards another source. Settled distances stay exact whatever the guide (a
  /// consistent heuristic never settles a cell early), so re-keying the queue with the new source's
  /// straight-line bound resumes an exact search: every road ending at the target shares it.
  void set_source(Cell source) {
    if (source == source_) return;
    source_ = source;
    for (Entry& e : heap_) {
      const Cell c{int(e.cell % std::size_t(t_.cols())), int(e.cell / std::size_t(t_.cols()))};
      e.f = e.g + graph_.lower_bound(c, source_);
    }
    std::make_heap(heap_.begin(), heap_.end());
  }

 private:
  struct Entry {
    double f, g;
    std::size_t cell;
    bool operator<(const Entry& o) const { return f != o.f ? f > o.f : cell > o.cell; }  // min-heap, fixed ties
  };
  struct Scratch {
    std::vector<double> g;
    std::vector<std::uint8_t> closed;
    std::vector<std::size_t> touched;
  };
  static inline thread_local Scratch shared_;
  static inline thread_local bool scratch_in_use_ = false;
  Scratch& scratch() { return own_ ? *own_ : shared_; }

  void relax(std::size_t i, double g) {
    Scratch& s = scratch();
    if (s.closed[i] || g >= s.g[i]) return;
    if (s.g[i] == kInfinity) s.touched.push_back(i);
    s.g[i] = g;
    const Cell c{int(i % std::size_t(t_.cols())), int(i / std::size_t(t_.cols()))};
    heap_.push_back({g + graph_.lower_bound(c, source_), g, i});
    std::push_heap(heap_.begin(), heap_.end());
  }
  /// Settles the next cell; false when the queue is empty.
  bool settle_next() {
    Scratch& s = scratch();
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end());
      const Entry e = heap_.back();
      heap_.pop_back();
      if (s.closed[e.cell] || e.g > s.g[e.cell]) continue;
      s.closed[e.cell] = 1;
      ++settled_;
      expand(e.cell, e.g);
      return true;
    }
    return false;
  }
  /// Relaxes the arcs into cell i (settled at distance d).
  void expand(std::size_t i, double d) {
    const Cell v{int(i % std::size_t(t_.cols())), int(i / std::size_t(t_.cols()))};
    const auto& arcs = graph_.arcs();
    for (std::size_t a = 0; a < graph_.surface_arcs(); ++a) {
      const Cell u{v.col - arcs[a].dcol, v.row - arcs[a].drow};
      if (!t_.inside(u.col, u.row)) continue;
      const std::size_t ui = t_.index(u.col, u.row);
      if (scratch().closed[ui]) continue;
      // The cheap bound first: most arcs into v cannot improve u, and need no integral.
      const double lb = graph_.surface_arc_bound(u, int(a));
      if (lb == kInfinity || d + lb >= scratch().g[ui]) continue;
      const double e = cache_.get(u, ui, int(a));
      if (e < kInfinity) relax(ui, d + e);
    }
    if (graph_.rings().empty() || t_.water(v.col, v.row)) return;  // long arcs join two land cells
    const double zv = t_.surface(v.col, v.row);
    // Sampled pairs are unordered: the long arcs out of v list the cells w whose arc w -> v exists.
    for (std::size_t r = 0; r < graph_.rings().size(); ++r) {
      const Structure st = graph_.rings()[r].structure;
      for (int a : graph_.arcs_from(v, 0, int(r) + 1)) {
        const Cell w{v.col + arcs[std::size_t(a)].dcol, v.row + arcs[std::size_t(a)].drow};
        if (!t_.inside(w.col, w.row) || t_.water(w.col, w.row)) continue;
        const std::size_t wi = t_.index(w.col, w.row);
        if (scratch().closed[wi]) continue;
        // As arc_cost prices the arc w -> v: the deck slope from the two surfaces over its length,
        // here bounded from the table (no atan, no curve lookup per arc).
        const double length = t_.length_m({double(w.col), double(w.row)}, {double(v.col), double(v.row)});
        const double floor = fixed_[int(st)] + slope_floor_[int(st)].front();
        if (d + (1 - 1e-6) * length * floor >= scratch().g[wi]) continue;  // cannot improve w
        const double grade = std::fabs(zv - double(t_.surface(w.col, w.row))) / length;
        if (grade > tan_max_[int(st)] * (1 + 1e-9)) continue;  // the deck breaks the slope threshold
        const auto& table = slope_floor_[int(st)];
        const double slope = table[std::min(table.size() - 1, std::size_t(grade / grade_step_[int(st)]))];
        // 1e-6 covers the float rounding of the priced long arcs.
        relax(wi, d + (1 - 1e-6) * length * (slope + fixed_[int(st)]));
      }
    }
  }

  const RoadGraph& graph_;
  const TerrainField& t_;
  Cell source_;
  ArcCache& cache_;
  std::optional<Scratch> own_;
  std::vector<Entry> heap_;
  double fixed_[3] = {0, 0, 0};
  std::vector<double> slope_floor_[3];  ///< per structure: lower bounds of the deck slope cost by grade step
  double grade_step_[3] = {1, 1, 1}, tan_max_[3] = {kInfinity, kInfinity, kInfinity};
  std::size_t settled_ = 0;
};

}  // namespace

struct TargetSearch::State {
  State(const RoadGraph& graph, Cell target)
      : target(target), arcs(graph), long_arcs(graph.terrain().size(), graph.rings().size(), std::size_t(1) << 25) {}  // at most 128 MB
  Cell target;
  ArcCache arcs;            ///< surface arc costs: a function of the graph alone
  LongArcCache long_arcs;   ///< long arc costs, likewise
  std::optional<RelaxedDistance> relaxed;  ///< the relaxed reverse search from the target, resumed by each road
};

TargetSearch::TargetSearch(const RoadGraph& graph, Cell target) : state_(std::make_unique<State>(graph, target)) {}
TargetSearch::~TargetSearch() = default;

SearchResult shortest_path(const RoadGraph& graph, Cell from, Cell to, SearchMethod method, std::size_t max_nodes,
                           Progress* progress, double max_seconds, TargetSearch* shared, const ArcDiscount* discount) {
  const auto started = std::chrono::steady_clock::now();
  std::size_t pops = 0;
  // The clock is read every 1024 pops (about a millisecond of search).
  auto out_of_time = [&]() {
    return max_seconds > 0 && (pops++ & 1023) == 0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() > max_seconds;
  };
  const TerrainField& t = graph.terrain();
  if (!t.inside(from.col, from.row) || !t.inside(to.col, to.row)) throw bad_input("path: an end point lies outside the DEM");
  SearchResult result;
  const std::uint64_t O = std::uint64_t(graph.orientations());
  auto key_of = [&](Cell c, int o) { return std::uint64_t(t.index(c.col, c.row)) * O + std::uint64_t(o); };
  auto cell_of = [&](std::uint64_t key) {
    const std::uint64_t i = key / O;
    return Cell{int(i % std::uint64_t(t.cols())), int(i / std::uint64_t(t.cols()))};
  };
  auto orient_of = [&](std::uint64_t key) { return int(key % O); };
  const bool use_h = method != SearchMethod::dijkstra;
  const bool bidir = method == SearchMethod::bidirectional;
  const bool relaxed = method == SearchMethod::astar;
  const std::size_t goal_index = t.index(to.col, to.row);
  if (from == to) {
    result.found = true;
    result.cost = 0;
    result.cells = {from};
    return result;
  }
  std::optional<ProgressStep> step;
  if (progress) step.emplace(*progress, "route");
  const double h0 = graph.lower_bound(from, to);
  double best_h = h0;
  auto report = [&](double h) {
    if (!step || h0 <= 0) return;
    best_h = std::min(best_h, h);
    if ((result.expanded & 4095) == 0) step->update(std::clamp(1.0 - best_h / h0, 0.0, 1.0));
  };
  // Queue keys. A*: g + h(v), h(v) = lower_bound(v, to); Dijkstra: g. Bidirectional A* uses the
  // balanced potential p(v) = (h_to(v) - h_from(v)) / 2 (Ikeda et al. 1994; Goldberg & Harrelson
  // 2005): forward key g + p(v), backward key g - p(v). Both heuristics are consistent, so the
  // reduced arc costs l(u,v) - p(u) + p(v) are >= 0 in both directions and the search may stop as
  // soon as top_f + top_b >= mu, the best meeting cost (the bidirectional Dijkstra rule on the
  // reduced costs).
  std::optional<TargetSearch> own;
  if (shared && !(shared->state().target == to)) throw processing_error("path: a shared target search used for another target");
  TargetSearch::State& state = (shared ? *shared : own.emplace(graph, to)).state();
  ArcCache& cache = state.arcs;
  RelaxedDistance* rel = nullptr;
  std::size_t settled_before = 0;
  if (relaxed) {
    if (state.relaxed) state.relaxed->set_source(from);
    else state.relaxed.emplace(graph, to, from, cache);
    rel = &*state.relaxed;
    settled_before = rel->settled_cells();
  }
  // Road reuse: a bound of the undiscounted costs times the smallest factor bounds the discounted
  // ones (and stays consistent), so the heuristic is scaled; arcs are discounted as they are read.
  const double h_scale = discount ? discount->floor : 1.0;
  auto reuse = [&](Cell c, int a) {
    if (!discount) return 1.0;
    const RoadGraph::Arc& arc = graph.arcs()[std::size_t(a)];
    const auto f = [&](int col, int row) { return discount->factor[t.index(col, row)]; };
    return double(std::max({f(c.col, c.row), f(c.col + arc.dcol / 2, c.row + arc.drow / 2), f(c.col + arc.dcol, c.row + arc.drow)}));
  };
  auto potential = [&](Cell v) {
    if (!use_h) return 0.0;
    if (relaxed) return h_scale * std::max(graph.lower_bound(v, to), rel->bound(v));
    if (!bidir) return h_scale * graph.lower_bound(v, to);
    return h_scale * 0.5 * (graph.lower_bound(v, to) - graph.lower_bound(v, from));
  };
  auto ring_offset = [&](int r) {
    const RoadGraph::Ring& ring = graph.rings()[std::size_t(r)];
    // The relaxed distance is consistent but leaves no margin to add (its long arcs are already
    // bounded by their structure's floor), so a ring waits only behind its node.
    return relaxed ? 0.0 : use_h ? ring.with_heuristic : ring.without_heuristic;
  };
  const std::vector<RoadGraph::Arc>& arcs = graph.arcs();

  Frontier fw(t.size(), O), bw(bidir ? t.size() : 0, O);
  LongArcCache& long_cache = state.long_arcs;
  // Long arcs are priced as floats in both directions, cached or not, so every search sees the same costs.
  auto long_cost = [&](Cell from_cell, int a) { return double(float(graph.arc_cost(from_cell, a))); };
  auto check_memory = [&]() {
    if (fw.nodes.size() + bw.nodes.size() + cache.cells() * graph.surface_arcs() / 4 > max_nodes)
      throw processing_error("path: the search stored more than " + std::to_string(max_nodes) +
                             " nodes; use a smaller --k or --angles, or closer end points");
  };
  double mu = kInfinity;
  std::uint64_t meet = 0;
  auto try_meet = [&](std::uint64_t key, double g, const Frontier& other) {
    if (!bidir) return;
    const std::uint32_t j = other.find(key);
    if (j == Frontier::kNone) return;
    const double total = g + other.nodes[j].g;
    if (total < mu || (total == mu && key < meet)) {
      mu = total;
      meet = key;
    }
  };
  // Forward: the arcs of `slot` (0 surface, r + 1 ring r) out of the node of q.
  auto expand_forward = [&](const QueueItem& q, int slot) {
    const Cell c = cell_of(q.key);
    const int o = orient_of(q.key);
    const std::span<const int> list = graph.arcs_from(c, o, slot);
    float* costs = slot == 0 ? cache.row(t.index(c.col, c.row)) : long_cache.ring(t.index(c.col, c.row), slot - 1, list.size());
    for (std::size_t i = 0; i < list.size(); ++i) {
      const int a = list[i];
      const RoadGraph::Arc& arc = arcs[std::size_t(a)];
      const Cell n{c.col + arc.dcol, c.row + arc.drow};
      if (!t.inside(n.col, n.row)) continue;
      const double turn = graph.turn_cost(o, a);
      if (turn == kInfinity) continue;  // long arcs: the lists do not depend on the orientation
      double e;
      if (slot == 0) {
        e = cache.get(c, costs, a) * reuse(c, a);
      } else if (costs) {
        if (std::isnan(costs[i])) costs[i] = float(long_cost(c, a));
        e = costs[i];
      } else {
        e = long_cost(c, a);
      }
      if (e == kInfinity) continue;
      const double g = q.g + turn + e;
      bool improved;
      const std::uint32_t idx = fw.relax(key_of(n, arc.orientation), g, q.node, a, improved);
      if (improved) {
        const double f = g + potential(n);
        if (f == kInfinity) continue;  // the target cannot be reached from n
        fw.push({f, fw.key(idx), idx, -1, g});
        try_meet(fw.key(idx), g, bw);
      }
    }
  };
  // Backward: the arcs of `slot` into the node of q, from every orientation of their source.
  auto expand_backward = [&](const QueueItem& q, int slot) {
    const Cell c = cell_of(q.key);
    const int o = orient_of(q.key);
    for (int a : graph.arcs_into(c, o, slot)) {
      const RoadGraph::Arc& arc = arcs[std::size_t(a)];
      const Cell p{c.col - arc.dcol, c.row - arc.drow};
      if (!t.inside(p.col, p.row)) continue;
      const double e = slot == 0 ? cache.get(p, t.index(p.col, p.row), a) * reuse(p, a) : long_cost(p, a);
      if (e == kInfinity) continue;
      const double hp = potential(p);
      for (int po = 0; po < graph.orientations(); ++po) {
        if (po == graph.start_orientation() && !(p == from)) continue;
        const double turn = graph.turn_cost(po, a);
        if (turn == kInfinity) continue;
        const double g = q.g + turn + e;
        bool improved;
        const std::uint32_t idx = bw.relax(key_of(p, po), g, q.node, a, improved);
        if (improved) {
          bw.push({g - hp, bw.key(idx), idx, -1, g});
          try_meet(bw.key(idx), g, fw);
        }
      }
    }
  };
  std::uint32_t goal_node = Frontier::kNone;  // A*, Dijkstra: the goal node when it is popped
  // Pops one entry of a direction and processes it; returns false when it is the goal (A*).
  auto step_once = [&](bool forward) {
    Frontier& me = forward ? fw : bw;
    const QueueItem q = me.pop();
    if (q.g > me.nodes[q.node].g) return true;  // stale: the node was reached more cheaply since
    const Cell c = cell_of(q.key);
    if (relaxed && q.ring < 0 && !rel->settled(c)) {
      // Queued with a bound of the relaxed distance: settle it, and queue the node again if its
      // key grew (keys only grow to admissible values, so the search stays exact).
      const double f = q.g + h_scale * std::max(graph.lower_bound(c, to), rel->exact(c));
      if (f > q.f) {
        if (f < kInfinity) me.push({f, q.key, q.node, -1, q.g});
        return true;
      }
    }
    const double node_key = forward ? q.g + potential(c) : q.g - potential(c);
    if (q.ring >= 0) {
      forward ? expand_forward(q, q.ring + 1) : expand_backward(q, q.ring + 1);
      const int next = graph.rings()[std::size_t(q.ring)].next;
      if (next >= 0) me.push({node_key + ring_offset(next), q.key, q.node, next, q.g});
      ++result.rings_priced;
      return true;
    }
    if (!bidir && t.index(c.col, c.row) == goal_index) {
      goal_node = q.node;
      return false;
    }
    ++result.expanded;
    report(forward ? graph.lower_bound(c, to) : graph.lower_bound(c, from));
    forward ? expand_forward(q, 0) : expand_backward(q, 0);
    // Long arcs wait in the queue, one entry per ring, keyed by the node's key plus a lower bound of
    // what an arc of the ring adds to it: a ring is priced only if that key comes up before the end.
    for (Structure s : {Structure::bridge, Structure::tunnel}) {
      if (!forward && graph.structure_of(orient_of(q.key)) != s) continue;  // arcs into the node are of its structure
      const int r = graph.first_ring(s);
      if (r >= 0) me.push({node_key + ring_offset(r), q.key, q.node, r, q.g});
    }
    check_memory();
    return true;
  };

  {
    bool imp;
    const std::uint32_t s = fw.relax(key_of(from, graph.start_orientation()), 0.0, Frontier::kNone, -1, imp);
    fw.push({potential(from), fw.key(s), s, -1, 0.0});
  }
  if (!bidir) {
    while (!fw.heap.empty()) {
      if (out_of_time()) {
        result.over_budget = true;
        break;
      }
      if (!step_once(true)) break;
    }
    result.nodes = fw.stored;
    if (rel) result.relaxed_settled = rel->settled_cells() - settled_before;
    if (goal_node == Frontier::kNone || result.over_budget) return result;
    result.found = true;
    result.cost = fw.nodes[goal_node].g;
    for (std::uint32_t n = goal_node; n != Frontier::kNone; n = fw.nodes[n].parent) {
      result.cells.push_back(cell_of(fw.key(n)));
      if (fw.nodes[n].arc >= 0) result.structures.push_back(arcs[std::size_t(fw.nodes[n].arc)].structure);
    }
    std::reverse(result.cells.begin(), result.cells.end());
    std::reverse(result.structures.begin(), result.structures.end());
    return result;
  }

  for (int o = 0; o < graph.start_orientation(); ++o) {
    bool imp;
    const std::uint32_t s = bw.relax(key_of(to, o), 0.0, Frontier::kNone, -1, imp);
    bw.push({-potential(to), bw.key(s), s, -1, 0.0});
  }
  while (!fw.heap.empty() && !bw.heap.empty()) {
    if (fw.top() + bw.top() >= mu) break;
    if (out_of_time()) {
      result.over_budget = true;
      mu = kInfinity;
      break;
    }
    step_once(fw.top() <= bw.top());
  }
  result.nodes = fw.stored + bw.stored;
  if (mu == kInfinity) return result;
  result.found = true;
  result.cost = mu;
  for (std::uint32_t n = fw.find(meet); n != Frontier::kNone; n = fw.nodes[n].parent) {
    result.cells.push_back(cell_of(fw.key(n)));
    if (fw.nodes[n].arc >= 0) result.structures.push_back(arcs[std::size_t(fw.nodes[n].arc)].structure);
  }
  std::reverse(result.cells.begin(), result.cells.end());
  std::reverse(result.structures.begin(), result.structures.end());
  for (std::uint32_t n = bw.find(meet); n != Frontier::kNone && bw.nodes[n].parent != Frontier::kNone; n = bw.nodes[n].parent) {
    const Node& nd = bw.nodes[n];
    result.cells.push_back(cell_of(bw.key(nd.parent)));
    result.structures.push_back(arcs[std::size_t(nd.arc)].structure);
  }
  return result;
}

double chain_cost(const RoadGraph& graph, const std::vector<Cell>& cells) {
  const auto& arcs = graph.arcs();
  double total = 0;
  int o = graph.start_orientation();
  for (std::size_t i = 1; i < cells.size(); ++i) {
    const int dc = cells[i].col - cells[i - 1].col, dr = cells[i].row - cells[i - 1].row;
    int arc = -1;
    for (std::size_t a = 0; a < graph.surface_arcs(); ++a)
      if (arcs[a].dcol == dc && arcs[a].drow == dr) arc = int(a);
    if (arc < 0) return kInfinity;
    total += graph.turn_cost(o, arc) + graph.arc_cost(cells[i - 1], arc);
    o = arcs[std::size_t(arc)].orientation;
  }
  return total;
}

}  // namespace terrapolis::roads
