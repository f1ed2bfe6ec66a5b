// Test scenarios: a density model and a buildable mask derived from a real sample DEM.
// SPDX-License-Identifier: MIT
#pragma once
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/raster.hpp"
#include "io/raster_io.hpp"
#include "sites/sites.hpp"

namespace terrapolis::fixtures {

struct SitesScenario {
  Raster<float> density;
  Raster<std::uint8_t> buildable;
};

/// buildable = land above 0 m and below 1000 m; density = exp(-z / 400 m) on buildable cells,
/// a smooth function of altitude that favours coasts and plains; NaN where the DEM has no data.
inline SitesScenario scenario_from_sample(const std::string& file) {
  const Dem dem = read_dem(std::string(TERRAPOLIS_SAMPLES) + "/" + file);
  SitesScenario s{dem.like<float>(std::numeric_limits<float>::quiet_NaN()), dem.like<std::uint8_t>(0)};
  for (std::size_t i = 0; i < dem.size(); ++i) {
    if (dem.is_nodata(i)) continue;
    const float z = dem[i];
    s.buildable[i] = z > 0 && z < 1000 ? 1 : 0;
    s.density[i] = s.buildable[i] ? float(std::exp(-z / 400.0)) : 0.0f;
  }
  return s;
}

/// A projected grid in metres (UTM 32N) of `cols` x `rows` cells of `cell_m` metres, all buildable, density 0.5.
inline SitesScenario flat_scenario(int cols, int rows, double cell_m) {
  Georef g;
  g.transform = {500000.0, cell_m, 0.0, 5000000.0, 0.0, -cell_m};
  g.crs.wkt = "PROJCS[\"WGS 84 / UTM zone 32N\"]";
  g.crs.epsg = 32632;
  g.crs.name = "WGS 84 / UTM zone 32N";
  g.crs.geographic = false;
  return {Raster<float>(cols, rows, g, 0.5f), Raster<std::uint8_t>(cols, rows, g, 1)};
}

/// Sites options with the thesis's quota table: the tests that start from them check Algorithms 13-15.
inline sites::SitesOptions thesis_options() {
  sites::SitesOptions o;
  o.quotas = sites::SitesOptions::Quotas::belhadj2007;
  return o;
}

/// The sites placed on a scenario, progress not reported.
inline sites::SitesResult place(const SitesScenario& s, const sites::SitesOptions& o) {
  SilentProgress progress;
  return sites::place_sites(s.density, s.buildable, o, progress);
}

}  // namespace terrapolis::fixtures
