// Each stage's options from a resolved scenario (schemas/scenario.schema.json is the one source of defaults).
// SPDX-License-Identifier: MIT
#pragma once
#include <string>

#include "density/density.hpp"
#include "hydro/hydro.hpp"
#include "network/network.hpp"
#include "pipeline/scenario.hpp"
#include "roads/cost_model.hpp"
#include "hydro/flat_water.hpp"
#include "roads/road_network.hpp"
#include "sites/sites.hpp"

namespace terrapolis::pipeline {

/// The hydro section (sea level from the water section). Weights are not part of a scenario.
hydro::HydroOptions hydro_options(const Scenario& scenario);
/// Code convention of flowdir.tif.
hydro::D8Codes d8_codes(const Scenario& scenario);
/// The density section, with the water section and file names resolved against the scenario.
density::DensityOptions density_options(const Scenario& scenario);
/// The sites section, with the scenario's seed.
sites::SitesOptions sites_options(const Scenario& scenario);
network::NetworkOptions network_options(const Scenario& scenario);

/// The roads section: the cost model (the paper's defaults, a costs file over them, structures
/// switched off), the routing options with the scenario's seed, and the vegetation raster.
struct RoadsSettings {
  roads::CostModel model;
  roads::RoutingOptions routing;
  std::string vegetation;  ///< resolved path, "" for none
  std::string water_mask;  ///< water.water_mask: resolved path, "" for none
  hydro::FlatWaterOptions flat_water;  ///< water.flat_water_*: lakes the DEM flattens
};
RoadsSettings roads_settings(const Scenario& scenario);

}  // namespace terrapolis::pipeline
