// G1 smoothing of grid paths, deck profiles and road/bridge/tunnel sections.
// SPDX-License-Identifier: MIT
#include "roads/road_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace terrapolis::roads {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

GridPoint lerp(GridPoint a, GridPoint b, double t) { return {a.col + t * (b.col - a.col), a.row + t * (b.row - a.row)}; }

/// Points of a quadratic Bézier a-v-b at t in (0,1], `n` samples.
void quad(std::vector<GridPoint>& out, GridPoint a, GridPoint v, GridPoint b, int n) {
  for (int i = 1; i <= n; ++i) {
    const double t = double(i) / n;
    out.push_back(lerp(lerp(a, v, t), lerp(v, b, t), t));
  }
}

/// Steepest grade (deg) along a polyline on the surface.
double steepest(const TerrainField& terrain, const std::vector<GridPoint>& pts) {
  double worst = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double l = terrain.length_m(pts[i - 1], pts[i]);
    if (l < 1e-6) continue;
    const double dz = terrain.surface_at(pts[i].col, pts[i].row) - terrain.surface_at(pts[i - 1].col, pts[i - 1].row);
    worst = std::max(worst, std::atan(std::fabs(dz) / l) * kDeg);
  }
  return worst;
}

/// Densifies a segment at the integration step (at least its two ends).
void densify(std::vector<GridPoint>& out, const TerrainField& terrain, GridPoint a, GridPoint b, double step) {
  const int n = std::max(1, int(std::ceil(terrain.length_m(a, b) / step)));
  for (int i = 1; i <= n; ++i) out.push_back(lerp(a, b, double(i) / n));
}

/// Smooths one surface run (the ends fixed) into a G1 spline with checked deviation and grade.
std::vector<GridPoint> smooth_run(const TerrainField& terrain, const CostModel& model, const std::vector<GridPoint>& run,
                                  double step) {
  std::vector<GridPoint> out{run.front()};
  if (run.size() < 3) {
    for (std::size_t i = 1; i < run.size(); ++i) densify(out, terrain, out.back(), run[i], step);
    return out;
  }
  const double tol_m = model.smoothing_tolerance_cells * terrain.typical_cell_m();
  const double max_slope = model.road.slope_deg.threshold;
  GridPoint cursor = run.front();  // where the previous corner's curve ended
  for (std::size_t i = 1; i + 1 < run.size(); ++i) {
    const GridPoint a = run[i - 1], v = run[i], b = run[i + 1];
    const double la = terrain.length_m(a, v), lb = terrain.length_m(v, b);
    double u = 0;
    if (la > 0 && lb > 0) {
      // Turn angle theta; a cut of u metres on both legs puts the curve's apex 0.5 u sin(theta/2)
      // from the vertex, the farthest it gets from the grid path.
      const double ax = (v.col - a.col) * terrain.metres_x(v.row) / la, ay = (v.row - a.row) * terrain.metres_y(v.row) / la;
      const double bx = (b.col - v.col) * terrain.metres_x(v.row) / lb, by = (b.row - v.row) * terrain.metres_y(v.row) / lb;
      const double theta = std::acos(std::clamp(ax * bx + ay * by, -1.0, 1.0));
      const double s = 0.5 * std::sin(0.5 * theta);
      u = std::min(0.5 * la, 0.5 * lb);
      if (s > 1e-9) u = std::min(u, tol_m / s);
    }
    for (int attempt = 0; attempt < 6 && u > 0; ++attempt) {
      std::vector<GridPoint> curve{lerp(v, a, u / la)};
      quad(curve, curve.front(), v, lerp(v, b, u / lb), 8);
      if (steepest(terrain, curve) <= max_slope) break;
      u = attempt == 5 ? 0 : 0.5 * u;
    }
    if (u <= 0) {
      densify(out, terrain, cursor, v, step);
      cursor = v;
      continue;
    }
    const GridPoint in = lerp(v, a, u / la), outp = lerp(v, b, u / lb);
    densify(out, terrain, cursor, in, step);
    quad(out, in, v, outp, std::max(4, int(std::ceil(2 * u / step))));
    cursor = outp;
  }
  densify(out, terrain, cursor, run.back(), step);
  return out;
}

double step_of(const TerrainField& terrain, const CostModel& model) {
  return model.sample_step_m > 0 ? model.sample_step_m : 0.5 * terrain.min_cell_m();
}

