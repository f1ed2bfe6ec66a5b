// The boosted density model: its margins against a walk of its own trees, its bounds, the model
// file's round trip and refusals, the same trees from the same data, and the density it gives.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <random>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "density/boosted.hpp"
#include "density/calibration.hpp"
#include "density/density.hpp"
#include "support/georefs.hpp"

namespace terrapolis::density {
namespace {

/// Presences where the first term is above 0.6 and the second below 0.5, against uniform background.
struct Synthetic {
  std::vector<float> rows, labels, weights;
};
Synthetic synthetic(int n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<float> u(0, 1);
  Synthetic s;
  for (int k = 0; k < n; ++k) {
    const float a = u(g), b = u(g);
    const bool presence = a > 0.6f && b < 0.5f && u(g) < 0.8f;
    s.rows.insert(s.rows.end(), {a, b});
    s.labels.push_back(presence ? 1.0f : 0.0f);
    s.weights.push_back(presence ? 3.0f : 1.0f);
  }
  return s;
}

BoostedModel::Parameters small() {
  BoostedModel::Parameters p;
  p.rounds = 30;
  p.max_depth = 2;
  p.min_child_weight = 1;  // leaves of a few rows: the samples here are small
  return p;
}

/// The margin of one row by walking the trees of the model file (XGBoost's JSON) by hand.
double walk(const nlohmann::json& file, const float* row) {
  const nlohmann::json& learner = file["xgboost"]["learner"];
  const double base = std::stod(learner["learner_model_param"]["base_score"].get<std::string>());
  double margin = std::log(base / (1 - base));
  for (const auto& tree : learner["gradient_booster"]["model"]["trees"]) {
    int node = 0;
    while (tree["left_children"][node].get<int>() != -1) {
      const float v = row[tree["split_indices"][node].get<int>()];
      const bool left = std::isnan(v) ? tree["default_left"][node].get<int>() != 0 : v < tree["split_conditions"][node].get<float>();
      node = left ? tree["left_children"][node].get<int>() : tree["right_children"][node].get<int>();
    }
    margin += tree["split_conditions"][node].get<double>();
  }
  return margin;
}

TEST(Boosted, MarginsAreTheTreesWalkedByHandWithinTheirBounds) {
  const Synthetic s = synthetic(4000, 1);
  const BoostedModel m = BoostedModel::fit({"coast", "slope"}, s.rows, s.labels, s.weights, small());
  const nlohmann::json file = nlohmann::json::parse(m.save_text());
  const std::vector<float> margins = m.margins(s.rows);
  ASSERT_EQ(margins.size(), s.labels.size());
  for (std::size_t k = 0; k < 200; ++k) EXPECT_NEAR(margins[k], walk(file, &s.rows[2 * k]), 1e-4) << k;
  for (float v : margins) {
    EXPECT_GE(v, m.lower_bound() - 1e-4);
    EXPECT_LE(v, m.upper_bound() + 1e-4);
    EXPECT_GE(m.unit(v), -1e-6);
    EXPECT_LE(m.unit(v), 1 + 1e-6);
  }
  // The trees learnt the rule: the presence corner scores above the rest.
  const std::vector<float> corner = m.margins({0.8f, 0.2f, 0.2f, 0.8f});
  EXPECT_GT(corner[0], corner[1] + 1.0);
}

TEST(Boosted, TheModelFileRoundTripsAndTheSameDataGiveTheSameTrees) {
  const Synthetic s = synthetic(3000, 2);
  const BoostedModel a = BoostedModel::fit({"coast", "slope"}, s.rows, s.labels, s.weights, small());
  const BoostedModel b = BoostedModel::fit({"coast", "slope"}, s.rows, s.labels, s.weights, small());
  EXPECT_EQ(a.save_text(), b.save_text());
  const std::string path = ::testing::TempDir() + "boosted_roundtrip.json";
  std::ofstream(path) << a.save_text();
  const BoostedModel c = BoostedModel::load(path);
  EXPECT_EQ(c.terms(), (std::vector<std::string>{"coast", "slope"}));
  EXPECT_EQ(c.margins(s.rows), a.margins(s.rows));
  EXPECT_EQ(c.lower_bound(), a.lower_bound());
  EXPECT_EQ(c.upper_bound(), a.upper_bound());
  std::remove(path.c_str());
}

TEST(Boosted, AnythingButAModelFileIsRefusedByName) {
  const std::string path = ::testing::TempDir() + "not_a_model.json";
  std::ofstream(path) << R"({"density": {"weights": {}}})";
  try {
    BoostedModel::load(path);
    FAIL() << "loaded";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find(path + ": not a boosted density model"), std::string::npos) << e.what();
  }
  EXPECT_THROW(BoostedModel::load(path + ".missing"), Error);
  std::remove(path.c_str());
}

TEST(Boosted, ItsDensityStandsInForTheWeightedSum) {
  // A hill: the trees, fitted to prefer low ground, give the foot a higher density than the top.
  Dem dem(60, 60, test::projected(100.0), 0.0f);
  for (int r = 0; r < 60; ++r)
    for (int c = 0; c < 60; ++c) dem(c, r) = float(50 + 1500 * std::exp(-(std::pow(c - 30, 2) + std::pow(r - 30, 2)) / 200.0));
  std::vector<float> rows, labels, weights;
  for (int k = 0; k <= 100; ++k) {  // altitude rank 0..1: presences below 0.3
    rows.push_back(float(k) / 100);
    labels.push_back(k < 30 ? 1.0f : 0.0f);
    weights.push_back(1.0f);
  }
  DensityOptions o;
  o.model = std::make_shared<const BoostedModel>(BoostedModel::fit({"altitude"}, rows, labels, weights, small()));
  o.weights = {0, 0, 0, 0};  // not read with a model: no "every weight is 0"
  SilentProgress p;
  const DensityResult r = compute_density(dem, dem.like<float>(0.0f), o, p);
  EXPECT_GT(r.density(2, 2), r.density(30, 30) + 0.3f);
  for (std::size_t i = 0; i < dem.size(); ++i) {
    EXPECT_GE(r.density[i], 0.0f);
    EXPECT_LE(r.density[i], 1.0f);
  }
  // A model over a term the density does not know is refused by the setting's name.
  o.model = std::make_shared<const BoostedModel>(BoostedModel::fit({"nightlights"}, rows, labels, weights, small()));
  try {
    compute_density(dem, dem.like<float>(0.0f), o, p);
    FAIL() << "computed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/density/model: unknown term 'nightlights'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace terrapolis::density
