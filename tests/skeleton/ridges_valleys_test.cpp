// The form index and the ridge and valley lines (Belhadj 2007 §5.2.2) on hand-computed grids, and
// the invariants of the lines on a rough terrain with nodata.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <set>

#include "core/geodesy.hpp"
#include "core/neighbours.hpp"
#include "core/random.hpp"
#include "skeleton/ridges_valleys.hpp"
#include "support/georefs.hpp"

using namespace terrapolis;
using namespace terrapolis::skeleton;

namespace {

/// A V-shaped valley (sign +1) or a roof-shaped ridge (sign -1) along column `axis`:
/// z = sign (s |x| - t row) on 1 m cells, so the axis falls (valley) or rises (ridge) by t a row.
Dem vee(int cols, int rows, int axis, double s, double t, double sign, const Georef& georef) {
  Dem d(cols, rows, georef, 0.0f);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) d(c, r) = float(sign * (s * std::abs(c - axis) - t * r));
  return d;
}

/// A grid corner: no pair of opposite neighbours, so no form index.
bool corner(const Dem& d, std::size_t i) {
  const int c = int(i % std::size_t(d.cols())), r = int(i / std::size_t(d.cols()));
  return (c == 0 || c == d.cols() - 1) && (r == 0 || r == d.rows() - 1);
}

/// The vertical component of the unit vector of a step of `d` metres and drop `dz` (footnote 14).
double vertical(double dz, double d) { return dz / std::hypot(d, dz); }

/// The thesis's literal form: lines only, no lattice.
SkeletonOptions only(Lines lines) {
  SkeletonOptions o;
  o.lines = lines;
  o.lattice = 0;
  o.line_step = 1;
  return o;
}

}  // namespace

TEST(FormIndex, ConePeakPitAndPlane) {
  // Cone z = -|r| (slope 1) on 1 m cells: each of the eight neighbours of the apex lies d lower at
  // distance d, so every V_i has vertical component 1/sqrt(2) and so has their mean.
  Dem cone(9, 9, test::projected(1), 0.0f), plane = cone;
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 9; ++c) {
      cone(c, r) = float(-std::hypot(c - 4, r - 4));
      plane(c, r) = float(0.3 * c - 0.2 * r);
    }
  const CellMetrics m = cell_metrics(cone.georef(), 9, 9);
  const Raster<float> f = form_index(cone, m);
  EXPECT_NEAR(f(4, 4), 1 / std::sqrt(2.0), 1e-6);
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (corner(cone, i)) {
      EXPECT_TRUE(std::isnan(f[i]));
      continue;
    }
    EXPECT_LE(f[i], f(4, 4));   // the apex is the strongest ridge cell: where a ridge ends
    EXPECT_GE(f[i], -1e-6);     // a cone is convex: no valley anywhere
  }
  // The pit (the cone upside down) reads the opposite, and a plane reads 0 up to its edges.
  for (std::size_t i = 0; i < cone.size(); ++i) cone[i] = -cone[i];
  EXPECT_NEAR(form_index(cone, m)(4, 4), -1 / std::sqrt(2.0), 1e-6);
  const Raster<float> flat = form_index(plane, m);
  for (std::size_t i = 0; i < flat.size(); ++i)
    if (!corner(plane, i)) {
      EXPECT_NEAR(flat[i], 0.0, 1e-6) << i;
    }
}

TEST(FormIndex, VeeAxisByHand) {
  const double s = 1, t = 0.1;
  const Dem dem = vee(9, 12, 4, s, t, 1, test::projected(1));
  const Raster<float> f = form_index(dem, cell_metrics(dem.georef(), 9, 12));
  // On the axis: east and west lie s higher at 1 m; north and south +-t cancel; the diagonals lie
  // s+t (north) and s-t (south) higher at sqrt(2) m.
  const double axis = (2 * vertical(-s, 1) + 2 * vertical(-(s + t), std::sqrt(2.0)) + 2 * vertical(-(s - t), std::sqrt(2.0))) / 8;
  EXPECT_NEAR(axis, -0.46449, 1e-5);
  for (int r = 1; r < 11; ++r) EXPECT_NEAR(f(4, r), axis, 1e-6);
  // The axis's end cells keep only their east-west pair: -1/sqrt(2). The flanks are planes: 0.
  EXPECT_NEAR(f(4, 0), vertical(-s, 1), 1e-6);
  for (int r = 0; r < 12; ++r)
    for (int c = 0; c < 9; ++c)
      if (c != 4 && !corner(dem, dem.index(c, r))) {
        EXPECT_NEAR(f(c, r), 0.0, 1e-6);
      }
}

