// Invariants of the skeleton generators: rivers descend in the DEM they built, trees are sound,
// the same seed gives the same bytes.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "generate/generators.hpp"

namespace terrapolis::generate {
namespace {

GenerateRequest request(std::uint64_t seed) {
  GenerateRequest r;
  Georef g;
  g.transform = {0, 30, 0, 0, 0, -30};
  r.grid = Raster<float>(129, 129, g, std::numeric_limits<float>::quiet_NaN());
  r.cell_m = 30;
  r.seed = seed;
  r.relief_m = 1000;
  r.dmmc.top_down.scale_m = 50;
  r.dmmc.top_down.seed = seed;
  return r;
}

void expect_sound(const GeneratedTerrain& t, const char* what) {
  ASSERT_FALSE(t.plan.rivers.empty()) << what;
  for (std::size_t i = 0; i < t.dem.size(); ++i) ASSERT_TRUE(std::isfinite(t.dem[i])) << what;
  int mouths = 0;
  for (const auto& r : t.plan.rivers) {
    ASSERT_GE(r.line.size(), 2u) << what;
    mouths += r.downstream < 0;
    if (r.downstream >= 0) {  // a reach ends on the first point of the reach it flows into
      const auto& d = t.plan.rivers[std::size_t(r.downstream)].line.front();
      EXPECT_EQ(r.line.back(), d) << what;
      EXPECT_GE(t.plan.rivers[std::size_t(r.downstream)].strahler, r.strahler) << what;
    }
    // The bed never rises downstream (cells are visited once each; a confluence point is the
    // receiving river's cell).
    for (std::size_t k = 1; k < r.line.size(); ++k) {
      const float up = t.dem(int(r.line[k - 1][0]), int(r.line[k - 1][1])), down = t.dem(int(r.line[k][0]), int(r.line[k][1]));
      EXPECT_LE(down, up + 1e-3f) << what << " reach point " << k;
    }
  }
  EXPECT_GT(mouths, 0) << what;
}

TEST(Generators, FlowRiversDescendAndTheTreeIsSound) { expect_sound(generate_flow(request(2)), "flow"); }
TEST(Generators, TectonicRiversDescendAndTheTreeIsSound) { expect_sound(generate_tectonic(request(2)), "tectonic"); }

TEST(Generators, SameSeedSameBytesOtherSeedOtherTerrain) {
  for (auto* generate : {&generate_flow, &generate_tectonic}) {
    const GeneratedTerrain a = generate(request(5)), b = generate(request(5)), c = generate(request(6));
    EXPECT_EQ(std::memcmp(a.dem.values().data(), b.dem.values().data(), a.dem.size() * sizeof(float)), 0);
    EXPECT_EQ(a.plan.rivers.size(), b.plan.rivers.size());
    EXPECT_NE(std::memcmp(a.dem.values().data(), c.dem.values().data(), a.dem.size() * sizeof(float)), 0);
  }
}

TEST(Generators, GivenRidgeIsTheCrest) {
  GenerateRequest r = request(1);
  r.lines = {{{20, 64}, {108, 64}}};
  const GeneratedTerrain t = generate_flow(r);
  // On the ridge the height is the relief (the thesis's constant-altitude crest), well above the border.
  EXPECT_NEAR(t.dem(64, 64), 1000, 60);
  EXPECT_LT(t.dem(64, 2), 500);
}

}  // namespace
}  // namespace terrapolis::generate
