// Reach discharge, slope, sinuosity and the paper's Rosgen-like types (Génévaux et al. 2013 §5.1-5.2).
// SPDX-License-Identifier: MIT
#include "hydro/river_types.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <vector>

#include "core/error.hpp"
#include "core/geodesy.hpp"
#include "hydro/grid.hpp"

namespace terrapolis::hydro {
namespace {

/// The cell whose centre is (x, y) (stream vertices are cell centres).
std::array<int, 2> cell_of(const Georef& g, double x, double y) {
  const auto& t = g.transform;
  const double det = t[1] * t[5] - t[2] * t[4];
  const double dx = x - t[0], dy = y - t[3];
  const double c = (t[5] * dx - t[2] * dy) / det, r = (t[1] * dy - t[4] * dx) / det;
  return {int(std::floor(c)), int(std::floor(r))};
}

std::int64_t integer(const Feature& f, int field) { return std::get<std::int64_t>(f.values[std::size_t(field)]); }
double real(const Feature& f, int field) { return std::get<double>(f.values[std::size_t(field)]); }

}  // namespace

double paper_discharge_m3s(double area_km2) { return 0.42 * std::pow(area_km2, 0.69); }

const char* river_type_name(RiverType type) {
  switch (type) {
    case RiverType::B: return "B";
    case RiverType::E: return "E";
    case RiverType::D: return "D";
    case RiverType::delta: return "delta";
  }
  return "";
}

RiverType classify_reach(const ReachMeasures& m, const RiverTypeOptions& o) {
  // §5.2: "Les deltas ne concernent que les points décrivant des embouchures avec un débit suffisant."
  if (m.mouth && m.discharge_m3s >= o.delta_discharge_m3s) return RiverType::delta;
  // "... typés comme des tresses s'ils sont suffisamment proches des côtes."
  if (m.to_mouth_km >= 0 && m.to_mouth_km <= o.coast_distance_km && m.discharge_m3s >= o.braided_discharge_m3s) return RiverType::D;
  // "Nous typons l'ensemble de notre réseau en fonction de la pente locale."
  if (m.slope < o.e_max_slope && m.sinuosity >= o.e_min_sinuosity) return RiverType::E;
  return RiverType::B;
}

void check(const RiverTypeOptions& o) {
  if (!(o.braided_discharge_m3s > 0) || !std::isfinite(o.braided_discharge_m3s)) throw bad_input("/hydro/braided_discharge_m3s: must be positive (m3/s)");
  if (!(o.delta_discharge_m3s > 0) || !std::isfinite(o.delta_discharge_m3s)) throw bad_input("/hydro/delta_discharge_m3s: must be positive (m3/s)");
  if (!(o.coast_distance_km >= 0) || !std::isfinite(o.coast_distance_km)) throw bad_input("/hydro/coast_distance_km: must be >= 0 km");
}

namespace {

/// The conditioned DEM as the typing reads it: its grid and its value at a cell (NaN on nodata).
struct FilledCells {
  const Georef& georef;
  int cols = 0, rows = 0;
  std::function<float(int col, int row)> at;
};

void classify(VectorLayer& streams, const FilledCells& filled, const std::optional<double>& sea_level, const RiverTypeOptions& o) {
  check(o);
  const int f_id = streams.field_index("id"), f_area = streams.field_index("upstream_km2"), f_length = streams.field_index("length_m"),
            f_down = streams.field_index("downstream_id");
  if (f_id < 0 || f_area < 0 || f_length < 0 || f_down < 0) throw bad_input("streams: not a layer of extract_streams");
  const Georef& g = filled.georef;
  auto sea = [&](int c, int r) { return c >= 0 && r >= 0 && c < filled.cols && r < filled.rows && is_sea(filled.at(c, r), sea_level); };
  const std::size_t n = streams.features.size();
  std::vector<ReachMeasures> m(n);
  std::map<std::int64_t, std::size_t> by_id;
  for (std::size_t i = 0; i < n; ++i) {
    const Feature& f = streams.features[i];
    by_id[integer(f, f_id)] = i;
    const auto& line = f.parts.at(0);
    const auto a = line.front(), b = line.back();
    const auto ca = cell_of(g, a[0], a[1]), cb = cell_of(g, b[0], b[1]);
    const double length = real(f, f_length);
    const double drop = double(filled.at(ca[0], ca[1])) - double(filled.at(cb[0], cb[1]));
    const double chord = crs_distance_m(g.crs, a[0], a[1], b[0], b[1]);
    m[i].discharge_m3s = paper_discharge_m3s(real(f, f_area));
    m[i].slope = length > 0 ? std::max(0.0, drop) / length : 0.0;
    // A D8 path is never shorter than its chord; rounding could make it 1 - 1e-16.
    m[i].sinuosity = chord > 0 ? std::max(1.0, length / chord) : 1.0;
    if (integer(f, f_down) == 0 && sea_level) {
      // A mouth: the reach ends in the sea or on a cell beside it.
      for (int k = -1; k < 8 && !m[i].mouth; ++k)
        m[i].mouth = k < 0 ? sea(cb[0], cb[1]) : sea(cb[0] + dcol[k], cb[1] + drow[k]);
    }
  }
  // River distance to a mouth: down the downstream_id chain (iterative: chains run to thousands).
  std::vector<char> done(n, 0);
  for (std::size_t s = 0; s < n; ++s) {
    std::vector<std::size_t> chain;
    std::size_t i = s;
    double below = -1;  // to_mouth_km of the reach after the chain's last one
    for (;;) {
      if (done[i]) {
        below = m[i].to_mouth_km;
        break;
      }
      chain.push_back(i);
      const std::int64_t down = integer(streams.features[i], f_down);
      const auto it = down == 0 ? by_id.end() : by_id.find(down);
      if (it == by_id.end()) {
        m[i].to_mouth_km = m[i].mouth ? 0.0 : -1.0;
        done[i] = 1;
        chain.pop_back();
        below = m[i].to_mouth_km;
        break;
      }
      i = it->second;
    }
    // Unwind: each reach's end is the start of the next, so add the next reach's length.
    for (std::size_t k = chain.size(); k-- > 0;) {
      const std::size_t next = k + 1 < chain.size() ? chain[k + 1] : std::size_t(-1);
      const std::size_t after = next != std::size_t(-1) ? next : by_id.at(integer(streams.features[chain[k]], f_down));
      const double next_to_mouth = next != std::size_t(-1) ? m[next].to_mouth_km : below;
      m[chain[k]].to_mouth_km = next_to_mouth < 0 ? -1.0 : next_to_mouth + real(streams.features[after], f_length) / 1000;
      done[chain[k]] = 1;
    }
  }
  streams.fields.push_back({"discharge_m3s", FieldType::real});
  streams.fields.push_back({"slope", FieldType::real});
  streams.fields.push_back({"sinuosity", FieldType::real});
  streams.fields.push_back({"to_mouth_km", FieldType::real});
  streams.fields.push_back({"river_type", FieldType::string});
  for (std::size_t i = 0; i < n; ++i) {
    auto& v = streams.features[i].values;
    v.emplace_back(m[i].discharge_m3s);
    v.emplace_back(m[i].slope);
    v.emplace_back(m[i].sinuosity);
    if (m[i].to_mouth_km < 0) v.emplace_back(std::monostate{});
    else v.emplace_back(m[i].to_mouth_km);
    v.emplace_back(std::string(river_type_name(classify_reach(m[i], o))));
  }
}

}  // namespace

void classify_streams(VectorLayer& streams, const Dem& filled, const std::optional<double>& sea_level, const RiverTypeOptions& o) {
  classify(streams, {filled.georef(), filled.cols(), filled.rows(), [&](int c, int r) { return filled(c, r); }}, sea_level, o);
}

void classify_streams(VectorLayer& streams, const DemWindowReader& filled, const Georef& grid, const std::optional<double>& sea_level,
                      const RiverTypeOptions& o) {
  CellSampler cells(filled);
  classify(streams, {grid, filled.header().cols, filled.header().rows, [&](int c, int r) { return cells.at(c, r); }}, sea_level, o);
}

std::string river_types_qml() {
  struct Type { const char* value; const char* label; const char* colour; };
  const Type types[] = {{"B", "B straight (steep or straight)", "#08519c"},
                        {"E", "E sinuous (gentle, meandering)", "#41ab5d"},
                        {"D", "D braided (near the coast, high discharge)", "#fd8d3c"},
                        {"delta", "delta (mouth, high discharge)", "#d7301f"}};
  std::string categories, symbols;
  for (int k = 0; k < 4; ++k) {
    const std::string id = std::to_string(k);
    categories += std::string("<category render=\"true\" symbol=\"") + id + "\" value=\"" + types[k].value + "\" label=\"" + types[k].label + "\"/>";
    symbols += "<symbol type=\"line\" name=\"" + id + "\" alpha=\"1\"><layer class=\"SimpleLine\" enabled=\"1\">"
               "<Option type=\"Map\"><Option type=\"QString\" name=\"line_color\" value=\"" + types[k].colour + "\"/>"
               "<Option type=\"QString\" name=\"line_width\" value=\"0.5\"/><Option type=\"QString\" name=\"line_width_unit\" value=\"MM\"/>"
               "</Option><data_defined_properties><Option type=\"Map\"><Option type=\"QString\" name=\"name\" value=\"\"/>"
               "<Option type=\"Map\" name=\"properties\"><Option type=\"Map\" name=\"outlineWidth\">"
               "<Option type=\"bool\" name=\"active\" value=\"true\"/>"
               "<Option type=\"QString\" name=\"expression\" value=\"0.2 + 0.35 * ln(1 + &quot;discharge_m3s&quot;)\"/>"
               "<Option type=\"int\" name=\"type\" value=\"3\"/></Option></Option>"
               "<Option type=\"QString\" name=\"type\" value=\"collection\"/></Option></data_defined_properties></layer></symbol>";
  }
  return "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n<qgis version=\"3.22.16\" styleCategories=\"AllStyleCategories\">"
         "<renderer-v2 type=\"categorizedSymbol\" attr=\"river_type\" enableorderby=\"0\" forceraster=\"0\" symbollevels=\"0\">"
         "<categories>" + categories + "</categories><symbols>" + symbols + "</symbols></renderer-v2></qgis>\n";
}

}  // namespace terrapolis::hydro
