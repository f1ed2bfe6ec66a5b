// Hydraulic and thermal erosion: mass balance, the angle of repose, nodata, the mask, determinism.
// SPDX-License-Identifier: MIT
#include "erode/erosion.hpp"

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

TEST(Erosion, HydraulicBalancesErodedDepositedAndCarriedOut) {
  Dem dem = random_dem(48, 40, 7, 5);
  for (int c = 10; c < 14; ++c) dem(c, 20) = NAN;  // a nodata gap the water falls into
  ErodeReport report;
  run(dem, with(Process::hydraulic, 60), &report);
  EXPECT_EQ(report.iterations, 60);
  EXPECT_GT(report.eroded_m3, 1000.0);
  EXPECT_GT(report.carried_out_m3, 0.0);
  EXPECT_GT(report.water_out_m3, 0.0);
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3 + report.carried_out_m3, float_tolerance_m3(dem));
}

TEST(Erosion, ThermalConservesMassExactly) {
  const Dem dem = random_dem(40, 36, 11, 60);  // noise steeper than any angle of repose
  ErodeReport report;
  run(dem, with(Process::thermal, 40), &report);
  EXPECT_GT(report.eroded_m3, 1e5);
  EXPECT_EQ(report.carried_out_m3, 0.0);
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3, float_tolerance_m3(dem));
}

TEST(Erosion, BothProcessesBalance) {
  const Dem dem = random_dem(36, 30, 3, 40);
  ErodeReport report;
  run(dem, with(Process::both, 30), &report);
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3 + report.carried_out_m3, float_tolerance_m3(dem));
}

TEST(Erosion, SteepSlopeRelaxesToTheAngleOfRepose) {
  const Dem dem = ramp(24, 5, 1.0);  // 45 degrees
  ErodeOptions o = with(Process::thermal, 100000);
  o.thermal.angle_deg = 30;
  ErodeReport report;
  const Dem out = run(dem, o, &report);
  EXPECT_LT(report.iterations, 100000);  // it stopped once stable
  const double limit = std::tan(30 * std::numbers::pi / 180);
  double steepest = 0;
  for (int r = 0; r < out.rows(); ++r)
    for (int c = 0; c + 1 < out.cols(); ++c) steepest = std::max(steepest, (double(out(c, r)) - out(c + 1, r)) / 10);
  EXPECT_LE(steepest, limit + 1e-3);
  EXPECT_GE(steepest, limit - 0.02);  // relaxed to the angle, not flattened
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3, float_tolerance_m3(dem));
}

TEST(Erosion, GentleSlopeDoesNotMove) {
  const Dem dem = ramp(24, 5, 0.3);  // 16.7 degrees, under sand's 32.5
  ErodeReport report;
  EXPECT_TRUE(same_bytes(run(dem, with(Process::thermal, 50), &report), dem));
  EXPECT_EQ(report.eroded_m3, 0.0);
  EXPECT_EQ(report.iterations, 1);  // the first iteration found nothing to move
}

TEST(Erosion, ZeroIterationsChangeNothing) {
  Dem dem = random_dem(20, 18, 5, 30);
  dem(3, 4) = NAN;
  for (const Process p : {Process::hydraulic, Process::thermal, Process::both, Process::layered}) EXPECT_TRUE(same_bytes(run(dem, with(p, 0)), dem));
}

TEST(Erosion, OneAndTwoThreadsGiveTheSameBytes) {
  const Dem dem = random_dem(64, 96, 13, 30);
  Dem one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = run(dem, with(Process::both, 25));
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = run(dem, with(Process::both, 25));
  }
  EXPECT_TRUE(same_bytes(one, two));
  EXPECT_FALSE(same_bytes(one, dem));
}

TEST(Erosion, NodataCellsStayNodataAndTheOthersStayFinite) {
  Dem dem = random_dem(30, 30, 17, 40);
  for (int r = 8; r < 14; ++r)
    for (int c = 5; c < 12; ++c) dem(c, r) = NAN;
  const Dem out = run(dem, with(Process::both, 40));
  for (std::size_t i = 0; i < dem.size(); ++i) {
    EXPECT_EQ(std::isnan(out[i]), std::isnan(dem[i])) << i;
    if (!std::isnan(dem[i])) {
      EXPECT_TRUE(std::isfinite(out[i])) << i;
    }
  }
}

TEST(Erosion, OutsideTheMaskHeightsAreFixed) {
  const Dem dem = random_dem(30, 24, 19, 40);
  Raster<std::uint8_t> mask = dem.like<std::uint8_t>(0);
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < 15; ++c) mask(c, r) = 1;
  ErodeReport report;
  const Dem out = run(dem, with(Process::both, 40), &report, &mask);
  int changed = 0;
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < dem.cols(); ++c) {
      if (c >= 15) {
        EXPECT_EQ(std::memcmp(&out(c, r), &dem(c, r), sizeof(float)), 0) << c << "," << r;
      }
      changed += c < 15 && out(c, r) != dem(c, r);
    }
  EXPECT_GT(changed, 100);
  EXPECT_NEAR(report.eroded_m3, report.deposited_m3 + report.carried_out_m3, float_tolerance_m3(dem));
}

TEST(Erosion, AnglesRasterOverridesTheAngle) {
  const Dem dem = ramp(24, 5, 1.0);
  Raster<float> angles = dem.like<float>(50);  // steeper than the ramp: nothing moves
  ErodeOptions o = with(Process::thermal, 20);
  o.thermal.angles_deg = &angles;
  EXPECT_TRUE(same_bytes(run(dem, o), dem));
  angles(3, 2) = 95;
  EXPECT_THROW(run(dem, o), Error);
}

TEST(Erosion, MaterialsAreTheMiddleOfPeytavieTable23) {
  EXPECT_EQ(material_angle_deg("sand"), 32.5);
  EXPECT_EQ(material_angle_deg("stones"), 42.5);
  EXPECT_EQ(material_angle_deg("earth"), 32.5);
  EXPECT_EQ(material_angle_deg("snow"), 60.0);
  EXPECT_THROW(material_angle_deg("gravel"), Error);
}

}  // namespace
}  // namespace terrapolis::erode
