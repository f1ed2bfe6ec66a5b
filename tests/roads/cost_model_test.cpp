// Transfer functions and the JSON cost file.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "roads/cost_model.hpp"

using namespace terrapolis::roads;

TEST(TransferFunction, PiecewiseLinearWithThreshold) {
  const TransferFunction f{{{0, 1}, {10, 3}}, 15};
  EXPECT_DOUBLE_EQ(f(-1), 1);
  EXPECT_DOUBLE_EQ(f(5), 2);
  EXPECT_DOUBLE_EQ(f(12), 3);  // constant beyond the last point
  EXPECT_DOUBLE_EQ(f(15), 3);  // the threshold itself is allowed
  EXPECT_EQ(f(15.01), kInfinity);
  EXPECT_DOUBLE_EQ(f.min_value(), 1);
}

TEST(CostModel, DefaultsFollowThePaper) {
  const CostModel m = default_cost_model();
  EXPECT_EQ(m.road.slope_deg.threshold, 15);
  EXPECT_EQ(m.road.water_depth_m.threshold, 0.5);
  EXPECT_EQ(m.road.curvature_deg.threshold, 170);
  EXPECT_EQ(m.bridge.curvature_deg.threshold, 50);
  EXPECT_EQ(m.tunnel.curvature_deg.threshold, 70);
  EXPECT_EQ(m.bridge.water_depth_m.threshold, 50);
  EXPECT_EQ(m.bridge.height_m.threshold, 150);
  EXPECT_EQ(m.tunnel.depth_m.threshold, 1000);
  EXPECT_DOUBLE_EQ(m.tunnel.depth_m(15), m.tunnel.depth_m(500));  // constant past 15 m
  EXPECT_LT(m.tunnel.depth_m(5), m.tunnel.depth_m(10));           // linear before
  EXPECT_DOUBLE_EQ(m.cheapest_per_metre(), 1.0);
}

TEST(CostModel, JsonOverridesOnlyWhatItNames) {
  const CostModel m = parse_cost_model(R"({"road": {"slope_deg": {"points": [[0, 2], [10, 4]], "threshold": 10}},
                                           "bridge": {"enabled": false, "samples": 7}})", "costs.json");
  EXPECT_EQ(m.road.slope_deg.threshold, 10);
  EXPECT_DOUBLE_EQ(m.road.slope_deg(5), 3);
  EXPECT_FALSE(m.bridge.enabled);
  EXPECT_EQ(m.bridge.samples, 7);
  EXPECT_EQ(m.tunnel.depth_m.threshold, 1000);  // untouched
  // The JSON written back reads to the same model.
  const CostModel again = parse_cost_model(cost_model_json(m), "round-trip");
  EXPECT_EQ(cost_model_json(again), cost_model_json(m));
}

/// The message parse_cost_model throws for `text` (exit code 2), "" when it parses.
std::string refusal(const std::string& text) {
  try {
    parse_cost_model(text, "costs.json");
  } catch (const terrapolis::Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    return e.what();
  }
  return "";
}

TEST(CostModel, BadFilesAreRefusedNamingTheSetting) {
  // Checked against schemas/road_costs.schema.json: the errors name the file and the pointer.
  EXPECT_EQ(refusal(R"({"road": {"slope": {}}})"), "costs.json: /road/slope: unknown key");
  EXPECT_EQ(refusal(R"({"colour": 1})"), "costs.json: /colour: unknown key");
  EXPECT_NE(refusal(R"({"bridge": {"samples": -1}})").find("costs.json: /bridge/samples: "), std::string::npos);
  EXPECT_NE(refusal(R"({"tunnel": {"enabled": "yes"}})").find("costs.json: /tunnel/enabled: "), std::string::npos);
  EXPECT_NE(refusal(R"({"road": {"slope_deg": {"points": [[0, -1]]}}})").find("costs.json: /road/slope_deg/points/0/1: "), std::string::npos);
  EXPECT_EQ(refusal(R"({"road": {"height_m": {}}})"), "costs.json: /road/height_m: unknown key");  // a bridge's term only
  EXPECT_NE(refusal(R"({"sample_step_m": -2})").find("costs.json: /sample_step_m: "), std::string::npos);
  // The rules the schema cannot state.
  EXPECT_EQ(refusal(R"({"road": {"slope_deg": {"points": [[5, 1], [2, 1]]}}})"), "costs.json: /road/slope_deg/points: kappa values must increase");
  EXPECT_EQ(refusal(R"({"bridge": {"min_length_cells": 40}})"), "costs.json: /bridge: a minimum length exceeds its maximum");
  EXPECT_EQ(refusal(R"({"$comment": "mine", "bridge": {"samples": 3}})"), "");
  EXPECT_THROW(parse_cost_model("{not json", "costs.json"), terrapolis::Error);
  EXPECT_THROW(load_cost_model("/nonexistent/costs.json"), terrapolis::Error);
}

TEST(CostModel, TheWrittenModelIsValidAgainstTheSchema) {
  // cost_model_json writes every key: a document the schema accepts, read back to the same model.
  CostModel m = default_cost_model();
  m.bridge.min_length_m = 60;
  m.tunnel.longest_m.reset();
  m.road.slope_deg.threshold = kInfinity;
  const CostModel again = parse_cost_model(cost_model_json(m), "written");
  EXPECT_EQ(cost_model_json(again), cost_model_json(m));
  EXPECT_EQ(again.road.slope_deg.threshold, kInfinity);
  EXPECT_EQ(*again.bridge.min_length_m, 60);
  EXPECT_FALSE(again.tunnel.longest_m);
}

TEST(CostModel, OneTransferFunctionIsCheckedByTheSameDefinition) {
  EXPECT_EQ(parse_transfer_function(R"({"points": [[0, 1], [1, 3]], "threshold": null})", "f")(0.5), 2);
  try {
    parse_transfer_function(R"({"points": [[0, 1]], "cap": 2})", "plugin/road");
    FAIL();
  } catch (const terrapolis::Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("plugin/road: /", 0), 0u) << e.what();
  }
}

TEST(CostModel, DocumentedDefaultsAreTheCodeDefaults) {
  // docs/roads_costs.json is the default cost file shown to users; it must stay what the code uses.
  std::ifstream in(std::string(TERRAPOLIS_SAMPLES) + "/../docs/roads_costs.json");
  ASSERT_TRUE(in.good());
  std::stringstream ss;
  ss << in.rdbuf();
  const CostModel documented = parse_cost_model(ss.str(), "docs/roads_costs.json", CostModel{});
  EXPECT_EQ(cost_model_json(documented), cost_model_json(default_cost_model()));
}

TEST(CostModel, TheDocumentedExampleParses) {
  const CostModel m = parse_cost_model(
      R"({"road": {"slope_deg": {"points": [[0,1],[5,2],[10,6]], "threshold": 10}}, "bridge": {"samples": 250}})", "example");
  EXPECT_EQ(m.bridge.samples, 250);
  EXPECT_DOUBLE_EQ(m.road.slope_deg(7.5), 4);
}
