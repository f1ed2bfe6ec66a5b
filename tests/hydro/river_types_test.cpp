// Discharge law, reach measures and the paper's type rules (Génévaux et al. 2013 §5.1-5.2).
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "hydro/hydro.hpp"
#include "hydro/river_types.hpp"
#include "hydro/test_grids.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;

TEST(RiverTypes, PaperDischargeLaw) {
  EXPECT_DOUBLE_EQ(paper_discharge_m3s(1), 0.42);
  // 0.42 * 100^0.69 = 0.42 * 10^1.38 = 10.08 m³/s (to the paper's two decimals).
  EXPECT_NEAR(paper_discharge_m3s(100), 10.08, 0.005);
  EXPECT_NEAR(paper_discharge_m3s(1000) / paper_discharge_m3s(100), std::pow(10.0, 0.69), 1e-12);
}

TEST(RiverTypes, RulesAllowDeltaOnlyAtMouthsAndBraidsOnlyNearThem) {
  const RiverTypeOptions o;  // D from 10 m³/s within 10 km of a mouth, delta from 50 m³/s
  ReachMeasures m;
  m.discharge_m3s = 80;
  m.slope = 0.001;
  m.sinuosity = 1.6;
  m.to_mouth_km = 0;
  m.mouth = true;
  EXPECT_EQ(classify_reach(m, o), RiverType::delta);
  m.mouth = false;  // same discharge, last reach but not into the sea (leaves the DEM): no delta
  EXPECT_EQ(classify_reach(m, o), RiverType::D);
  m.to_mouth_km = 10.5;  // beyond the coast distance: neither
  EXPECT_EQ(classify_reach(m, o), RiverType::E);
  m.to_mouth_km = -1;  // reaches no sea at all
  EXPECT_EQ(classify_reach(m, o), RiverType::E);
  m.to_mouth_km = 3;
  m.discharge_m3s = 9.9;  // near the coast but small: not braided
  EXPECT_EQ(classify_reach(m, o), RiverType::E);
  m.mouth = true;  // a small mouth reach is no delta either
  EXPECT_EQ(classify_reach(m, o), RiverType::E);
  m.slope = 0.03;  // steep: straight B whatever the sinuosity
  EXPECT_EQ(classify_reach(m, o), RiverType::B);
  m.slope = 0.001;
  m.sinuosity = 1.1;  // gentle but straight: B
  EXPECT_EQ(classify_reach(m, o), RiverType::B);
}

namespace {

/// A V valley of 1 km cells draining south at 1 % along its centre column (50 m above 0 at its
/// lowest), optionally into a sea row (z = -5 m) at the south edge.
Dem valley(int cols, int rows, bool sea_row) {
  std::vector<float> v;
  const int centre = cols / 2;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      v.push_back(sea_row && r == rows - 1 ? -5.0f : float(50.0 + 10.0 * (rows - 1 - r) + 100.0 * std::abs(c - centre)));
  return test::grid(cols, rows, v, 1000.0);
}

VectorLayer classified(const Dem& dem, std::optional<double> sea_level, const RiverTypeOptions& types) {
  HydroOptions o;
  o.with_hydrometry = false;
  o.sea_level = sea_level;
  o.streams.threshold_km2 = 15;  // the centre column only: a side cell drains at most 10 km²
  SilentProgress p;
  HydroResult r = run_hydro(dem, o, p);
  classify_streams(r.streams, r.filled, sea_level, types);
  return r.streams;
}

template <class T>
T field(const VectorLayer& l, std::size_t i, const char* name) {
  return std::get<T>(l.features.at(i).values.at(std::size_t(l.field_index(name))));
}

}  // namespace

TEST(RiverTypes, StraightSyntheticChannel) {
  const VectorLayer s = classified(valley(21, 40, false), std::nullopt, {});
  ASSERT_EQ(s.features.size(), 1u);  // one reach down the centre column
  EXPECT_DOUBLE_EQ(field<double>(s, 0, "sinuosity"), 1.0);
  EXPECT_NEAR(field<double>(s, 0, "slope"), 0.01, 1e-6);
  EXPECT_NEAR(field<double>(s, 0, "discharge_m3s"), paper_discharge_m3s(field<double>(s, 0, "upstream_km2")), 1e-12);
  EXPECT_EQ(field<std::string>(s, 0, "river_type"), "B");  // straight
  // No sea level: no coast, so no distance to a mouth.
  EXPECT_TRUE(std::holds_alternative<std::monostate>(s.features[0].values[std::size_t(s.field_index("to_mouth_km"))]));
}

TEST(RiverTypes, DeltaOnlyWhereTheChannelMeetsTheSea) {
  RiverTypeOptions types;
  types.delta_discharge_m3s = 1;  // the valley drains some 800 km² (φ ≈ 42 m³/s): high enough
  const VectorLayer sea = classified(valley(21, 40, true), 0.0, types);
  ASSERT_EQ(sea.features.size(), 1u);
  EXPECT_EQ(field<std::string>(sea, 0, "river_type"), "delta");
  EXPECT_DOUBLE_EQ(field<double>(sea, 0, "to_mouth_km"), 0.0);
  // The same channel leaving the DEM's edge without a sea: the paper's rules give no delta, no braids.
  const VectorLayer edge = classified(valley(21, 40, false), 0.0, types);
  EXPECT_EQ(field<std::string>(edge, 0, "river_type"), "B");
  types.delta_discharge_m3s = 1e6;  // too small for a delta, but near the coast and large: braided
  EXPECT_EQ(field<std::string>(classified(valley(21, 40, true), 0.0, types), 0, "river_type"), "D");
}
