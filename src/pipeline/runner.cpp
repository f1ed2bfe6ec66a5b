// The scenario runner: stage list, run folder, run.json.
// SPDX-License-Identifier: MIT
#include "pipeline/runner.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>

#include "core/error.hpp"
#include "io/checksum.hpp"
#include "io/output_set.hpp"
#include "io/text_io.hpp"
#include "io/raster_io.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/places.hpp"
#include "core/geodesy.hpp"
#include "density/tiled_density.hpp"
#include "pipeline/publish.hpp"
#include "pipeline/run_state.hpp"
#include "pipeline/stage_options.hpp"
#include "pipeline/stages.hpp"
#include "roads/existing_roads.hpp"
#include "terrapolis/version.hpp"

namespace terrapolis::pipeline {
namespace {

using json = nlohmann::ordered_json;

long peak_rss_kb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}


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
      if (!saved["scenario"].contains(key) || saved["scenario"][key] != scenario.resolved[key])
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
    if (!file.raster) state.vectors.emplace_back(file.style, read_vector((state.folder / file.name).string(), state.dem.georef().crs));
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
  StageSettings settings = prepare_stages(scenario);  // every stage's settings and files, before anything is created
  const bool rerun = std::any_of(plan.begin(), plan.end(), [](Action a) { return a != Action::run; });
  json saved;
  if (rerun) saved = load_manifest(output.string());
  // A rerun replaces its own run folder; the new run is built beside it and swapped in at the end.
  OutputSet run_folder("run", scenario_inputs(scenario), options.overwrite || rerun);
  const fs::path temp = run_folder.folder(output.string(), rerun);

  const std::string dem_path = scenario.path("dem");
  const ReadOptions read = read_options(scenario.resolved["input"]["band"].get<int>(), scenario.resolved["input"]["assume_crs"].get<std::string>());
  Dem dem = read_dem(dem_path, read);  // before creating anything: bad input leaves no folder
  if (const std::string existing = scenario.path("/sites/existing"); !existing.empty()) {
    try {  // its format and figures now, before any stage (whether each place finds land needs the density)
      check_existing_places(existing, dem.georef().crs);
    } catch (const Error& e) {
      throw Error(e.kind(), scenario.source + ": /sites/existing: " + e.what());
    }
  }
  if (const std::string& lines = settings.roads.existing; !lines.empty()) {
    try {  // its CRS and geometry now, before any stage (which roads lie on the DEM needs its grid)
      roads::check_existing_roads(lines, dem.georef().crs);
    } catch (const Error& e) {
      throw Error(e.kind(), scenario.source + ": /roads/existing: " + e.what());
    }
  }
  try {  // r_max against r_min raised to this grid's cells, before the hydrology runs
    density::raised_r_min(cell_metrics(dem.georef(), dem.cols(), dem.rows()), settings.density);
  } catch (const Error& e) {
    throw Error(e.kind(), scenario.source + ": " + e.what());
  }
  const std::string dem_sha256 = file_sha256(dem_path);
  plugin::PluginSet plugins = plugin::load_plugins(nlohmann::json::parse(scenario.resolved["plugins"].dump()), log,
                                                   scenario.base_dir.string());
  const json files = input_files(scenario);
  if (rerun) check_reusable(output, saved, scenario, dem_sha256, files, plan);
  {
    RunState state(scenario, temp, dem_sha256, std::move(dem));
    state.plugins = std::move(plugins);
    state.settings = std::move(settings);
    json timings = json::array();
    json ran = json::array(), reused = json::array(), stale = json::array();
    const std::size_t last = options.until.empty() ? stages().size() - 1 : stage_index("--until", options.until);
    if (rerun && last + 1 < stages().size()) throw bad_input("--until: only for a new run (not with --from or --only)");
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
      timings.push_back({{"stage", stage.name}, {"seconds", seconds}, {"peak_memory_mb", double(peak_rss_kb()) / 1024.0}});
      ran.push_back(stage.name);
      stage_log.detail("done in " + std::to_string(seconds) + " s");
    }

