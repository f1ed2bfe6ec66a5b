// Génévaux et al., river networks from a coastline (seeds/002 §4-7). See river_grammar.hpp.
// SPDX-License-Identifier: MIT
#include "generate/river_grammar.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "generate/generators.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::generate {
namespace {

constexpr double kPi = std::numbers::pi;
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Even-odd crossings of the horizontal line y with every ring edge, sorted: [x0,x1), [x2,x3)... are inside.
std::vector<double> row_crossings(const std::vector<std::vector<Point2>>& rings, double y) {
  std::vector<double> xs;
  for (const auto& ring : rings)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      const Point2 a = ring[i], b = ring[(i + 1) % n];
      if ((a.y <= y) != (b.y <= y)) xs.push_back(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
    }
  std::sort(xs.begin(), xs.end());
  return xs;
}

/// Value noise in [-1,1]: bilinear between hashed lattice values, two octaves (the paper's n(p) is Perlin's).
double value_noise(std::uint64_t seed, Point2 p, double wavelength) {
  double sum = 0, amplitude = 1, total = 0;
  for (int octave = 0; octave < 2; ++octave, wavelength /= 2, amplitude /= 2) {
    const double u = p.x / wavelength, v = p.y / wavelength;
    const int i = int(std::floor(u)), j = int(std::floor(v));
    const double fu = u - i, fv = v - j;
    const double su = fu * fu * (3 - 2 * fu), sv = fv * fv * (3 - 2 * fv);
    const std::uint64_t s = seed + 7919 * std::uint64_t(octave);
    const double top = (1 - su) * terrain::position_noise(s, i, j) + su * terrain::position_noise(s, i + 1, j);
    const double bottom = (1 - su) * terrain::position_noise(s, i, j + 1) + su * terrain::position_noise(s, i + 1, j + 1);
    sum += amplitude * ((1 - sv) * top + sv * bottom);
    total += amplitude;
  }
  return sum / total;
}

/// Nearest segment of a polyline set within `reach`: its index, distance and parameter.
struct Nearest {
  int index = -1;
  double distance = std::numeric_limits<double>::infinity(), t = 0;
};
template <class SegmentAt>
Nearest nearest_segment(const SpatialBins& bins, Point2 p, double reach, SegmentAt&& segment_at) {
  Nearest best;
  bins.visit(p.x - reach, p.y - reach, p.x + reach, p.y + reach, [&](int id) {
    const auto [a, b] = segment_at(id);
    const double t = segment_parameter(p, a, b);
    const double d = norm(p - (a + t * (b - a)));
    if (d < best.distance || (d == best.distance && id < best.index)) best = {id, d, t};
  });
  return best;
}

/// Widening search: the nearest segment at any distance (bins of a non-empty set).
template <class SegmentAt>
Nearest nearest_anywhere(const SpatialBins& bins, Point2 p, double limit, SegmentAt&& segment_at) {
  for (double reach = bins.bin(); ; reach *= 2) {
    const Nearest n = nearest_segment(bins, p, reach, segment_at);
    if (n.distance <= reach || reach > limit) return n;
  }
}

}  // namespace

GrammarRule choose_rule(int priority, double u, const CoastParams& params) {
  if (priority <= 0) return GrammarRule::fill;
  if (u < params.p_continue) return GrammarRule::continuation;
  if (u < params.p_continue + params.p_asymmetric) return GrammarRule::asymmetric;
  return GrammarRule::symmetric;
}

std::size_t select_candidate(const std::vector<double>& z, const std::vector<int>& priority, double zeta_m) {
  const double lowest = *std::min_element(z.begin(), z.end());
  std::size_t best = z.size();
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (!(z[i] - lowest <= zeta_m)) continue;  // X_ζ (the lowest itself when ζ = 0)
    if (best == z.size() || priority[i] > priority[best] || (priority[i] == priority[best] && z[i] < z[best])) best = i;
  }
  return best;
}

double ridge_height(double z0, double z1, double z2, double lambda, double d) { return std::max({z0, z1, z2}) + lambda * d; }

RiverGraph::RiverGraph(double width_m, double height_m, std::vector<std::vector<Point2>> coast, const CoastParams& params)
    : params_(params), coast_(std::move(coast)), coast_bins_(width_m, height_m, std::max(params.delta_m, params.edge_m)),
      edge_bins_(width_m, height_m, std::max(params.sigma_m, params.edge_m)), node_bins_(width_m, height_m, params.edge_m) {
  for (const auto& ring : coast_)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      const Point2 a = ring[i], b = ring[(i + 1) % n];
      coast_bins_.insert(int(coast_segments_.size()), std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y));
      coast_segments_.emplace_back(a, b);
    }
}

