// Existing roads: classes from the user's field, lines drawn onto the grid, the checks of a run.
// SPDX-License-Identifier: MIT
#include "roads/existing_roads.hpp"

#include <cctype>
#include <cmath>

#include "core/error.hpp"

namespace terrapolis::roads {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Fractional grid position (cell corners at integers) of a point in the DEM's CRS.
std::optional<GridPoint> grid_position(const TerrainField& t, const std::array<double, 2>& p) {
  const auto& g = t.georef().transform;
  const double det = g[1] * g[5] - g[2] * g[4];
  if (det == 0 || !std::isfinite(p[0]) || !std::isfinite(p[1])) return std::nullopt;
  const double dx = p[0] - g[0], dy = p[1] - g[3];
  return GridPoint{(g[5] * dx - g[2] * dy) / det, (-g[4] * dx + g[1] * dy) / det};
}

/// Appends the chains of one line string (cut where it leaves the grid) to `out`, and the length
/// of each (m) of the line itself inside the grid to `lengths`.
void draw_line(const TerrainField& t, const std::vector<std::array<double, 2>>& line, std::vector<CellChain>& out, std::vector<double>& lengths) {
  CellChain chain;
  double length = 0;
  std::optional<GridPoint> last;  // the previous sample, when inside the grid (cell centres at integers)
  auto flush = [&] {
    if (chain.cells.size() >= 2) out.push_back(std::move(chain)), lengths.push_back(length);
    chain = {};
    length = 0;
    last.reset();
  };
  auto visit = [&](double col, double row) {
    const int c = int(std::floor(col)), r = int(std::floor(row));
    if (!std::isfinite(col) || !std::isfinite(row) || !t.inside(c, r)) return flush();
    const GridPoint here{col - 0.5, row - 0.5};
    if (last) length += t.length_m(*last, here);
    last = here;
    const std::uint32_t cell = std::uint32_t(t.index(c, r));
    if (!chain.cells.empty() && chain.cells.back() == cell) return;
    if (!chain.cells.empty()) chain.structures.push_back(Structure::road);
    chain.cells.push_back(cell);
  };
  std::optional<GridPoint> prev;
  for (const auto& xy : line) {
    const std::optional<GridPoint> p = grid_position(t, xy);
    if (!p) {
      flush();
      prev.reset();
      continue;
    }
    if (!prev) {
      visit(p->col, p->row);
    } else {
      // A quarter of a cell at most per sample: consecutive cells are 8-neighbours.
      const double span = std::max(std::fabs(p->col - prev->col), std::fabs(p->row - prev->row));
      const int n = std::max(1, int(std::ceil(span * 4)));
      for (int k = 1; k <= n; ++k) visit(prev->col + (p->col - prev->col) * k / n, prev->row + (p->row - prev->row) * k / n);
    }
    prev = p;
  }
  flush();
}

}  // namespace

std::optional<RoadClass> existing_road_class(std::string_view value) {
  std::string v = lower(value);
  if (v.ends_with("_link")) v.resize(v.size() - 5);
  if (v == "maritime" || v == "ferry") return std::nullopt;
  if (const auto ours = road_class_named(v)) return *ours;
  if (v == "trunk" || v == "autoroute" || v == "motorway") return RoadClass::motorway;
  if (v == "primary" || v == "nationale" || v == "route nationale") return RoadClass::national;
  if (v == "secondary" || v == "tertiary" || v == "departementale" || v == "d\xc3\xa9partementale" || v == "d\xc3\x89partementale" ||
      v == "route d\xc3\xa9partementale")
    return RoadClass::departmental;
  return RoadClass::local;
}

int existing_class_field(const VectorLayer& lines) {
  for (const char* name : {"class", "highway", "fclass", "cl_admin"})
    for (std::size_t k = 0; k < lines.fields.size(); ++k)
      if (lower(lines.fields[k].name) == name) return int(k);
  return -1;
}

ExistingRoads rasterise_roads(const TerrainField& t, const VectorLayer& lines) {
  ExistingRoads out;
  const int field = existing_class_field(lines);
  for (const Feature& f : lines.features) {
    if (f.parts.empty()) continue;
    ++out.lines;
    std::string value;
    if (field >= 0)
      if (const auto* s = std::get_if<std::string>(&f.values[std::size_t(field)])) value = *s;
    const std::optional<RoadClass> c = existing_road_class(value);
    if (!c) {
      ++out.ferries;
      continue;
    }
    const std::size_t before = out.chains.size();
    draw_line(t, f.parts[0], out.chains, out.chain_length_m);
    if (out.chains.size() == before) ++out.outside;
    for (std::size_t k = before; k < out.chains.size(); ++k) {
      out.classes.push_back(*c);
      out.source_class.push_back(value);
      out.length_m[std::size_t(*c)] += out.chain_length_m[k];
    }
  }
  return out;
}

void check_existing_roads(const std::string& path, const Crs& dem_crs) {
  if (!vector_has_crs(path))
    throw bad_input(path + ": has no CRS; give it one (e.g. ogr2ogr -a_srs EPSG:4326 out.gpkg in.gpkg) or use GeoJSON (WGS 84)");
  const VectorLayer layer = read_vector(path, dem_crs);
  if (layer.features.empty()) throw bad_input(path + ": holds no line");
  if (layer.geometry != GeometryType::line_string) throw bad_input(path + ": roads must be line strings");
}

ExistingRoads read_existing_roads(const std::string& path, const TerrainField& terrain) {
  check_existing_roads(path, terrain.georef().crs);
  ExistingRoads out = rasterise_roads(terrain, read_vector(path, terrain.georef().crs));
  if (out.empty()) throw bad_input(path + ": no road of it runs on the DEM");
  return out;
}

VectorLayer existing_roads_layer(const TerrainField& t, const ExistingRoads& existing) {
  VectorLayer layer;
  layer.name = "existing_roads";
  layer.geometry = GeometryType::line_string;
  layer.crs = t.georef().crs;
  layer.fields = {{"class", FieldType::string}, {"source_class", FieldType::string}, {"length_m", FieldType::real}};
  for (std::size_t k = 0; k < existing.chains.size(); ++k) {
    layer.features.push_back({{chain_line(t, existing.chains[k].cells)},
                              {std::string(name_of(existing.classes[k])), existing.source_class[k],
                               std::round(existing.chain_length_m[k] * 100) / 100}});
  }
  return layer;
}

}  // namespace terrapolis::roads
