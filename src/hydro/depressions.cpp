// Priority-Flood filling and breaching, and Barnes et al. (2014) flat resolution.
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
#include "hydro/spill_graph.hpp"

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


/// Open-addressing map from a pair of watershed labels to the lowest spill elevation seen between
/// them (the spillover graph's edges of one strip).
class SpillEdges {
 public:
  SpillEdges() : keys_(1024, 0), spill_(1024, 0.0f) {}
  void lower(std::uint32_t a, std::uint32_t b, float spill) {
    const std::uint64_t k = a < b ? (std::uint64_t(a) << 32 | b) : (std::uint64_t(b) << 32 | a);  // never 0: a != b
    std::size_t mask = keys_.size() - 1, h = std::size_t((k * 0x9e3779b97f4a7c15ull) >> 20) & mask;
    while (keys_[h] != 0 && keys_[h] != k) h = (h + 1) & mask;
    if (keys_[h] == k) {
      spill_[h] = std::min(spill_[h], spill);
      return;
    }
    keys_[h] = k;
    spill_[h] = spill;
    if (++size_ * 2 > keys_.size()) grow();
  }
  template <class F>
  void for_each(F&& f) const {
    for (std::size_t h = 0; h < keys_.size(); ++h)
      if (keys_[h] != 0) f(std::uint32_t(keys_[h] >> 32), std::uint32_t(keys_[h]), spill_[h]);
  }

 private:
  void grow() {
    std::vector<std::uint64_t> keys(keys_.size() * 2, 0);
    std::vector<float> spill(keys.size());
    keys.swap(keys_);
    spill.swap(spill_);
    size_ = 0;
    for (std::size_t h = 0; h < keys.size(); ++h)
      if (keys[h] != 0) lower(std::uint32_t(keys[h] >> 32), std::uint32_t(keys[h]), spill[h]);
  }
  std::vector<std::uint64_t> keys_;
  std::vector<float> spill_;
  std::size_t size_ = 0;
};