bool RiverGraph::inside(Point2 p) const {
  const std::vector<double> xs = row_crossings(coast_, p.y);
  const auto above = std::upper_bound(xs.begin(), xs.end(), p.x) - xs.begin();
  return above % 2 == 1;
}

double RiverGraph::coast_distance(Point2 p) const {
  if (coast_segments_.empty()) return std::numeric_limits<double>::infinity();
  return nearest_anywhere(coast_bins_, p, 1e9, [&](int id) { return coast_segments_[std::size_t(id)]; }).distance;
}

int RiverGraph::add_mouth(Point2 p, int priority) {
  RiverNode node;
  node.p = p;
  node.priority = priority;
  nodes_.push_back(node);
  node_bins_.insert(int(nodes_.size() - 1), p.x, p.y, p.x, p.y);
  return int(nodes_.size() - 1);
}

bool RiverGraph::valid(int from, Point2 p, double z) const {
  const Point2 q = nodes_[std::size_t(from)].p;
  // p in Ω and d(E, Γ) > δ; the edge leaving a mouth starts on Γ, so only its far end is tested.
  if (!inside(p)) return false;
  const bool from_mouth = nodes_[std::size_t(from)].parent < 0;
  bool near_coast = false;
  coast_bins_.visit(std::min(p.x, q.x) - params_.delta_m, std::min(p.y, q.y) - params_.delta_m, std::max(p.x, q.x) + params_.delta_m,
                    std::max(p.y, q.y) + params_.delta_m, [&](int id) {
                      const auto& [a, b] = coast_segments_[std::size_t(id)];
                      const double d = from_mouth ? point_segment_distance(p, a, b) : segment_segment_distance(p, q, a, b);
                      near_coast = near_coast || d <= params_.delta_m;
                    });
  if (near_coast) return false;
  // ∀ E_i: d(E, E_i) > σ. Edges sharing the node `from` meet E there: for them only the new end
  // is tested, at σ/2, so that siblings do not overlap. Edges sharing `from`'s parent come within
  // e of E whatever its direction: for them too only the new end is tested, at σ (the paper allows
  // σ > e, which the plain test would forbid to every continuation).
  bool crowded = false;
  const double s = params_.sigma_m;
  const int grand = nodes_[std::size_t(from)].parent;
  edge_bins_.visit(std::min(p.x, q.x) - s, std::min(p.y, q.y) - s, std::max(p.x, q.x) + s, std::max(p.y, q.y) + s, [&](int id) {
    if (crowded) return;
    const int child_index = edge_child_[std::size_t(id)];
    const RiverNode& child = nodes_[std::size_t(child_index)];
    const Point2 a = child.p, b = nodes_[std::size_t(child.parent)].p;
    if (child_index == from || child.parent == from) crowded = point_segment_distance(p, a, b) <= 0.5 * s;
    else if (grand >= 0 && (child_index == grand || child.parent == grand)) crowded = point_segment_distance(p, a, b) <= s;
    else crowded = segment_segment_distance(p, q, a, b) <= s;
  });
  if (crowded) return false;
  // Slope to the nodes near p below κ.
  bool steep = false;
  const double r = 2 * params_.edge_m;
  node_bins_.visit(p.x - r, p.y - r, p.x + r, p.y + r, [&](int id) {
    const RiverNode& n = nodes_[std::size_t(id)];
    const double d = norm(p - n.p);
    steep = steep || (d <= r && d > 0 && std::abs(z - n.z) / d >= params_.kappa);
  });
  return !steep;
}

int RiverGraph::add(int from, Point2 p, double z, int priority) {
  RiverNode node;
  node.p = p;
  node.z = z;
  node.parent = from;
  node.priority = priority;
  nodes_.push_back(node);
  const int id = int(nodes_.size() - 1);
  const Point2 q = nodes_[std::size_t(from)].p;
  edge_bins_.insert(int(edge_child_.size()), std::min(p.x, q.x), std::min(p.y, q.y), std::max(p.x, q.x), std::max(p.y, q.y));
  edge_child_.push_back(id);
  node_bins_.insert(id, p.x, p.y, p.x, p.y);
  return id;
}

