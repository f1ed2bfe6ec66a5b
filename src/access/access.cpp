// SPDX-License-Identifier: MIT
#include "access/access.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/catchment.hpp"
#include "io/crs.hpp"
#include "roads/radix_heap.hpp"
#include "roads/road_class.hpp"

namespace terrapolis::access {
namespace {

/// Moves as (dcol, drow): the 8 neighbours, then the 8 knight's moves.
constexpr std::array<std::array<int, 2>, 16> kMoves = {{{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1},
                                                         {2, 1}, {1, 2}, {-1, 2}, {-2, 1}, {-2, -1}, {-1, -2}, {1, -2}, {2, -1}}};

/// Geodesic length of each move from each row, metres (row-major, 16 per row): east-west at the
/// mean width of the rows it spans, north-south by the meridian arcs between them (CellMetrics),
/// combined by Pythagoras (the exact diagonal for one-cell moves). Moves off the grid get 0.
std::vector<double> move_lengths(const Georef& georef, int cols, int rows) {
  const CellMetrics m = cell_metrics(georef, cols, rows);
  auto width = [&](int r) { return m.width_m[std::size_t(std::clamp(r, 0, rows - 1))]; };
  std::vector<double> out(std::size_t(rows) * kMoves.size(), 0.0);
  for (int row = 0; row < rows; ++row)
    for (std::size_t k = 0; k < kMoves.size(); ++k) {
      const int dcol = kMoves[k][0], drow = kMoves[k][1], r2 = row + drow;
      if (r2 < 0 || r2 >= rows) continue;
      double length;
      if (std::abs(drow) == 1 && std::abs(dcol) == 1) {
        length = m.diagonal_m[std::size_t(drow > 0 ? row + 1 : row)];
      } else {
        double north_south = 0;
        for (int r = std::min(row, r2) + 1; r <= std::max(row, r2); ++r) north_south += m.height_m[std::size_t(r)];
        length = std::hypot(std::abs(dcol) * 0.5 * (width(row) + width(r2)), north_south);
      }
      out[std::size_t(row) * kMoves.size() + k] = length;
    }
  return out;
}

}  // namespace

double tobler_kmh(double dz_dx) { return 6.0 * std::exp(-3.5 * std::fabs(dz_dx + 0.05)); }

RoadCells road_cells(const VectorLayer& roads, const Raster<float>& like, const AccessOptions& options) {
  RoadCells out{like.like<float>(0.0f), like.like<std::uint8_t>(0)};
  Raster<std::uint8_t> surface = like.like<std::uint8_t>(0);  // a road at the surface passes there
  const int class_field = roads.field_index("class"), structure_field = roads.field_index("structure");
  const GridLocator locator(like.georef());
  bool underground = false;
  auto mark = [&](double col, double row, float kmh) {
    const int c = int(std::floor(col)), r = int(std::floor(row));
    if (!out.kmh.inside(c, r)) return;
    out.kmh(c, r) = std::max(out.kmh(c, r), kmh);
    (underground ? out.tunnel : surface)(c, r) = 1;
  };
  auto text = [](const Feature& f, int field) -> std::string {
    if (field < 0) return {};
    const auto* v = std::get_if<std::string>(&f.values[std::size_t(field)]);
    return v ? *v : std::string();
  };
  for (const auto& f : roads.features) {
    double kmh = options.road_kmh[std::size_t(roads::RoadClass::local)];
    if (const auto c = roads::road_class_named(text(f, class_field))) kmh = options.road_kmh[std::size_t(*c)];
    underground = text(f, structure_field) == "tunnel";
    for (const auto& part : f.parts)
      for (std::size_t k = 0; k < part.size(); ++k) {
        const auto b = locator.crs_to_pixel(part[k][0], part[k][1]);
        if (k == 0) {
          mark(b[0], b[1], float(kmh));
          continue;
        }
        // Samples a quarter of a cell apart: consecutive cells touch by a side or a corner.
        const auto a = locator.crs_to_pixel(part[k - 1][0], part[k - 1][1]);
        const int steps = std::max(1, int(std::ceil(4 * std::max(std::fabs(b[0] - a[0]), std::fabs(b[1] - a[1])))));
        for (int s = 1; s <= steps; ++s) {
          const double t = double(s) / steps;
          mark(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), float(kmh));
        }
      }
  }
  for (std::size_t i = 0; i < surface.size(); ++i)
    if (surface[i]) out.tunnel[i] = 0;  // a portal, or a surface road crossing over the tunnel
  return out;
}