/// Plain Priority-Flood filling on row strips filled in parallel, after Barnes 2016 ("Parallel
/// priority-flood depression filling for trillion cell digital elevation models", Environmental
/// Modelling & Software 86): each strip is filled on its own with the rows it shares with its
/// neighbours as extra outlets, every cell labelled with the seed it was flooded from (label 0 for
/// all true outlets, one label per cut-row seed); the labels form a small spillover graph (edge
/// between two labels: the lowest max(filled a, filled b) over 8-adjacent cells a, b, within a strip
/// or across a cut), whose Priority-Flood from label 0 gives each label its water level; each cell
/// then ends at max(strip-filled value, its label's level). That is the lowest spill elevation of
/// any path to a true outlet, the unique plain filling, whatever the number of strips or threads.
template <class Label>
void fill_strips(Dem& z, const std::optional<double>& sea_level, int strips, Progress& progress) {
  constexpr Label kOpen = std::numeric_limits<Label>::max(), kVoid = kOpen - 1;  // not reached, nodata
  const int cols = z.cols(), rows = z.rows();
  strips = std::clamp(strips, 1, std::max(rows, 1));
  auto first_row = [&](int s) { return int(std::int64_t(rows) * s / strips); };
  // The labels, one per cell (each strip writes its own rows), on pages that go back to the
  // system when the fill ends: the later steps of `hydro` need more memory than this one.
  BigVector<Label> labels(z.size());
  Label* const label = labels.data();
  std::vector<SpillEdges> edges(static_cast<std::size_t>(strips));
  std::vector<std::uint32_t> labels_used(static_cast<std::size_t>(strips), 1);
  ProgressStep step(progress, "fill");
  std::mutex progress_mutex;
  std::atomic<std::size_t> done{0};
  const std::size_t report = std::max<std::size_t>(z.size() / 50, 1);
  tbb::parallel_for(tbb::blocked_range<int>(0, strips, 1), [&](const tbb::blocked_range<int>& range) {
    for (int s = range.begin(); s < range.end(); ++s) {
      const int r0 = first_row(s), r1 = first_row(s + 1);
      RadixQueue open;
      std::deque<std::uint32_t> pit;
      Label next = 1;
      auto row_has_nodata = [&](int r) {
        if (r < 0 || r >= rows) return false;
        bool nodata = false;
        for (int c = 0; c < cols; ++c) nodata |= std::isnan(z(c, r));
        return nodata;
      };
      bool above = row_has_nodata(r0 - 1), here = row_has_nodata(r0);
      for (int r = r0; r < r1; ++r) {
        const bool below = row_has_nodata(r + 1);
        const bool near_nodata = above || here || below, edge_row = r == 0 || r == rows - 1;
        above = here;
        here = below;
        const bool cut = (r == r0 && s > 0) || (r == r1 - 1 && s < strips - 1);
        for (int c = 0; c < cols; ++c) {
          const std::size_t i = z.index(c, r);
          if (std::isnan(z[i])) {
            label[i] = kVoid;
          } else if (edge_row || c == 0 || c == cols - 1 || (near_nodata && touches_outside(z, c, r)) ||
                     is_sea(z[i], sea_level)) {
            label[i] = 0;
            open.push(flood_key(z[i], std::uint32_t(i)));
          } else if (cut) {
            label[i] = next++;
            open.push(flood_key(z[i], std::uint32_t(i)));
          } else {
            label[i] = kOpen;
          }
        }
      }
      labels_used[std::size_t(s)] = next;
      SpillEdges& spill = edges[std::size_t(s)];
      std::size_t local = 0;
      while (!open.empty() || !pit.empty()) {
        const std::uint32_t i = next_cell(open, pit);
        if (++local == 4096) {
          if ((done += local) / report != (done - local) / report) {
            std::unique_lock lock(progress_mutex, std::try_to_lock);
            if (lock) step.update(double(done) / double(z.size()));
          }
          local = 0;
        }
        flood_neighbours(i, cols, r0, r1, z, label, kOpen, kVoid, open, pit,
                         [&](Label a, Label b, float level) { spill.lower(a, b, level); });
      }
    }
  }, tbb::simple_partitioner());
  if (strips == 1) return;
  // Global labels: 0 for the true outlets, then each strip's cut-row seeds.
  std::vector<std::uint32_t> base(static_cast<std::size_t>(strips), 0);
  std::uint32_t nodes = 1;
  for (int s = 0; s < strips; ++s) {
    base[std::size_t(s)] = nodes - 1;
    nodes += labels_used[std::size_t(s)] - 1;
  }
  auto global = [&](int s, Label l) { return l == 0 ? 0u : base[std::size_t(s)] + l; };
  std::vector<SpillEdge> list;
  for (int s = 0; s < strips; ++s)
    edges[std::size_t(s)].for_each(
        [&](std::uint32_t a, std::uint32_t b, float w) { list.push_back({global(s, Label(a)), global(s, Label(b)), w}); });
  edges.clear();
  edges.shrink_to_fit();
  for (int s = 0; s + 1 < strips; ++s) {  // across the cut between the last row of s and the first of s + 1
    const int r = first_row(s + 1) - 1;
    for (int c = 0; c < cols; ++c) {
      const std::size_t a = z.index(c, r);
      if (label[a] == kVoid) continue;
      for (int dc = -1; dc <= 1; ++dc) {
        if (c + dc < 0 || c + dc >= cols) continue;
        const std::size_t b = z.index(c + dc, r + 1);
        if (label[b] == kVoid) continue;
        const std::uint32_t ga = global(s, label[a]), gb = global(s + 1, label[b]);
        if (ga != gb) list.push_back({ga, gb, std::max(z[a], z[b])});
      }
    }
  }
  const std::vector<float> level = spill_levels(nodes, list);
  // Every valid cell is connected to a true outlet, so every label has a finite level.
  tbb::parallel_for(tbb::blocked_range<int>(0, strips, 1), [&](const tbb::blocked_range<int>& range) {
    for (int s = range.begin(); s < range.end(); ++s) {
      const std::size_t i0 = std::size_t(first_row(s)) * std::size_t(cols), i1 = std::size_t(first_row(s + 1)) * std::size_t(cols);
      for (std::size_t i = i0; i < i1; ++i) {
        const Label l = label[i];
        if (l != 0 && l != kVoid) z[i] = std::max(z[i], level[global(s, l)]);
      }
    }
  }, tbb::simple_partitioner());
}