std::vector<std::vector<Point2>> synthetic_coast(double width_m, double height_m, std::uint64_t seed) {
  Rng draw(seed ^ 0xC0A57ull);
  const Point2 centre{width_m / 2, height_m / 2};
  const double radius = 0.36 * std::min(width_m, height_m);
  double amplitude[9] = {}, phase[9] = {};
  for (int k = 2; k <= 8; ++k) {
    amplitude[k] = between(draw, 0.3, 1.0) * 0.22 / k;
    phase[k] = between(draw, 0, 2 * kPi);
  }
  std::vector<Point2> ring;
  const int n = 360;
  for (int i = 0; i < n; ++i) {
    const double theta = 2 * kPi * i / n;
    double r = 1;
    for (int k = 2; k <= 8; ++k) r += amplitude[k] * std::cos(k * theta + phase[k]);
    ring.push_back({centre.x + radius * r * std::cos(theta), centre.y + radius * r * std::sin(theta)});
  }
  return {ring};
}

namespace {

/// Mouths (§4.1): the coast sampled every e/2, accessibility a(p) = share of a disc of radius 4e
/// inside Ω (high in concave coast), mouths taken greedily by accessibility at least
/// `mouth_spacing_m` apart; the k-th mouth gets priority S - floor(log2(k+1)).
void place_mouths(RiverGraph& graph, const std::vector<std::vector<Point2>>& coast, const CoastParams& params,
                  std::vector<Point2>& directions) {
  struct Sample {
    Point2 p, inward;
    double access;
  };
  std::vector<Sample> samples;
  const double step = params.edge_m / 2, disc = 4 * params.edge_m;
  for (const auto& ring : coast)
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      stop_if_interrupted();  // no progress bar here: a long coast still stops on Ctrl-C
      const Point2 a = ring[i], b = ring[(i + 1) % n];
      const int pieces = std::max(1, int(std::ceil(norm(b - a) / step)));
      for (int k = 0; k < pieces; ++k) {
        const Point2 p = a + (double(k) / pieces) * (b - a);
        int in = 0, total = 0;
        Point2 sum{0, 0};
        for (int dy = -6; dy <= 6; ++dy)
          for (int dx = -6; dx <= 6; ++dx) {
            const Point2 o{dx * disc / 6, dy * disc / 6};
            if (norm(o) > disc) continue;
            ++total;
            if (graph.inside(p + o)) {
              ++in;
              sum = sum + o;
            }
          }
        if (in == 0) continue;
        const double l = norm(sum);
        if (l == 0) continue;
        samples.push_back({p, (1.0 / l) * sum, double(in) / total});
      }
    }
  std::stable_sort(samples.begin(), samples.end(), [](const Sample& x, const Sample& y) { return x.access > y.access; });
  std::vector<Point2> placed;
  for (const Sample& s : samples) {
    bool far = true;
    for (Point2 q : placed) far = far && norm(q - s.p) >= params.mouth_spacing_m;
    if (!far) continue;
    const int k = int(placed.size());
    placed.push_back(s.p);
    graph.add_mouth(s.p, std::max(0, params.max_priority - int(std::floor(std::log2(k + 1.0)))));
    directions.push_back(s.inward);
  }
}

/// Grows the forest (§4.2): mixed selection, then the production of the chosen candidate; each
/// child β is instantiated if valid (3.1) or dropped (3.2).
void grow(RiverGraph& graph, std::vector<Point2> directions, const CoastParams& params, Rng& draw, Progress* progress) {
  struct Candidate {
    int node;
    Point2 dir;
  };
  std::vector<Candidate> open;
  for (std::size_t i = 0; i < graph.nodes().size(); ++i) open.push_back({int(i), directions[i]});
  const auto rotate = [](Point2 d, double a) { return Point2{d.x * std::cos(a) - d.y * std::sin(a), d.x * std::sin(a) + d.y * std::cos(a)}; };
  const double deg = kPi / 180;
  std::vector<double> z;
  std::vector<int> priority;
  std::size_t steps = 0;
  while (!open.empty()) {
    stop_if_interrupted();  // each step scans every open candidate: 256 steps can take long
    z.clear();
    priority.clear();
    for (const Candidate& c : open) {
      z.push_back(graph.nodes()[std::size_t(c.node)].z);
      priority.push_back(graph.nodes()[std::size_t(c.node)].priority);
    }
    const std::size_t chosen = select_candidate(z, priority, params.zeta_m);
    const Candidate c = open[chosen];
    open.erase(open.begin() + std::ptrdiff_t(chosen));  // α becomes τ
    const RiverNode from = graph.nodes()[std::size_t(c.node)];
    const int s = from.priority;
    struct Child {
      double angle;
      int priority;
    };
    std::vector<Child> children;
    const double side = draw.uniform() < 0.5 ? -1 : 1;
    switch (choose_rule(s, draw.uniform(), params)) {
      case GrammarRule::fill: {
        const int p = integer(draw, 1, 5);
        children.push_back({between(draw, -20, 20) * deg, 0});
        for (int i = 1; i < p; ++i) children.push_back({(i % 2 ? side : -side) * between(draw, 35, 75) * deg, 0});
        break;
      }
      case GrammarRule::continuation: children.push_back({between(draw, -20, 20) * deg, s}); break;
      case GrammarRule::asymmetric:
        children.push_back({between(draw, -15, 15) * deg, s});
        children.push_back({side * between(draw, 40, 75) * deg, integer(draw, 0, s - 1)});
        break;
      case GrammarRule::symmetric:
        children.push_back({side * between(draw, 20, 45) * deg, s - 1});
        children.push_back({-side * between(draw, 20, 45) * deg, s - 1});
        break;
    }
    for (const Child& child : children) {
      const Point2 dir = rotate(c.dir, child.angle);
      const Point2 p = from.p + params.edge_m * dir;
      // Altitudes grow upstream (§4.2.2); low-priority streams are steeper.
      const double grade = params.river_grade * std::pow(std::sqrt(2.0), params.max_priority - child.priority) * between(draw, 0.6, 1.4);
      const double zc = from.z + grade * params.edge_m;
      if (graph.valid(c.node, p, zc)) open.push_back({graph.add(c.node, p, zc, child.priority), dir});
    }
    if (progress && ++steps % 256 == 0 && !progress->update(std::min(0.99, 1.0 - 1.0 / (1.0 + 0.001 * double(steps)))))
      throw Error(ErrorKind::cancelled, "generate: interrupted");
  }
}

