// Run comparison: flattened parameters and summary figures, side by side.
// SPDX-License-Identifier: MIT
#include "pipeline/compare.hpp"

#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/error.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;

/// Flattens nested objects into "a.b.c" -> leaf (arrays stay leaves).
void flatten(const json& j, const std::string& prefix, std::vector<std::pair<std::string, json>>& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) flatten(v, prefix.empty() ? k : prefix + "." + k, out);
  } else {
    out.emplace_back(prefix, j);
  }
}

std::vector<std::pair<std::string, json>> flat(const json& j) {
  std::vector<std::pair<std::string, json>> out;
  flatten(j, "", out);
  return out;
}

std::string text(const json& v) {
  if (v.is_null()) return "-";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.6g", v.get<double>());
    return buf;
  }
  return v.dump();
}

}  // namespace

json load_manifest(const std::string& run_folder) {
  const std::string path = run_folder + "/run.json";
  std::ifstream in(path);
  if (!in) throw bad_input(run_folder + ": not a run folder (no run.json)");
  try {
    return json::parse(in);
  } catch (const json::parse_error&) {
    throw bad_input(path + ": not valid JSON");
  }
}

json compare_runs(const json& a, const json& b) {
  json out;
  json params = json::array();
  auto pa = a["scenario"], pb = b["scenario"];
  pa.erase("output");
  pb.erase("output");
  const auto fa = flat(pa), fb = flat(pb);
  std::map<std::string, json> mb(fb.begin(), fb.end());
  std::set<std::string> seen;
  for (const auto& [k, v] : fa) {
    seen.insert(k);
    const json other = mb.count(k) ? mb[k] : json(nullptr);
    if (other != v) params.push_back({{"parameter", k}, {"a", v}, {"b", other}});
  }
  for (const auto& [k, v] : fb)
    if (!seen.count(k)) params.push_back({{"parameter", k}, {"a", nullptr}, {"b", v}});
  out["parameters"] = params;

  json figures = json::array();
  const auto sa = flat(a["summary"]), sb = flat(b["summary"]);
  std::map<std::string, json> msb(sb.begin(), sb.end());
  std::set<std::string> seen_figures;
  auto add = [&](const std::string& k, const json& va, const json& vb) {
    json row = {{"figure", k}, {"a", va}, {"b", vb}};
    if (va.is_number() && vb.is_number()) row["change"] = vb.get<double>() - va.get<double>();
    figures.push_back(row);
  };
  for (const auto& [k, v] : sa) {
    seen_figures.insert(k);
    add(k, v, msb.count(k) ? msb[k] : json(nullptr));
  }
  for (const auto& [k, v] : sb)
    if (!seen_figures.count(k)) add(k, nullptr, v);
  out["figures"] = figures;
  return out;
}

std::string format_comparison(const json& c) {
  std::ostringstream s;
  auto row = [&](const std::string& a, const std::string& b, const std::string& cc, const std::string& d) {
    char buf[512];
    std::snprintf(buf, sizeof(buf), "  %-40s %16s %16s %14s\n", a.c_str(), b.c_str(), cc.c_str(), d.c_str());
    s << buf;
  };
  s << "Parameters that differ:\n";
  if (c["parameters"].empty()) s << "  (none)\n";
  for (const auto& p : c["parameters"]) row(p["parameter"].get<std::string>(), text(p["a"]), text(p["b"]), "");
  s << "\nFigures:\n";
  row("", "A", "B", "B - A");
  for (const auto& f : c["figures"]) {
    std::string change;
    if (f.contains("change")) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), "%+.6g", f["change"].get<double>());
      change = buf;
    }
    row(f["figure"].get<std::string>(), text(f["a"]), text(f["b"]), change);
  }
  return s.str();
}

}  // namespace terrapolis::pipeline
