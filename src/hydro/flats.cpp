// Flat resolution: drainage directions over flats (Barnes, Lehman, Mulla 2014b, Computers & Geosciences 62).
// SPDX-License-Identifier: MIT
#include "hydro/depressions.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "hydro/grid.hpp"

namespace terrapolis::hydro {
namespace {

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

/// The flat resolution of Barnes et al. 2014b, step by step. Everything works on a grid padded
/// with one cell of "outside" (kind 0, label 0) so that the waves need no bounds test and no
/// division, and the label and gradient of a cell share one 8-byte slot: a wave step reads one
/// array. The waves are the breadth-first rings of Barnes 2014b; each cell's value depends only on
/// its ring distance, not on visiting order.
class FlatDrainage {
 public:
  FlatDrainage(const Dem& filled, Raster<std::uint8_t>& d8)
      : filled_(filled), d8_(d8), cols_(filled.cols()), rows_(filled.rows()), width_(std::size_t(cols_) + 2),
        padded_(width_ * (std::size_t(rows_) + 2)), bands_(std::min(rows_, 64)), kind_(padded_, kOut) {
    for (int k = 0; k < 8; ++k) {
      poff_[k] = std::ptrdiff_t(drow[k]) * std::ptrdiff_t(width_) + dcol[k];
      uoff_[k] = neighbour_offset(cols_, k);
    }
  }

  void run() {
    classify();
    find_edges();
    if (low_.empty()) {  // no flat can drain
      for (auto& v : d8_.values())
        if (v == kNoFlow) v = kTerminal;
      return;
    }
    cell_.assign(padded_, Slot{0, 0});
    label_flats();
    gradients();
    directions();
  }

 private:
  // kind: 0 outside, nodata or terminal; 1 draining; 2 undrained (kNoFlow); bit 4: low edge seen.
  static constexpr std::uint8_t kOut = 0, kDrains = 1, kFlat = 2, kLowSeen = 4;
  /// A cell's flat label (+ on undrained cells, - on draining ones, so that a wave step tests
  /// membership with one comparison) and its gradient mask.
  struct Slot {
    std::int32_t label;
    std::int32_t mask;
  };

  /// The row scans run on bands of rows in parallel; what they collect is merged in band order, so
  /// the result is the one of a single row-major scan.
  template <class Body>
  void for_bands(Body&& body) const {
    tbb::parallel_for(0, bands_, [&](int b) { body(b, int(std::int64_t(rows_) * b / bands_), int(std::int64_t(rows_) * (b + 1) / bands_)); });
  }
  std::size_t padded_index(int c, int r) const { return std::size_t(r + 1) * width_ + std::size_t(c) + 1; }
  std::size_t unpadded(std::size_t p) const {
    const std::size_t r = p / width_ - 1;
    return r * std::size_t(cols_) + (p - (r + 1) * width_ - 1);
  }
  // Two threads of a wave reaching one cell write the same values (see gradients): relaxed atomics.
  static std::int32_t load(std::int32_t& v) { return std::atomic_ref<std::int32_t>(v).load(std::memory_order_relaxed); }
  static void store(std::int32_t& v, std::int32_t x) { std::atomic_ref<std::int32_t>(v).store(x, std::memory_order_relaxed); }

  void classify() {
    for_bands([&](int, int r0, int r1) {
      for (int r = r0; r < r1; ++r)
        for (int c = 0; c < cols_; ++c) {
          const std::uint8_t v = d8_(c, r);
          kind_[padded_index(c, r)] = v == kNoData || v == kTerminal ? kOut : v == kNoFlow ? kFlat : kDrains;
        }
    });
  }

  /// Edges (Barnes 2014b, Algorithm 3): a low edge drains and has a same-elevation undrained
  /// neighbour; a high edge is undrained with a higher neighbour. Each low edge once, in scan order.
  void find_edges() {
    std::vector<std::vector<std::uint32_t>> band_low(static_cast<std::size_t>(bands_)), band_high(static_cast<std::size_t>(bands_));
    for_bands([&](int b, int r0, int r1) {
      auto& low = band_low[std::size_t(b)];
      auto& high = band_high[std::size_t(b)];
      for (int r = r0; r < r1; ++r)
        for (int c = 0; c < cols_; ++c) {
          const std::size_t p = padded_index(c, r);
          if (kind_[p] != kFlat) continue;
          const std::size_t u = filled_.index(c, r);
          const float zc = filled_[u];
          bool higher = false;
          for (int k = 0; k < 8; ++k) {
            const std::size_t pn = std::size_t(std::ptrdiff_t(p) + poff_[k]);
            const std::uint8_t kn = kind_[pn];
            if (kn == kOut) continue;
            const float zn = filled_[std::size_t(std::ptrdiff_t(u) + uoff_[k])];
            if (zn > zc) higher = true;
            if (kn == kDrains && zn == zc) low.push_back(std::uint32_t(pn));  // may repeat: see below
          }
          if (higher) high.push_back(std::uint32_t(p));
        }
    });
    for (int b = 0; b < bands_; ++b) {
      for (std::uint32_t p : band_low[std::size_t(b)])
        if (!(kind_[p] & kLowSeen)) {
          kind_[p] |= kLowSeen;
          low_.push_back(p);
        }
      high_.insert(high_.end(), band_high[std::size_t(b)].begin(), band_high[std::size_t(b)].end());
    }
  }