/// Strahler orders of the forest; nodes come parents first.
void strahler_orders(std::vector<RiverNode>& nodes) {
  std::vector<int> top(nodes.size(), 0), count(nodes.size(), 0);
  for (std::size_t i = nodes.size(); i-- > 0;) {
    RiverNode& n = nodes[i];
    n.strahler = top[i] == 0 ? 1 : (count[i] >= 2 ? top[i] + 1 : top[i]);
    if (n.parent < 0) continue;
    const std::size_t p = std::size_t(n.parent);
    if (n.strahler > top[p]) {
      top[p] = n.strahler;
      count[p] = 1;
    } else if (n.strahler == top[p]) {
      ++count[p];
    }
  }
}

/// Refines each edge into pieces of about e/4 whose perpendicular offsets depend on the river type
/// (§7.1 "Subdivision des rivières": B nearly straight, E meandering, D and deltas wandering).
void refine_courses(std::vector<RiverNode>& nodes, const CoastParams& params) {
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    RiverNode& n = nodes[i];
    if (n.parent < 0) continue;
    const RiverNode& down = nodes[std::size_t(n.parent)];
    const Point2 a = n.p, b = down.p, ab = b - a;
    const double length = norm(ab);
    const Point2 normal{-ab.y / length, ab.x / length};
    const int pieces = std::max(2, int(std::ceil(length / (params.edge_m / 4))));
    double amplitude = 0.03;
    if (n.type == hydro::RiverType::E) amplitude = 0.12;
    else if (n.type == hydro::RiverType::D || n.type == hydro::RiverType::delta) amplitude = 0.06;
    const double phase = terrain::position_noise(params.seed ^ 0x5EEDull, int(i), 0) > 0 ? 1 : -1;
    n.course.clear();
    n.course_z.clear();
    for (int k = 0; k <= pieces; ++k) {
      const double t = double(k) / pieces;
      const double wiggle = (k == 0 || k == pieces) ? 0
          : amplitude * length * (phase * std::sin(2 * kPi * t) * (n.type == hydro::RiverType::E ? 1.0 : 0.3) +
                                  0.5 * terrain::position_noise(params.seed ^ 0xC0u, int(i), k));
      n.course.push_back(a + t * ab + wiggle * normal);
      n.course_z.push_back(n.z + t * (down.z - n.z));
    }
  }
}

/// Cells whose centre lies inside the coast polygons (plan metres of `cell` a side).
std::vector<std::uint8_t> land_cells(const Raster<float>& grid, const std::vector<std::vector<Point2>>& coast, double cell) {
  std::vector<std::uint8_t> land(grid.size(), 0);
  for (int r = 0; r < grid.rows(); ++r) {
    const std::vector<double> xs = row_crossings(coast, (r + 0.5) * cell);
    for (std::size_t k = 0; k + 1 < xs.size(); k += 2)
      for (int c = std::max(0, int(std::ceil(xs[k] / cell - 0.5))); c < grid.cols() && (c + 0.5) * cell < xs[k + 1]; ++c)
        land[grid.index(c, r)] = 1;
  }
  return land;
}