    json manifest;
    manifest["terrapolis"] = terrapolis::version;
    manifest["scenario"] = scenario.resolved;
    manifest["scenario_source"] = scenario.source;
    manifest["input"] = {{"dem", dem_path}, {"sha256", state.dem_sha256}, {"bytes", fs::file_size(dem_path)},
                         {"crs", state.dem.georef().crs.name},
                         {"epsg", state.dem.georef().crs.epsg ? json(*state.dem.georef().crs.epsg) : json(nullptr)}, {"files", files}};
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
  std::string out;
  auto line = [&out](const char* format, auto... values) {
    char buf[256];
    std::snprintf(buf, sizeof(buf), format, values...);
    out += buf;
  };
  const json& sum = manifest["summary"];
  line("Run of %s (seed %llu)\n", manifest["input"]["dem"].get<std::string>().c_str(),
       static_cast<unsigned long long>(manifest["scenario"]["seed"].get<std::uint64_t>()));
  if (sum.contains("terrain")) {
    const json& t = sum["terrain"];
    line("  terrain  %d x %d cells, %.0f .. %.0f m, %.1f%% nodata\n", t["cols"].get<int>(), t["rows"].get<int>(), t["min_m"].get<double>(),
         t["max_m"].get<double>(), 100 * t["nodata_share"].get<double>());
  }
  if (sum.contains("hydro")) {
    const json& h = sum["hydro"];
    line("  hydro    %d stream reaches, %.1f km, Strahler up to %d, largest catchment %.1f km2\n", h["stream_reaches"].get<int>(),
         h["stream_length_km"].get<double>(), h["max_strahler"].get<int>(), h["largest_catchment_km2"].get<double>());
  }
  if (sum.contains("density")) {
    const json& d = sum["density"];
    line("  density  %.1f%% water, %.1f%% of the land buildable, mean density %.3f\n", 100 * d["water_share"].get<double>(),
         100 * d["buildable_land_share"].get<double>(), d["mean_density"].get<double>());
  }
  if (sum.contains("sites")) {
    const json& c = sum["sites"];
    line("  sites    %d cities (%d roots, %d suburbs), %.0f people\n", c["cities"].get<int>(), c["roots"].get<int>(),
         c["suburbs"].get<int>(), c["population"].get<double>());
    if (c.contains("population_source"))
      line("           %.0f people in the region, %s; largest %.0f\n", c["target_population"].get<double>(),
           c["population_source"].get<std::string>().c_str(), c["largest"].get<double>());
    if (c.contains("growth"))
      line("           %.0f of them in the settlements (the existing places grown by %g%%), the new ones split by a rank-size law of exponent %.2f\n",
           c["settled_population"].get<double>(), 100 * c["growth"]["share"].get<double>(), c["sizes_exponent"].get<double>());
    else if (c.contains("settled_population"))
      line("           %.0f of them in the settlements (sites.urban_share %g), split by a rank-size law of exponent %.2f (%s)\n",
           c["settled_population"].get<double>(), c["urban_share"].get<double>(), c["sizes_exponent"].get<double>(),
           c["sizes"] == "catchment" ? "read from the catchments" : "sites.zipf_exponent");
    if (c.value("count_limited_by_spacing", false))
      line("           count held to the %lld settlements the land holds at sites.spacing_km (closer where denser than an urban centre)\n",
           c["room"].get<long long>());
    if (c.value("crowded", 0) > 0)
      line("           %d placed without a disc clear of water and steep land (their built-up area reaches over it)\n", c["crowded"].get<int>());
    if (c.contains("growth")) {
      const json& g = c["growth"];
      line("           growth +%g%%: %lld new settled people, %lld to the existing places, %lld in %d new settlements\n",
           100 * g["share"].get<double>(), g["people"].get<long long>(), g["to_existing"].get<long long>(),
           g["to_new_settlements"].get<long long>(), g["new_settlements"].get<int>());
      int shown = 0;
      for (const auto& [name, gain] : g["gained"].items())
        if (shown++ < 3) line("             %s +%lld\n", name.c_str(), gain.get<long long>());
      for (const auto& [rank, n] : g["new_largest"].items())
        if (n.contains("near"))
          line("             new settlement of %lld people %.1f km from %s\n", n["people"].get<long long>(), n["near_km"].get<double>(),
               n["near"].get<std::string>().c_str());
    }
    for (const auto& [k, v] : c["per_class"].items())
      line("           class %s (radius %.0f m): %d\n", k.c_str(), v["radius_m"].get<double>(), v["cities"].get<int>());
    if (c.contains("warnings"))
      for (const auto& w : c["warnings"]) line("           warning: %.200s\n", w.get<std::string>().c_str());
  }
  if (sum.contains("realism")) {
    const json& r = sum["realism"];
    line("  realism  against %zu real places: %d settlements of min_population or more for %d, %.0f people for %.0f, largest %.0f for %.0f\n",
         r["places"].get<std::size_t>(), r["count"]["generated"].get<int>(), r["count"]["reference"].get<int>(),
         r["total"]["generated"].get<double>(), r["total"]["reference"].get<double>(), r["largest"]["generated"].get<double>(),
         r["largest"]["reference"].get<double>());
    if (r.contains("skill")) {
      const json& k = r["skill"];
      line("           density AUC %.3f (population-weighted %.3f); baselines:", k["auc"].get<double>(), k["weighted_auc"].get<double>());
      for (const auto& [name, b] : k["baselines"].items()) line(" %s %.3f", name.c_str(), b["auc"].get<double>());
      line("\n           ten largest real places with a top-10 settlement within 10 km: %d (random land points: %.1f)\n",
           r["top10"]["within_10km"].get<int>(), r["top10"]["random_within_10km"].get<double>());
    }
  }
  if (sum.contains("network")) {
    const json& n = sum["network"];
    line("  network  %d of %d candidate links kept, %.1f km\n", n["kept_edges"].get<int>(), n["candidate_edges"].get<int>(),
         n["kept_length_km"].get<double>());
  }
  if (sum.contains("roads")) {
    const json& r = sum["roads"];
    line("  roads    %d roads (%d not routable, %d redundant), bridges %.0f m, tunnels %.0f m\n", r["roads"].get<int>(),
         r["failed"].get<int>(), r.value("redundant", 0), r["bridge_m"].get<double>(), r["tunnel_m"].get<double>());
    if (r.contains("network_km"))
      line("           network %.1f km drawn once, %d sections, %d junctions\n", r["network_km"].get<double>(), r.value("sections", 0),
           r.value("junctions", 0));
    if (r.contains("existing")) {
      const json& e = r["existing"];
      line("           existing roads %.1f km given (%d lines, %d outside the DEM); the new links run %.1f km on them, %.1f km new\n",
           e["total_km"].get<double>(), e["lines"].get<int>(), e["outside_dem"].get<int>(), r["on_existing_km"].get<double>(),
           r["new_network_km"].get<double>());
      line("           %-13s %9s %9s %9s   (links; new, drawn once; existing given)\n", "", "links", "new", "existing");
      for (const auto& [cls, km] : r["length_km"].items())
        line("           %-13s %9.1f %9.1f %9.1f km\n", cls.c_str(), km.get<double>(), r["new_km"].value(cls, 0.0), e["km"].value(cls, 0.0));
    } else {
      for (const auto& [cls, km] : r["length_km"].items()) line("           %-13s %9.1f km\n", cls.c_str(), km.get<double>());
    }
  }
  if (sum.contains("access")) {
    const json& a = sum["access"];
    line("  access   of %.0f people, within reach of\n", a["people"].get<double>());
    for (const auto& [level, v] : a["levels"].items()) {
      const std::string whom = level == "all" ? "any settlement" : "settlements of " + level + "+";
      line("           %-22s (%3d)", whom.c_str(), v["destinations"].get<int>());
      for (const auto& [minutes, share] : v["share_within"].items())
        line(" %5.1f%% in %s", 100 * share.get<double>(), minutes.substr(0, minutes.find('_')).c_str());
      line(" min; mean %.1f min, p90 %.1f min\n", v["mean_minutes"].get<double>(), v["p90_minutes"].get<double>());
    }
  }
  out += "  timings ";
  for (const auto& t : manifest["timings"])
    line(" %s %.2f s%s", t["stage"].get<std::string>().c_str(), t["seconds"].get<double>(), t.value("reused", false) ? " (saved)" : "");
  out += "\n";
  return out;
}

}  // namespace terrapolis::pipeline