/// Breadth-first rings: `run(front, first, expand)` calls `expand(cell, ring, next)` for every cell
/// of `front` (ring `first`), then of what it pushed to `next` (ring first + 1), and so on. Rings
/// of many cells are split between threads, each pushing to its own list; the next ring is their
/// concatenation. The lists are kept from one run to the next (flats are many and mostly small).
template <class Cell>
class Rings {
 public:
  template <class Expand>
  void run(std::vector<Cell>& front, std::int32_t first, Expand&& expand) {
    constexpr std::size_t kSplit = 4096;  // below this a ring costs less than sharing it out
    for (std::int32_t ring = first; !front.empty(); ++ring) {
      next_.clear();
      if (front.size() < kSplit || !parallel_) {
        for (const Cell c : front) expand(c, ring, next_);
      } else {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, front.size(), kSplit / 4), [&](const auto& range) {
          std::vector<Cell>& out = pushed_.local();
          for (std::size_t i = range.begin(); i < range.end(); ++i) expand(front[i], ring, out);
        });
        for (std::vector<Cell>& out : pushed_) {
          next_.insert(next_.end(), out.begin(), out.end());
          out.clear();
        }
      }
      std::swap(front, next_);
    }
  }

 private:
  bool parallel_ = tbb::this_task_arena::max_concurrency() > 1;
  std::vector<Cell> next_;
  tbb::enumerable_thread_specific<std::vector<Cell>> pushed_;
};

