// Transfer functions, default costs from Peytavie 2010, and their JSON form.
// SPDX-License-Identifier: MIT
#include "roads/cost_model.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/json_input.hpp"

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

/// JSON text bounded (size, depth, number range) then parsed; one-line errors naming `origin`.
nlohmann::json parse_bounded(const std::string& text, const std::string& origin) {
  check_json_text(text, origin);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw bad_input(origin + ": not valid JSON (" + json_error_text(e.what()) + ")");
  }
}

using nlohmann::json;

[[noreturn]] void fail(const std::string& origin, const std::string& key, const std::string& problem) {
  throw bad_input(origin + ": " + key + ": " + problem);
}

double number(const json& j, const std::string& origin, const std::string& key) {
  if (!j.is_number()) fail(origin, key, "expected a number");
  return j.get<double>();
}

void read_transfer(const json& j, TransferFunction& f, const std::string& origin, const std::string& key) {
  if (!j.is_object()) fail(origin, key, "expected an object with \"points\" and \"threshold\"");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string k = key + "." + it.key();
    if (it.key() == "points") {
      if (!it->is_array()) fail(origin, k, "expected an array of [kappa, cost] pairs");
      f.points.clear();
      for (const auto& p : *it) {
        if (!p.is_array() || p.size() != 2) fail(origin, k, "expected [kappa, cost] pairs");
        const double x = number(p[0], origin, k), y = number(p[1], origin, k);
        if (!std::isfinite(x) || !std::isfinite(y) || y < 0) fail(origin, k, "costs must be finite and >= 0");
        if (!f.points.empty() && x <= f.points.back()[0]) fail(origin, k, "kappa values must increase");
        f.points.push_back({x, y});
      }
    } else if (it.key() == "threshold") {
      f.threshold = it->is_null() ? kInfinity : number(*it, origin, k);
    } else {
      fail(origin, k, "unknown key");
    }
  }
}

json transfer_json(const TransferFunction& f) {
  json pts = json::array();
  for (const auto& p : f.points) pts.push_back({p[0], p[1]});
  return {{"points", pts}, {"threshold", f.threshold == kInfinity ? json(nullptr) : json(f.threshold)}};
}

void read_structure(const json& j, StructureCosts& s, const std::string& origin, const std::string& key, bool long_arcs) {
  if (!j.is_object()) fail(origin, key, "expected an object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string k = key + "." + it.key();
    const std::string& name = it.key();
    if (name == "slope_deg") read_transfer(*it, s.slope_deg, origin, k);
    else if (name == "water_depth_m") read_transfer(*it, s.water_depth_m, origin, k);
    else if (name == "curvature_deg") read_transfer(*it, s.curvature_deg, origin, k);
    else if (name == "vegetation") read_transfer(*it, s.vegetation, origin, k);
    else if (name == "height_m" && key == "bridge") read_transfer(*it, s.height_m, origin, k);
    else if (name == "depth_m" && key == "tunnel") read_transfer(*it, s.depth_m, origin, k);
    else if (name == "enabled" && long_arcs) {
      if (!it->is_boolean()) fail(origin, k, "expected true or false");
      s.enabled = it->get<bool>();
    } else if (long_arcs && name == "longest_m") {
      std::optional<double> v;
      if (!it->is_null()) v = number(*it, origin, k);
      if (v && !(*v > 0)) fail(origin, k, "must be > 0");
      s.longest_m = v;
    } else if (long_arcs && (name == "min_length_m" || name == "max_length_m")) {
      std::optional<double> v;
      if (!it->is_null()) v = number(*it, origin, k);
      if (v && !(*v > 0)) fail(origin, k, "must be > 0");
      (name == "min_length_m" ? s.min_length_m : s.max_length_m) = v;
    } else if (long_arcs && (name == "min_length_cells" || name == "max_length_cells")) {
      const double v = number(*it, origin, k);
      if (!(v >= 1)) fail(origin, k, "must be >= 1");
      (name == "min_length_cells" ? s.min_length_cells : s.max_length_cells) = v;
    } else if (long_arcs && name == "samples") {
      if (!it->is_number_integer() || it->get<long long>() < 0) fail(origin, k, "expected an integer >= 0");
      s.samples = int(std::min<long long>(it->get<long long>(), 1 << 20));
    } else {
      fail(origin, k, "unknown key");
    }
  }
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
  TransferFunction f;
  read_transfer(j, f, origin, "transfer function");
  return f;
}

CostModel parse_cost_model(const std::string& text, const std::string& origin, CostModel m) {
  const json j = parse_bounded(text, origin);
  if (!j.is_object()) throw bad_input(origin + ": expected a JSON object");
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    if (key == "road") read_structure(*it, m.road, origin, key, false);
    else if (key == "bridge") read_structure(*it, m.bridge, origin, key, true);
    else if (key == "tunnel") read_structure(*it, m.tunnel, origin, key, true);
    else if (key == "sample_step_m") m.sample_step_m = number(*it, origin, key);
    else if (key == "unknown_water_depth_m") m.unknown_water_depth_m = number(*it, origin, key);
    else if (key == "structure_min_m") m.structure_min_m = number(*it, origin, key);
    else if (key == "road_radius_m") m.road_radius_m = number(*it, origin, key);
    else if (key == "smoothing_tolerance_cells") m.smoothing_tolerance_cells = number(*it, origin, key);
    else if (key == "$comment") continue;
    else fail(origin, key, "unknown key");
  }
  if (m.sample_step_m < 0 || m.unknown_water_depth_m < 0 || m.structure_min_m < 0 || m.road_radius_m < 0 ||
      m.smoothing_tolerance_cells < 0)
    throw bad_input(origin + ": lengths must be >= 0");
  for (const StructureCosts* s : {&m.bridge, &m.tunnel})
    if (s->min_length_cells > s->max_length_cells || (s->min_length_m && s->max_length_m && *s->min_length_m > *s->max_length_m))
      throw bad_input(origin + ": a minimum length exceeds its maximum");
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