  /// Labels each flat from its low edges (8-connected cells of equal elevation).
  void label_flats() {
    std::vector<std::uint64_t> front;  // padded index << 32 | unpadded index
    Rings<std::uint64_t> label_rings;
    for (std::uint32_t seed : low_) {
      if (cell_[seed].label != 0) continue;
      const std::size_t useed = unpadded(seed);
      const float zf = filled_[useed];
      const std::int32_t label = next_label_++;
      cell_[seed].label = -label;
      front.assign(1, std::uint64_t(seed) << 32 | useed);
      // Breadth first: rings stay compact in memory, where a depth-first flood wanders across rows.
      // The partition into flats is the same either way.
      label_rings.run(front, 1, [&](std::uint64_t top, std::int32_t, std::vector<std::uint64_t>& next) {
        const std::size_t p = std::size_t(top >> 32), u = std::size_t(top & 0xffffffffu);
        for (int k = 0; k < 8; ++k) {
          const std::size_t pn = std::size_t(std::ptrdiff_t(p) + poff_[k]);
          const std::uint8_t kn = kind_[pn] & 3;
          if (kn == kOut || load(cell_[pn].label) != 0) continue;
          const std::size_t un = std::size_t(std::ptrdiff_t(u) + uoff_[k]);
          if (filled_[un] != zf) continue;
          store(cell_[pn].label, kn == kFlat ? label : -label);
          next.push_back(std::uint64_t(pn) << 32 | un);
        }
      });
    }
  }

  /// Breadth-first wave over undrained cells of the same flat, one ring per loop. A cell is
  /// marked (mask > 0 after `set`) when it is first reached.
  template <class Set>
  void wave(const std::vector<std::uint32_t>& seeds, Set&& set) {
    std::vector<std::uint32_t> front;
    for (std::uint32_t p : seeds)
      if (cell_[p].mask <= 0) {
        set(p, 1);
        front.push_back(p);
      }
    wave_rings_.run(front, 2, [&](std::uint32_t p, std::int32_t ring, std::vector<std::uint32_t>& next) {
      const std::int32_t label = std::abs(cell_[p].label);
      for (int k = 0; k < 8; ++k) {
        const std::size_t pn = std::size_t(std::ptrdiff_t(p) + poff_[k]);
        // Not an undrained cell of this flat, or seen.
        if (cell_[pn].label != label || load(cell_[pn].mask) > 0) continue;
        set(pn, ring);
        next.push_back(std::uint32_t(pn));
      }
    });
  }

  /// The waves are run ring by ring, the large rings (the sea, a lake) split between threads. What
  /// a wave writes in a cell depends only on its ring and on what earlier waves wrote, never on the
  /// order of the cells in a ring, so two threads reaching one cell write the same values, and such
  /// a cell is then queued twice, which costs a little work and changes nothing.
  void gradients() {
    std::vector<std::int32_t> flat_height(std::size_t(next_label_), 0);
    // Gradient away from higher terrain (only high edges of labelled, i.e. drainable, flats).
    std::vector<std::uint32_t> high_labelled;
    for (std::uint32_t p : high_)
      if (cell_[p].label != 0) high_labelled.push_back(p);
    wave(high_labelled, [&](std::size_t p, std::int32_t ring) {
      store(cell_[p].mask, ring);
      store(flat_height[std::size_t(cell_[p].label)], ring);
    });
    // Gradient towards lower terrain, combined: 2*towards + (height - away), always > 0.
    for (auto& s : cell_) s.mask = -s.mask;
    wave(low_, [&](std::size_t p, std::int32_t ring) {
      const std::int32_t away = load(cell_[p].mask);  // -away, or 0 where the first wave did not reach
      if (away < 0) store(cell_[p].mask, flat_height[std::size_t(std::abs(cell_[p].label))] + away + 2 * ring);
      else if (away == 0) store(cell_[p].mask, 2 * ring);
    });
  }

  /// Directions (Barnes 2014b, D8FlowFlats): towards the same-flat neighbour of smallest gradient,
  /// the first in neighbour order on ties; none smaller than the cell itself: terminal.
  void directions() {
    for_bands([&](int, int r0, int r1) {
      for (int r = r0; r < r1; ++r)
        for (int c = 0; c < cols_; ++c) {
          const std::size_t p = padded_index(c, r);
          if ((kind_[p] & 3) != kFlat) continue;
          const std::int32_t label = cell_[p].label;  // > 0 on a labelled undrained cell
          int best = -1;
          std::int32_t best_mask = cell_[p].mask;
          if (label != 0)
            for (int k = 0; k < 8; ++k) {
              const Slot s = cell_[std::size_t(std::ptrdiff_t(p) + poff_[k])];
              if (std::abs(s.label) == label && s.mask < best_mask) {
                best_mask = s.mask;
                best = k;
              }
            }
          d8_(c, r) = best >= 0 ? std::uint8_t(best) : kTerminal;
        }
    });
  }

  const Dem& filled_;
  Raster<std::uint8_t>& d8_;
  const int cols_, rows_;
  const std::size_t width_, padded_;
  const int bands_;
  std::ptrdiff_t poff_[8], uoff_[8];
  BigVector<std::uint8_t> kind_;
  std::vector<std::uint32_t> low_, high_;  // padded indices
  BigVector<Slot> cell_;
  std::int32_t next_label_ = 1;
  Rings<std::uint32_t> wave_rings_;
};

}  // namespace

void drain_flats(const Dem& filled, Raster<std::uint8_t>& d8) { FlatDrainage(filled, d8).run(); }

}  // namespace terrapolis::hydro
