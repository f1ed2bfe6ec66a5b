// Plain Priority-Flood on row strips in parallel, joined through their spillover graph (Barnes 2016).
// SPDX-License-Identifier: MIT
#include "hydro/strip_fill.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <mutex>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hydro/flood_queue.hpp"
#include "hydro/grid.hpp"
#include "hydro/spill_graph.hpp"

namespace terrapolis::hydro {
namespace {

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

}  // namespace

void fill_in_strips(Dem& z, const std::optional<double>& sea_level, int strips, Progress& progress) {
  if (z.cols() <= 32000) fill_strips<std::uint16_t>(z, sea_level, strips, progress);  // 2 * cols + 1 labels a strip
  else fill_strips<std::uint32_t>(z, sea_level, strips, progress);
}

}  // namespace terrapolis::hydro
