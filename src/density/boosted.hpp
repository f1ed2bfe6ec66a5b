// A boosted density model: gradient-boosted trees (XGBoost; Chen & Guestrin 2016) over the density
// model's terms, fitted by `terrapolis calibrate --model boosted` on real places.
// SPDX-License-Identifier: MIT
#pragma once
#include <memory>
#include <string>
#include <vector>

namespace terrapolis::density {

/// Trees of a presence/background classifier. The density of a cell is the trees' margin (log-odds)
/// mapped onto [0,1] by its exact bounds, the sums of each tree's smallest and largest leaf, as the
/// weighted sum is by its weights (combine): the same for a region and any crop of it.
class BoostedModel {
 public:
  /// Defaults: the best of eight sizes by the mean leave-one-region-out AUC on the ten shared
  /// regions (bench/density_terms.sh --models; docs/benchmarks.md, "A boosted density model").
  struct Parameters {
    int rounds = 100;              ///< trees
    int max_depth = 2;             ///< splits from root to leaf
    double learning_rate = 0.1;    ///< shrinkage of each tree (XGBoost's eta)
    double lambda = 1;             ///< L2 penalty on the leaf values
    double min_child_weight = 20;  ///< smallest hessian sum of a leaf (weights are scaled to a mean of 1)
  };
  /// Fits on `rows` (row-major, terms.size() values each), labels 1 (presence) or 0 (background),
  /// weights (scaled inside to a mean of 1). One thread: the same data give the same trees.
  static BoostedModel fit(const std::vector<std::string>& terms, const std::vector<float>& rows, const std::vector<float>& labels,
                          const std::vector<float>& weights, const Parameters& parameters);
  /// Reads a model file written by save_text; throws bad_input naming `path` for anything else.
  static BoostedModel load(const std::string& path);
  /// The model file: JSON with the terms, the bounds and XGBoost's own model.
  std::string save_text() const;

  /// The terms the trees read, in column order (names of density::term_names()).
  const std::vector<std::string>& terms() const { return terms_; }
  /// Margins of `rows` (row-major, terms().size() values each; NaN: missing). Any thread count, same values.
  std::vector<float> margins(const std::vector<float>& rows) const;
  /// A margin onto [0,1] by the bounds.
  double unit(double margin) const { return hi_ > lo_ ? (margin - lo_) / (hi_ - lo_) : 0.5; }
  double lower_bound() const { return lo_; }
  double upper_bound() const { return hi_; }

 private:
  struct Handle;
  BoostedModel(std::shared_ptr<Handle> handle, std::vector<std::string> terms);
  void read_bounds();
  std::shared_ptr<Handle> handle_;
  std::vector<std::string> terms_;
  double lo_ = 0, hi_ = 0;
};

}  // namespace terrapolis::density
