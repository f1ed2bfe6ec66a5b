// Road corridors: carriageway and earthworks polygons, cut and fill, clearing and land take.
// SPDX-License-Identifier: MIT
#include "roads/corridor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/error.hpp"
#include "io/polygon_union.hpp"
#include "roads/road_network.hpp"

namespace terrapolis::roads {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

using Point2 = std::array<double, 2>;

double side_slope_of(double angle_deg) { return 1.0 / std::tan(angle_deg * kRad); }

/// A unit direction in the local metric plane at a station (x east, y south, metres).
struct Direction {
  double x = 1, y = 0;
};

/// Tangent at point j of `pts` from its neighbours (one-sided at the ends, so section ends are square).
Direction tangent(const TerrainField& t, const std::vector<GridPoint>& pts, std::size_t j) {
  const GridPoint a = pts[j > 0 ? j - 1 : j], b = pts[j + 1 < pts.size() ? j + 1 : j];
  const double mx = t.metres_x(pts[j].row), my = t.metres_y(pts[j].row);
  const double x = (b.col - a.col) * mx, y = (b.row - a.row) * my, l = std::hypot(x, y);
  return l > 0 ? Direction{x / l, y / l} : Direction{};
}

/// One side of a station's cross-section.
struct Side {
  double half_width_m = 0;  ///< R
  double cut_m2 = 0, fill_m2 = 0;  ///< areas between the ground and the works, per metre of road
  double cover_m = 0;       ///< vegetation cover integrated over [0, R]
  bool walled = false;
};

/// The cross-section on one side of a station, from the centreline outwards along the normal n
/// (Peytavie §4.4.3: within r the ground takes the deck's height; between r and R the works blend
/// into the ground, here by the side slope of earthworks(): |z' - deck| <= (d - r) / side_slope).
/// R is the first distance where that side slope meets the ground (linear interpolation between
/// steps of at most r / 8 and a quarter of the smallest cell); the areas by the midpoint rule on
/// the same steps. Stops at the grid's edge and the shore, and where the side would pass
/// max_height_m (walled).
Side cross_section(const TerrainField& t, const EarthworkOptions& o, GridPoint p, Direction n, double deck) {
  const double r = o.half_width_m;
  const double step = r / std::ceil(r / std::min(0.25 * t.min_cell_m(), r / 8));
  const double mx = t.metres_x(p.row), my = t.metres_y(p.row);
  auto at = [&](double d) { return GridPoint{p.col + n.x * d / mx, p.row + n.y * d / my}; };
  auto slope = [&](GridPoint q) {
    const int c = t.clamp_col(int(std::lround(q.col))), rr = t.clamp_row(int(std::lround(q.row)));
    return o.slope_at(t.index(c, rr));
  };
  // On the grid and on land (earthworks() leaves water and nodata alone: the works end at the shore).
  auto on_land = [&](GridPoint q) {
    if (!(q.col >= t.col0() - 0.5 && q.row >= t.row0() - 0.5 && q.col <= t.col0() + t.cols() - 0.5 && q.row <= t.row0() + t.rows() - 0.5))
      return false;
    return !t.water(t.clamp_col(int(std::lround(q.col))), t.clamp_row(int(std::lround(q.row))));
  };
  // How far the ground is beyond the side's reach at d (<= 0: the side has met it).
  auto excess = [&](double d) {
    const GridPoint q = at(d);
    return std::fabs(t.surface_at(q.col, q.row) - deck) - std::max(0.0, d - r) / slope(q);
  };
  Side side;
  auto integrate = [&](double d0, double d1) {  // the works over [d0, d1], midpoint rule
    const GridPoint q = at(0.5 * (d0 + d1));
    const double g = t.surface_at(q.col, q.row), allowed = std::max(0.0, 0.5 * (d0 + d1) - r) / slope(q);
    const double z = std::clamp(g, deck - allowed, deck + allowed);
    (z > g ? side.fill_m2 : side.cut_m2) += std::fabs(z - g) * (d1 - d0);
    side.cover_m += std::clamp(double(t.vegetation_at(q.col, q.row)), 0.0, 1.0) * (d1 - d0);
  };
  double d = 0;
  for (; d + 0.5 * step < r; d += step) integrate(d, d + step);  // the carriageway
  d = r;
  double e0 = excess(r);
  while (e0 > 0) {
    const double d1 = d + step;
    if (!on_land(at(d1))) break;
    const double e1 = excess(d1);
    if (e1 <= 0) {
      const double met = d + step * e0 / (e0 - e1);
      integrate(d, met);
      d = met;
      break;
    }
    integrate(d, d1);
    d = d1;
    e0 = e1;
    if ((d - r) / slope(at(d)) > o.max_height_m) {
      side.walled = true;
      break;
    }
  }
  side.half_width_m = d;
  return side;
}

/// The pieces a cross-section's half sweeps between two stations: the quadrilateral
/// a (centre), b (next centre), c (next offset), d (offset), or, where it folds (the inner side of
/// a bend tighter than the offset: the offsets cross), its two triangles about the crossing.
/// Degenerate pieces (no area) are left out: the union needs valid polygons.
void add_swept(std::vector<Polygon>& out, const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  auto cross = [](const Point2& o, const Point2& p, const Point2& q) {
    return (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0]);
  };
  // Where segments pq and uv cross properly, their crossing point.
  auto crossing = [&](const Point2& p, const Point2& q, const Point2& u, const Point2& v) -> std::optional<Point2> {
    const double d1 = cross(p, q, u), d2 = cross(p, q, v), d3 = cross(u, v, p), d4 = cross(u, v, q);
    if (!((d1 > 0) != (d2 > 0) && d1 != 0 && d2 != 0 && (d3 > 0) != (d4 > 0) && d3 != 0 && d4 != 0)) return std::nullopt;
    const double t = d3 / (d3 - d4);
    return Point2{p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
  };
  auto piece = [&](Ring ring) {
    double twice = 0;
    for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) twice += cross({0, 0}, ring[j], ring[i]);
    const double scale = std::max(std::fabs(a[0] - d[0]) + std::fabs(a[1] - d[1]), std::fabs(b[0] - c[0]) + std::fabs(b[1] - c[1]));
    if (std::fabs(twice) > 1e-9 * scale * scale) out.push_back(Polygon{{std::move(ring)}});
  };
  if (const auto x = crossing(b, c, d, a)) {
    piece({a, b, *x});
    piece({*x, c, d});
  } else if (const auto y = crossing(a, b, c, d)) {
    piece({a, *y, d});
    piece({*y, b, c});
  } else {
    piece({a, b, c, d});
  }
}