/// Classifies each segment by the deck height against the surface (Peytavie §4.4.2).
void classify(const TerrainField& terrain, const CostModel& model, RoadGeometry& road) {
  road.segments.assign(road.points.size() > 0 ? road.points.size() - 1 : 0, Structure::road);
  for (std::size_t i = 0; i + 1 < road.points.size(); ++i) {
    const GridPoint m = lerp(road.points[i], road.points[i + 1], 0.5);
    const double dz = 0.5 * (road.z[i] + road.z[i + 1]) - terrain.surface_at(m.col, m.row);
    const bool over_water = terrain.depth_at(m.col, m.row) > model.road.water_depth_m.threshold;
    if (dz > model.structure_min_m || over_water) road.segments[i] = Structure::bridge;
    else if (dz < -model.structure_min_m) road.segments[i] = Structure::tunnel;
  }
}

}  // namespace

RoadGeometry build_road_geometry(const TerrainField& terrain, const CostModel& model, const SearchResult& path) {
  RoadGeometry road;
  if (path.cells.empty()) return road;
  const double step = step_of(terrain, model);
  auto gp = [](Cell c) { return GridPoint{double(c.col), double(c.row)}; };
  road.points.push_back(gp(path.cells.front()));
  road.z.push_back(terrain.surface(path.cells.front().col, path.cells.front().row));
  std::size_t i = 0;
  while (i + 1 < path.cells.size()) {
    if (path.structures[i] == Structure::road) {
      std::vector<GridPoint> run{gp(path.cells[i])};
      std::size_t j = i;
      while (j + 1 < path.cells.size() && path.structures[j] == Structure::road) run.push_back(gp(path.cells[++j]));
      const auto pts = smooth_run(terrain, model, run, step);
      for (std::size_t p = 1; p < pts.size(); ++p) {
        road.points.push_back(pts[p]);
        road.z.push_back(terrain.surface_at(pts[p].col, pts[p].row));
      }
      i = j;
    } else {
      const Cell a = path.cells[i], b = path.cells[i + 1];
      const double za = terrain.surface(a.col, a.row), zb = terrain.surface(b.col, b.row);
      std::vector<GridPoint> pts;
      densify(pts, terrain, gp(a), gp(b), step);
      for (std::size_t p = 0; p < pts.size(); ++p) {
        road.points.push_back(pts[p]);
        road.z.push_back(za + (zb - za) * double(p + 1) / double(pts.size()));
      }
      ++i;
    }
  }
  classify(terrain, model, road);
  return road;
}

RoadGeometry surface_geometry(const TerrainField& terrain, const CostModel& model, const std::vector<GridPoint>& polyline) {
  RoadGeometry road;
  if (polyline.empty()) return road;
  const double step = step_of(terrain, model);
  road.points.push_back(polyline.front());
  for (std::size_t i = 1; i < polyline.size(); ++i) densify(road.points, terrain, road.points.back(), polyline[i], step);
  for (const GridPoint& p : road.points) road.z.push_back(terrain.surface_at(p.col, p.row));
  classify(terrain, model, road);
  return road;
}

RoadStats road_stats(const TerrainField& terrain, const RoadGeometry& road) {
  RoadStats s;
  double weighted = 0;
  for (std::size_t i = 0; i + 1 < road.points.size(); ++i) {
    const double l = terrain.length_m(road.points[i], road.points[i + 1]);
    if (l <= 0) continue;
    const double grade = 100.0 * std::fabs(road.z[i + 1] - road.z[i]) / l;
    s.length_m += l;
    weighted += grade * l;
    s.max_grade_pct = std::max(s.max_grade_pct, grade);
    if (road.segments[i] == Structure::bridge) s.bridge_m += l;
    if (road.segments[i] == Structure::tunnel) s.tunnel_m += l;
  }
  s.mean_grade_pct = s.length_m > 0 ? weighted / s.length_m : 0;
  return s;
}

std::vector<RoadSection> road_sections(const TerrainField& terrain, const RoadGeometry& road) {
  std::vector<RoadSection> out;
  for (std::size_t i = 0; i + 1 < road.points.size(); ++i) {
    const std::string kind = structure_name(road.segments[i]);
    if (out.empty() || out.back().structure != kind) out.push_back({kind, {road.points[i]}, 0});
    out.back().points.push_back(road.points[i + 1]);
    out.back().length_m += terrain.length_m(road.points[i], road.points[i + 1]);
  }
  return out;
}

}  // namespace terrapolis::roads
