// Priority-Flood filling and breaching, and Barnes et al. (2014) flat resolution.
// SPDX-License-Identifier: MIT
#include "hydro/depressions.hpp"

#include <cmath>
#include <cstring>
#include <functional>
#include <deque>
#include <queue>
#include <vector>

#include "hydro/grid.hpp"

namespace terrapolis::hydro {
namespace {

/// Queue key: the elevation's bits made order-preserving as an unsigned integer, then the cell
/// index, so one 64-bit comparison orders by elevation and breaks ties by index (determinism).
inline std::uint64_t key(float z, std::uint32_t i) {
  std::uint32_t bits;
  std::memcpy(&bits, &z, sizeof bits);
  bits = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
  return (std::uint64_t(bits) << 32) | i;
}
using MinQueue = std::priority_queue<std::uint64_t, std::vector<std::uint64_t>, std::greater<>>;

/// The Priority-Flood of Barnes et al. 2014, Algorithm 2 (with its plain queue for cells inside
/// depressions) or 3 (epsilon). `visit(cell, parent_direction)` is told the neighbour index k from
/// which each non-seed cell was flooded, in flood order (used by breaching).
template <class Visit>
void priority_flood(Dem& z, const std::optional<double>& sea_level, bool epsilon, bool raise, Progress& progress,
                    Visit&& visit) {
  ProgressStep step(progress, epsilon ? "fill (epsilon)" : "fill");
  const int cols = z.cols(), rows = z.rows();
  std::vector<std::uint8_t> closed(z.size(), 0);
  MinQueue open;
  std::deque<std::uint32_t> pit;
  // Seeds: every outlet (border, next to nodata, sea).
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = z.index(c, r);
      if (std::isnan(z[i])) {
        closed[i] = 1;
        continue;
      }
      if (touches_outside(z, c, r) || is_sea(z[i], sea_level)) {
        closed[i] = 1;
        open.push(key(z[i], std::uint32_t(i)));
      }
    }
  std::size_t done = 0;
  const std::size_t report = std::max<std::size_t>(z.size() / 50, 1);
  while (!open.empty() || !pit.empty()) {
    std::uint32_t i;
    if (!pit.empty()) {
      i = pit.front();
      pit.pop_front();
    } else {
      i = std::uint32_t(open.top());
      open.pop();
    }
    if (++done % report == 0) step.update(double(done) / double(z.size()));
    const int c = int(i % std::uint32_t(cols)), r = int(i / std::uint32_t(cols));
    const float zc = z[i];
    for (int k = 0; k < 8; ++k) {
      const int nc = c + dcol[k], nr = r + drow[k];
      if (nc < 0 || nr < 0 || nc >= cols || nr >= rows) continue;
      const std::size_t n = z.index(nc, nr);
      if (closed[n]) continue;
      closed[n] = 1;
      visit(n, opposite(k));
      const float spill = epsilon ? std::nextafter(zc, INFINITY) : zc;
      if (z[n] <= (epsilon ? spill : zc)) {
        if (raise) z[n] = spill;
        pit.push_back(std::uint32_t(n));
      } else {
        open.push(key(z[n], std::uint32_t(n)));
      }
    }
  }
}

}  // namespace

Dem fill_depressions(const Dem& dem, const FillOptions& options, Progress& progress) {
  Dem z = dem;
  switch (options.method) {
    case FillMethod::none:
      return z;
    case FillMethod::priority_flood:
    case FillMethod::epsilon:
      priority_flood(z, options.sea_level, options.method == FillMethod::epsilon, true, progress,
                     [](std::size_t, int) {});
      return z;
    case FillMethod::breach: {
      // Flood on a filled copy to get the flooding tree (each cell's parent is the cell that
      // flooded it), then lower every parent to the lowest of its descendants, in reverse flood
      // order: parents are never above their children, so every cell drains along its tree path.
      Dem flooded = dem;
      std::vector<std::uint32_t> order;
      order.reserve(dem.size());
      std::vector<std::uint8_t> parent(dem.size(), kTerminal);
      priority_flood(flooded, options.sea_level, false, true, progress, [&](std::size_t n, int k) {
        order.push_back(std::uint32_t(n));
        parent[n] = std::uint8_t(k);
      });
      const int cols = z.cols();
      for (auto it = order.rbegin(); it != order.rend(); ++it) {
        const std::size_t n = *it;
        const int k = parent[n];
        const std::size_t p = std::size_t(std::ptrdiff_t(n) + neighbour_offset(cols, k));
        if (z[n] < z[p]) z[p] = z[n];
      }
      return z;
    }
  }
  return z;
}

FlatGradient resolve_flats(const Dem& filled, const Raster<std::uint8_t>& d8) {
  const int cols = filled.cols(), rows = filled.rows();
  FlatGradient out{filled.like<std::int32_t>(0), filled.like<std::int32_t>(0)};
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

}  // namespace terrapolis::hydro