void fill_in_strips(Dem& z, const std::optional<double>& sea_level, int strips, Progress& progress) {
  if (z.cols() <= 32000) fill_strips<std::uint16_t>(z, sea_level, strips, progress);  // 2 * cols + 1 labels a strip
  else fill_strips<std::uint32_t>(z, sea_level, strips, progress);
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

void drain_flats(const Dem& filled, Raster<std::uint8_t>& d8) {
  // Everything works on a grid padded with one cell of "outside" (kind 0, label 0) so that the
  // waves need no bounds test and no division, and the label and gradient of a cell share one
  // 8-byte slot: a wave step reads one array. The waves are the breadth-first rings of Barnes
  // 2014b; each cell's value depends only on its ring distance, not on visiting order.
  const int cols = filled.cols(), rows = filled.rows();
  const std::size_t width = std::size_t(cols) + 2;
  const std::size_t padded = width * (std::size_t(rows) + 2);
  std::ptrdiff_t poff[8], uoff[8];
  for (int k = 0; k < 8; ++k) {
    poff[k] = std::ptrdiff_t(drow[k]) * std::ptrdiff_t(width) + dcol[k];
    uoff[k] = neighbour_offset(cols, k);
  }
  // kind: 0 outside, nodata or terminal; 1 draining; 2 undrained (kNoFlow); bit 4: low edge seen.
  constexpr std::uint8_t kOut = 0, kDrains = 1, kFlat = 2, kLowSeen = 4;
  BigVector<std::uint8_t> kind(padded, kOut);
  // The row scans run on bands of rows in parallel; what they collect is merged in band order, so
  // the result is the one of a single row-major scan.
  const int bands = std::min(rows, 64);
  auto for_bands = [&](auto&& body) {
    tbb::parallel_for(0, bands, [&](int b) { body(b, int(std::int64_t(rows) * b / bands), int(std::int64_t(rows) * (b + 1) / bands)); });
  };
  for_bands([&](int, int r0, int r1) {
    for (int r = r0; r < r1; ++r)
      for (int c = 0; c < cols; ++c) {
        const std::uint8_t v = d8(c, r);
        kind[std::size_t(r + 1) * width + std::size_t(c) + 1] =
            v == kNoData || v == kTerminal ? kOut : v == kNoFlow ? kFlat : kDrains;
      }
  });
  auto unpadded = [&](std::size_t p) {
    const std::size_t r = p / width - 1;
    return r * std::size_t(cols) + (p - (r + 1) * width - 1);
  };
  // Edges (Barnes 2014b, Algorithm 3): a low edge drains and has a same-elevation undrained
  // neighbour; a high edge is undrained with a higher neighbour.
  std::vector<std::vector<std::uint32_t>> band_low(static_cast<std::size_t>(bands)),
      band_high(static_cast<std::size_t>(bands));
  for_bands([&](int b, int r0, int r1) {
    auto& low = band_low[std::size_t(b)];
    auto& high = band_high[std::size_t(b)];
    for (int r = r0; r < r1; ++r)
      for (int c = 0; c < cols; ++c) {
        const std::size_t p = std::size_t(r + 1) * width + std::size_t(c) + 1;
        if (kind[p] != kFlat) continue;
        const std::size_t u = filled.index(c, r);
        const float zc = filled[u];
        bool higher = false;
        for (int k = 0; k < 8; ++k) {
          const std::size_t pn = std::size_t(std::ptrdiff_t(p) + poff[k]);
          const std::uint8_t kn = kind[pn];
          if (kn == kOut) continue;
          const float zn = filled[std::size_t(std::ptrdiff_t(u) + uoff[k])];
          if (zn > zc) higher = true;
          if (kn == kDrains && zn == zc) low.push_back(std::uint32_t(pn));  // may repeat: see below
        }
        if (higher) high.push_back(std::uint32_t(p));
      }
  });
  std::vector<std::uint32_t> low, high;  // padded indices, each low edge once, in scan order
  for (int b = 0; b < bands; ++b) {
    for (std::uint32_t p : band_low[std::size_t(b)])
      if (!(kind[p] & kLowSeen)) {
        kind[p] |= kLowSeen;
        low.push_back(p);
      }
    high.insert(high.end(), band_high[std::size_t(b)].begin(), band_high[std::size_t(b)].end());
  }
  if (low.empty()) {  // no flat can drain
    for (auto& v : d8.values())
      if (v == kNoFlow) v = kTerminal;
    return;
  }
  // Label each flat from its low edges (8-connected cells of equal elevation): +label on undrained
  // cells, -label on draining ones, so that a wave step tests membership with one comparison.
  struct Slot {
    std::int32_t label;
    std::int32_t mask;
  };
  BigVector<Slot> cell(padded, Slot{0, 0});
  // The waves are run ring by ring, the large rings (the sea, a lake) split between threads. What
  // a wave writes in a cell depends only on its ring and on what earlier waves wrote, never on the
  // order of the cells in a ring, so two threads reaching one cell write the same values: the
  // accesses are relaxed atomics (plain moves on x86), and such a cell is then queued twice, which
  // costs a little work and changes nothing.
  auto load = [](std::int32_t& v) { return std::atomic_ref<std::int32_t>(v).load(std::memory_order_relaxed); };
  auto store = [](std::int32_t& v, std::int32_t x) { std::atomic_ref<std::int32_t>(v).store(x, std::memory_order_relaxed); };
  std::int32_t next_label = 1;
  std::vector<std::uint64_t> front;  // padded index << 32 | unpadded index
  Rings<std::uint64_t> label_rings;
  for (std::uint32_t seed : low) {
    if (cell[seed].label != 0) continue;
    const std::size_t useed = unpadded(seed);
    const float zf = filled[useed];
    const std::int32_t label = next_label++;
    cell[seed].label = -label;
    front.assign(1, std::uint64_t(seed) << 32 | useed);
    // Breadth first: rings stay compact in memory, where a depth-first flood wanders across rows.
    // The partition into flats is the same either way.
    label_rings.run(front, 1, [&](std::uint64_t top, std::int32_t, std::vector<std::uint64_t>& next) {
      const std::size_t p = std::size_t(top >> 32), u = std::size_t(top & 0xffffffffu);
      for (int k = 0; k < 8; ++k) {
        const std::size_t pn = std::size_t(std::ptrdiff_t(p) + poff[k]);
        const std::uint8_t kn = kind[pn] & 3;
        if (kn == kOut || load(cell[pn].label) != 0) continue;
        const std::size_t un = std::size_t(std::ptrdiff_t(u) + uoff[k]);
        if (filled[un] != zf) continue;
        store(cell[pn].label, kn == kFlat ? label : -label);
        next.push_back(std::uint64_t(pn) << 32 | un);
      }
    });
  }
  std::vector<std::int32_t> flat_height(std::size_t(next_label), 0);
  // Breadth-first wave over undrained cells of the same flat, one ring per loop. A cell is
  // marked (mask > 0 after `set`) when it is first reached.
  Rings<std::uint32_t> wave_rings;
  auto wave = [&](const std::vector<std::uint32_t>& seeds, auto&& set) {
    std::vector<std::uint32_t> front;
    for (std::uint32_t p : seeds)
      if (cell[p].mask <= 0) {
        set(p, 1);
        front.push_back(p);
      }
    wave_rings.run(front, 2, [&](std::uint32_t p, std::int32_t ring, std::vector<std::uint32_t>& next) {
      const std::int32_t label = std::abs(cell[p].label);
      for (int k = 0; k < 8; ++k) {
        const std::size_t pn = std::size_t(std::ptrdiff_t(p) + poff[k]);
        // Not an undrained cell of this flat, or seen.
        if (cell[pn].label != label || load(cell[pn].mask) > 0) continue;
        set(pn, ring);
        next.push_back(std::uint32_t(pn));
      }
    });
  };
  // Gradient away from higher terrain (only high edges of labelled, i.e. drainable, flats).
  std::vector<std::uint32_t> high_labelled;
  for (std::uint32_t p : high)
    if (cell[p].label != 0) high_labelled.push_back(p);
  wave(high_labelled, [&](std::size_t p, std::int32_t ring) {
    store(cell[p].mask, ring);
    store(flat_height[std::size_t(cell[p].label)], ring);
  });
  // Gradient towards lower terrain, combined: 2*towards + (height - away), always > 0.
  for (auto& s : cell) s.mask = -s.mask;
  wave(low, [&](std::size_t p, std::int32_t ring) {
    const std::int32_t away = load(cell[p].mask);  // -away, or 0 where the first wave did not reach
    if (away < 0) store(cell[p].mask, flat_height[std::size_t(std::abs(cell[p].label))] + away + 2 * ring);
    else if (away == 0) store(cell[p].mask, 2 * ring);
  });
  // Directions (Barnes 2014b, D8FlowFlats): towards the same-flat neighbour of smallest gradient,
  // the first in neighbour order on ties; none smaller than the cell itself: terminal.
  for_bands([&](int, int r0, int r1) {
    for (int r = r0; r < r1; ++r)
      for (int c = 0; c < cols; ++c) {
        const std::size_t p = std::size_t(r + 1) * width + std::size_t(c) + 1;
        if ((kind[p] & 3) != kFlat) continue;
        const std::int32_t label = cell[p].label;  // > 0 on a labelled undrained cell
        int best = -1;
        std::int32_t best_mask = cell[p].mask;
        if (label != 0)
          for (int k = 0; k < 8; ++k) {
            const Slot s = cell[std::size_t(std::ptrdiff_t(p) + poff[k])];
            if (std::abs(s.label) == label && s.mask < best_mask) {
              best_mask = s.mask;
              best = k;
            }
          }
        d8(c, r) = best >= 0 ? std::uint8_t(best) : kTerminal;
      }
  });
}

}  // namespace terrapolis::hydro
