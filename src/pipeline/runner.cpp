// The scenario runner: stage list, run folder, run.json.
// SPDX-License-Identifier: MIT
#include "pipeline/runner.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <functional>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "io/checksum.hpp"
#include "io/output_set.hpp"
#include "io/text_io.hpp"
#include "io/raster_io.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/publish.hpp"
#include "pipeline/run_state.hpp"
#include "pipeline/stage_options.hpp"
#include "pipeline/stages.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;



/// What a run does with each stage.
enum class Action { run, load, keep };

std::size_t stage_index(const std::string& option, const std::string& name) {
  std::string names;
  for (std::size_t i = 0; i < stages().size(); ++i) {
    if (name == stages()[i].name) return i;
    names += std::string(i ? ", " : "") + stages()[i].name;
  }
  throw bad_input(option + ": unknown stage '" + name + "' (stages: " + names + ")");
}

/// --from X: the stages before X are read back, X and after run. --only S...: those run, the
/// stages before the last of them are read back, the stages after it keep their saved files.
std::vector<Action> plan_stages(const RunOptions& options) {
  const std::size_t n = stages().size();
  if (!options.from.empty() && !options.only.empty()) throw bad_input("--from and --only: give one or the other");
  std::vector<Action> plan(n, Action::run);
  if (!options.from.empty()) {
    const std::size_t from = stage_index("--from", options.from);
    for (std::size_t i = 0; i < from; ++i) plan[i] = Action::load;
  } else if (!options.only.empty()) {
    std::vector<bool> only(n, false);
    std::size_t last = 0;
    for (const auto& name : options.only) {
      const std::size_t i = stage_index("--only", name);
      only[i] = true;
      last = std::max(last, i);
    }
    for (std::size_t i = 0; i < n; ++i) plan[i] = only[i] ? Action::run : i < last ? Action::load : Action::keep;
  }
  return plan;
}

/// A section of the scenario as a rerun compares it: how a run by tiles is cut (input.tile_size,
/// input.memory_limit_mb) gives the same cells, so only whether it worked by tiles counts (its
/// rasters are VRTs then, the whole grid's GeoTIFFs otherwise).
json compared(const std::string& key, json section) {
  if (key != "input" || !section.is_object()) return section;
  const bool by_tiles = section.value("tile_size", 0) > 0 || section.value("memory_limit_mb", 0.0) > 0;
  section.erase("tile_size");
  section.erase("memory_limit_mb");
  section["by_tiles"] = by_tiles;
  return section;
}

/// A saved stage is read back only for the same DEM and the same parameters of its own (those of
/// the stages before it are checked too when they are read back; a rerun one makes it stale).
void check_reusable(const std::filesystem::path& folder, const json& saved, const Scenario& scenario, const std::string& dem_sha256,
                    const json& files, const std::vector<Action>& plan) {
  if (saved["input"].value("sha256", "") != dem_sha256)
    throw bad_input(folder.string() + ": the saved run was made from another DEM; run the whole scenario");
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const StageDef& stage = stages()[i];
    if (plan[i] == Action::run) continue;
    // A later stage the saved run never made (it stopped with --until) stays absent.
    if (plan[i] == Action::keep && !saved["summary"].contains(stage.name)) continue;
    if (!saved["summary"].contains(stage.name))
      throw bad_input(folder.string() + ": the saved run has no " + stage.name + " stage; rerun from it");
    if (plan[i] != Action::load) continue;
    for (const auto& key : stage.sections) {
      if (!saved["scenario"].contains(key) || compared(key, saved["scenario"][key]) != compared(key, scenario.resolved[key]))
        throw bad_input(folder.string() + ": the saved run used other '" + key + "' parameters; rerun from " + stage.name +
                        " (--from " + stage.name + ")");
      // The same settings may name a file whose content changed since (a new mask, refitted trees).
      const json& before = saved["input"].contains("files") ? saved["input"]["files"] : files;
      for (const auto& [pointer, sha256] : files.items())
        if (pointer.rfind("/" + key + "/", 0) == 0 && before.value(pointer, "") != sha256)
          throw bad_input(folder.string() + ": " + pointer + " names a file changed since the saved run; rerun from " + stage.name +
                          " (--from " + stage.name + ")");
    }
  }
}

