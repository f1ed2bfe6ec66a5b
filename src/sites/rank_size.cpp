// Settlement sizes from a region's population: a rank-size (Zipf) law and an urban-area allometry.
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "core/error.hpp"
#include "sites/sites.hpp"

namespace terrapolis::sites {

std::vector<std::int64_t> rank_size_populations(double total, double q, double min_population, std::size_t max_count,
                                                std::size_t first_rank) {
  if (!(std::isfinite(total) && total >= 0)) throw bad_input("sites: population must be a number of people >= 0");
  if (!(std::isfinite(q) && q > 0)) throw bad_input("sites: zipf_exponent must be positive");
  if (!(std::isfinite(min_population) && min_population >= 1)) throw bad_input("sites: min_population must be at least 1 person");
  total = std::round(total);
  if (first_rank < 1) throw bad_input("sites: the rank-size law's first rank is 1");
  // g(N) = total k_N^-q / sum_{k <= k_N} k^-q (k from first_rank), the N-th size of the law over N
  // ranks, decreases with N: the count is the last N with g(N) >= min_population.
  double harmonic = 0;
  std::size_t count = 0;
  for (std::size_t n = 1; n <= max_count; ++n) {
    const double term = std::pow(double(first_rank + n - 1), -q);
    const double h = harmonic + term;
    if (total * term / h < min_population) break;
    harmonic = h;
    count = n;
    if (count > 50000000) throw bad_input("sites: the rank-size law gives more than 5x10^7 settlements; raise min_population");
  }
  return rank_size_split(total, q, count, first_rank);
}

namespace {

/// round(total) split in proportion to `weights` (their sum positive): floors first, then one more
/// person to the largest fractional parts (ties: the earlier index), so the shares add up exactly.
std::vector<std::int64_t> largest_remainders(double total, const std::vector<double>& weights) {
  const std::size_t count = weights.size();
  double sum = 0;
  for (double w : weights) sum += w;
  std::vector<double> exact(count);
  std::vector<std::int64_t> shares(count);
  std::int64_t assigned = 0;
  for (std::size_t k = 0; k < count; ++k) {
    exact[k] = total * weights[k] / sum;
    shares[k] = std::int64_t(std::floor(exact[k]));
    assigned += shares[k];
  }
  std::vector<std::size_t> order(count);
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return exact[a] - std::floor(exact[a]) > exact[b] - std::floor(exact[b]);
  });
  for (std::size_t k = 0; assigned < std::int64_t(total); ++k, ++assigned) ++shares[order[k % count]];
  return shares;
}

}  // namespace

std::vector<std::int64_t> rank_size_split(double total, double q, std::size_t count, std::size_t first_rank) {
  if (!(std::isfinite(total) && total >= 0)) throw bad_input("sites: population must be a number of people >= 0");
  if (!(std::isfinite(q) && q >= 0)) throw bad_input("sites: a rank-size exponent must be >= 0");
  if (count == 0) return {};
  std::vector<double> weights(count);
  for (std::size_t k = 0; k < count; ++k) weights[k] = std::pow(double(first_rank + k), -q);
  std::vector<std::int64_t> sizes = largest_remainders(std::round(total), weights);
  // Equal shares can leave a later rank one person above an earlier one: keep the order.
  std::sort(sizes.begin(), sizes.end(), std::greater<>());
  return sizes;
}

std::vector<std::int64_t> proportional_split(std::int64_t total, const std::vector<std::int64_t>& weights) {
  if (total < 0) throw bad_input("sites: a number of people to share must be >= 0");
  std::vector<double> w(weights.begin(), weights.end());
  const bool any = std::any_of(w.begin(), w.end(), [](double x) { return x > 0; });
  if (std::any_of(w.begin(), w.end(), [](double x) { return x < 0; }) || (!any && total > 0))
    throw bad_input("sites: people shared in proportion to negative or all-zero sizes");
  if (!any) return std::vector<std::int64_t>(weights.size(), 0);
  return largest_remainders(double(total), w);
}

std::size_t settleable_count(double land_area_km2, const SitesOptions& o, double people) {
  if (!(std::isfinite(o.spacing_km) && o.spacing_km >= 0)) throw bad_input("sites: spacing_km must be >= 0 (0: no limit)");
  if (o.spacing_km == 0) return std::numeric_limits<std::size_t>::max();
  // One hexagon of side-to-side width `spacing` per settlement of 1,000 people; a floor of
  // m people is reached by 1000 / m times fewer of them (q = 1), so the lattice widens as sqrt(m / 1000).
  double hexagon_km2 = std::sqrt(3.0) / 2 * o.spacing_km * o.spacing_km * (o.min_population / 1000.0);
  // A region denser on average than an urban centre is urban through and through: its places lie
  // as close as its people make them, each hexagon holding the people it holds at that density.
  const double density = land_area_km2 > 0 ? people / land_area_km2 : 0;
  if (density > kUrbanCentrePeoplePerKm2) hexagon_km2 *= kUrbanCentrePeoplePerKm2 / density;
  return std::size_t(std::max(1.0, std::floor(land_area_km2 / hexagon_km2 + 1e-9)));
}

double urban_radius_m(double people, const SitesOptions& o) {
  const double area_km2 = 1000.0 / o.town_density_per_km2 * std::pow(people / 1000.0, o.area_exponent);
  return std::sqrt(area_km2 * 1e6 / M_PI);
}

QuotaTable rank_size_quotas(double cell_size_m, const std::vector<std::int64_t>& populations, const SitesOptions& o) {
  if (!(std::isfinite(o.area_exponent) && o.area_exponent > 0 && o.area_exponent <= 1.5))
    throw bad_input("sites: area_exponent must lie in (0, 1.5]");
  if (!(std::isfinite(o.town_density_per_km2) && o.town_density_per_km2 > 0)) throw bad_input("sites: town_density_per_km2 must be positive");
  QuotaTable table;
  table.dr_m = class_step_m(cell_size_m, o);
  table.r_min_m = table.dr_m;
  // Class i (ascending) has radius dr (i + 1): a settlement goes to the first radius covering its built-up disc.
  std::vector<int> index(populations.size());
  int n = 1;
  for (std::size_t k = 0; k < populations.size(); ++k) {
    const double steps = std::ceil(urban_radius_m(double(populations[k]), o) / table.dr_m - 1e-9);
    if (steps > 100000) throw bad_input("sites: a settlement's radius spans more than 100000 class steps; raise dr_min");
    index[k] = std::max(0, int(steps) - 1);
    n = std::max(n, index[k] + 1);
  }
  table.r_max_m = table.r_min_m + n * table.dr_m;
  table.classes.resize(std::size_t(n));
  table.populations.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) table.classes[std::size_t(n - 1 - i)].radius_m = table.r_min_m + i * table.dr_m;
  for (std::size_t k = 0; k < populations.size(); ++k) {  // largest first, so each class's list is too
    const std::size_t c = std::size_t(n - 1 - index[k]);
    ++table.classes[c].quota;
    table.populations[c].push_back(populations[k]);
  }
  return table;
}

double rank_size_exponent(std::vector<double> sizes) {
  std::sort(sizes.begin(), sizes.end(), std::greater<>());
  const std::size_t n = sizes.size();
  if (n < 3 || !(sizes.back() > 0)) return NAN;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double x = std::log(double(k + 1) - 0.5), y = std::log(sizes[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double var = sxx - sx * sx / double(n);
  return var > 0 ? -(sxy - sx * sy / double(n)) / var : NAN;
}

}  // namespace terrapolis::sites
