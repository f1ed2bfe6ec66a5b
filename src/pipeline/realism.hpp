// How a run's settlements compare with real ones, and the warnings a planner would want.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "density/density.hpp"
#include "pipeline/run_state.hpp"
#include "sites/sites.hpp"

namespace terrapolis::pipeline {

/// Warnings on the placed settlements: a centre on a flat surface (9 x 9 cells of one altitude,
/// a lake in SRTM), on nodata, and a population implausibly dense for the land area.
std::vector<std::string> settlement_warnings(const RunState& state, const sites::SitesResult& result);

/// The run against the real places of `reference` (sites.reference): count and total of
/// settlements of min_population or more, largest, rank-size exponents, the density's skill (AUC,
/// population-weighted AUC) and the single-factor baselines', and how many of the ten largest
/// real places have one of the ten largest generated settlements within 10 km, against the same
/// count for random land points. Appends warnings (skill below a baseline) to `warnings`.
/// `density` is the run's density inputs (the terrain terms are switched on for the baselines).
nlohmann::ordered_json realism_figures(RunState& state, density::DensityOptions density, const sites::SitesResult& result,
                                       const std::string& reference,
                                       std::vector<std::string>& warnings, Progress& progress);

}  // namespace terrapolis::pipeline
