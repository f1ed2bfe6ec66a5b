// The layered ground (Peytavie 2010 §2.3): loose material slides to its angle of repose and bare rock
// does not; global erosion by hand on a 3x3 peak; local erosion; mass balance; determinism.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "core/error.hpp"
#include "erode/erode_grids.hpp"

namespace terrapolis::erode {
namespace {

using namespace test_grids;

ErodeOptions layered(int iterations, double erodibility) {
  ErodeOptions o = with(Process::layered, iterations);
  o.layered.erodibility = erodibility;
  return o;
}

/// The steepest eastward fall between neighbours of a row, m/m on 10 m cells.
double steepest_fall(const Dem& dem) {
  double steepest = 0;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c + 1 < dem.cols(); ++c) steepest = std::max(steepest, (double(dem(c, r)) - dem(c + 1, r)) / 10);
  return steepest;
}

/// Total volume of a thickness raster, m³.
double volume_m3(const Raster<float>& thickness) {
  const CellMetrics m = cell_metrics(thickness.georef(), thickness.cols(), thickness.rows());
  double v = 0;
  for (int r = 0; r < thickness.rows(); ++r)
    for (int c = 0; c < thickness.cols(); ++c)
      if (!std::isnan(thickness(c, r))) v += thickness(c, r) * m.area_m2[std::size_t(r)];
  return v;
}

/// The layered process at a 30 degree angle of repose on `dem` under `loose`, run until stable.
Dem relax_at_30_degrees(const Dem& dem, const Raster<float>& loose, ErodeReport& report, Raster<float>& loose_end) {
  ErodeOptions o = layered(100000, 0);
  o.thermal.angle_deg = 30;
  o.layered.loose_m = &loose;
  return run(dem, o, &report, nullptr, &loose_end);
}

TEST(LayeredErosion, LooseSlopeRelaxesToTheAngleOfRepose) {
  const Dem dem = ramp(24, 5, 1.0);  // 45 degrees, all of it loose down to the foot (100 m)
  Raster<float> loose = dem.like<float>();
  for (std::size_t i = 0; i < dem.size(); ++i) loose[i] = dem[i] - 100.0f;
  ErodeReport report;
  Raster<float> loose_end;
  const Dem out = relax_at_30_degrees(dem, loose, report, loose_end);
  EXPECT_LT(report.iterations, 100000);  // stable before the end
  const double limit = std::tan(30 * std::numbers::pi / 180);
  EXPECT_LE(steepest_fall(out), limit + 1e-3);
  EXPECT_GE(steepest_fall(out), limit - 0.02);  // relaxed to the angle, not flattened
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3, float_tolerance_m3(dem));
  for (std::size_t i = 0; i < dem.size(); ++i) EXPECT_NEAR(out[i] - loose_end[i], 100.0, 1e-3) << i;  // the bedrock stayed
}

TEST(LayeredErosion, BareRockSteeperThanTheAngleDoesNotMove) {
  const Dem dem = ramp(24, 5, 1.0);  // the same 45 degrees, bare rock
  ErodeOptions o = layered(50, 0);
  o.thermal.angle_deg = 30;
  ErodeReport report;
  EXPECT_TRUE(same_bytes(run(dem, o, &report), dem));
  EXPECT_EQ(report.iterations, 1);
  EXPECT_EQ(report.eroded_m3, 0.0);
  // The same ramp under the thermal process, one material that all moves, does.
  o.process = Process::thermal;
  EXPECT_FALSE(same_bytes(run(dem, o), dem));
}

TEST(LayeredErosion, OnlyTheLooseLayerSlides) {
  const Dem dem = ramp(24, 5, 1.0);
  Raster<float> loose = dem.like<float>(0.5f);  // a thin cover: it slides off, the rock under it stays
  ErodeReport report;
  Raster<float> loose_end;
  const Dem out = relax_at_30_degrees(dem, loose, report, loose_end);
  for (std::size_t i = 0; i < dem.size(); ++i) {
    EXPECT_GE(loose_end[i], 0.0f) << i;
    EXPECT_NEAR(out[i] - loose_end[i], dem[i] - 0.5, 1e-3) << i;  // the bedrock did not move
  }
  EXPECT_GT(report.eroded_m3, 0.0);
  EXPECT_NEAR(volume_m3(loose_end), volume_m3(loose), 1e-6 * volume_m3(loose));
}