/// Records a saved stage's files (vector layers read back for the preview), figures and timing.
void reuse_saved(RunState& state, const json& saved, const std::string& stage, json& timings) {
  for (const auto& o : saved["outputs"]) {
    if (o["stage"] != stage) continue;
    OutputFile file{o["file"].get<std::string>(), stage, o["description"].get<std::string>(), style_from_name(o.value("style", "")),
                    o["kind"] == "raster", o.value("features", std::size_t(0))};
    if (!file.raster) state.vectors.emplace_back(file.style, read_vector((state.folder / file.name).string(), state.grid.georef.crs));
    state.outputs.push_back(file);
  }
  if (saved["summary"].contains(stage)) state.summary[stage] = saved["summary"][stage];
  for (const auto& t : saved["timings"])
    if (t["stage"] == stage) {
      json entry = t;
      entry["reused"] = true;
      timings.push_back(entry);
    }
}

/// The checksum of every file the scenario names besides the DEM (which input.sha256 holds), by the
/// JSON pointer of its setting: a rerun reuses a saved stage only if the files it read are unchanged.
json input_files(const Scenario& scenario) {
  json files = json::object();
  std::function<void(const json&, const std::string&)> walk = [&](const json& j, const std::string& pointer) {
    if (j.is_object()) {
      for (const auto& [key, value] : j.items())
        if (!(pointer.empty() && (key == "output" || key == "dem"))) walk(value, pointer + "/" + key);
    } else if (j.is_array()) {
      for (std::size_t k = 0; k < j.size(); ++k) walk(j[k], pointer + "/" + std::to_string(k));
    } else if (j.is_string() && !j.get<std::string>().empty()) {
      std::error_code ec;
      if (const std::string path = scenario.file(j.get<std::string>()); std::filesystem::is_regular_file(path, ec))
        files[pointer] = file_sha256(path);
    }
  };
  walk(scenario.resolved, "");
  return files;
}

