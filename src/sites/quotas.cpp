// Quotas of sites per radius class (Belhadj 2007, §4.3.1.1, eq. 4.1-4.2, Algorithm 13).
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "sites/sites.hpp"

namespace terrapolis::sites {
namespace {

std::string metres(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g m", v);
  return buf;
}


}  // namespace

int QuotaTable::total() const {
  int n = 0;
  for (const auto& c : classes) n += c.quota;
  return n;
}

double units_for_people(double people, const SitesOptions& o) {
  const double base = std::max(0.0, (o.x_max - people) / o.x_max);
  return o.u_min + (o.u_max - o.u_min) * std::pow(base, o.p);
}

double class_step_m(double cell_size_m, const SitesOptions& o) { return std::max(o.dr_min_m, std::floor(cell_size_m)); }

void check_settings(const SitesOptions& o) {
  auto positive = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0)) throw bad_input(std::string("/sites/") + name + ": must be a positive number");
  };
  positive(o.dr_min_m, "dr_min_m");
  positive(o.x_max, "x_max");
  positive(o.p, "p");
  positive(o.people_per_m, "people_per_m");
  positive(o.quota_scale, "quota_scale");
  positive(o.town_density_per_km2, "town_density_per_km2");
  positive(o.zipf_exponent, "zipf_exponent");
  if (!(std::isfinite(o.u_min) && o.u_min >= 0)) throw bad_input("/sites/u_min: must be >= 0");
  if (!(std::isfinite(o.u_max) && o.u_max >= o.u_min)) throw bad_input("/sites/u_max: must be >= /sites/u_min");
  if (!(std::isfinite(o.r_min_m) && o.r_min_m >= 0)) throw bad_input("/sites/r_min_m: must be >= 0 metres (0: automatic)");
  if (!(std::isfinite(o.r_max_m) && o.r_max_m >= 0)) throw bad_input("/sites/r_max_m: must be >= 0 metres (0: automatic)");
  if (o.candidates < 0) throw bad_input("/sites/candidates: must be >= 0 (0: automatic)");
  if (o.refill_rounds < 0) throw bad_input("/sites/refill_rounds: must be >= 0");
  if (!(std::isfinite(o.growth) && o.growth >= 0 && o.growth <= 100)) throw bad_input("/sites/growth: must lie in [0, 100] (0.2: +20 %)");
  if (!(std::isfinite(o.growth_new_share) && o.growth_new_share >= 0 && o.growth_new_share <= 1))
    throw bad_input("/sites/growth_new_share: must lie in [0, 1]");
  if (o.quotas == SitesOptions::Quotas::belhadj2007) {
    if (o.growth > 0) throw bad_input("/sites/growth: needs /sites/quotas rank_size (and /sites/existing)");
    return;
  }
  if (o.r_min_m > 0 || o.r_max_m > 0)
    throw bad_input(std::string(o.r_min_m > 0 ? "/sites/r_min_m" : "/sites/r_max_m") +
                    ": sets the classes of /sites/quotas belhadj2007; with rank_size the radii come from the populations");
  if (!(std::isfinite(o.population) && o.population >= 0)) throw bad_input("/sites/population: must be a number of people >= 0");
  if (!(std::isfinite(o.people_per_km2) && o.people_per_km2 >= 0)) throw bad_input("/sites/people_per_km2: must be >= 0");
  if (!(std::isfinite(o.influence_factor) && o.influence_factor >= 0)) throw bad_input("/sites/influence_factor: must be >= 0");
  if (!(std::isfinite(o.urban_share) && o.urban_share > 0 && o.urban_share <= 1)) throw bad_input("/sites/urban_share: must lie in (0, 1]");
  if (!(std::isfinite(o.min_population) && o.min_population >= 1)) throw bad_input("/sites/min_population: must be at least 1 person");
  if (!(std::isfinite(o.spacing_km) && o.spacing_km >= 0)) throw bad_input("/sites/spacing_km: must be >= 0 (0: no limit)");
  if (!(std::isfinite(o.min_distance_share) && o.min_distance_share >= 0 && o.min_distance_share <= 2))
    throw bad_input("/sites/min_distance_share: must lie in [0, 2] (0: none)");
  if (!(std::isfinite(o.area_exponent) && o.area_exponent > 0 && o.area_exponent <= 1.5))
    throw bad_input("/sites/area_exponent: must lie in (0, 1.5]");
}

QuotaTable compute_quotas(double cell_size_m, const SitesOptions& o) {
  check_settings(o);
  QuotaTable table;
  table.dr_m = class_step_m(cell_size_m, o);
  table.r_min_m = o.r_min_m > 0 ? o.r_min_m : table.dr_m;
  table.r_max_m = o.r_max_m > 0 ? o.r_max_m : o.x_max / o.people_per_m + table.dr_m;
  // A tiny tolerance so that r_max - r_min an exact multiple of dr is not lost to rounding.
  const double steps = (table.r_max_m - table.r_min_m) / table.dr_m;
  const int n = int(std::floor(steps + 1e-9));
  if (n < 1)
    throw bad_input("sites: r_max (" + metres(table.r_max_m) + ") must exceed r_min (" + metres(table.r_min_m) +
                    ") by at least one class step dr (" + metres(table.dr_m) + ")");
  if (n > 100000) throw bad_input("sites: more than 100000 radius classes; raise dr_min or narrow r_min..r_max");
  table.classes.resize(std::size_t(n));
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double r = table.r_min_m + i * table.dr_m;
    const double units = o.quota_scale * units_for_people(o.people_per_m * r, o);
    sum += std::floor(units);
    if (sum > 5e7) throw bad_input("sites: the quotas add up to more than 5x10^7 sites; check u_max and the radius range");
    // Class 0 is the largest radius; Algorithm 13's index i counts from r_min.
    table.classes[std::size_t(n - 1 - i)] = QuotaClass{r, int(std::floor(units)), 0, 0};
  }
  return table;
}

}  // namespace terrapolis::sites
