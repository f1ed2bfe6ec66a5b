// Clothoid smoothing of grid paths, deck profiles and road/bridge/tunnel sections.
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

/// Points of the unit clothoid of half-deflection phi at arc lengths i / n, i = 0..n: tangent angle
/// phi s^2, so curvature 2 phi s (linear); the Fresnel integrals by Simpson's rule, 8 intervals per
/// step (the integrands are smooth: the error is far below a millimetre per kilometre).
std::vector<PlanePoint> unit_spiral(double phi, int n) {
  constexpr int m = 8;
  std::vector<PlanePoint> out(std::size_t(n) + 1);
  const double h = 1.0 / (double(n) * m);
  double x = 0, y = 0;
  for (int i = 1; i <= n; ++i) {
    double sx = 0, sy = 0;
    for (int j = 0; j <= m; ++j) {
      const double t = (double(i - 1) * m + j) * h, w = (j == 0 || j == m) ? 1 : (j % 2 ? 4 : 2);
      sx += w * std::cos(phi * t * t);
      sy += w * std::sin(phi * t * t);
    }
    x += sx * h / 3;
    y += sy * h / 3;
    out[std::size_t(i)] = {x, y};
  }
  return out;
}

}  // namespace

ClothoidShape clothoid_shape(double turn_rad) {
  const double phi = 0.5 * turn_rad;
  const PlanePoint e = unit_spiral(phi, 32).back();
  ClothoidShape c;
  c.tangent_per_m = e.x + e.y * std::tan(phi);
  c.apex_per_m = std::hypot(c.tangent_per_m - e.x, e.y);
  return c;
}

std::vector<PlanePoint> clothoid_corner(PlanePoint a, PlanePoint v, PlanePoint b, double tangent_m, int samples) {
  const double la = std::hypot(v.x - a.x, v.y - a.y), lb = std::hypot(b.x - v.x, b.y - v.y);
  const PlanePoint da{(v.x - a.x) / la, (v.y - a.y) / la}, db{(b.x - v.x) / lb, (b.y - v.y) / lb};
  const double cross = da.x * db.y - da.y * db.x;
  const double turn = std::acos(std::clamp(da.x * db.x + da.y * db.y, -1.0, 1.0));
  const double sign = cross >= 0 ? 1.0 : -1.0;
  const ClothoidShape shape = clothoid_shape(turn);
  const double ls = tangent_m / shape.tangent_per_m;  // spiral length
  const PlanePoint t1{v.x - tangent_m * da.x, v.y - tangent_m * da.y}, t2{v.x + tangent_m * db.x, v.y + tangent_m * db.y};
  const PlanePoint na{-da.y, da.x}, nb{-db.y, db.x};
  std::vector<PlanePoint> out(std::size_t(2 * samples + 1));
  // First spiral from t1 along a-v bending towards b; the second is its mirror image, run back from t2.
  const std::vector<PlanePoint> spiral = unit_spiral(0.5 * turn, samples);
  for (int i = 0; i <= samples; ++i) {
    const PlanePoint& p = spiral[std::size_t(i)];
    const PlanePoint first{t1.x + ls * (p.x * da.x + sign * p.y * na.x), t1.y + ls * (p.x * da.y + sign * p.y * na.y)};
    const PlanePoint second{t2.x + ls * (-p.x * db.x + sign * p.y * nb.x), t2.y + ls * (-p.x * db.y + sign * p.y * nb.y)};
    if (i < samples) {
      out[std::size_t(i)] = first;
      out[std::size_t(2 * samples - i)] = second;
    } else {
      out[std::size_t(i)] = {0.5 * (first.x + second.x), 0.5 * (first.y + second.y)};  // the apex, met from both sides
    }
  }
  return out;
}