/// The area a cross-section sweeps along the stations: centres[j] to left[j] and right[j], united.
std::vector<Polygon> swept_area(const Ring& centres, const Ring& left, const Ring& right) {
  std::vector<Polygon> pieces;
  for (std::size_t j = 0; j + 1 < centres.size(); ++j) {
    add_swept(pieces, centres[j], centres[j + 1], left[j + 1], left[j]);
    add_swept(pieces, centres[j], centres[j + 1], right[j + 1], right[j]);
  }
  return polygon_union(pieces);
}

/// The carriageway and earthworks zone of one section (points pts, decks from road point
/// `first`), and its cross-sections' volumes and clearing.
void section_corridor(const TerrainField& t, const EarthworkOptions& o, const RoadGeometry& road, std::size_t first,
                      const std::vector<GridPoint>& pts, SectionCorridor& s) {
  if (s.structure == "ferry") return;
  Ring centres, lane_left, lane_right, zone_left, zone_right;
  const bool surface = s.structure == "road";
  double sum_r = 0, cover_m2 = 0, zone_m2 = 0;  // the cross-sections' cover and widths, integrated along the road
  auto crs = [&](GridPoint p) { return t.georef().cell_centre(p.col, p.row); };
  for (std::size_t j = 0; j < pts.size(); ++j) {
    const Direction along = tangent(t, pts, j), left{along.y, -along.x}, right{-along.y, along.x};
    const double mx = t.metres_x(pts[j].row), my = t.metres_y(pts[j].row);
    auto offset = [&](Direction n, double d) { return crs({pts[j].col + n.x * d / mx, pts[j].row + n.y * d / my}); };
    centres.push_back(crs(pts[j]));
    lane_left.push_back(offset(left, s.carriageway_half_width_m));
    lane_right.push_back(offset(right, s.carriageway_half_width_m));
    if (!surface) continue;
    // The station's share of the section's length.
    const double share = 0.5 * ((j > 0 ? t.length_m(pts[j - 1], pts[j]) : 0) + (j + 1 < pts.size() ? t.length_m(pts[j], pts[j + 1]) : 0));
    for (const auto& [n, ring] : {std::pair{left, &zone_left}, std::pair{right, &zone_right}}) {
      const Side side = cross_section(t, o, pts[j], n, road.z[first + j]);
      ring->push_back(offset(n, side.half_width_m));
      sum_r += side.half_width_m;
      s.max_half_width_m = std::max(s.max_half_width_m, side.half_width_m);
      s.totals.cut_m3 += share * side.cut_m2;
      s.totals.fill_m3 += share * side.fill_m2;
      cover_m2 += share * side.cover_m;
      zone_m2 += share * side.half_width_m;
      if (side.walled) s.walled_m += share;
    }
  }
  s.carriageway = swept_area(centres, lane_left, lane_right);
  if (!surface) return;
  s.zone = swept_area(centres, zone_left, zone_right);
  s.mean_half_width_m = sum_r / double(2 * pts.size());
  s.totals.land_take_ha = polygons_area_m2(t.georef().crs, s.zone) / 1e4;
  // The zone's mean cover over its polygon's area (so a fully covered zone is cleared entirely).
  s.totals.cleared_ha = zone_m2 > 0 ? s.totals.land_take_ha * cover_m2 / zone_m2 : 0;
}