/// Each node's drained area: its Voronoi block on the grid (the land cells nearest to it) and
/// the blocks upstream. Returns the land's area, km².
double drained_areas(std::vector<RiverNode>& nodes, const Raster<float>& grid, const std::vector<std::uint8_t>& land, double cell,
                     double width, double height, double edge_m) {
  SpatialBins node_bins(width, height, edge_m);
  for (std::size_t i = 0; i < nodes.size(); ++i) node_bins.insert(int(i), nodes[i].p.x, nodes[i].p.y, nodes[i].p.x, nodes[i].p.y);
  std::vector<double> block_km2(nodes.size(), 0);
  const double cell_km2 = cell * cell * 1e-6;
  double land_km2 = 0;
  for (int r = 0; r < grid.rows(); ++r)
    for (int c = 0; c < grid.cols(); ++c) {
      if (!land[grid.index(c, r)]) continue;
      const Point2 p{(c + 0.5) * cell, (r + 0.5) * cell};
      int best = -1;
      double bd = std::numeric_limits<double>::infinity();
      for (double reach = edge_m; best < 0 && reach < 4 * (width + height); reach *= 2)
        node_bins.visit(p.x - reach, p.y - reach, p.x + reach, p.y + reach, [&](int id) {
          const double d = norm(p - nodes[std::size_t(id)].p);
          if (d < bd || (d == bd && id < best)) {
            bd = d;
            best = id;
          }
        });
      block_km2[std::size_t(best)] += cell_km2;
      land_km2 += cell_km2;
    }
  for (std::size_t i = 0; i < nodes.size(); ++i) nodes[i].area_km2 = block_km2[i];
  for (std::size_t i = nodes.size(); i-- > 0;)
    if (nodes[i].parent >= 0) nodes[std::size_t(nodes[i].parent)].area_km2 += nodes[i].area_km2;
  return land_km2;
}

/// Discharge and types (§5.1-5.2) with the project's rules of `hydro --classify`.
void classify_nodes(std::vector<RiverNode>& nodes) {
  const hydro::RiverTypeOptions types;
  std::vector<double> to_mouth_km(nodes.size(), 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    RiverNode& n = nodes[i];
    n.discharge_m3s = hydro::paper_discharge_m3s(n.area_km2);
    if (n.parent < 0) {
      n.type = hydro::RiverType::delta;
      continue;
    }
    const RiverNode& down = nodes[std::size_t(n.parent)];
    const double length = norm(n.p - down.p);
    to_mouth_km[i] = to_mouth_km[std::size_t(n.parent)] + length / 1000;
    hydro::ReachMeasures m;
    m.discharge_m3s = n.discharge_m3s;
    m.slope = (n.z - down.z) / length;
    m.sinuosity = types.e_min_sinuosity;  // the trajectory is drawn from the type: a gentle reach may meander
    m.to_mouth_km = to_mouth_km[std::size_t(n.parent)];
    m.mouth = down.parent < 0;
    n.type = hydro::classify_reach(m, types);
  }
}

/// The ridges between the rivers: the Voronoi edges of the river graph inside the domain.
std::vector<RidgeSegment> graph_ridges(const std::vector<RiverNode>& nodes, const RiverGraph& graph, const CoastParams& params) {
  std::vector<Point2> points;
  std::vector<double> z;
  std::vector<std::pair<int, int>> edges;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    points.push_back(nodes[i].p);
    z.push_back(nodes[i].z);
    if (nodes[i].parent >= 0) edges.emplace_back(int(i), nodes[i].parent);
  }
  const auto lambda_at = [&](Point2 q) { return params.lambda * std::min(1.0, graph.coast_distance(q) / (5 * params.edge_m)); };
  std::vector<RidgeSegment> ridges;
  for (const RidgeSegment& s : voronoi_ridges(points, z, edges, lambda_at))
    if (graph.inside(s.a) && graph.inside(s.b)) ridges.push_back(s);
  return ridges;
}

