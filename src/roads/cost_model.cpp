// Transfer functions, default costs from Peytavie 2010, and their JSON form.
// SPDX-License-Identifier: MIT
#include "roads/cost_model.hpp"

#define VALIJSON_USE_EXCEPTIONS 1  // report invalid schemas as exceptions, not aborts
#include <nlohmann/json.hpp>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/json_input.hpp"
#include "core/schema_error.hpp"

namespace terrapolis::roads {

double TransferFunction::operator()(double kappa) const {
  if (kappa > threshold) return kInfinity;
  if (points.empty()) return 0.0;
  if (kappa <= points.front()[0]) return points.front()[1];
  if (kappa >= points.back()[0]) return points.back()[1];
  auto it = std::upper_bound(points.begin(), points.end(), kappa, [](double v, const std::array<double, 2>& p) { return v < p[0]; });
  const auto& b = *it;
  const auto& a = *(it - 1);
  const double t = (kappa - a[0]) / (b[0] - a[0]);
  return a[1] + t * (b[1] - a[1]);
}

double TransferFunction::min_value() const {
  if (points.empty()) return 0.0;
  double m = kInfinity;
  for (const auto& p : points)
    if (p[0] <= threshold) m = std::min(m, p[1]);
  if (m == kInfinity) m = (*this)(std::min(threshold, points.front()[0]));  // threshold before the first point
  return m;
}

const char* structure_name(Structure s) {
  switch (s) {
    case Structure::road: return "road";
    case Structure::bridge: return "bridge";
    case Structure::tunnel: return "tunnel";
  }
  return "road";
}

double CostModel::cheapest_per_metre() const {
  double best = road.slope_deg.min_value() + road.water_depth_m.min_value() + road.vegetation.min_value();
  if (bridge.enabled)
    best = std::min(best, bridge.slope_deg.min_value() + bridge.water_depth_m.min_value() + bridge.height_m.min_value() +
                              bridge.vegetation.min_value());
  if (tunnel.enabled)
    best = std::min(best, tunnel.slope_deg.min_value() + tunnel.water_depth_m.min_value() + tunnel.depth_m.min_value() +
                              tunnel.vegetation.min_value());
  return std::max(0.0, best);
}

CostModel default_cost_model() {
  CostModel m;
  // Surface roads: 1 per metre on the flat, log-shaped growth with the slope (the grade that
  // minimises cost per metre climbed is about 4-5 deg, 8 %), impassable above 15 deg.
  m.road.slope_deg = {{{0, 1}, {2, 1.1}, {4, 1.5}, {6, 2.5}, {8, 4}, {10, 6}, {12, 9}, {15, 14}}, 15};
  m.road.water_depth_m = {{{0, 0}, {0.5, 50}}, 0.5};
  // Per turn; convex so that a bend made of small turns costs less than one sharp turn.
  m.road.curvature_deg = {{{0, 0}, {20, 1}, {45, 6}, {90, 30}, {135, 80}, {170, 150}}, 170};
  // Vegetation (only with --vegetation): dense cover doubles the cost of a road, no threshold;
  // bridges pass over it at a tenth of that, tunnels under it for free (Peytavie §4.2.3).
  m.road.vegetation = {{{0, 0}, {1, 1}}, kInfinity};
  m.bridge.vegetation = {{{0, 0}, {1, 0.1}}, kInfinity};
  // Bridges: dearer per metre than roads, with a stricter slope and curvature; over water up to 50 m deep.
  m.bridge.slope_deg = {{{0, 1}, {4, 3}, {8, 10}}, 8};
  m.bridge.water_depth_m = {{{0, 0}, {50, 10}}, 50};
  m.bridge.curvature_deg = {{{0, 0}, {20, 4}, {50, 40}}, 50};
  m.bridge.height_m = {{{0, 8}, {150, 30}}, 150};
  m.bridge.longest_m = 3000;  // beyond the paper: long road bridges and viaducts are 1-3 km
  // Tunnels: slope and curvature as roads (70 deg), cost linear to 15 m depth then constant,
  // much dearer under water, at most 1000 m deep.
  m.tunnel.slope_deg = m.road.slope_deg;
  m.tunnel.water_depth_m = {{{0, 0}, {0.01, 40}, {50, 80}}, kInfinity};
  m.tunnel.curvature_deg = {{{0, 0}, {20, 2}, {45, 12}, {70, 40}}, 70};
  m.tunnel.depth_m = {{{0, 10}, {15, 25}}, 1000};
  m.tunnel.longest_m = 5000;  // beyond the paper: most road tunnels are under 5 km
  return m;
}

namespace {

using nlohmann::json;

/// JSON text bounded (size, depth, number range) then parsed; one-line errors naming `origin`.
json parse_bounded(const std::string& text, const std::string& origin) {
  check_json_text(text, origin);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throw bad_input(origin + ": not valid JSON (" + json_error_text(e.what()) + ")");
  }
}

/// A schema parsed once: schemas/road_costs.schema.json, or the definition `definition` of it.
struct ParsedSchema {
  explicit ParsedSchema(const char* definition) : document(json::parse(road_costs_schema_text())) {
    const json& root = definition ? document["definitions"][definition] : document;
    valijson::SchemaParser parser;
    valijson::adapters::NlohmannJsonAdapter adapter(root);
    parser.populateSchema(adapter, schema);
  }
  json document;
  valijson::Schema schema;
};

/// `doc` against the cost file's schema (or its transfer function definition): throws bad_input
/// "ORIGIN: /json/pointer: problem".
void validate(const json& doc, const std::string& origin, bool transfer_only) {
  static const ParsedSchema whole(nullptr), transfer("transfer");
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(doc);
  if (validator.validate((transfer_only ? transfer : whole).schema, target, &results)) return;
  const auto [pointer, problem] = schema_error(results, transfer_only ? nullptr : &whole.document);
  throw bad_input(origin + ": " + pointer + ": " + problem);
}

// The readers below take documents the schema accepted: types and ranges are its to check,
// only the rules it cannot state are checked here.

void read_transfer(const json& j, TransferFunction& f, const std::string& origin, const std::string& pointer) {
  if (j.contains("points")) {
    f.points.clear();
    for (const auto& p : j["points"]) {
      const double x = p[0].get<double>(), y = p[1].get<double>();
      if (!f.points.empty() && x <= f.points.back()[0]) throw bad_input(origin + ": " + pointer + "/points: kappa values must increase");
      f.points.push_back({x, y});
    }
  }
  if (j.contains("threshold")) f.threshold = j["threshold"].is_null() ? kInfinity : j["threshold"].get<double>();
}

std::optional<double> optional_number(const json& j) { return j.is_null() ? std::nullopt : std::optional<double>(j.get<double>()); }

void read_structure(const json& j, StructureCosts& s, const std::string& origin, const std::string& pointer) {
  const std::pair<const char*, TransferFunction*> terms[] = {{"slope_deg", &s.slope_deg},         {"water_depth_m", &s.water_depth_m},
                                                             {"curvature_deg", &s.curvature_deg}, {"vegetation", &s.vegetation},
                                                             {"height_m", &s.height_m},           {"depth_m", &s.depth_m}};
  for (const auto& [name, term] : terms)
    if (j.contains(name)) read_transfer(j[name], *term, origin, pointer + "/" + name);
  if (j.contains("enabled")) s.enabled = j["enabled"].get<bool>();
  if (j.contains("longest_m")) s.longest_m = optional_number(j["longest_m"]);
  if (j.contains("min_length_m")) s.min_length_m = optional_number(j["min_length_m"]);
  if (j.contains("max_length_m")) s.max_length_m = optional_number(j["max_length_m"]);
  if (j.contains("min_length_cells")) s.min_length_cells = j["min_length_cells"].get<double>();
  if (j.contains("max_length_cells")) s.max_length_cells = j["max_length_cells"].get<double>();
  if (j.contains("samples")) s.samples = j["samples"].get<int>();
  if (s.min_length_cells > s.max_length_cells || (s.min_length_m && s.max_length_m && *s.min_length_m > *s.max_length_m))
    throw bad_input(origin + ": " + pointer + ": a minimum length exceeds its maximum");
}

json transfer_json(const TransferFunction& f) {
  json pts = json::array();
  for (const auto& p : f.points) pts.push_back({p[0], p[1]});
  return {{"points", pts}, {"threshold", f.threshold == kInfinity ? json(nullptr) : json(f.threshold)}};
}

json structure_json(const StructureCosts& s, bool bridge, bool tunnel) {
  json j;
  if (bridge || tunnel) j["enabled"] = s.enabled;
  j["slope_deg"] = transfer_json(s.slope_deg);
  j["water_depth_m"] = transfer_json(s.water_depth_m);
  j["curvature_deg"] = transfer_json(s.curvature_deg);
  j["vegetation"] = transfer_json(s.vegetation);
  if (bridge) j["height_m"] = transfer_json(s.height_m);
  if (tunnel) j["depth_m"] = transfer_json(s.depth_m);
  if (bridge || tunnel) {
    j["min_length_m"] = s.min_length_m ? json(*s.min_length_m) : json(nullptr);
    j["max_length_m"] = s.max_length_m ? json(*s.max_length_m) : json(nullptr);
    j["min_length_cells"] = s.min_length_cells;
    j["max_length_cells"] = s.max_length_cells;
    j["longest_m"] = s.longest_m ? json(*s.longest_m) : json(nullptr);
    j["samples"] = s.samples;
  }
  return j;
}

}  // namespace