/// Sets `totals`' land take to the area of `zones` united (returned), scaling the clearing with it.
std::vector<Polygon> unite(const Crs& crs, const std::vector<Polygon>& zones, CorridorTotals& totals) {
  std::vector<Polygon> united = polygon_union(zones);
  const double ha = polygons_area_m2(crs, united) / 1e4;
  totals.cleared_ha = totals.land_take_ha > 0 ? totals.cleared_ha * ha / totals.land_take_ha : 0;
  totals.land_take_ha = ha;
  return united;
}

void add(CorridorTotals& to, const CorridorTotals& from) {
  to.land_take_ha += from.land_take_ha;
  to.cut_m3 += from.cut_m3;
  to.fill_m3 += from.fill_m3;
  to.cleared_ha += from.cleared_ha;
}

double round_to(double v, double unit) { return std::round(v / unit) * unit; }

}  // namespace

double repose_angle_deg(const std::string& material) {
  if (material == "sand") return 30;
  if (material == "earth") return 25;
  if (material == "stones") return 40;
  if (material == "rock") return std::atan(2.0) / kRad;
  throw bad_input("material: '" + material + "' is none of sand, earth, stones, rock");
}

double corridor_reach_m(const CorridorOptions& options) {
  double half = options.half_width_m;
  for (const ClassWidths& w : options.widths) half = std::max(half, 0.5 * w.platform_m);
  // The side slope earthwork_options uses, unclamped (an angle out of (0, 90) is refused there).
  const double least = options.least_side_angle_deg;
  const double angle = least > 0 && least < options.side_angle_deg ? least : options.side_angle_deg;
  return half + (angle > 0 && angle < 90 ? options.max_height_m / std::tan(angle * kRad) : 0.0);
}

EarthworkOptions earthwork_options(const CorridorOptions& c, Raster<float>& slopes, RoadClass road_class) {
  const ClassWidths& w = c.widths[std::min(std::size_t(road_class), c.widths.size() - 1)];
  if (!(c.half_width_m >= 0) || !(w.carriageway_m > 0) || !(w.platform_m >= w.carriageway_m) || !(c.side_angle_deg > 0 && c.side_angle_deg < 90) ||
      !(c.max_height_m >= 0))
    throw bad_input("corridor: the widths must be > 0 (a platform no narrower than its carriageway) and the side angle within 0-90 degrees");
  EarthworkOptions o;
  o.half_width_m = c.half_width_m > 0 ? c.half_width_m : 0.5 * w.platform_m;
  o.side_slope = side_slope_of(c.side_angle_deg);
  o.max_height_m = c.max_height_m;
  if (c.side_angles_deg.size() > 0) {
    slopes = c.side_angles_deg;
    for (std::size_t k = 0; k < slopes.size(); ++k) {
      const double a = slopes[k];
      slopes[k] = a > 0 && a < 90 ? float(side_slope_of(a)) : 0.f;  // NaN and out of range: the default angle
    }
    o.side_slopes = &slopes;
  }
  return o;
}

