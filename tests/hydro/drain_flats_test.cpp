// Flat resolution: the padded single-array implementation against the plain one it replaced.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <random>
#include <vector>

#include "core/geodesy.hpp"
#include "core/neighbours.hpp"
#include "hydro/depressions.hpp"
#include "hydro/flow_directions.hpp"
#include "hydro/grid.hpp"
#include "hydro/test_grids.hpp"

using namespace terrapolis;
using namespace terrapolis::hydro;

namespace {

struct Flats {
  Raster<std::int32_t> mask, labels;
};

/// Barnes, Lehman, Mulla 2014b written plainly on the unpadded grid with bounds tests, labels and
/// gradient in two rasters (the implementation drain_flats replaced).
Flats reference_flats(const Dem& filled, const Raster<std::uint8_t>& d8) {
  const int cols = filled.cols(), rows = filled.rows();
  Flats out{filled.like<std::int32_t>(0), filled.like<std::int32_t>(0)};
  auto& mask = out.mask;
  auto& labels = out.labels;
  std::vector<std::uint32_t> low, high;
  // Edges (Barnes 2014b, Algorithm 3): a low edge drains and has a same-elevation undrained
  // neighbour; a high edge is undrained with a higher neighbour. Only undrained cells and their
  // neighbours can be edges, so only they are looked at; the waves below depend on the ring
  // distances only, not on the order of the edges.
  std::vector<std::uint8_t> is_low(0);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = filled.index(c, r);
      if (d8[i] != kNoFlow) continue;
      const float zc = filled[i];
      bool higher = false;
      for (int k = 0; k < 8; ++k) {
        const int nc = c + dcol[k], nr = r + drow[k];
        if (!filled.inside(nc, nr)) continue;
        const std::size_t n = filled.index(nc, nr);
        const std::uint8_t dn = d8[n];
        if (dn == kNoData || dn == kTerminal) continue;
        if (filled[n] > zc) higher = true;
        if (dn != kNoFlow && filled[n] == zc) {
          if (is_low.empty()) is_low.assign(filled.size(), 0);
          if (!is_low[n]) {
            is_low[n] = 1;
            low.push_back(std::uint32_t(n));
          }
        }
      }
      if (higher) high.push_back(std::uint32_t(i));
    }
  // Label each flat from its low edges (8-connected cells of equal elevation).
  std::int32_t next_label = 1;
  std::vector<std::uint32_t> stack;
  for (std::uint32_t seed : low) {
    if (labels[seed] != 0) continue;
    const float zf = filled[seed];
    labels[seed] = next_label;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::uint32_t i = stack.back();
      stack.pop_back();
      const int c = int(i % std::uint32_t(cols)), r = int(i / std::uint32_t(cols));
      for (int k = 0; k < 8; ++k) {
        const int nc = c + dcol[k], nr = r + drow[k];
        if (!filled.inside(nc, nr)) continue;
        const std::size_t n = filled.index(nc, nr);
        if (labels[n] != 0 || filled[n] != zf || d8[n] == kNoData || d8[n] == kTerminal) continue;
        labels[n] = next_label;
        stack.push_back(std::uint32_t(n));
      }
    }
    ++next_label;
  }
  std::vector<std::int32_t> flat_height(std::size_t(next_label), 0);
  // Breadth-first wave over undrained cells of the same flat, one ring per loop. A cell is
  // marked (mask > 0 after `set`) when it is first reached, so each is queued once; its value
  // depends only on its ring, as in Barnes's algorithm where duplicates are skipped when popped.
  auto wave = [&](const std::vector<std::uint32_t>& seeds, auto&& set) {
    std::vector<std::uint32_t> front, next;
    for (std::uint32_t i : seeds)
      if (mask[i] <= 0) {
        set(i, 1);
        front.push_back(i);
      }
    for (std::int32_t loops = 2; !front.empty(); ++loops) {
      next.clear();
      for (std::uint32_t i : front) {
        const int c = int(i % std::uint32_t(cols)), r = int(i / std::uint32_t(cols));
        for (int k = 0; k < 8; ++k) {
          const int nc = c + dcol[k], nr = r + drow[k];
          if (!filled.inside(nc, nr)) continue;
          const std::size_t n = filled.index(nc, nr);
          if (mask[n] > 0 || d8[n] != kNoFlow || labels[n] != labels[i]) continue;
          set(n, loops);
          next.push_back(std::uint32_t(n));
        }
      }
      std::swap(front, next);
    }
  };
  // Gradient away from higher terrain (only high edges of labelled, i.e. drainable, flats).
  std::vector<std::uint32_t> high_labelled;
  for (std::uint32_t i : high)
    if (labels[i] != 0) high_labelled.push_back(i);
  wave(high_labelled, [&](std::size_t i, std::int32_t loops) {
    mask[i] = loops;
    flat_height[std::size_t(labels[i])] = loops;
  });
  // Gradient towards lower terrain, combined: 2*towards + (height - away), always > 0.
  for (auto& m : mask.values()) m = -m;
  wave(low, [&](std::size_t i, std::int32_t loops) {
    if (mask[i] < 0) mask[i] = flat_height[std::size_t(labels[i])] + mask[i] + 2 * loops;
    else mask[i] = 2 * loops;
  });
  return out;
}