// A 3x3 peak 10 m above its neighbours, 10 m cells, sphere of 15 m. The accessibility of its top
// (Beardall et al. 2007, the share of air in the sphere), column by column: its own chord, half 15 m,
// half air; the four sides at 10 m, half sqrt(125) m, air from their surface 0 up to 10 + sqrt(125);
// the corners at 14.14 m, half 5 m, all air. Weighted by chord length (equal areas):
// a = (15 + 4 (10 + h) + 4 x 10) / (30 + 8 h + 40), h = sqrt(125): 0.876 31.
TEST(LayeredErosion, GlobalErosionByHandOnAPeak) {
  Dem dem(3, 3, projected(10), 0.0f);
  dem(1, 1) = 10;
  const double h = std::sqrt(125.0), a = (15 + 4 * (10 + h) + 40) / (30 + 8 * h + 40);
  auto loosened_after = [&](int iterations, double erodibility) {
    ErodeOptions o = layered(iterations, erodibility);
    o.layered.radius_m = 15;
    o.layered.voxel_m = 2;
    o.thermal.angle_deg = 89;  // nothing slides: the voxels stay where they weathered
    ErodeReport report;
    Raster<float> loose;
    EXPECT_TRUE(same_bytes(run(dem, o, &report, nullptr, &loose), dem));  // rock turned loose in place
    EXPECT_DOUBLE_EQ(report.loosened_m3, volume_m3(loose));
    return loose;
  };
  // eta = 1 - n a S reaches 0 on the third iteration when S = 1 / (2.999 a), the fourth when 1 / (3.001 a).
  const Raster<float> third = loosened_after(3, 1 / (2.999 * a)), fourth = loosened_after(3, 1 / (3.001 * a));
  EXPECT_EQ(third(1, 1), 2.0f);
  EXPECT_EQ(fourth(1, 1), 0.0f);
  EXPECT_EQ(loosened_after(4, 1 / (3.001 * a))(1, 1), 2.0f);
  // The flanks are less accessible (the peak hides part of their sky): still intact.
  for (const Raster<float>* loose : {&third, &fourth})
    for (std::size_t i = 0; i < loose->size(); ++i) {
      if (i != 4) {
        EXPECT_EQ((*loose)[i], 0.0f) << i;
      }
    }
}

TEST(LayeredErosion, HardStrataWeatherSlower) {
  // Flat rock (a = 1/2) in the soft bed [0, 10) m and in the hard bed [10, 20) m, half as erodible.
  ErodeOptions o = layered(11, 0.2);  // soft: eta = 1 - n x 0.5 x 0.2, 0 at the tenth iteration (to rounding)
  o.layered.strata_m = 10;
  o.layered.hard_ratio = 0.5;
  o.layered.radius_m = 15;
  o.layered.voxel_m = 1;
  for (const float height : {6.0f, 16.0f}) {
    ErodeReport report;
    run(Dem(4, 4, projected(10), height), o, &report);
    EXPECT_NEAR(report.loosened_m3, height < 10 ? 16 * 100.0 : 0.0, 1e-9) << height;
  }
}

TEST(LayeredErosion, RockfallSlidesIntoATalus) {
  // A 30 m cliff: its top three columns broken off 20 m deep pile up at its foot at the angle.
  Dem dem(30, 4, projected(10), 100.0f);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 12; ++c) dem(c, r) = 130;
  Raster<float> rockfall = dem.like<float>(NAN);
  for (int r = 0; r < 4; ++r)
    for (int c = 9; c < 12; ++c) rockfall(c, r) = 20;
  ErodeOptions o = layered(100000, 0);
  o.layered.rockfall_m = &rockfall;
  ErodeReport report;
  Raster<float> loose;
  const Dem out = run(dem, o, &report, nullptr, &loose);
  EXPECT_NEAR(report.loosened_m3, 4 * 3 * 20 * 100.0, 1e-6);
  EXPECT_NEAR(volume_m3(loose), report.loosened_m3, 0.05);  // float thicknesses of about 20 m
  EXPECT_GT(out(12, 0), 100.0f);     // the foot is covered
  EXPECT_GE(out(11, 0), 110.0f - 1e-3f);  // not below the rock left under the broken columns
  EXPECT_EQ(out(5, 0), 130.0f);      // the cliff top behind the tool's region did not move
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3, float_tolerance_m3(dem));
  rockfall(10, 2) = -1;
  EXPECT_THROW(run(dem, o), Error);
}