namespace {

/// The window of the grid (`frame`'s) holding a road's points and `w.margin_cells` around them:
/// its first cell and size.
std::array<int, 4> window_around(const CorridorWindows& w, const TerrainField& frame, const RoadGeometry& road) {
  double c0 = kInfinity, r0 = kInfinity, c1 = -kInfinity, r1 = -kInfinity;
  for (const GridPoint& p : road.points) c0 = std::min(c0, p.col), r0 = std::min(r0, p.row), c1 = std::max(c1, p.col), r1 = std::max(r1, p.row);
  const int a = std::max(0, int(std::floor(c0)) - w.margin_cells), b = std::max(0, int(std::floor(r0)) - w.margin_cells);
  const int c = std::min(frame.grid_cols() - 1, int(std::ceil(c1)) + w.margin_cells);
  const int d = std::min(frame.grid_rows() - 1, int(std::ceil(r1)) + w.margin_cells);
  return {a, b, c - a + 1, d - b + 1};
}

}  // namespace

Corridors corridors(const TerrainField& terrain, const std::vector<const RoadGeometry*>& roads, const CorridorOptions& options,
                    const std::vector<RoadClass>& classes, const CorridorWindows* windows) {
  if (!classes.empty() && classes.size() != roads.size()) throw processing_error("corridor: one class per road");
  if (windows && options.side_angles_deg.size() > 0) throw processing_error("corridor: by windows, the map of side angles is read on each window");
  Raster<float> slopes;
  std::array<EarthworkOptions, 4> by_class;
  for (std::size_t c = 0; c < by_class.size(); ++c) by_class[c] = earthwork_options(options, slopes, RoadClass(c));
  CorridorOptions with_map;  // by windows: the options with the road's window of the map
  if (windows && windows->side_angles) with_map = options;
  const Crs& crs = terrain.georef().crs;
  Corridors out;
  out.vegetation = windows ? windows->vegetation : terrain.has_vegetation();
  out.roads.resize(roads.size());
  std::vector<Polygon> road_zones;  // every road's zone, united road by road
  for (std::size_t ri = 0; ri < roads.size(); ++ri) {
    const RoadGeometry& road = *roads[ri];
    const std::size_t c = classes.empty() ? std::size_t(RoadClass::departmental) : std::min(std::size_t(classes[ri]), by_class.size() - 1);
    std::optional<TerrainField> window;
    if (windows && !road.points.empty()) {
      const auto [c0, r0, w, h] = window_around(*windows, terrain, road);
      window.emplace(windows->read(c0, r0, w, h));
      if (windows->side_angles) {  // the road's class's options on its window of the map
        with_map.side_angles_deg = windows->side_angles(c0, r0, w, h);
        by_class[c] = earthwork_options(with_map, slopes, RoadClass(c));
      }
    }
    const TerrainField& t = window ? *window : terrain;
    const EarthworkOptions& o = by_class[c];
    const auto sections = road_sections(t, road);
    std::vector<Polygon> zones;
    std::size_t first = 0;  // the section's first point in the road
    for (std::size_t si = 0; si < sections.size(); ++si) {
      SectionCorridor s;
      s.road = ri;
      s.section = si;
      s.structure = sections[si].structure;
      s.length_m = sections[si].length_m;
      s.half_width_m = o.half_width_m;
      s.carriageway_half_width_m = options.half_width_m > 0 ? options.half_width_m : 0.5 * options.widths[c].carriageway_m;
      section_corridor(t, o, road, first, sections[si].points, s);
      add(out.roads[ri], s.totals);
      zones.insert(zones.end(), s.zone.begin(), s.zone.end());
      first += sections[si].points.size() - 1;
      out.sections.push_back(std::move(s));
    }
    const std::vector<Polygon> united = unite(crs, zones, out.roads[ri]);
    road_zones.insert(road_zones.end(), united.begin(), united.end());
    add(out.run, out.roads[ri]);
  }
  out.land_take = unite(crs, road_zones, out.run);
  return out;
}