/// §6: the terrain A = C(B(T_i), U(R_i)) of river primitives R_i (one per piece of a river's
/// course) and terrain primitives T_i, evaluated at a point.
class CoastPrimitives {
 public:
  CoastPrimitives(const std::vector<RiverNode>& nodes, const std::vector<RidgeSegment>& ridges, const RiverGraph& domain, double cell,
                  double width, double height, const CoastParams& params, CoastTerrain& out)
      : ridges_(ridges), params_(params), piece_bins_(width, height, params.edge_m / 2), ridge_bins_(width, height, params.edge_m),
        radius_(1.5 * params.primitive_spacing_m), primitive_bins_(width, height, radius_) {
    add_rivers(nodes, cell, out);
    for (std::size_t i = 0; i < ridges.size(); ++i) {
      const RidgeSegment& s = ridges[i];
      ridge_bins_.insert(int(i), std::min(s.a.x, s.b.x), std::min(s.a.y, s.b.y), std::max(s.a.x, s.b.x), std::max(s.a.y, s.b.y));
    }
    add_terrain(domain, width, height);
    out.terrain_primitives = primitives_.size();
  }

  /// The height at plan point p.
  double height_at(Point2 p) const {
    const double radius = radius_, spacing = params_.primitive_spacing_m;
    // B(T_i): h = Σ w h / Σ w with h = c_z + n(p) and w = (1 - d²/r²)².
    double hw = 0, ws = 0;
    primitive_bins_.visit(p.x - radius, p.y - radius, p.x + radius, p.y + radius, [&](int id) {
      const Primitive& t = primitives_[std::size_t(id)];
      const double d2 = dot(p - t.c, p - t.c);
      if (d2 >= radius * radius) return;
      const double w = (1 - d2 / (radius * radius)) * (1 - d2 / (radius * radius));
      hw += w * (t.z + params_.noise * t.relief * value_noise(noise_seed_, p, 4 * spacing));
      ws += w;
    });
    // U(R_i) then C(A, U): the nearest river primitive replaces the terrain where it weighs.
    const Nearest near = nearest_segment(piece_bins_, p, max_radius_, [&](int id) { return piece_ends(id); });
    double h = ws > 0 ? hw / ws : 0;
    if (near.index >= 0) {
      const Piece& s = pieces_[std::size_t(near.index)];
      if (near.distance < s.radius) {
        const double u = near.distance / s.radius, w = (1 - u * u) * (1 - u * u);
        const double x = near.distance / s.half_width;
        const double hr = s.za + near.t * (s.zb - s.za) - (x < 1 ? s.depth * (1 - x * x) : 0.0);  // δ(d): the bed
        if (ws == 0) h = hr;
        h = (1 - w) * std::max(h, hr) + w * hr;
      }
    }
    return h;
  }

 private:
  struct Piece {
    Point2 a, b;
    double za, zb, radius, half_width, depth;
  };
  struct Primitive {
    Point2 c;
    double z, relief;
  };

  std::pair<Point2, Point2> piece_ends(int id) const { return {pieces_[std::size_t(id)].a, pieces_[std::size_t(id)].b}; }

  void add_rivers(const std::vector<RiverNode>& nodes, double cell, CoastTerrain& out) {
    for (const RiverNode& n : nodes) {
      if (n.course.size() < 2) continue;
      ++out.river_primitives;
      // Hydraulic geometry (Leopold & Maddock 1953): width ∝ Q^0.5, depth ∝ Q^0.4; the valley floor
      // a few channel widths, at least 2 cells so that the grid resolves it.
      const double q = std::max(n.discharge_m3s, 0.01);
      const double half_width = std::max(0.5 * 2.5 * std::sqrt(q), 0.6 * cell), depth = 0.3 * std::pow(q, 0.4) + 0.5;
      const double radius = std::max(3 * cell, 120 + 40 * std::sqrt(q));
      max_radius_ = std::max(max_radius_, radius);
      for (std::size_t k = 0; k + 1 < n.course.size(); ++k) {
        pieces_.push_back({n.course[k], n.course[k + 1], n.course_z[k], n.course_z[k + 1], radius, half_width, depth});
        out.river_km += norm(n.course[k + 1] - n.course[k]) / 1000;
      }
    }
    for (std::size_t i = 0; i < pieces_.size(); ++i) {
      const Piece& s = pieces_[i];
      piece_bins_.insert(int(i), std::min(s.a.x, s.b.x), std::min(s.a.y, s.b.y), std::max(s.a.x, s.b.x), std::max(s.a.y, s.b.y));
    }
  }