namespace {

/// Smooths one surface run (the ends fixed): clothoid pairs at the corners, with checked
/// deviation and grade (Peytavie §4.4.1), a G1 quadratic Bézier where no clothoid passes.
std::vector<GridPoint> smooth_run(const TerrainField& terrain, const CostModel& model, const std::vector<GridPoint>& run,
                                  double step, RoadGeometry& counts) {
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
    // The corner in a local metric plane centred on v.
    const double mx = terrain.metres_x(v.row), my = terrain.metres_y(v.row);
    auto plane = [&](GridPoint p) { return PlanePoint{(p.col - v.col) * mx, (p.row - v.row) * my}; };
    auto grid = [&](PlanePoint p) { return GridPoint{v.col + p.x / mx, v.row + p.y / my}; };
    double theta = 0;
    if (la > 0 && lb > 0) {
      const PlanePoint pa = plane(a), pb = plane(b);
      theta = std::acos(std::clamp((-pa.x * pb.x - pa.y * pb.y) / (la * lb), -1.0, 1.0));
    }
    if (theta < 1e-6 || theta > std::numbers::pi - 1e-6) {  // straight on, or a U-turn that no curve can round
      densify(out, terrain, cursor, v, step);
      cursor = v;
      continue;
    }
    // Clothoid pair: tangent length u, apex u * apex/tangent from the vertex, within the tolerance.
    std::vector<GridPoint> curve;
    const ClothoidShape shape = clothoid_shape(theta);
    // Radius at the apex of a clothoid pair: spiral length / turn; the class's smallest radius
    // needs a tangent of at least u_radius, and may push the curve past the corridor's tolerance.
    const double u_radius = model.min_curve_radius_m * theta * shape.tangent_per_m;
    double u = std::min(0.5 * la, 0.5 * lb);
    if (shape.apex_per_m > 1e-12) u = std::min(u, std::max(u_radius, tol_m * shape.tangent_per_m / shape.apex_per_m));
    // A curve must keep under the slope threshold and, since it cuts across the slope, must not be
    // more than 1 degree steeper than the corner of the grid path it replaces.
    auto grade_ok = [&](const std::vector<GridPoint>& c, double cut_m) {
      std::vector<GridPoint> corner{lerp(v, a, cut_m / la)};
      densify(corner, terrain, corner.front(), v, step);
      densify(corner, terrain, v, lerp(v, b, cut_m / lb), step);
      return steepest(terrain, c) <= std::min(max_slope, steepest(terrain, corner) + 1.0);
    };
    for (int attempt = 0; attempt < 6 && u > 0; ++attempt, u *= 0.5) {
      const double spiral = u / shape.tangent_per_m;
      const auto pts = clothoid_corner(plane(a), {0, 0}, plane(b), u, std::max(8, int(std::ceil(spiral / step))));
      curve.clear();
      for (const PlanePoint& p : pts) curve.push_back(grid(p));
      if (grade_ok(curve, u)) break;
      curve.clear();
    }
    if (!curve.empty()) ++counts.clothoid_corners;
    if (!curve.empty() && u < u_radius * (1 - 1e-9)) ++counts.tight_corners;
    if (curve.empty()) {
      // G1 fallback: a quadratic Bézier whose apex lies 0.5 u sin(theta/2) from the vertex.
      double uq = std::min({0.5 * la, 0.5 * lb, tol_m / (0.5 * std::sin(0.5 * theta))});
      for (int attempt = 0; attempt < 6 && uq > 0; ++attempt, uq *= 0.5) {
        curve = {lerp(v, a, uq / la)};
        quad(curve, curve.front(), v, lerp(v, b, uq / lb), std::max(4, int(std::ceil(2 * uq / step))));
        if (grade_ok(curve, uq)) break;
        curve.clear();
      }
      if (!curve.empty()) ++counts.g1_corners;
      if (!curve.empty() && u_radius > 0) ++counts.tight_corners;  // a quadratic's apex curvature is not checked
    }
    if (curve.empty()) {
      ++counts.sharp_corners;
      if (u_radius > 0) ++counts.tight_corners;
      densify(out, terrain, cursor, v, step);
      cursor = v;
      continue;
    }
    densify(out, terrain, cursor, curve.front(), step);
    out.insert(out.end(), curve.begin() + 1, curve.end());
    cursor = curve.back();
  }
  densify(out, terrain, cursor, run.back(), step);
  return out;
}

double step_of(const TerrainField& terrain, const CostModel& model) {
  return model.sample_step_m > 0 ? model.sample_step_m : 0.5 * terrain.min_cell_m();
}

/// Classifies each segment by the deck height against the surface (Peytavie §4.4.2). A disabled
/// structure is never built: its segments stay roads (the search already kept roads off deep water
/// and away from heights a structure would need; what is left is the smoothing's corridor).
void classify(const TerrainField& terrain, const CostModel& model, RoadGeometry& road) {
  road.segments.assign(road.points.size() > 0 ? road.points.size() - 1 : 0, Structure::road);
  for (std::size_t i = 0; i + 1 < road.points.size(); ++i) {
    const GridPoint m = lerp(road.points[i], road.points[i + 1], 0.5);
    const double dz = 0.5 * (road.z[i] + road.z[i + 1]) - terrain.surface_at(m.col, m.row);
    const bool over_water = terrain.depth_at(m.col, m.row) > model.road.water_depth_m.threshold;
    if (model.bridge.enabled && (dz > model.structure_min_m || over_water)) road.segments[i] = Structure::bridge;
    else if (model.tunnel.enabled && dz < -model.structure_min_m) road.segments[i] = Structure::tunnel;
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
      auto pts = smooth_run(terrain, model, run, step, road);
      // The search priced the grid path sampled exactly as `raw` is, so raw keeps under the slope
      // threshold; a smoothed run must too, whatever its curves and the short legs between them
      // sample (bilinear heights are steeper over short chords than over the search's steps).
      if (steepest(terrain, pts) > model.road.slope_deg.threshold) {
        std::vector<GridPoint> raw{run.front()};
        for (std::size_t p = 1; p < run.size(); ++p) densify(raw, terrain, run[p - 1], run[p], step);
        pts = std::move(raw);
        ++road.unsmoothed_runs;
      }
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

RoadStats road_stats(const TerrainField& terrain, const CostModel& model, const RoadGeometry& road) {
  RoadStats s;
  const double threshold = model.road.slope_deg.threshold;
  s.grade_limit_pct = threshold < 90 ? 100.0 * std::tan(threshold / kDeg) : kInfinity;
  double weighted = 0, run = 0;
  for (std::size_t i = 0; i + 1 < road.points.size(); ++i) {
    const double l = terrain.length_m(road.points[i], road.points[i + 1]);
    if (l <= 0) continue;
    const double grade = 100.0 * std::fabs(road.z[i + 1] - road.z[i]) / l;
    s.length_m += l;
    weighted += grade * l;
    s.max_grade_pct = std::max(s.max_grade_pct, grade);
    if (road.segments[i] == Structure::bridge) s.bridge_m += l;
    if (road.segments[i] == Structure::tunnel) s.tunnel_m += l;
    if (road.segments[i] != Structure::road) {
      run = 0;
      continue;
    }
    const GridPoint m = lerp(road.points[i], road.points[i + 1], 0.5);
    if (terrain.depth_at(m.col, m.row) > 0) s.water_m += l;
    // 1e-6: the grades the search and the smoothing checked, up to rounding.
    if (grade > s.grade_limit_pct * (1 + 1e-6)) {
      s.over_limit_m += l;
      run += l;
      s.longest_over_limit_m = std::max(s.longest_over_limit_m, run);
    } else {
      run = 0;
    }
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