VectorLayer corridors_layer(const TerrainField& terrain, const Corridors& corridors) {
  VectorLayer layer;
  layer.name = "corridors";
  layer.geometry = GeometryType::polygon;
  layer.crs = terrain.georef().crs;
  layer.fields = {{"road", FieldType::integer},         {"section", FieldType::integer},       {"structure", FieldType::string},
                  {"part", FieldType::string},          {"length_m", FieldType::real},         {"area_ha", FieldType::real},
                  {"half_width_m", FieldType::real},    {"max_half_width_m", FieldType::real}, {"cut_m3", FieldType::real},
                  {"fill_m3", FieldType::real},         {"cleared_ha", FieldType::real},       {"walled_m", FieldType::real}};
  const FieldValue none;
  auto feature = [&](const Polygon& polygon, std::vector<FieldValue> values) {
    values.insert(values.begin() + 5, round_to(polygons_area_m2(layer.crs, {polygon}) / 1e4, 1e-4));  // area_ha
    layer.features.push_back({polygon.rings, std::move(values)});
  };
  for (const SectionCorridor& s : corridors.sections) {
    // A part united into several polygons (rare: slivers) carries the section's figures on its first.
    for (std::size_t k = 0; k < s.zone.size(); ++k)
      feature(s.zone[k], {std::int64_t(s.road), std::int64_t(s.section), s.structure, "earthworks", round_to(s.length_m, 0.01),
                          round_to(s.mean_half_width_m, 0.01), round_to(s.max_half_width_m, 0.01),
                          k == 0 ? FieldValue(round_to(s.totals.cut_m3, 0.1)) : none, k == 0 ? FieldValue(round_to(s.totals.fill_m3, 0.1)) : none,
                          k == 0 && corridors.vegetation ? FieldValue(round_to(s.totals.cleared_ha, 1e-4)) : none,
                          k == 0 ? FieldValue(round_to(s.walled_m, 0.01)) : none});
    for (const Polygon& p : s.carriageway)
      feature(p, {std::int64_t(s.road), std::int64_t(s.section), s.structure, "carriageway", round_to(s.length_m, 0.01),
                  round_to(s.carriageway_half_width_m, 0.01), round_to(s.carriageway_half_width_m, 0.01), none, none, none, none});
  }
  for (const Polygon& p : corridors.land_take) feature(p, {none, none, none, "land_take", none, none, none, none, none, none, none});
  return layer;
}

void add_corridor_fields(VectorLayer& layer, const Corridors& corridors) {
  if (layer.features.size() != corridors.roads.size()) throw processing_error("corridor: the roads layer does not match the corridors");
  for (const char* name : {"land_take_ha", "cut_m3", "fill_m3", "cleared_ha"}) layer.fields.push_back({name, FieldType::real});
  for (std::size_t i = 0; i < corridors.roads.size(); ++i) {
    const CorridorTotals& t = corridors.roads[i];
    auto& v = layer.features[i].values;
    v.emplace_back(round_to(t.land_take_ha, 1e-4));
    v.emplace_back(round_to(t.cut_m3, 0.1));
    v.emplace_back(round_to(t.fill_m3, 0.1));
    if (corridors.vegetation) v.emplace_back(round_to(t.cleared_ha, 1e-4));
    else v.emplace_back(std::monostate{});
  }
}

std::string corridors_renderer() {
  struct Category { const char* value; const char* label; const char* fill; const char* outline; const char* style; };
  const Category categories[] = {{"land_take", "land take (the zones united)", "0,0,0,0", "165,15,21,255", "dash"},
                                 {"earthworks", "earthworks zone (cut and fill sides)", "217,179,120,170", "140,100,50,255", "solid"},
                                 {"road", "carriageway", "82,82,82,255", "40,40,40,255", "solid"},
                                 {"bridge", "bridge deck", "8,81,156,255", "8,48,107,255", "solid"},
                                 {"tunnel", "tunnel (underground)", "150,150,150,90", "60,60,60,255", "dash"}};
  std::string list, symbols;
  for (std::size_t k = 0; k < std::size(categories); ++k) {
    const Category& c = categories[k];
    const std::string id = std::to_string(k);
    list += std::string("<category render=\"true\" symbol=\"") + id + "\" value=\"" + c.value + "\" label=\"" + c.label + "\"/>";
    symbols += "<symbol type=\"fill\" name=\"" + id + "\" alpha=\"1\"><layer class=\"SimpleFill\" enabled=\"1\"><Option type=\"Map\">"
               "<Option type=\"QString\" name=\"color\" value=\"" + std::string(c.fill) + "\"/>"
               "<Option type=\"QString\" name=\"outline_color\" value=\"" + c.outline + "\"/>"
               "<Option type=\"QString\" name=\"outline_style\" value=\"" + c.style + "\"/>"
               "<Option type=\"QString\" name=\"outline_width\" value=\"0.2\"/><Option type=\"QString\" name=\"outline_width_unit\" value=\"MM\"/>"
               "</Option></layer></symbol>";
  }
  // The land take's outline first, then the zones, carriageways on top: ordered by part, descending.
  return "<renderer-v2 type=\"categorizedSymbol\" attr=\"CASE WHEN &quot;part&quot; = 'carriageway' THEN &quot;structure&quot; ELSE &quot;part&quot; END\" "
         "enableorderby=\"1\" forceraster=\"0\" symbollevels=\"0\"><categories>" + list + "</categories><symbols>" + symbols +
         "</symbols><orderby><orderByClause asc=\"0\" nullsFirst=\"0\">\"part\"</orderByClause></orderby></renderer-v2>";
}