TEST(LayeredErosion, BalancesOnGeographicCellsWithNodata) {
  Dem dem = random_dem(40, 36, 23, 30);
  for (int c = 8; c < 14; ++c) dem(c, 17) = NAN;
  Raster<float> loose = dem.like<float>(1.5f), rockfall = dem.like<float>(0);
  for (int r = 4; r < 12; ++r) rockfall(20, r) = 8;
  ErodeOptions o = layered(40, 0.2);
  o.layered.loose_m = &loose;
  o.layered.rockfall_m = &rockfall;
  ErodeReport report;
  Raster<float> loose_end;
  const Dem out = run(dem, o, &report, nullptr, &loose_end);
  EXPECT_GT(report.eroded_m3, 1e5);
  EXPECT_GT(report.loosened_m3, volume_m3(rockfall) + 1e4);  // more than the rockfall alone: the rock weathered
  EXPECT_EQ(report.carried_out_m3, 0.0);
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3, float_tolerance_m3(dem));
  // The loose volume is what was there and what the rock gave, to float precision.
  for (std::size_t i = 0; i < dem.size(); ++i)
    if (std::isnan(dem[i])) loose[i] = NAN;
  EXPECT_NEAR(volume_m3(loose_end), volume_m3(loose) + report.loosened_m3, float_tolerance_m3(dem));
  for (std::size_t i = 0; i < dem.size(); ++i) EXPECT_EQ(std::isnan(out[i]), std::isnan(dem[i])) << i;
}

TEST(LayeredErosion, OutsideTheMaskNothingChanges) {
  const Dem dem = random_dem(30, 24, 31, 40);
  Raster<std::uint8_t> mask = dem.like<std::uint8_t>(0);
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < 15; ++c) mask(c, r) = 1;
  const Raster<float> loose = dem.like<float>(2.0f);
  ErodeOptions o = layered(40, 0.3);
  o.layered.loose_m = &loose;
  Raster<float> loose_end;
  const Dem out = run(dem, o, nullptr, &mask, &loose_end);
  int changed = 0;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c) {
      if (c >= 15) {
        EXPECT_EQ(out(c, r), dem(c, r)) << c << "," << r;
        EXPECT_EQ(loose_end(c, r), 2.0f) << c << "," << r;
      }
      changed += c < 15 && loose_end(c, r) != 2.0f;
    }
  EXPECT_GT(changed, 100);
}

TEST(LayeredErosion, OneAndTwoThreadsGiveTheSameBytes) {
  const Dem dem = random_dem(64, 96, 29, 30);
  Raster<float> rockfall = dem.like<float>(0);
  for (int r = 30; r < 60; ++r) rockfall(32, r) = 10;
  auto at = [&](int threads, Raster<float>& loose) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    ErodeOptions o = layered(25, 0.3);
    o.layered.rockfall_m = &rockfall;
    return run(dem, o, nullptr, nullptr, &loose);
  };
  Raster<float> loose_one, loose_two;
  const Dem one = at(1, loose_one), two = at(2, loose_two);
  EXPECT_TRUE(same_bytes(one, two));
  EXPECT_TRUE(same_bytes(loose_one, loose_two));
  EXPECT_FALSE(same_bytes(one, dem));
}

TEST(LayeredErosion, RefusesARadiusOverTwentyFiveCells) {
  ErodeOptions o = layered(1, 0.1);
  o.layered.radius_m = 260;  // 26 cells of 10 m
  EXPECT_THROW(run(ramp(8, 8, 0.1), o), Error);
  o.layered.radius_m = 250;
  EXPECT_NO_THROW(run(ramp(8, 8, 0.1), o));
}

}  // namespace
}  // namespace terrapolis::erode