/// Every file the scenario names (its strings that name an existing file, resolved as its paths
/// are), and the scenario file itself: the run folder may not hold them.
std::vector<std::string> scenario_inputs(const Scenario& scenario) {
  namespace fs = std::filesystem;
  std::vector<std::string> inputs;
  if (fs::path source = scenario.source; fs::is_regular_file(source)) inputs.push_back(source.string());
  std::function<void(const json&)> walk = [&](const json& j) {
    if (j.is_object() || j.is_array()) {
      for (const auto& [key, value] : j.items())
        if (!(j.is_object() && &j == &scenario.resolved && key == "output")) walk(value);
    } else if (j.is_string() && !j.get<std::string>().empty()) {
      const fs::path p = fs::path(j.get<std::string>()).is_absolute() ? fs::path(j.get<std::string>()) : scenario.base_dir / j.get<std::string>();
      std::error_code ec;
      if (fs::is_regular_file(p, ec)) inputs.push_back(p.string());  // inputs are files; "grass" may name a folder
    }
  };
  walk(scenario.resolved);
  inputs.push_back(scenario.path("dem"));
  return inputs;
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
  const std::vector<Action> plan = plan_stages(options);
  const std::string dem_path = scenario.path("dem");
  const ReadOptions read = read_options(scenario.resolved["input"]["band"].get<int>(), scenario.resolved["input"]["assume_crs"].get<std::string>());
  // Before creating anything, so that bad input leaves no folder: the whole DEM, or its grid when
  // the stages read it by windows (docs/scale.md).
  const TileSettings tiles = [&] {
    try {
      return tile_settings(scenario);
    } catch (const Error& e) {
      throw Error(e.kind(), scenario.source + ": " + e.what());
    }
  }();
  Dem dem;
  RasterHeader grid;
  if (tiles.given()) {
    const DemWindowReader reader(dem_path, read);
    reader.check_cells();  // one pass of reads: a bad file is refused before any stage, as read_dem would
    grid = reader.header();
  } else {
    dem = read_dem(dem_path, read);
    grid = grid_of(dem);
  }
  const std::size_t last = options.until.empty() ? stages().size() - 1 : stage_index("--until", options.until);
  // Every stage's settings and checks before the first stage runs, and before anything is created.
  StageSettings settings;
  for (const StageDef& stage : stages()) {
    try {
      stage.prepare(scenario, grid, settings);
    } catch (const Error& e) {
      throw Error(e.kind(), scenario.source + ": " + e.what());
    }
  }
  const bool rerun = std::any_of(plan.begin(), plan.end(), [](Action a) { return a != Action::run; });
  json saved;
  if (rerun) saved = load_manifest(output.string());
  // A rerun may stop where its saved run stopped (a run by tiles, made --until network), never
  // before a stage it made: that stage's files would stay without their entry in run.json.
  for (std::size_t i = last + 1; rerun && i < stages().size(); ++i)
    if (saved["summary"].contains(stages()[i].name))
      throw bad_input(std::string("--until: the run made the ") + stages()[i].name + " stage: a rerun goes on to its last stage");
  // A rerun replaces its own run folder; the new run is built beside it and swapped in at the end.
  OutputSet run_folder("run", scenario_inputs(scenario), options.overwrite || rerun);
  const fs::path temp = run_folder.folder(output.string(), rerun);
  const std::string dem_sha256 = input_sha256(dem_path);
  plugin::PluginSet plugins = plugin::load_plugins(nlohmann::json::parse(scenario.resolved["plugins"].dump()), log,
                                                   scenario.base_dir.string());
  const json files = input_files(scenario);
  if (rerun) check_reusable(output, saved, scenario, dem_sha256, files, plan);
  {
    RunState state(scenario, temp, dem_sha256, std::move(dem), grid);
    if (tiles.given()) state.by_tiles = TiledInput{dem_path, read, tiles, 0};
    state.plugins = std::move(plugins);
    state.settings = std::move(settings);
    json timings = json::array();
    json ran = json::array(), reused = json::array(), stale = json::array();
    for (std::size_t i = 0; i <= last; ++i) {
      const StageDef& stage = stages()[i];
      const Log stage_log = log.stage(stage.name);
      if (plan[i] == Action::keep && !saved["summary"].contains(stage.name)) continue;  // never made
      if (plan[i] != Action::run) {
        // A saved stage: its files, figures and timing come from the saved run.
        reuse_saved(state, saved, stage.name, timings);
        if (plan[i] == Action::load) stage.load(state);
        if (plan[i] == Action::load) reused.push_back(stage.name);
        if (!ran.empty()) stale.push_back(stage.name);  // made before a stage upstream of it was rerun
        continue;
      }
      const auto start = std::chrono::steady_clock::now();
      stage.run(state, progress, stage_log);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      timings.push_back({{"stage", stage.name}, {"seconds", seconds}, {"peak_memory_mb", peak_resident_mb()}});
      ran.push_back(stage.name);
      stage_log.detail("done in " + std::to_string(seconds) + " s");
    }

    json manifest;
    manifest["terrapolis"] = terrapolis::version;
    manifest["scenario"] = scenario.resolved;
    manifest["scenario_source"] = scenario.source;
    manifest["input"] = {{"dem", dem_path}, {"sha256", state.dem_sha256}, {"bytes", input_bytes(dem_path)},
                         {"crs", state.grid.georef.crs.name},
                         {"epsg", state.grid.georef.crs.epsg ? json(*state.grid.georef.crs.epsg) : json(nullptr)}, {"files", files}};
    json libs = json::object();
    for (const auto& [name, version] : io_library_versions()) libs[name] = version;
    manifest["libraries"] = libs;
    json outputs = json::array();
    for (const auto& o : state.outputs) {
      json entry = {{"file", o.name}, {"stage", o.stage}, {"description", o.description}, {"kind", o.raster ? "raster" : "vector"},
                    {"style", style_name(o.style)}};
      if (!o.raster) entry["features"] = o.features;
      outputs.push_back(entry);
    }
    manifest["outputs"] = outputs;
    manifest["summary"] = state.summary;
    manifest["timings"] = timings;
    if (rerun) manifest["rerun"] = {{"ran", ran}, {"reused", reused}, {"stale", stale}};
    publish(state, manifest, log.stage("publish"));
    write_text_file((temp / "run.json").string(), manifest.dump(2) + "\n", true);
    run_folder.commit();
    return manifest;
  }
}

std::string format_summary(const json& manifest) {
  SummaryText out;
  const json& figures = manifest["summary"];
  out.line("Run of %s (seed %llu)\n", manifest["input"]["dem"].get<std::string>().c_str(),
           static_cast<unsigned long long>(manifest["scenario"]["seed"].get<std::uint64_t>()));
  for (const StageDef& stage : stages())
    if (figures.contains(stage.name)) stage.summary(figures, out);
  out.text += "  timings ";
  for (const auto& t : manifest["timings"])
    out.line(" %s %.2f s%s", t["stage"].get<std::string>().c_str(), t["seconds"].get<double>(), t.value("reused", false) ? " (saved)" : "");
  out.text += "\n";
  return out.text;
}

}  // namespace terrapolis::pipeline