AccessResult travel_time(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const RoadCells& roads,
                         const std::vector<Destination>& destinations, const AccessOptions& options, Progress& progress) {
  const Raster<float>& road_kmh = roads.kmh;
  const int cols = dem.cols(), rows = dem.rows();
  if (passable.cols() != cols || passable.rows() != rows || road_kmh.cols() != cols || road_kmh.rows() != rows ||
      roads.tunnel.cols() != cols || roads.tunnel.rows() != rows)
    throw bad_input("access: the water mask or the roads are not on the DEM's grid");
  if (!(options.walk_factor > 0) || !std::isfinite(options.walk_factor)) throw bad_input("/access/walk_factor: must be a positive number");
  for (double v : options.road_kmh)
    if (!(v > 0) || !std::isfinite(v)) throw bad_input("/access/road_kmh: every speed must be a positive number of km/h");
  const std::vector<double> length = move_lengths(dem.georef(), cols, rows);
  const std::size_t moves = options.knight_moves ? 16 : 8;
  auto open = [&](int c, int r) {
    const std::size_t i = dem.index(c, r);
    return road_kmh[i] > 0 || (passable[i] == 1 && !std::isnan(dem[i]));
  };

  AccessResult out{dem.like<float>(NAN), dem.like<std::int32_t>(-1), 0};
  out.nearest.nodata = -1;
  std::vector<std::uint8_t> done(dem.size(), 0);
  struct Entry {
    double f;  ///< minutes
    std::size_t cell;
  };
  roads::RadixHeap<Entry> queue;  // Dijkstra's keys only grow; equal keys pop in a fixed order
  std::vector<double> best(dem.size(), INFINITY);
  for (const auto& d : destinations) {
    if (!dem.inside(d.col, d.row) || !open(d.col, d.row)) continue;
    const std::size_t i = dem.index(d.col, d.row);
    if (best[i] == 0) continue;  // two destinations on one cell: the first keeps it
    best[i] = 0;
    out.nearest[i] = d.id;
    queue.push({0.0, i});
  }
  ProgressStep step(progress, "access");
  std::size_t settled = 0;
  while (!queue.empty()) {
    const auto [t, v] = queue.pop();
    if (done[v] || t > best[v]) continue;
    done[v] = 1;
    out.minutes[v] = float(t);
    if ((++settled & 0x3ffff) == 0) step.update(std::min(0.99, double(settled) / double(dem.size())));
    const int vc = int(v % std::size_t(cols)), vr = int(v / std::size_t(cols));
    const double zv = dem[v];
    for (std::size_t k = 0; k < moves; ++k) {
      // The move u -> v (towards the destination), from u = v - move.
      const int uc = vc - kMoves[k][0], ur = vr - kMoves[k][1];
      if (!dem.inside(uc, ur) || !open(uc, ur)) continue;
      const std::size_t u = dem.index(uc, ur);
      if (done[u]) continue;
      // A knight's move crosses the two cells beside its line: both must be open (no corner cut across water).
      if (k >= 8) {
        const int dc = kMoves[k][0], dr = kMoves[k][1];
        const bool wide = std::abs(dc) == 2;
        const int c1 = wide ? uc + dc / 2 : uc, r1 = wide ? ur : ur + dr / 2;
        const int c2 = wide ? uc + dc / 2 : uc + dc, r2 = wide ? ur + dr : ur + dr / 2;
        if (!open(c1, r1) || !open(c2, r2)) continue;
      }
      const double metres = length[std::size_t(ur) * kMoves.size() + k];
      double kmh;
      if (road_kmh[u] > 0 && road_kmh[v] > 0) {
        kmh = std::min(road_kmh[u], road_kmh[v]);
      } else {
        if (roads.tunnel[u] || roads.tunnel[v]) continue;  // no way into a tunnel but by its road
        const double zu = dem[u];
        if (std::isnan(zu) || std::isnan(zv)) continue;  // a road cell on nodata: reached only by road
        kmh = options.walk_factor * tobler_kmh((zv - zu) / metres);
      }
      const double arrive = t + metres / (kmh / 0.06);  // km/h -> metres per minute: x 1000 / 60
      if (arrive < best[u]) {
        best[u] = arrive;
        out.nearest[u] = out.nearest[v];
        queue.push({arrive, u});
      }
    }
  }
  for (std::size_t i = 0; i < dem.size(); ++i) {
    if (!done[i]) out.nearest[i] = -1;
    if (!done[i] && passable[i] == 1 && !std::isnan(dem[i])) ++out.unreachable_land;
  }
  return out;
}

