// Gradient-boosted trees for the density (XGBoost's C API), and the model file that carries them.
// SPDX-License-Identifier: MIT
#include "density/boosted.hpp"

#include <tbb/global_control.h>
#include <xgboost/c_api.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "density/calibration.hpp"

namespace terrapolis::density {

using json = nlohmann::json;

namespace {

constexpr const char* kFormat = "terrapolis-boosted-density";

void check(int status, const std::string& what) {
  if (status != 0) throw processing_error("xgboost: " + what + ": " + XGBGetLastError());
}

/// A DMatrix over row-major values, freed with it.
struct Matrix {
  DMatrixHandle h = nullptr;
  Matrix(const std::vector<float>& rows, std::size_t columns) {
    const bst_ulong n = columns ? bst_ulong(rows.size() / columns) : 0;
    check(XGDMatrixCreateFromMat(rows.data(), n, bst_ulong(columns), NAN, &h), "matrix");
  }
  ~Matrix() { XGDMatrixFree(h); }
  Matrix(const Matrix&) = delete;
  Matrix& operator=(const Matrix&) = delete;
};

}  // namespace

struct BoostedModel::Handle {
  BoosterHandle h = nullptr;
  Handle() = default;
  ~Handle() { XGBoosterFree(h); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
};

BoostedModel::BoostedModel(std::shared_ptr<Handle> handle, std::vector<std::string> terms) : handle_(std::move(handle)), terms_(std::move(terms)) {
  read_bounds();
}

BoostedModel BoostedModel::fit(const std::vector<std::string>& terms, const std::vector<float>& rows, const std::vector<float>& labels,
                               const std::vector<float>& weights, const Parameters& p) {
  if (terms.empty() || rows.size() != labels.size() * terms.size() || weights.size() != labels.size() || labels.empty())
    throw processing_error("boosted: rows, labels and weights do not match");
  const Matrix data(rows, terms.size());
  check(XGDMatrixSetFloatInfo(data.h, "label", labels.data(), bst_ulong(labels.size())), "labels");
  // Weights to a mean of 1, so min_child_weight means what it says whatever the sample's size.
  const double mean = std::accumulate(weights.begin(), weights.end(), 0.0) / double(weights.size());
  std::vector<float> scaled(weights.size());
  for (std::size_t i = 0; i < weights.size(); ++i) scaled[i] = float(weights[i] / mean);
  check(XGDMatrixSetFloatInfo(data.h, "weight", scaled.data(), bst_ulong(scaled.size())), "weights");
  auto handle = std::make_shared<Handle>();
  check(XGBoosterCreate(&data.h, 1, &handle->h), "booster");
  const std::pair<const char*, std::string> settings[] = {
      {"objective", "binary:logistic"}, {"base_score", "0.5"}, {"tree_method", "hist"}, {"nthread", "1"},  // one thread: the same trees
      {"seed", "0"}, {"verbosity", "0"}, {"max_depth", std::to_string(p.max_depth)},
      {"eta", std::to_string(p.learning_rate)}, {"lambda", std::to_string(p.lambda)}, {"min_child_weight", std::to_string(p.min_child_weight)}};
  for (const auto& [key, value] : settings) check(XGBoosterSetParam(handle->h, key, value.c_str()), key);
  for (int round = 0; round < p.rounds; ++round) check(XGBoosterUpdateOneIter(handle->h, round, data.h), "training");
  return BoostedModel(std::move(handle), terms);
}

BoostedModel BoostedModel::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw bad_input(path + ": cannot read the boosted model");
  std::stringstream text;
  text << in.rdbuf();
  json doc = json::parse(text.str(), nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || doc.value("format", "") != kFormat || !doc.contains("terms") || !doc["terms"].is_array() ||
      !doc.contains("xgboost") || !doc["xgboost"].is_object())
    throw bad_input(path + ": not a boosted density model (written by terrapolis calibrate --model boosted)");
  std::vector<std::string> terms;
  const auto known = term_names();
  for (const auto& t : doc["terms"]) {
    if (!t.is_string()) throw bad_input(path + ": terms: names expected");
    if (std::find_if(known.begin(), known.end(), [&](const char* k) { return t.get<std::string>() == k; }) == known.end())
      throw bad_input(path + ": unknown term '" + t.get<std::string>() + "' (the density's terms: coast, hydrometry, plateau, plain, altitude, ...)");
    terms.push_back(t.get<std::string>());
  }
  const std::string model = doc["xgboost"].dump();
  auto handle = std::make_shared<Handle>();
  check(XGBoosterCreate(nullptr, 0, &handle->h), "booster");
  if (XGBoosterLoadModelFromBuffer(handle->h, model.data(), bst_ulong(model.size())) != 0)
    throw bad_input(path + ": its XGBoost model does not load: " + XGBGetLastError());
  bst_ulong features = 0;
  check(XGBoosterGetNumFeature(handle->h, &features), "features");
  if (features != terms.size())
    throw bad_input(path + ": the trees read " + std::to_string(features) + " terms, the file names " + std::to_string(terms.size()));
  return BoostedModel(std::move(handle), std::move(terms));
}

std::string BoostedModel::save_text() const {
  bst_ulong length = 0;
  const char* buffer = nullptr;
  check(XGBoosterSaveModelToBuffer(handle_->h, R"({"format": "json"})", &length, &buffer), "save");
  json doc = {{"format", kFormat}, {"terms", terms_}, {"margin_bounds", {lo_, hi_}}, {"xgboost", json::parse(std::string(buffer, length))}};
  return doc.dump() + "\n";
}

void BoostedModel::read_bounds() {
  bst_ulong length = 0;
  const char* buffer = nullptr;
  check(XGBoosterSaveModelToBuffer(handle_->h, R"({"format": "json"})", &length, &buffer), "save");
  const json model = json::parse(std::string(buffer, length));
  const json& learner = model.at("learner");
  // binary:logistic keeps its base score as a probability; the margins start at its log-odds.
  const double base = std::stod(learner.at("learner_model_param").at("base_score").get<std::string>());
  lo_ = hi_ = std::log(base / (1 - base));
  for (const json& tree : learner.at("gradient_booster").at("model").at("trees")) {
    const auto& left = tree.at("left_children");
    const auto& value = tree.at("split_conditions");  // a leaf's value where it has no children
    double tree_lo = INFINITY, tree_hi = -INFINITY;
    for (std::size_t i = 0; i < left.size(); ++i)
      if (left[i].get<int>() == -1) tree_lo = std::min(tree_lo, value[i].get<double>()), tree_hi = std::max(tree_hi, value[i].get<double>());
    if (std::isfinite(tree_lo)) lo_ += tree_lo, hi_ += tree_hi;
  }
}

std::vector<float> BoostedModel::margins(const std::vector<float>& rows) const {
  if (rows.empty()) return {};
  const Matrix data(rows, terms_.size());
  // As many threads as the run allows (--threads); the margins do not depend on it.
  const std::size_t threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  check(XGBoosterSetParam(handle_->h, "nthread", std::to_string(threads).c_str()), "threads");
  const char* config = R"({"type": 1, "training": false, "iteration_begin": 0, "iteration_end": 0, "strict_shape": false})";
  const bst_ulong* shape = nullptr;
  bst_ulong dims = 0;
  const float* result = nullptr;
  check(XGBoosterPredictFromDMatrix(handle_->h, data.h, config, &shape, &dims, &result), "prediction");
  return std::vector<float>(result, result + rows.size() / terms_.size());
}

}  // namespace terrapolis::density