  // Terrain primitives T_i = (c, r): one per square of the spacing at a jittered position (a Poisson-like
  // stratified draw in place of the paper's aperiodic tiling [LD05]); r = 1.5 spacing covers Ω.
  void add_terrain(const RiverGraph& domain, double width, double height) {
    const auto ridge_at = [&](int id) { return std::pair{ridges_[std::size_t(id)].a, ridges_[std::size_t(id)].b}; };
    const double spacing = params_.primitive_spacing_m;
    const int pc = int(std::ceil(width / spacing)), pr = int(std::ceil(height / spacing));
    for (int j = 0; j < pr; ++j)
      for (int i = 0; i < pc; ++i) {
        const Point2 c{(i + 0.5 + 0.5 * terrain::position_noise(params_.seed ^ 0x7E11ull, i, 2 * j)) * spacing,
                       (j + 0.5 + 0.5 * terrain::position_noise(params_.seed ^ 0x7E11ull, i, 2 * j + 1)) * spacing};
        if (!domain.inside(c)) continue;
        // c_z = d_a/(d_a+d_b) b_z + d_b/(d_a+d_b) a_z (§7.2): a on the rivers, b on the ridges.
        const Nearest a = nearest_anywhere(piece_bins_, c, width + height, [&](int id) { return piece_ends(id); });
        double az = 0, bz = 0, da = a.distance, db = std::numeric_limits<double>::infinity();
        if (a.index >= 0) az = pieces_[std::size_t(a.index)].za + a.t * (pieces_[std::size_t(a.index)].zb - pieces_[std::size_t(a.index)].za);
        if (!ridges_.empty()) {
          const Nearest b = nearest_anywhere(ridge_bins_, c, width + height, ridge_at);
          db = b.distance;
          const RidgeSegment& s = ridges_[std::size_t(b.index)];
          bz = s.za + b.t * (s.zb - s.za);
        }
        if (a.index < 0) continue;
        double z = az;
        if (std::isfinite(db) && da + db > 0) z = da / (da + db) * bz + db / (da + db) * az;
        primitives_.push_back({c, z, std::max(0.0, bz - az) * (std::isfinite(db) ? da / (da + db) : 0.0)});
      }
    for (std::size_t i = 0; i < primitives_.size(); ++i)
      primitive_bins_.insert(int(i), primitives_[i].c.x, primitives_[i].c.y, primitives_[i].c.x, primitives_[i].c.y);
  }

  const std::vector<RidgeSegment>& ridges_;
  const CoastParams& params_;
  const std::uint64_t noise_seed_ = params_.seed ^ 0xA0153ull;
  std::vector<Piece> pieces_;
  double max_radius_ = 0;
  SpatialBins piece_bins_, ridge_bins_;
  std::vector<Primitive> primitives_;
  const double radius_;
  SpatialBins primitive_bins_;
};

}  // namespace

CoastTerrain generate_coast_terrain(Raster<float>& grid, const std::vector<std::vector<Point2>>& coast, const CoastParams& params,
                                    Progress* progress) {
  if (!(params.sigma_m > params.edge_m / std::sqrt(2.0)))
    throw bad_input("--sigma: must exceed e/sqrt(2) = " + std::to_string(params.edge_m / std::sqrt(2.0)) + " m (Génévaux et al. §4.2.2)");
  const double cell = std::abs(grid.georef().transform[1]) * (grid.georef().crs.linear_unit_m > 0 ? grid.georef().crs.linear_unit_m : 1.0);
  const double width = grid.cols() * cell, height = grid.rows() * cell;
  CoastTerrain out;
  Rng draw(params.seed);

  // 1. Graph: mouths and grammar.
  auto t0 = Clock::now();
  if (progress) progress->begin("generate: river grammar");
  RiverGraph graph(width, height, coast, params);
  std::vector<Point2> directions;
  place_mouths(graph, coast, params, directions);
  if (graph.nodes().empty()) throw bad_input("coast: no river mouth fits on the coast (is the polygon inside the grid and larger than a few edges?)");
  out.mouths = graph.nodes().size();
  grow(graph, directions, params, draw, progress);
  if (progress) progress->end();
  std::vector<RiverNode> nodes = std::move(graph.nodes());
  strahler_orders(nodes);
  out.graph_s = seconds_since(t0);

  // 2. Analysis: Voronoi blocks on the grid (nearest node of each land cell), areas, discharge, types, ridges.
  t0 = Clock::now();
  const std::vector<std::uint8_t> land = land_cells(grid, coast, cell);
  out.land_km2 = drained_areas(nodes, grid, land, cell, width, height, params.edge_m);
  classify_nodes(nodes);
  refine_courses(nodes, params);
  out.ridges = graph_ridges(nodes, graph, params);
  out.analysis_s = seconds_since(t0);

  // 3. Terrain: A = C(B(T_i), U(R_i)) of §6, rasterised.
  t0 = Clock::now();
  if (progress) progress->begin("generate: terrain primitives");
  const CoastPrimitives terrain(nodes, out.ridges, graph, cell, width, height, params, out);
  for (int r = 0; r < grid.rows(); ++r) {
    for (int c = 0; c < grid.cols(); ++c)
      grid(c, r) = land[grid.index(c, r)] ? float(terrain.height_at({(c + 0.5) * cell, (r + 0.5) * cell})) : std::numeric_limits<float>::quiet_NaN();
    if (progress && r % 64 == 0 && !progress->update(double(r) / grid.rows())) throw Error(ErrorKind::cancelled, "generate: interrupted");
  }
  if (progress) progress->end();
  out.terrain_s = seconds_since(t0);
  out.nodes = std::move(nodes);
  return out;
}

