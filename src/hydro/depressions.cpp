// Priority-Flood filling (Barnes et al. 2014) and breaching; strip fill and flats have their own files.
// SPDX-License-Identifier: MIT
#include "hydro/depressions.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <functional>
#include <limits>
#include <mutex>
#include <queue>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "hydro/flood_queue.hpp"
#include "hydro/grid.hpp"
#include "hydro/strip_fill.hpp"

namespace terrapolis::hydro {
namespace {

/// Binary heap on the keys: pops in (elevation, index) order, the order epsilon filling and
/// breaching depend on.
class HeapQueue {
 public:
  bool empty() const { return heap_.empty(); }
  void push(std::uint64_t item) { heap_.push(item); }
  std::uint64_t pop() {
    const std::uint64_t top = heap_.top();
    heap_.pop();
    return top;
  }

 private:
  std::priority_queue<std::uint64_t, std::vector<std::uint64_t>, std::greater<>> heap_;
};

/// The Priority-Flood of Barnes et al. 2014, Algorithm 2 (with its plain queue for cells inside
/// depressions) or 3 (epsilon). `visit(cell, parent_direction)` is told the neighbour index k from
/// which each non-seed cell was flooded, in flood order (used by breaching).
template <class Queue, class Visit>
void priority_flood(Dem& z, const std::optional<double>& sea_level, bool epsilon, bool raise, Progress& progress,
                    Visit&& visit) {
  ProgressStep step(progress, epsilon ? "fill (epsilon)" : "fill");
  const int cols = z.cols(), rows = z.rows();
  std::vector<std::uint8_t> closed(z.size(), 0);
  Queue open;
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
        open.push(flood_key(z[i], std::uint32_t(i)));
      }
    }
  std::size_t done = 0;
  const std::size_t report = std::max<std::size_t>(z.size() / 50, 1);
  while (!open.empty() || !pit.empty()) {
    const std::uint32_t i = next_cell(open, pit);
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
        open.push(flood_key(z[n], std::uint32_t(n)));
      }
    }
  }
}


/// Plain filling of DEMs of at least this many cells runs on kFillStrips strips when threads are
/// allowed (below, the joining costs more than the second thread saves). The strip count is fixed,
/// not taken from the thread count; the result does not depend on it anyway.
constexpr std::size_t kStripFillCells = std::size_t(1) << 20;
constexpr int kFillStrips = 4;

}  // namespace

Dem fill_depressions_in_strips(const Dem& dem, std::optional<double> sea_level, int strips, Progress& progress) {
  Dem z = dem;
  fill_in_strips(z, sea_level, strips, progress);
  return z;
}

Dem fill_depressions(const Dem& dem, const FillOptions& options, Progress& progress) {
  Dem z = dem;
  switch (options.method) {
    case FillMethod::none:
      return z;
    case FillMethod::priority_flood:
    case FillMethod::epsilon:
      if (options.method == FillMethod::epsilon)
        priority_flood<HeapQueue>(z, options.sea_level, true, true, progress, [](std::size_t, int) {});
      else if (z.size() >= kStripFillCells && tbb::this_task_arena::max_concurrency() > 1)
        fill_in_strips(z, options.sea_level, kFillStrips, progress);
      else
        priority_flood<RadixQueue>(z, options.sea_level, false, true, progress, [](std::size_t, int) {});
      return z;
    case FillMethod::breach: {
      // Flood on a filled copy to get the flooding tree (each cell's parent is the cell that
      // flooded it), then lower every parent to the lowest of its descendants, in reverse flood
      // order: parents are never above their children, so every cell drains along its tree path.
      Dem flooded = dem;
      std::vector<std::uint32_t> order;
      order.reserve(dem.size());
      std::vector<std::uint8_t> parent(dem.size(), kTerminal);
      priority_flood<HeapQueue>(flooded, options.sea_level, false, true, progress, [&](std::size_t n, int k) {
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

}  // namespace terrapolis::hydro
