// Presence/background calibration of the density model and its skill (Warton & Shepherd 2010).
// SPDX-License-Identifier: MIT
#include "density/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.hpp"

namespace terrapolis::density {

std::vector<std::uint8_t> land_cells(const DensityResult& model) {
  const Raster<float>& altitude = model.term(TerrainTerm::altitude);
  if (altitude.size() == 0) throw processing_error("density: the terrain terms were not computed");
  std::vector<std::uint8_t> land(altitude.size());
  for (std::size_t i = 0; i < land.size(); ++i) land[i] = std::isnan(altitude[i]) ? 0 : 1;
  return land;
}

double auc(const std::vector<double>& presence, const std::vector<double>& weights, std::vector<double> background) {
  background.erase(std::remove_if(background.begin(), background.end(), [](double v) { return std::isnan(v); }), background.end());
  std::sort(background.begin(), background.end());
  double sum = 0, total = 0;
  for (std::size_t k = 0; k < presence.size(); ++k) {
    const double v = presence[k];
    if (std::isnan(v) || background.empty()) continue;
    const double w = weights.empty() ? 1.0 : weights[k];
    const auto lo = std::lower_bound(background.begin(), background.end(), v);
    const auto hi = std::upper_bound(lo, background.end(), v);
    sum += w * (double(lo - background.begin()) + 0.5 * double(hi - lo)) / double(background.size());
    total += w;
  }
  return total > 0 ? sum / total : NAN;
}

std::vector<double> fit_logistic(const std::vector<std::vector<double>>& x, const std::vector<double>& y, const std::vector<double>& w,
                                 double ridge) {
  const std::size_t n = x.size(), p = n ? x[0].size() + 1 : 1;
  std::vector<double> b(p, 0.0);
  const double total_w = std::accumulate(w.begin(), w.end(), 0.0);
  for (int iter = 0; iter < 100; ++iter) {
    std::vector<double> g(p, 0.0), h(p * p, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      double eta = b[0];
      for (std::size_t j = 1; j < p; ++j) eta += b[j] * x[i][j - 1];
      const double mu = 1 / (1 + std::exp(-eta)), v = w[i] * mu * (1 - mu), r = w[i] * (y[i] - mu);
      for (std::size_t j = 0; j < p; ++j) {
        const double xj = j ? x[i][j - 1] : 1.0;
        g[j] += r * xj;
        for (std::size_t k = 0; k <= j; ++k) h[j * p + k] += v * xj * (k ? x[i][k - 1] : 1.0);
      }
    }
    for (std::size_t j = 1; j < p; ++j) {
      g[j] -= ridge * total_w * b[j];
      h[j * p + j] += ridge * total_w;
    }
    for (std::size_t j = 0; j < p; ++j)
      for (std::size_t k = j + 1; k < p; ++k) h[j * p + k] = h[k * p + j];
    // Newton step: solve h d = g by Gaussian elimination with partial pivoting.
    std::vector<double> d = g;
    for (std::size_t c = 0; c < p; ++c) {
      std::size_t piv = c;
      for (std::size_t r = c + 1; r < p; ++r)
        if (std::abs(h[r * p + c]) > std::abs(h[piv * p + c])) piv = r;
      for (std::size_t k = 0; k < p; ++k) std::swap(h[c * p + k], h[piv * p + k]);
      std::swap(d[c], d[piv]);
      if (std::abs(h[c * p + c]) < 1e-300) throw processing_error("calibration: singular system (no variation in a term?)");
      for (std::size_t r = c + 1; r < p; ++r) {
        const double f = h[r * p + c] / h[c * p + c];
        for (std::size_t k = c; k < p; ++k) h[r * p + k] -= f * h[c * p + k];
        d[r] -= f * d[c];
      }
    }
    for (std::size_t c = p; c-- > 0;) {
      for (std::size_t k = c + 1; k < p; ++k) d[c] -= h[c * p + k] * d[k];
      d[c] /= h[c * p + c];
    }
    double step = 0;
    for (std::size_t j = 0; j < p; ++j) b[j] += d[j], step = std::max(step, std::abs(d[j]));
    if (step < 1e-9) break;
  }
  return b;
}

std::array<const char*, kTermCount> term_names() {
  std::array<const char*, kTermCount> names = {"coast", "hydrometry", "plateau", "plain"};
  std::copy(kTerrainTerms.begin(), kTerrainTerms.end(), names.begin() + 4);
  return names;
}

Terms terms_at(const DensityResult& m, std::size_t i) {
  Terms t = {m.coast[i], m.hydrometry[i], m.plateau[i], m.plain[i]};
  for (std::size_t k = 0; k < kTerrainCount; ++k) t[4 + k] = m.terrain[k][i];
  return t;
}

std::array<double, 3> baselines_at(const DensityResult& m, std::size_t i) {
  return {-m.term(TerrainTerm::altitude)[i], -m.term(TerrainTerm::slope)[i], m.term(TerrainTerm::coast_near)[i]};
}

double Skill::best_baseline() const { return *std::max_element(baseline_auc.begin(), baseline_auc.end()); }

Scores scores_at(const Raster<float>& density, const DensityResult& terms, std::size_t i) {
  const auto b = baselines_at(terms, i);
  return {density[i], float(b[0]), float(b[1]), float(b[2])};
}

Skill skill(const Raster<float>& density, const DensityResult& terms, const std::vector<Place>& places, const std::vector<std::uint8_t>& land) {
  SkillCounter counter;
  for (std::size_t i = 0; i < land.size(); ++i)
    if (land[i]) counter.add_land(scores_at(density, terms, i));
  std::vector<Scores> at;
  std::vector<double> populations;
  for (const Place& p : places) at.push_back(scores_at(density, terms, density.index(p.col, p.row))), populations.push_back(p.population);
  return counter.skill(at, populations);
}

void SkillCounter::add_land(const Scores& s) {
  if (finished_) throw processing_error("density: a land cell counted after the skill");
  for (std::size_t k = 0; k < 4; ++k) ranks_[k].add(&s[k], 1);
}

Skill SkillCounter::skill(const std::vector<Scores>& places, const std::vector<double>& populations) {
  if (finished_) throw processing_error("density: the skill taken twice");
  finished_ = true;
  for (LandRanks& r : ranks_) r.finish();
  std::array<double, 4> sum{}, total{}, weighted{}, weight{};
  for (std::size_t p = 0; p < places.size(); ++p)
    for (std::size_t k = 0; k < 4; ++k) {
      if (std::isnan(places[p][k]) || ranks_[k].count() == 0) continue;
      const double share = ranks_[k].rank(places[p][k]);
      sum[k] += share, total[k] += 1;
      weighted[k] += populations[p] * share, weight[k] += populations[p];
    }
  const auto mean = [](double s, double n) { return n > 0 ? s / n : NAN; };
  Skill s;
  s.auc = mean(sum[0], total[0]);
  s.weighted_auc = mean(weighted[0], weight[0]);
  for (std::size_t k = 0; k < 3; ++k) {
    s.baseline_auc[k] = mean(sum[k + 1], total[k + 1]);
    s.baseline_weighted_auc[k] = mean(weighted[k + 1], weight[k + 1]);
  }
  return s;
}

}  // namespace terrapolis::density