TEST(Skeleton, VeeAxisIsTheOneValleyLineAndARoofTheOneRidge) {
  for (const double sign : {1.0, -1.0}) {
    const Dem dem = vee(9, 12, 4, 1, 0.1, sign, test::projected(1));
    SilentProgress p;
    const Skeleton s = extract_skeleton(dem, cell_metrics(dem.georef(), 9, 12), only(Lines::both), p);
    // The end cells (index -0.71) differ from the axis (-0.46) by more than 10 %: alone, too short.
    ASSERT_EQ(s.lines.size(), 1u);
    const Line& line = s.lines[0];
    EXPECT_EQ(line.kind, sign > 0 ? Kind::valley : Kind::ridge);
    ASSERT_EQ(line.cells.size(), 10u);
    std::set<std::size_t> cells(line.cells.begin(), line.cells.end());
    for (int r = 1; r < 11; ++r) EXPECT_TRUE(cells.count(dem.index(4, r))) << r;
    EXPECT_NEAR(line.length_m, 9.0, 1e-9);
    EXPECT_NEAR(line.relief_m, 0.9, 1e-5);
    EXPECT_EQ(s.kept_cells, 10u);
    EXPECT_EQ(s.valid_cells, 108u);
    EXPECT_EQ(s.kept(4, 5), dem(4, 5));
    EXPECT_TRUE(std::isnan(s.kept(3, 5)));
    // Asking for the other kind finds nothing.
    const Skeleton none = extract_skeleton(dem, cell_metrics(dem.georef(), 9, 12), only(sign > 0 ? Lines::ridges : Lines::valleys), p);
    EXPECT_TRUE(none.lines.empty());
    EXPECT_EQ(none.kept_cells, 0u);
    // A lattice of spacing 4 adds the cells of columns 2, 6 and rows 2, 6, 10: (2, r) and (6, r) are
    // off the axis (column 4), so 2 x 3 = 6 cells more, the same lines.
    SkeletonOptions lattice = only(Lines::both);
    lattice.lattice = 4;
    const Skeleton more = extract_skeleton(dem, cell_metrics(dem.georef(), 9, 12), lattice, p);
    ASSERT_EQ(more.lines.size(), 1u);
    EXPECT_EQ(more.line_cells, 10u);
    EXPECT_EQ(more.lattice_cells, 6u);
    EXPECT_EQ(more.kept_cells, 16u);
    EXPECT_EQ(more.kept(6, 10), dem(6, 10));
    EXPECT_TRUE(std::isnan(more.kept(6, 9)));
  }
}

TEST(Skeleton, LengthsAreGeodesicOnGeographicGrids) {
  // The same valley on 3" cells at 45 N: 9 north-south steps of one 3" arc of meridian.
  const Dem dem = vee(9, 12, 4, 30, 3, 1, test::geographic(45.0, 1.0 / 1200));
  SilentProgress p;
  const CellMetrics m = cell_metrics(dem.georef(), 9, 12);
  const Skeleton s = extract_skeleton(dem, m, only(Lines::valleys), p);
  ASSERT_EQ(s.lines.size(), 1u);
  // A degree of latitude at 45 N is 111,132 m on WGS 84: 3" is 92.61 m.
  EXPECT_NEAR(s.lines[0].length_m, 9 * 111132.0 / 1200, 1.0);
}