std::string corridors_qml() {
  return "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n<qgis version=\"3.22.16\" styleCategories=\"AllStyleCategories\">" +
         corridors_renderer() + "</qgis>\n";
}

std::string corridor_summary(const Corridors& c, double seconds) {
  char line[256];
  std::snprintf(line, sizeof line, "land take %.2f ha, cut %.0f m³, fill %.0f m³", c.run.land_take_ha, c.run.cut_m3, c.run.fill_m3);
  std::string out = line;
  if (c.vegetation) {
    std::snprintf(line, sizeof line, ", vegetation cleared %.2f ha", c.run.cleared_ha);
    out += line;
  }
  std::snprintf(line, sizeof line, ", %.2f s", seconds);
  return out + line;
}

namespace {

/// The stretches of a road off the given roads: maximal runs of segments not on them (on_existing).
std::vector<RoadGeometry> new_stretches(const RoadGeometry& road, const TerrainField& t, const GivenCells& existing) {
  auto cell = [&](const GridPoint& p) {
    const int c = t.clamp_col(int(std::lround(p.col))), r = t.clamp_row(int(std::lround(p.row)));
    return std::uint32_t(t.index(c, r));
  };
  std::vector<RoadGeometry> out;
  RoadGeometry* open = nullptr;
  for (std::size_t i = 0; i < road.segments.size(); ++i) {
    if (on_existing(t, existing, cell(road.points[i]), cell(road.points[i + 1]))) {
      open = nullptr;
      continue;
    }
    if (!open) {
      open = &out.emplace_back();
      open->points.push_back(road.points[i]);
      open->z.push_back(road.z[i]);
    }
    open->points.push_back(road.points[i + 1]);
    open->z.push_back(road.z[i + 1]);
    open->segments.push_back(road.segments[i]);
  }
  return out;
}

}  // namespace

Corridors road_corridors(const TerrainField& terrain, const std::vector<Road>& roads, const CorridorOptions& options,
                         const GivenCells& existing, const CorridorWindows* windows) {
  if (existing.empty()) {
    std::vector<const RoadGeometry*> geometries;
    std::vector<RoadClass> classes;
    for (const Road& r : roads) geometries.push_back(&r.geometry), classes.push_back(r.road_class);
    return corridors(terrain, geometries, options, classes, windows);
  }
  std::vector<RoadGeometry> stretches;
  std::vector<std::size_t> road_of;
  std::vector<RoadClass> classes;
  for (std::size_t i = 0; i < roads.size(); ++i)
    for (RoadGeometry& g : new_stretches(roads[i].geometry, terrain, existing)) {
      stretches.push_back(std::move(g));
      road_of.push_back(i);
      classes.push_back(roads[i].road_class);
    }
  std::vector<const RoadGeometry*> geometries;
  for (const RoadGeometry& g : stretches) geometries.push_back(&g);
  Corridors out = corridors(terrain, geometries, options, classes, windows);
  std::vector<CorridorTotals> per_road(roads.size());
  for (std::size_t k = 0; k < out.roads.size(); ++k) add(per_road[road_of[k]], out.roads[k]);
  std::vector<std::size_t> next_section(roads.size(), 0);
  for (SectionCorridor& s : out.sections) {
    s.road = road_of[s.road];
    s.section = next_section[s.road]++;
  }
  out.roads = std::move(per_road);
  return out;
}

}  // namespace terrapolis::roads