/// The reference directions: first-pass d8 with flats drained by the plain implementation.
Raster<std::uint8_t> reference_d8(const Dem& filled, Raster<std::uint8_t> d8) {
  const Flats flats = reference_flats(filled, d8);
  for (int r = 0; r < filled.rows(); ++r)
    for (int c = 0; c < filled.cols(); ++c) {
      const std::size_t i = d8.index(c, r);
      if (d8[i] != kNoFlow) continue;
      const std::int32_t label = flats.labels[i];
      int best = -1;
      std::int32_t best_mask = flats.mask[i];
      if (label != 0)
        for (int k = 0; k < 8; ++k) {
          const int nc = c + dcol[k], nr = r + drow[k];
          if (!filled.inside(nc, nr)) continue;
          const std::size_t n = d8.index(nc, nr);
          if (flats.labels[n] == label && flats.mask[n] < best_mask) {
            best_mask = flats.mask[n];
            best = k;
          }
        }
      d8[i] = best >= 0 ? std::uint8_t(best) : kTerminal;
    }
  return d8;
}

/// First pass only: steepest strictly lower neighbour, outside for border/nodata cells, else kNoFlow.
Raster<std::uint8_t> first_pass(const Dem& z) {
  Raster<std::uint8_t> d8 = z.like<std::uint8_t>(kNoData);
  for (int r = 0; r < z.rows(); ++r)
    for (int c = 0; c < z.cols(); ++c) {
      if (std::isnan(z(c, r))) continue;
      int best = -1, outside = -1;
      float best_drop = 0;
      for (int k = 0; k < 8; ++k) {
        const int nc = c + dcol[k], nr = r + drow[k];
        if (!z.inside(nc, nr) || std::isnan(z(nc, nr))) {
          if (outside < 0) outside = k;
          continue;
        }
        const float drop = z(c, r) - z(nc, nr);
        if (drop > best_drop) best_drop = drop, best = k;
      }
      d8(c, r) = std::uint8_t(best >= 0 ? best : outside >= 0 ? outside : kNoFlow);
    }
  return d8;
}

}  // namespace

TEST(DrainFlats, MatchesThePlainImplementationOnRandomFlatDems) {
  SilentProgress p;
  std::size_t undrained = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    // Few levels, so filling leaves large flats, some walled, some touching nodata or the border.
    std::mt19937_64 rng(seed);
    const int cols = 20 + int(rng() % 40), rows = 15 + int(rng() % 40);
    std::vector<float> v(std::size_t(cols * rows));
    for (auto& x : v) x = float(rng() % 4);
    for (int h = 0; h < int(v.size()) / 25; ++h)
      if (seed % 3 == 0) v[rng() % v.size()] = NAN;
    const Dem dem = test::grid(cols, rows, v, 30.0);
    for (FillMethod m : {FillMethod::priority_flood, FillMethod::none}) {
      const Dem filled = fill_depressions(dem, {m, std::nullopt}, p);
      Raster<std::uint8_t> d8 = first_pass(filled);
      // Some undrainable pits too (FillMethod::none): terminal first-pass cells stay terminal.
      if (seed % 4 == 1)
        for (std::size_t i = 0; i < d8.size(); i += 37)
          if (d8[i] != kNoData) d8[i] = kTerminal;
      for (auto v : d8.values()) undrained += v == kNoFlow;
      const Raster<std::uint8_t> expected = reference_d8(filled, d8);
      drain_flats(filled, d8);
      ASSERT_EQ(d8.values(), expected.values()) << "seed " << seed;
    }
  }
  EXPECT_GT(undrained, 5000u);  // the cases do exercise flats
}

TEST(DrainFlats, RingsSharedBetweenThreadsGiveTheSameDirections) {
  // A long strip of flat at 1 m with walls at 2 m and nodata holes: its border rings hold tens of
  // thousands of cells, so the waves are split between threads; the result must still be the
  // plain implementation's, with one thread or two.
  SilentProgress p;
  std::mt19937_64 rng(7);
  const int cols = 20000, rows = 12;
  std::vector<float> v(std::size_t(cols * rows), 1.0f);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const auto draw = rng() % 100;
    if (draw < 3) v[i] = 2.0f;
    else if (draw < 4) v[i] = NAN;
  }
  const Dem filled = fill_depressions(test::grid(cols, rows, v, 30.0), {FillMethod::priority_flood, std::nullopt}, p);
  const Raster<std::uint8_t> first = first_pass(filled);
  const Raster<std::uint8_t> expected = reference_d8(filled, first);
  for (std::size_t threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Raster<std::uint8_t> d8 = first;
    drain_flats(filled, d8);
    ASSERT_EQ(d8.values(), expected.values()) << threads << " thread(s)";
  }
}

TEST(DrainFlats, HugePageVectorsBehaveAsVectors) {
  BigVector<std::int32_t> big(std::size_t(3) << 20, 7);  // 12 MiB: the huge-page path
  BigVector<std::int32_t> small(10, 7);
  EXPECT_EQ(big[big.size() - 1], 7);
  EXPECT_EQ(small[9], 7);
  big.resize(big.size() + 1, 8);
  EXPECT_EQ(big.back(), 8);
}
