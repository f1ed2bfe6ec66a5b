// Run comparison: flattened parameters and summary figures, side by side.
// SPDX-License-Identifier: MIT
#include "pipeline/compare.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "core/json_input.hpp"
#include "io/raster_io.hpp"

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

struct Pair {
  std::string key;
  json a, b;  ///< null where a run does not have the key
};

/// The leaves of two objects side by side: a's keys in order, then those only b has.
std::vector<Pair> paired(const json& a, const json& b) {
  std::vector<std::pair<std::string, json>> fa, fb;
  flatten(a, "", fa);
  flatten(b, "", fb);
  const std::map<std::string, json> mb(fb.begin(), fb.end());
  std::set<std::string> seen;
  std::vector<Pair> out;
  for (const auto& [k, v] : fa) {
    seen.insert(k);
    const auto it = mb.find(k);
    out.push_back({k, v, it == mb.end() ? json(nullptr) : it->second});
  }
  for (const auto& [k, v] : fb)
    if (!seen.count(k)) out.push_back({k, nullptr, v});
  return out;
}

/// `value` padded to `width` characters (UTF-8: a place name such as L'Île-Rousse is one column per
/// character, not per byte), on the left (`left`) or right.
std::string padded(const std::string& value, std::size_t width, bool left) {
  std::size_t chars = 0;
  for (const unsigned char c : value) chars += (c & 0xC0) != 0x80;
  const std::string fill(width > chars ? width - chars : 0, ' ');
  return left ? value + fill : fill + value;
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

/// A run's road km of one class (or the total for an empty class): new, drawn once, and given
/// (roads.existing); null where its run.json does not say (a run from before new_km was written
/// has only the whole network, all of it new).
std::pair<json, json> road_km(const json& roads, const std::string& cls) {
  const bool given = roads.contains("existing");
  json existing = given ? (cls.empty() ? roads["existing"].value("total_km", json(nullptr)) : roads["existing"]["km"].value(cls, json(0.0)))
                        : json(0.0);
  json built = nullptr;
  if (cls.empty() && roads.contains("new_network_km")) built = roads["new_network_km"];
  else if (cls.empty() && !given && roads.contains("network_km")) built = roads["network_km"];
  else if (!cls.empty() && roads.contains("new_km")) built = roads["new_km"].value(cls, json(0.0));
  return {built, existing};
}

/// New and existing road km by class, both runs side by side (summary.roads.new_km and
/// summary.roads.existing.km), with the change of the new km: what a scenario builds beyond the
/// roads it was given. Empty when neither run has a roads stage.
json road_table(const json& a, const json& b) {
  const json none = json::object();
  const json& ra = a.contains("summary") && a["summary"].contains("roads") ? a["summary"]["roads"] : none;
  const json& rb = b.contains("summary") && b["summary"].contains("roads") ? b["summary"]["roads"] : none;
  json rows = json::array();
  if (ra.empty() && rb.empty()) return rows;
  std::vector<std::string> classes;
  for (const json* r : {&ra, &rb})
    for (const char* key : {"new_km", "length_km"})
      if (r->contains(key))
        for (const auto& [cls, v] : (*r)[key].items())
          if (std::find(classes.begin(), classes.end(), cls) == classes.end()) classes.push_back(cls);
  classes.push_back("");  // the total
  for (const auto& cls : classes) {
    const auto [a_new, a_given] = ra.empty() ? std::pair<json, json>{nullptr, nullptr} : road_km(ra, cls);
    const auto [b_new, b_given] = rb.empty() ? std::pair<json, json>{nullptr, nullptr} : road_km(rb, cls);
    json row = {{"class", cls.empty() ? "total" : cls}, {"a_new_km", a_new}, {"a_existing_km", a_given}, {"b_new_km", b_new},
                {"b_existing_km", b_given}};
    if (a_new.is_number() && b_new.is_number()) row["new_change_km"] = b_new.get<double>() - a_new.get<double>();
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

json load_manifest(const std::string& run_folder) {
  const std::string path = run_folder + "/run.json";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw bad_input(run_folder + ": not a run folder (no run.json)");
  const std::string text = read_json_file(path);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throw bad_input(path + ": not valid JSON (" + json_error_text(e.what()) + ")");
  }
}

json compare_runs(const json& a, const json& b) {
  json pa = a["scenario"], pb = b["scenario"];
  pa.erase("output");  // where, not what
  pb.erase("output");
  json params = json::array(), figures = json::array();
  for (const auto& p : paired(pa, pb))
    if (p.a != p.b) params.push_back({{"parameter", p.key}, {"a", p.a}, {"b", p.b}});
  for (const auto& p : paired(a["summary"], b["summary"])) {
    json row = {{"figure", p.key}, {"a", p.a}, {"b", p.b}};
    if (p.a.is_number() && p.b.is_number()) row["change"] = p.b.get<double>() - p.a.get<double>();
    figures.push_back(row);
  }
  return {{"parameters", params}, {"figures", figures}, {"roads", road_table(a, b)}};
}

namespace {

/// A number of a comparison by a printf format, or `missing` where it is not one.
std::string formatted(const json& v, const char* format, const std::string& missing) {
  if (!v.is_number()) return missing;
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v.get<double>());
  return buf;
}

/// The new and existing road km of the two runs, by class (compare_runs' "roads").
void format_road_table(const json& rows, std::ostringstream& s) {
  s << "\nRoads, new and existing, km (new: drawn once, off the given roads; existing: given by roads.existing):\n";
  auto line = [&](const std::string& k, const std::string& an, const std::string& ae, const std::string& bn, const std::string& be,
                  const std::string& d) {
    s << "  " << padded(k, 14, true) << ' ' << padded(an, 12, false) << ' ' << padded(ae, 12, false) << ' ' << padded(bn, 12, false) << ' '
      << padded(be, 12, false) << ' ' << padded(d, 14, false) << '\n';
  };
  line("", "A new", "A existing", "B new", "B existing", "B - A new");
  for (const auto& r : rows)
    line(r["class"].get<std::string>(), formatted(r["a_new_km"], "%.2f", "-"), formatted(r["a_existing_km"], "%.2f", "-"),
         formatted(r["b_new_km"], "%.2f", "-"), formatted(r["b_existing_km"], "%.2f", "-"), formatted(r.value("new_change_km", json()), "%+.2f", ""));
}

}  // namespace

std::string format_comparison(const json& c) {
  std::ostringstream s;
  auto row = [&](const std::string& a, const std::string& b, const std::string& cc, const std::string& d) {
    s << "  " << padded(a, 40, true) << ' ' << padded(b, 16, false) << ' ' << padded(cc, 16, false) << ' ' << padded(d, 14, false) << '\n';
  };
  s << "Parameters that differ:\n";
  if (c["parameters"].empty()) s << "  (none)\n";
  for (const auto& p : c["parameters"]) row(p["parameter"].get<std::string>(), text(p["a"]), text(p["b"]), "");
  s << "\nFigures:\n";
  row("", "A", "B", "B - A");
  for (const auto& f : c["figures"]) row(f["figure"].get<std::string>(), text(f["a"]), text(f["b"]), formatted(f.value("change", json()), "%+.6g", ""));
  if (c.contains("roads") && !c["roads"].empty()) format_road_table(c["roads"], s);
  return s.str();
}

std::vector<std::pair<std::string, Raster<float>>> access_changes(const std::string& run_a, const std::string& run_b) {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(run_a, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("access_minutes", 0) == 0 && e.path().extension() == ".tif" && fs::exists(fs::path(run_b) / name, ec)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  std::vector<std::pair<std::string, Raster<float>>> out;
  for (const auto& name : names) {
    const Dem a = read_dem((fs::path(run_a) / name).string()), b = read_dem((fs::path(run_b) / name).string());
    if (a.cols() != b.cols() || a.rows() != b.rows() || a.georef().transform != b.georef().transform) continue;
    Raster<float> change = a.like<float>(NAN);
    for (std::size_t i = 0; i < a.size(); ++i) change[i] = b[i] - a[i];  // NaN on either side stays NaN
    out.emplace_back(fs::path(name).stem().string() + "_change.tif", std::move(change));
  }
  return out;
}

}  // namespace terrapolis::pipeline
