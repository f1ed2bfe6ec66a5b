// The stages of a run, in data-flow order: what each checks, reads from the scenario, computes,
// writes and says in the summary.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.hpp"
#include "io/raster_io.hpp"
#include "pipeline/run_state.hpp"

namespace terrapolis::pipeline {

/// The run summary's text, built a line at a time with printf formats.
class SummaryText {
 public:
  template <class... Values>
  void line(const char* format, Values... values) {
    char buf[512];
    std::snprintf(buf, sizeof buf, format, values...);
    text += buf;
  }
  std::string text;
};

/// One stage of a run. Its life (docs/architecture.md): every stage's `prepare` runs before the
/// first stage starts, then each stage's `run` (or `load`, on a rerun that reuses its saved files),
/// which writes its files through RunState::write and its figures into RunState::summary; the
/// summary printed at the end is each stage's `summary` of those figures.
struct StageDef {
  const char* name;
  /// Scenario keys the stage reads (besides those of the stages before it): a saved result of
  /// the stage can be reused only when they are unchanged.
  std::vector<std::string> sections;
  /// Builds the stage's settings into `settings` and makes every check that needs no earlier
  /// stage's result (the settings against each other and the DEM's grid, the files the stage reads).
  /// Throws bad_input naming the setting's JSON pointer ("/sites/u_max: must be >= /sites/u_min").
  void (*prepare)(const Scenario&, const RasterHeader& grid, StageSettings& settings);
  /// Computes the stage from the state and writes its files into state.folder.
  void (*run)(RunState&, Progress&, const Log&);
  /// Reads the stage's typed results back from its saved files in state.folder (reruns).
  void (*load)(RunState&);
  /// The stage's lines of the run summary, from the run's figures (run.json's `summary`, which
  /// holds this stage's entry).
  void (*summary)(const nlohmann::ordered_json& figures, SummaryText&);
};

/// The stages, in data-flow order: the one list the runner, --help and the docs read.
const std::vector<StageDef>& stages();
/// A stage by name (an unknown name is a programming error: std::out_of_range).
const StageDef& stage(const std::string& name);

/// What a run's hydro stage hands its density stage, computed in memory on `dem` with these water
/// and hydro settings: the inland water (the lakes the DEM flattens, the mask, the reservoirs) and,
/// when asked, the hydrometry and the river cells (for river_near).
struct HydroForDensity {
  Raster<std::uint8_t> water;
  Raster<float> hydrometry;                    ///< empty unless asked
  std::optional<Raster<std::uint8_t>> rivers;  ///< none unless asked
};
HydroForDensity hydro_for_density(const Scenario& scenario, const Dem& dem, const InlandWaterSettings& water, hydro::HydroOptions hydro,
                                  bool hydrometry, bool rivers, Progress& progress, const Log& log);

/// The density the hydro and density stages of a run compute on `dem` (the same hydrometry,
/// inland water, rivers and model), in memory: for a command given a DEM where a run has its
/// density stage (`terrapolis sites DEM`). `settings` holds those two stages' prepared settings.
density::DensityResult run_density(const Scenario& scenario, const StageSettings& settings, const Dem& dem, Progress& progress,
                                   const Log& log);
/// The land area of the density (km2) as the run's summary records it and the sites stage reads it.
double land_area_figure(const density::DensityStats& stats);

}  // namespace terrapolis::pipeline
