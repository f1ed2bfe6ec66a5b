// The oriented road graph of Galin et al. 2010 (Peytavie 2010 §4.1-4.3): arcs, costs, lower bounds.
// SPDX-License-Identifier: MIT
#include "roads/road_graph.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
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
  if (options.angles < 1 || options.angles > 64) throw bad_input("/roads/angles: must be in 1..64, got " + std::to_string(options.angles));
  const int m = options.angles;
  for (int s = 0; s < 3; ++s) salt_[s] = splitmix64(options.seed * 3 + std::uint64_t(s));
  build_slope_tables();
  step_m_ = model_.sample_step_m > 0 ? model_.sample_step_m : 0.5 * terrain_.min_cell_m();
  cheapest_ = model_.cheapest_per_metre();
  // Orientation layers: one block of m sectors per enabled structure, then the "start" orientation.
  int block[3] = {0, -1, -1};
  int blocks = 1;
  if (model_.bridge.enabled) block[1] = blocks++;
  if (model_.tunnel.enabled) block[2] = blocks++;
  orientations_ = blocks * m + 1;
  for (const MaskArc& a : segment_mask(options_.k)) arcs_.push_back({a.dcol, a.drow, Structure::road, block[0] * m + sector_of(a.angle_rad, m), a.angle_rad});
  surface_arcs_ = arcs_.size();
  // The rows held, from row0 (a frame's graph prices nothing: no table).
  if (terrain_.holds_values() && surface_arcs_ * std::size_t(terrain_.rows()) <= kMaxLengthTable) {
    surface_length_.resize(surface_arcs_ * std::size_t(terrain_.rows()));
    for (int r = terrain_.row0(); r < terrain_.row0() + terrain_.rows(); ++r)
      for (std::size_t a = 0; a < surface_arcs_; ++a)
        surface_length_[std::size_t(r - terrain_.row0()) * surface_arcs_ + a] =
            terrain_.length_m({0, double(r)}, {double(arcs_[a].dcol), double(r + arcs_[a].drow)});
  }
  const double cell = terrain_.typical_cell_m();
  for (Structure s : {Structure::bridge, Structure::tunnel}) {
    const StructureCosts& sc = s == Structure::bridge ? model_.bridge : model_.tunnel;
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
  orientation_structure_.assign(std::size_t(orientations_), Structure::road);
  for (int s = 0; s < 3; ++s)
    if (block[s] >= 0)
      for (int i = 0; i < m; ++i) orientation_structure_[std::size_t(block[s] * m + i)] = Structure(s);
  build_envelope();
  build_rings();
  build_turns();
  build_arc_lists();
}

void RoadGraph::build_slope_tables() {
  // The road slope cost as a table over the grade (no atan per sample): 4096 steps up to the
  // threshold's grade; the threshold itself is tested exactly on the grade.
  {
    const double thr = model_.road.slope_deg.threshold;
    tan_slope_max_ = thr < 90 ? std::tan(thr / kDeg) : kInfinity;
    const double gmax = thr < 90 ? tan_slope_max_ : std::tan(80 / kDeg);
    lut_step_ = gmax / 4096;
    slope_lut_.resize(4098);
    for (std::size_t i = 0; i < slope_lut_.size(); ++i)
      slope_lut_[i] = model_.road.slope_deg(std::min(std::atan(double(i) * lut_step_) * kDeg, thr < 90 ? thr : 90.0));
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
  road_floor_ = model_.road.water_depth_m.min_value() + model_.road.vegetation.min_value();
}

void RoadGraph::build_envelope() {
  // Heuristic: per-metre cost against the grade t = tan(slope), the cheapest structure at each
  // grade, sampled every 0.05 deg; its lower convex hull bounds every arc from below (an increasing
  // piecewise-linear function of the slope is concave in the grade, so it lies above its chords).
  {
    std::vector<std::array<double, 2>> pts;
    for (double sdeg = 0; sdeg <= 89.5; sdeg += 0.05) {
      double c = model_.road.slope_deg(sdeg) + model_.road.water_depth_m.min_value() + model_.road.vegetation.min_value();
      if (model_.bridge.enabled)
        c = std::min(c, model_.bridge.slope_deg(sdeg) + model_.bridge.water_depth_m.min_value() + model_.bridge.height_m.min_value() +
                                model_.bridge.vegetation.min_value());
      if (model_.tunnel.enabled)
        c = std::min(c, model_.tunnel.slope_deg(sdeg) + model_.tunnel.water_depth_m.min_value() + model_.tunnel.depth_m.min_value() +
                                model_.tunnel.vegetation.min_value());
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
}

void RoadGraph::build_turns() {
  const int m = options_.angles;
  // Turn costs: the turn is the angle between the incoming sector and the new arc, less half a
  // sector (the exact incoming direction is only known to within a sector), priced by the stricter
  // of the two structures' curvature functions. m = 1 makes every turn free.
  const StructureCosts* costs[3] = {&model_.road, &model_.bridge, &model_.tunnel};
  turn_.assign(std::size_t(orientations_) * arcs_.size(), 0.0);
  for (int o = 0; o + 1 < orientations_; ++o) {
    const int sector = o % m;
    const Structure in = orientation_structure_[std::size_t(o)];
    const double centre = sector * 2 * std::numbers::pi / m;
    for (std::size_t a = 0; a < arcs_.size(); ++a) {
      double d = std::fabs(arcs_[a].angle_rad - centre);
      if (d > std::numbers::pi) d = 2 * std::numbers::pi - d;
      const double turn = std::max(0.0, d - std::numbers::pi / m) * kDeg;
      turn_[std::size_t(o) * arcs_.size() + a] =
          std::max(costs[int(in)]->curvature_deg(turn), costs[int(arcs_[a].structure)]->curvature_deg(turn));
    }
  }
}

void RoadGraph::build_arc_lists() {
  // Arc lists. Surface arcs: out of a node only those with a finite turn, into it every arc of its
  // orientation. Long arcs: the same per ring and per sampling class of the cell (see pair_sampled).
  from_.assign(std::size_t(orientations_), {});
  into_.assign(std::size_t(orientations_), {});
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
  for (int r = 0; r < terrain_.grid_rows(); ++r) {  // the whole grid's, so that a window's rings are the grid's
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

double RoadGraph::surface_length_m(int row, int arc) const {
  if (!surface_length_.empty()) return surface_length_[std::size_t(row - terrain_.row0()) * surface_arcs_ + std::size_t(arc)];
  const Arc& a = arcs_[std::size_t(arc)];
  return terrain_.length_m({0, double(row)}, {double(a.dcol), double(row + a.drow)});
}

double RoadGraph::surface_arc_bound(Cell from, int arc) const {
  const Arc& a = arcs_[std::size_t(arc)];
  const int c1 = from.col + a.dcol, r1 = from.row + a.drow;
  if (!terrain_.inside(c1, r1)) return kInfinity;
  const double length = surface_length_m(from.row, arc);
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
  const double length = a.structure == Structure::road ? surface_length_m(from.row, arc) : terrain_.length_m(p0, p1);
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
