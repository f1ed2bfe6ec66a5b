// Real settlements against the density model: presence/background fits, skill (AUC).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/raster.hpp"
#include "density/density.hpp"

namespace terrapolis::density {

/// A real settlement on the DEM grid.
struct Place {
  std::string name;
  double population = 0;
  double x = 0, y = 0;  ///< in the DEM's CRS (the snapped cell's centre when it was moved)
  int col = 0, row = 0;
};

/// 1 on land cells with data (not water, not nodata): from the model's altitude term.
std::vector<std::uint8_t> land_cells(const DensityResult& model);

/// Mann-Whitney AUC: the chance that a presence scores above a background cell, ties
/// counted half; presences weighted by `weights` (empty: all 1). NaN scores are skipped.
double auc(const std::vector<double>& presence, const std::vector<double>& weights, std::vector<double> background);

/// Weighted logistic regression y ~ 1 / (1 + exp(-(b0 + b.x))) by Newton-Raphson with a ridge
/// penalty `ridge` x total weight on b (not on b0). Returns {b0, b...}.
std::vector<double> fit_logistic(const std::vector<std::vector<double>>& x, const std::vector<double>& y,
                                 const std::vector<double>& w, double ridge);

/// Every term of the model, in weight order: the four characteristics, then the terrain terms.
inline constexpr std::size_t kTermCount = 4 + kTerrainCount;
using Terms = std::array<double, kTermCount>;
std::array<const char*, kTermCount> term_names();

/// The model's terms at cell i, in weight order.
Terms terms_at(const DensityResult& model, std::size_t i);

/// Single-factor baselines scored at cell i: minus the elevation, minus the slope, nearness to water.
std::array<double, 3> baselines_at(const DensityResult& model, std::size_t i);
inline constexpr std::array<const char*, 3> kBaselineNames = {"minus_elevation", "minus_slope", "coast_nearness"};

/// Skill of a density raster (and of the baselines) at places against every land cell.
struct Skill {
  double auc = 0, weighted_auc = 0;  ///< of the density; weighted: presences by population
  std::array<double, 3> baseline_auc{}, baseline_weighted_auc{};
  double best_baseline() const;
};
Skill skill(const Raster<float>& density, const DensityResult& terms, const std::vector<Place>& places,
            const std::vector<std::uint8_t>& land);

/// The density's and the baselines' scores at a cell: the density, then baselines_at's three.
using Scores = std::array<float, 4>;
Scores scores_at(const Raster<float>& density, const DensityResult& terms, std::size_t i);
/// skill() counted cell by cell, in any order (a region by tiles): the land cells' scores go into
/// one LandRanks each, and a place's AUC share is its score's rank among them (the keys' rounding,
/// docs/density.md; a place's NaN score takes no part).
class SkillCounter {
 public:
  void add_land(const Scores& s);
  /// Once, after the last add_land.
  Skill skill(const std::vector<Scores>& places, const std::vector<double>& populations);

 private:
  std::array<LandRanks, 4> ranks_;
  bool finished_ = false;
};

}  // namespace terrapolis::density