TransferFunction parse_transfer_function(const std::string& text, const std::string& origin) {
  const json j = parse_bounded(text, origin);
  validate(j, origin, true);
  TransferFunction f;
  read_transfer(j, f, origin, "");
  return f;
}

CostModel parse_cost_model(const std::string& text, const std::string& origin, CostModel m) {
  const json j = parse_bounded(text, origin);
  validate(j, origin, false);
  const std::pair<const char*, StructureCosts*> structures[] = {{"road", &m.road}, {"bridge", &m.bridge}, {"tunnel", &m.tunnel}};
  for (const auto& [name, structure] : structures)
    if (j.contains(name)) read_structure(j[name], *structure, origin, std::string("/") + name);
  const std::pair<const char*, double*> lengths[] = {{"sample_step_m", &m.sample_step_m}, {"unknown_water_depth_m", &m.unknown_water_depth_m},
                                                     {"structure_min_m", &m.structure_min_m}, {"road_radius_m", &m.road_radius_m},
                                                     {"smoothing_tolerance_cells", &m.smoothing_tolerance_cells}};
  for (const auto& [name, value] : lengths)
    if (j.contains(name)) *value = j[name].get<double>();
  return m;
}

CostModel load_cost_model(const std::string& path, CostModel base) {
  return parse_cost_model(read_json_file(path), path, std::move(base));
}

std::string cost_model_json(const CostModel& m) {
  json j;
  j["road"] = structure_json(m.road, false, false);
  j["bridge"] = structure_json(m.bridge, true, false);
  j["tunnel"] = structure_json(m.tunnel, false, true);
  j["sample_step_m"] = m.sample_step_m;
  j["unknown_water_depth_m"] = m.unknown_water_depth_m;
  j["structure_min_m"] = m.structure_min_m;
  j["road_radius_m"] = m.road_radius_m;
  j["smoothing_tolerance_cells"] = m.smoothing_tolerance_cells;
  return j.dump(2);
}

}  // namespace terrapolis::roads
