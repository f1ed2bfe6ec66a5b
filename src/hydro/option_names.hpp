// The names of the hydrology options, as the command line and scenario files spell them.
// SPDX-License-Identifier: MIT
#pragma once
#include <map>
#include <string>

#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/hydrometry.hpp"

namespace terrapolis::hydro {

inline const std::map<std::string, FillMethod> kFillMethods = {
    {"priority-flood", FillMethod::priority_flood}, {"epsilon", FillMethod::epsilon}, {"breach", FillMethod::breach}, {"none", FillMethod::none}};
inline const std::map<std::string, FlowMethod> kFlowMethods = {{"d8", FlowMethod::d8}, {"dinf", FlowMethod::dinf}, {"mfd", FlowMethod::mfd}};
inline const std::map<std::string, D8Codes> kD8Codes = {{"esri", D8Codes::esri}, {"grass", D8Codes::grass}, {"taudem", D8Codes::taudem}};
inline const std::map<std::string, HydrometryMethod> kHydrometryMethods = {{"belhadj", HydrometryMethod::belhadj},
                                                                          {"accumulation", HydrometryMethod::accumulation}};
inline const std::map<std::string, VerticalScale> kVerticalScales = {{"metres", VerticalScale::metres},
                                                                     {"normalised16", VerticalScale::normalised16}};
inline const std::map<std::string, BelhadjShare> kBelhadjShares = {{"all", BelhadjShare::all_neighbours}, {"fed", BelhadjShare::fed_neighbours}};

}  // namespace terrapolis::hydro
