// What each output file is: the one description that its raster band, the run's manifest (run.json,
// the QGIS project) and a command writing the same file all carry.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include "pipeline/scenario.hpp"

namespace terrapolis::pipeline {

/// The parts of a description that settings decide.
struct DescriptionTerms {
  std::string fill, flow, hydrometry;  ///< hydro: the schema's names of hydro.fill, hydro.flow, hydro.hydrometry
  std::string d8_codes;                ///< hydro: hydro::describe of the D8 code convention
  std::string accumulation_unit = "km2";  ///< "km2", "m2" or "cells"
  bool weighted = false;                  ///< accumulation of per-cell weights
  double lake_level_m = 0;                ///< lake: the water surface (m)
};

/// The terms a scenario's hydro section decides (the run's and every command's that reads it).
DescriptionTerms description_terms(const Scenario& scenario);

/// The description of `file` (its name in a run folder or a command's output folder, as
/// "accumulation.tif"); throws std::out_of_range for a file it does not know (a programming error).
std::string describe_output(const std::string& file, const DescriptionTerms& terms = {});

}  // namespace terrapolis::pipeline