TEST(Skeleton, InvariantsOnRoughTerrainWithNodata) {
  // Sums of waves at several scales with a hole of nodata: many ridges and valleys.
  const int cols = 120, rows = 90;
  Dem dem(cols, rows, test::projected(30), 0.0f);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      double z = 0;
      for (int k = 1; k <= 5; ++k) {
        const double u = splitmix64(std::uint64_t(k)) % 1000 / 1000.0;
        z += 200.0 / k * std::sin(0.013 * k * k * c + 6.28 * u) * std::cos(0.017 * k * k * r + 3 * u);
      }
      dem(c, r) = float(z);
      if (std::hypot(c - 60, r - 45) < 8) dem(c, r) = NAN;
    }
  const CellMetrics m = cell_metrics(dem.georef(), cols, rows);
  SilentProgress p;
  SkeletonOptions o;
  const Skeleton s = extract_skeleton(dem, m, o, p);
  ASSERT_GT(s.ridges, 5u);
  ASSERT_GT(s.valleys, 5u);
  std::set<std::size_t> on_lines;
  for (const Line& line : s.lines) {
    ASSERT_GE(int(line.cells.size()), o.min_cells);
    const double sign = line.kind == Kind::ridge ? 1 : -1;
    double length = 0;
    int previous_k = -1;
    for (std::size_t j = 0; j < line.cells.size(); ++j) {
      const std::size_t cell = line.cells[j];
      EXPECT_FALSE(std::isnan(dem[cell]));
      EXPECT_GT(sign * s.index[cell], 0);  // ridge cells have a positive index, valley cells a negative one
      // Every third cell of a line from its first, and its last, is kept with the DEM's height.
      if (j % 3 == 0 || j + 1 == line.cells.size()) {
        on_lines.insert(cell);
        EXPECT_EQ(s.kept[cell], dem[cell]);
      }
      if (j == 0) continue;
      const std::size_t a = line.cells[j - 1];
      const int dc = int(cell % cols) - int(a % cols), dr = int(cell / cols) - int(a / cols);
      int k = 0;
      while (k < 8 && (dcol[k] != dc || drow[k] != dr)) ++k;
      ASSERT_LT(k, 8) << "not 8-adjacent";
      // Within ±10 % of the previous cell's index, from the seed outwards: one of the two holds.
      const double fa = s.index[a], fb = s.index[cell];
      EXPECT_TRUE(std::abs(fb - fa) <= o.tolerance * std::abs(fa) + 1e-7 || std::abs(fa - fb) <= o.tolerance * std::abs(fb) + 1e-7);
      if (previous_k >= 0) {
        const int d = std::abs(k - previous_k) & 7;
        EXPECT_LE(std::min(d, 8 - d), 1) << "a turn sharper than 45 degrees";
      }
      previous_k = k;
      length += m.step_m(int(a / cols), k);
    }
    EXPECT_NEAR(line.length_m, length, 1e-6);
  }
  // Kept cells are exactly the lines' kept cells and the valid cells of the default lattice (every 6th).
  ASSERT_EQ(o.lattice, 6);
  ASSERT_EQ(o.line_step, 3);
  std::size_t kept = 0, lattice = 0, both = 0;
  for (std::size_t i = 0; i < s.kept.size(); ++i) {
    const int c = int(i % cols), r = int(i / cols);
    const bool on = c % 6 == 3 && r % 6 == 3 && !std::isnan(dem[i]);
    lattice += on ? 1 : 0;
    both += on && on_lines.count(i) ? 1 : 0;
    if (!std::isnan(s.kept[i])) {
      ++kept;
      EXPECT_TRUE(on_lines.count(i) || on) << i;
      EXPECT_EQ(s.kept[i], dem[i]);
    }
  }
  EXPECT_EQ(lattice, 20u * 15u - 6u);  // 20 x 15 lattice cells, 6 of them in the hole
  EXPECT_EQ(s.lattice_cells, lattice);
  EXPECT_EQ(s.line_cells, on_lines.size());
  EXPECT_EQ(kept, on_lines.size() + lattice - both);
  EXPECT_EQ(kept, s.kept_cells);
  // The same lines on one thread.
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const Skeleton again = extract_skeleton(dem, m, o, p);
  ASSERT_EQ(again.lines.size(), s.lines.size());
  for (std::size_t i = 0; i < s.lines.size(); ++i) EXPECT_EQ(again.lines[i].cells, s.lines[i].cells);
}
