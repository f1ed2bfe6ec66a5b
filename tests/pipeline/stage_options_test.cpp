// The schema's defaults are the code's defaults: a scenario with nothing set runs each stage as its command does.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>

#include "hydro/option_names.hpp"
#include "pipeline/stage_options.hpp"

using namespace terrapolis;
using namespace terrapolis::pipeline;

TEST(StageOptions, HydroDefaultsEqualTheCode) {
  const hydro::HydroOptions s = hydro_options(load_scenario("")), c;
  EXPECT_EQ(s.fill, c.fill);
  EXPECT_EQ(s.flow, c.flow);
  EXPECT_EQ(s.mfd_exponent, c.mfd_exponent);
  EXPECT_EQ(s.unit, c.unit);
  EXPECT_EQ(s.hydrometry.method, c.hydrometry.method);
  EXPECT_EQ(s.hydrometry.max_iterations, c.hydrometry.max_iterations);
  EXPECT_EQ(s.hydrometry.threshold, c.hydrometry.threshold);
  EXPECT_EQ(s.hydrometry.vertical, c.hydrometry.vertical);
  EXPECT_EQ(s.hydrometry.share, c.hydrometry.share);
  EXPECT_EQ(s.streams.threshold_km2, c.streams.threshold_km2);
  EXPECT_EQ(d8_codes(load_scenario("")), hydro::D8Codes::esri);  // the command's default convention
  // The run's one deliberate difference: the sea (default 0 m) drains the land.
  ASSERT_TRUE(s.sea_level.has_value());
  EXPECT_EQ(*s.sea_level, 0.0);
}

TEST(StageOptions, DensityDefaultsEqualTheCode) {
  const density::DensityOptions s = density_options(load_scenario("")), c;
  EXPECT_EQ(s.sea_level_m, c.sea_level_m);
  EXPECT_EQ(s.nodata_is_sea, c.nodata_is_sea);
  EXPECT_EQ(s.water_mask.size(), c.water_mask.size());
  EXPECT_EQ(s.max_altitude_m, c.max_altitude_m);
  EXPECT_EQ(s.max_slope_deg, c.max_slope_deg);
  EXPECT_EQ(s.river_bed_cap, c.river_bed_cap);
  EXPECT_EQ(s.r_min_m, c.r_min_m);
  EXPECT_EQ(s.r_max_m, c.r_max_m);
  EXPECT_EQ(s.ring_bands, c.ring_bands);
  EXPECT_EQ(s.plateau_min_m, c.plateau_min_m);
  EXPECT_EQ(s.plateau_max_m, c.plateau_max_m);
  EXPECT_EQ(s.plain_max_variation_m, c.plain_max_variation_m);
  // The code's weights are the thesis's: the scenario's belhadj2007 preset; its default is the fitted set.
  const density::DensityOptions t = density_options(load_scenario("", {"density.preset=\"belhadj2007\""}));
  EXPECT_EQ(t.weights, c.weights);
  EXPECT_EQ(t.terrain_weights, c.terrain_weights);
  EXPECT_NE(s.terrain_weights, c.terrain_weights);
  // A weight set by hand wins over the preset.
  EXPECT_EQ(density_options(load_scenario("", {"density.preset=\"belhadj2007\"", "density.weights.plain=2"})).weights[3], 2.0);
  EXPECT_EQ(s.factors.size(), c.factors.size());
  EXPECT_EQ(s.exclusion_masks.size(), c.exclusion_masks.size());
}

TEST(StageOptions, SitesAndNetworkDefaultsEqualTheCode) {
  const sites::SitesOptions s = sites_options(load_scenario("")), c;
  EXPECT_EQ(s.seed, c.seed);
  EXPECT_EQ(s.candidates, c.candidates);
  EXPECT_EQ(s.r_min_m, c.r_min_m);
  EXPECT_EQ(s.r_max_m, c.r_max_m);
  EXPECT_EQ(s.dr_min_m, c.dr_min_m);
  EXPECT_EQ(s.u_min, c.u_min);
  EXPECT_EQ(s.u_max, c.u_max);
  EXPECT_EQ(s.x_max, c.x_max);
  EXPECT_EQ(s.p, c.p);
  EXPECT_EQ(s.people_per_m, c.people_per_m);
  EXPECT_EQ(s.quota_scale, c.quota_scale);
  EXPECT_EQ(s.mode, c.mode);
  EXPECT_EQ(s.disc_test, c.disc_test);
  EXPECT_EQ(s.refill_rounds, c.refill_rounds);
  EXPECT_EQ(s.influence_factor, c.influence_factor);
  EXPECT_EQ(network_options(load_scenario("")).k, network::NetworkOptions{}.k);
}