GeneratedTerrain generate_coast(const GenerateRequest& request) {
  const double cell = request.cell_m;
  // Plan metres have the centre of cell (c,r) at ((c+0.5) cell, (r+0.5) cell); GridPoint at (c,r).
  const auto plan = [&](const GridPoint& g) { return Point2{(g[0] + 0.5) * cell, (g[1] + 0.5) * cell}; };
  const auto grid_point = [&](Point2 p) { return GridPoint{p.x / cell - 0.5, p.y / cell - 0.5}; };
  std::vector<std::vector<Point2>> coast;
  for (const auto& ring : request.polygons) {
    std::vector<Point2> r;
    for (const GridPoint& g : ring) r.push_back(plan(g));
    coast.push_back(std::move(r));
  }
  if (coast.empty()) coast = synthetic_coast(request.grid.cols() * cell, request.grid.rows() * cell, request.seed);
  CoastParams params = request.coast;
  params.seed = request.seed;
  GeneratedTerrain out;
  out.dem = request.grid;
  const CoastTerrain t = generate_coast_terrain(out.dem, coast, params, request.progress);

  // One reach per grammar edge, upstream to downstream; an edge flows into its parent's edge, or
  // out at a mouth. Width: the channel the primitives carve (Leopold & Maddock, see above).
  std::vector<int> reach_of(t.nodes.size(), -1);
  for (std::size_t i = 0; i < t.nodes.size(); ++i)
    if (t.nodes[i].parent >= 0) reach_of[i] = int(out.plan.rivers.size()), out.plan.rivers.emplace_back();
  for (std::size_t i = 0; i < t.nodes.size(); ++i) {
    const RiverNode& n = t.nodes[i];
    if (n.parent < 0) continue;
    RiverReach& reach = out.plan.rivers[std::size_t(reach_of[i])];
    for (Point2 p : n.course) reach.line.push_back(grid_point(p));
    reach.downstream = reach_of[std::size_t(n.parent)];
    reach.width_m = 2.5 * std::sqrt(std::max(n.discharge_m3s, 0.01));
  }
  assign_strahler(out.plan);
  for (const RidgeSegment& s : t.ridges) out.plan.ridges.push_back({{grid_point(s.a), grid_point(s.b)}, {float(s.za), float(s.zb)}});
  out.timings = {{"grammar graph", t.graph_s}, {"analysis", t.analysis_s}, {"terrain", t.terrain_s}};
  std::size_t streams = 0, low = 0;
  for (const RiverNode& n : t.nodes)
    if (n.parent >= 0) ++streams, low += n.priority <= 1 ? 1 : 0;
  out.figures = {{"mouths", double(t.mouths)},
                 {"land_km2", t.land_km2},
                 {"river_km_per_km2", t.land_km2 > 0 ? t.river_km / t.land_km2 : 0.0},
                 {"terrain_primitives", double(t.terrain_primitives)},
                 {"terrain_primitives_per_km2", t.land_km2 > 0 ? t.terrain_primitives / t.land_km2 : 0.0},
                 {"river_primitives", double(t.river_primitives)},
                 {"low_priority_stream_share", streams ? double(low) / streams : 0.0}};
  // River types of §5.2 (the skeleton layer carries widths, from the discharge; the types are counted here).
  for (const hydro::RiverType type : {hydro::RiverType::B, hydro::RiverType::E, hydro::RiverType::D, hydro::RiverType::delta}) {
    std::size_t count = 0;
    for (const RiverNode& n : t.nodes) count += n.parent >= 0 && n.type == type ? 1 : 0;
    out.figures.emplace_back(std::string("reaches_type_") + hydro::river_type_name(type), double(count));
  }
  double top_discharge = 0;
  for (const RiverNode& n : t.nodes) top_discharge = std::max(top_discharge, n.discharge_m3s);
  out.figures.emplace_back("largest_discharge_m3s", top_discharge);
  return out;
}

}  // namespace terrapolis::generate
