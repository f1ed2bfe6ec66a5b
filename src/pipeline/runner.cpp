// The scenario runner: stage list, run folder, run.json.
// SPDX-License-Identifier: MIT
#include "pipeline/runner.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/checksum.hpp"
#include "io/raster_io.hpp"
#include "pipeline/hillshade.hpp"
#include "pipeline/publish.hpp"
#include "pipeline/run_state.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;

struct StageDef {
  const char* name;
  void (*run)(RunState&, Progress&, const Log&);
};

void terrain_stage(RunState& s, Progress&, const Log&) {
  s.write("terrain", "elevation.tif", s.dem, "elevation in metres (as read from the input DEM)", Style::elevation);
  s.write("terrain", "hillshade.tif", hillshade(s.dem), "hillshade (Horn 1981), light from 315 deg at 45 deg", Style::hillshade);
  double lo = 1e300, hi = -1e300;
  std::size_t valid = 0;
  for (float v : s.dem.values()) {
    if (std::isnan(v)) continue;
    lo = std::min(lo, double(v));
    hi = std::max(hi, double(v));
    ++valid;
  }
  s.summary["terrain"] = {{"cols", s.dem.cols()}, {"rows", s.dem.rows()}, {"min_m", lo}, {"max_m", hi},
                          {"nodata_share", 1.0 - double(valid) / double(s.dem.size())}};
}

/// The stages, in data-flow order: the one list the runner, --help and the docs read.
std::vector<StageDef> stages() {
  return {
      {"terrain", terrain_stage},
  };
}

long peak_rss_kb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

}  // namespace

std::vector<std::string> stage_names() {
  std::vector<std::string> names;
  for (const auto& s : stages()) names.emplace_back(s.name);
  return names;
}

json run_scenario(const Scenario& scenario, const RunOptions& options, Progress& progress, const Log& log) {
  namespace fs = std::filesystem;
  const fs::path output = scenario.path("output");
  std::error_code ec;
  if (fs::exists(output, ec) && !options.overwrite)
    throw bad_input(output.string() + ": run folder exists (use --overwrite to replace it)");
  const fs::path parent = output.parent_path().empty() ? fs::path(".") : output.parent_path();
  if (!fs::is_directory(parent, ec)) throw bad_input(output.string() + ": folder " + parent.string() + " does not exist");

  const std::string dem_path = scenario.path("dem");
  ReadOptions read;
  if (int band = scenario.resolved["input"]["band"].get<int>(); band > 0) read.band = band;
  if (auto crs = scenario.resolved["input"]["assume_crs"].get<std::string>(); !crs.empty()) read.assume_crs = crs;

  Dem dem = read_dem(dem_path, read);  // before creating anything: bad input leaves no folder
  const fs::path temp = output.string() + ".tmp-" + std::to_string(::getpid());
  fs::remove_all(temp, ec);
  if (!fs::create_directory(temp, ec)) throw bad_input(output.string() + ": cannot create the run folder (" + ec.message() + ")");
  try {
    RunState state{.scenario = scenario, .folder = temp, .dem_sha256 = file_sha256(dem_path), .dem = std::move(dem),
                   .hydrometry = {}, .density = {}, .outputs = {}, .vectors = {}, .summary = nlohmann::ordered_json::object()};
    json timings = json::array();
    for (const auto& stage : stages()) {
      const Log stage_log = log.stage(stage.name);
      const auto start = std::chrono::steady_clock::now();
      stage.run(state, progress, stage_log);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      timings.push_back({{"stage", stage.name}, {"seconds", seconds}, {"peak_memory_mb", double(peak_rss_kb()) / 1024.0}});
      stage_log.detail("done in " + std::to_string(seconds) + " s");
    }

    json manifest;
    manifest["terrapolis"] = terrapolis::version;
    manifest["scenario"] = scenario.resolved;
    manifest["scenario_source"] = scenario.source;
    manifest["input"] = {{"dem", dem_path}, {"sha256", state.dem_sha256}, {"bytes", fs::file_size(dem_path)},
                         {"crs", state.dem.georef().crs.name},
                         {"epsg", state.dem.georef().crs.epsg ? json(*state.dem.georef().crs.epsg) : json(nullptr)}};
    json libs = json::object();
    for (const auto& [name, version] : io_library_versions()) libs[name] = version;
    manifest["libraries"] = libs;
    json outputs = json::array();
    for (const auto& o : state.outputs) {
      json entry = {{"file", o.name}, {"stage", o.stage}, {"description", o.description}, {"kind", o.raster ? "raster" : "vector"}};
      if (!o.raster) entry["features"] = o.features;
      outputs.push_back(entry);
    }
    manifest["outputs"] = outputs;
    manifest["summary"] = state.summary;
    manifest["timings"] = timings;
    publish(state, manifest, log.stage("publish"));
    {
      std::ofstream out(temp / "run.json");
      out << manifest.dump(2) << "\n";
      if (!out) throw processing_error((temp / "run.json").string() + ": cannot write");
    }
    if (fs::exists(output, ec)) fs::remove_all(output);
    fs::rename(temp, output);
    return manifest;
  } catch (...) {
    fs::remove_all(temp, ec);
    throw;
  }
}

std::string format_summary(const json& manifest) {
  std::ostringstream s;
  const auto& sum = manifest["summary"];
  s << "Run of " << manifest["input"]["dem"].get<std::string>() << " (seed " << manifest["scenario"]["seed"] << ")\n";
  if (sum.contains("terrain")) {
    const auto& t = sum["terrain"];
    s << "  terrain: " << t["cols"] << " x " << t["rows"] << " cells, " << t["min_m"].get<double>() << " .. "
      << t["max_m"].get<double>() << " m\n";
  }
  s << "  timings:";
  for (const auto& t : manifest["timings"]) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), " %s %.2f s", t["stage"].get<std::string>().c_str(), t["seconds"].get<double>());
    s << buf;
  }
  s << "\n";
  return s.str();
}

}  // namespace terrapolis::pipeline