Coverage coverage(const Raster<float>& minutes, const Raster<float>& people, const std::vector<double>& thresholds_minutes) {
  if (minutes.cols() != people.cols() || minutes.rows() != people.rows())
    throw bad_input("access: the population raster is not on the DEM's grid");
  Coverage c;
  c.within_people.assign(thresholds_minutes.size(), 0.0);
  std::vector<std::pair<float, double>> reached;  // (minutes, people)
  for (std::size_t i = 0; i < minutes.size(); ++i) {
    const double p = people[i];
    if (!(p > 0)) continue;
    c.total_people += p;
    if (std::isnan(minutes[i])) {
      c.unreachable_people += p;
      continue;
    }
    reached.push_back({minutes[i], p});
    for (std::size_t k = 0; k < thresholds_minutes.size(); ++k)
      if (minutes[i] <= thresholds_minutes[k]) c.within_people[k] += p;
  }
  std::sort(reached.begin(), reached.end());
  double sum = 0, weight = 0;
  for (const auto& [m, p] : reached) sum += double(m) * p, weight += p;
  if (weight > 0) {
    c.mean_minutes = sum / weight;
    double seen = 0;
    for (const auto& [m, p] : reached)
      if ((seen += p) >= 0.9 * weight) {
        c.p90_minutes = m;
        break;
      }
  }
  return c;
}

VectorLayer catchments_layer(const AccessResult& times, const Raster<float>& weight, const std::string& counted,
                             const std::vector<Settlement>& settlements) {
  struct Figures {
    double people = 0, area_m2 = 0, minutes_people = 0;
  };
  std::map<std::int32_t, Figures> by_id;
  const Raster<std::int32_t>& nearest = times.nearest;
  const CellMetrics metrics = cell_metrics(nearest.georef(), nearest.cols(), nearest.rows());
  for (int r = 0; r < nearest.rows(); ++r)
    for (int c = 0; c < nearest.cols(); ++c) {
      const std::int32_t id = nearest(c, r);
      if (id < 0) continue;
      Figures& f = by_id[id];
      f.area_m2 += metrics.area_m2[std::size_t(r)];
      const double p = weight(c, r);
      if (p > 0) f.people += p, f.minutes_people += p * double(times.minutes(c, r));
    }
  std::map<std::int32_t, double> population;
  for (const Settlement& s : settlements) population[s.at.id] = s.population;
  VectorLayer layer;
  layer.name = "access_catchments";
  layer.geometry = GeometryType::polygon;
  layer.crs = nearest.georef().crs;
  layer.fields = {{"id", FieldType::integer}, {"population", FieldType::integer}, {counted, FieldType::real},
                  {"area_km2", FieldType::real}, {"mean_minutes", FieldType::real}};
  for (auto& [id, feature] : hydro::polygonize_labels(nearest)) {
    const Figures& f = by_id[id];
    feature.values = {std::int64_t(id), std::int64_t(std::llround(population[id])), std::round(f.people * 100) / 100,
                      std::round(f.area_m2 / 1e4) / 100,
                      f.people > 0 ? FieldValue(std::round(f.minutes_people / f.people * 10) / 10) : FieldValue(std::monostate{})};
    layer.features.push_back(std::move(feature));
  }
  return layer;
}

void for_each_level(const Raster<float>& dem, const Raster<std::uint8_t>& passable, const RoadCells& roads,
                    const std::vector<Settlement>& settlements, const std::vector<double>& levels,
                    const std::vector<double>& thresholds_minutes, const Raster<float>& people, const AccessOptions& options,
                    Progress& progress, const std::function<void(const LevelFigures&)>& use) {
  for (const double level : levels) {
    std::vector<Destination> to;
    for (const Settlement& s : settlements)
      if (s.population >= level) to.push_back(s.at);
    if (to.empty()) continue;
    LevelFigures f;
    f.level = level;
    f.key = level > 0 ? std::to_string(std::llround(level)) : "all";
    f.destinations = to.size();
    f.times = travel_time(dem, passable, roads, to, options, progress);
    f.coverage = coverage(f.times.minutes, people, thresholds_minutes);
    use(f);
  }
}

}  // namespace terrapolis::access