TEST(StageOptions, RoadsDefaultsEqualTheCode) {
  const RoadsSettings s = roads_settings(load_scenario(""));
  const roads::RoutingOptions c;
  EXPECT_EQ(s.routing.router, c.router);
  EXPECT_EQ(s.routing.graph.k, c.graph.k);
  EXPECT_EQ(s.routing.graph.angles, c.graph.angles);
  EXPECT_EQ(s.routing.graph.seed, c.graph.seed);
  EXPECT_EQ(s.routing.search, c.search);
  EXPECT_EQ(s.routing.bezier.max_evaluations, c.bezier.max_evaluations);
  EXPECT_EQ(s.routing.bezier.threshold, c.bezier.threshold);
  EXPECT_EQ(s.routing.bezier.tries, c.bezier.tries);
  EXPECT_EQ(s.routing.bezier.seed, c.bezier.seed);
  EXPECT_EQ(roads::cost_model_json(s.model), roads::cost_model_json(roads::default_cost_model()));
  EXPECT_EQ(s.vegetation, "");
}

TEST(StageOptions, ScenarioValuesReachTheStages) {
  const Scenario sc = load_scenario("", {"seed=7", "water.sea_level_m=-3", "hydro.flow=\"mfd\"", "density.weights.plain=-0.5",
                                         "density.max_slope_deg=30", "sites.mode=\"manhattan\"", "network.k=2.5",
                                         "roads.bridges=false", "roads.router=\"bezier\""});
  EXPECT_EQ(hydro_options(sc).flow, hydro::FlowMethod::mfd);
  EXPECT_EQ(*hydro_options(sc).sea_level, -3.0);
  const density::DensityOptions d = density_options(sc);
  EXPECT_EQ(d.sea_level_m, -3.0);
  EXPECT_EQ(d.weights[3], -0.5);
  EXPECT_EQ(d.max_slope_deg, 30.0);
  EXPECT_EQ(sites_options(sc).seed, 7u);
  EXPECT_EQ(sites_options(sc).mode, sites::SitesOptions::Mode::manhattan);
  EXPECT_EQ(network_options(sc).k, 2.5);
  const RoadsSettings r = roads_settings(sc);
  EXPECT_FALSE(r.model.bridge.enabled);
  EXPECT_TRUE(r.model.tunnel.enabled);
  EXPECT_EQ(r.routing.router, roads::Router::bezier);
  EXPECT_EQ(r.routing.graph.seed, 7u);
}

// The schema offers exactly the names the hydrology module knows (the command line checks the same tables).
TEST(StageOptions, HydroSchemaChoicesAreTheModuleNames) {
  const auto schema = nlohmann::json::parse(scenario_schema_text())["properties"]["hydro"]["properties"];
  auto names = [&](const char* field) { return schema[field]["enum"].get<std::vector<std::string>>(); };
  auto keys = [](const auto& table) {
    std::vector<std::string> k;
    for (const auto& [name, value] : table) k.push_back(name);
    return k;
  };
  auto sorted = [](std::vector<std::string> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  EXPECT_EQ(sorted(names("fill")), keys(hydro::kFillMethods));
  EXPECT_EQ(sorted(names("flow")), keys(hydro::kFlowMethods));
  EXPECT_EQ(sorted(names("d8_codes")), keys(hydro::kD8Codes));
  EXPECT_EQ(sorted(names("hydrometry")), keys(hydro::kHydrometryMethods));
  EXPECT_EQ(sorted(names("vertical")), keys(hydro::kVerticalScales));
  EXPECT_EQ(sorted(names("belhadj_share")), keys(hydro::kBelhadjShares));
}
