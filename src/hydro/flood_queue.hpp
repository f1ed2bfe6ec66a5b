// The queues of the Priority-Flood: order-preserving keys, a monotone radix queue, the next cell.
// SPDX-License-Identifier: MIT
#pragma once
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <deque>
#include <vector>

#include "core/neighbours.hpp"

namespace terrapolis::hydro {

/// Queue key: the elevation's bits made order-preserving as an unsigned integer, then the cell
/// index, so one 64-bit comparison orders by elevation and breaks ties by index (determinism).
inline std::uint64_t flood_key(float z, std::uint32_t i) {
  std::uint32_t bits;
  std::memcpy(&bits, &z, sizeof bits);
  bits = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
  return (std::uint64_t(bits) << 32) | i;
}

/// Radix heap (Ahuja, Mehlhorn, Orlin, Tarjan 1990) on the 32 elevation bits of the keys: a
/// monotone queue (Priority-Flood never pushes below the last popped elevation) in O(1) amortised
/// per item instead of a heap's O(log n) cache misses. Equal elevations pop in no fixed index
/// order, which plain filling does not see: its result, each cell raised to the lowest spill
/// elevation of any path to an outlet, does not depend on the order of ties.
class RadixQueue {
 public:
  bool empty() const { return size_ == 0; }
  void push(std::uint64_t item) {
    buckets_[std::size_t(bucket(std::uint32_t(item >> 32)))].push_back(item);
    ++size_;
  }
  std::uint64_t pop() {
    if (buckets_[0].empty()) {
      std::size_t b = 1;
      while (buckets_[b].empty()) ++b;
      std::uint32_t lowest = 0xffffffffu;
      for (std::uint64_t item : buckets_[b]) lowest = std::min(lowest, std::uint32_t(item >> 32));
      last_ = lowest;
      for (std::uint64_t item : buckets_[b]) buckets_[std::size_t(bucket(std::uint32_t(item >> 32)))].push_back(item);
      buckets_[b].clear();
    }
    const std::uint64_t item = buckets_[0].back();
    buckets_[0].pop_back();
    --size_;
    return item;
  }

 private:
  int bucket(std::uint32_t key) const { return key == last_ ? 0 : 32 - std::countl_zero(key ^ last_); }
  std::array<std::vector<std::uint64_t>, 33> buckets_;
  std::uint32_t last_ = 0;
  std::size_t size_ = 0;
};

/// The next cell to flood: the depression queue first (cells raised to the current spill), then
/// the lowest of the priority queue.
template <class Queue>
inline std::uint32_t next_cell(Queue& open, std::deque<std::uint32_t>& pit) {
  if (pit.empty()) return std::uint32_t(open.pop());
  const std::uint32_t i = pit.front();
  pit.pop_front();
  return i;
}

/// One step of the labelled Priority-Flood (Barnes 2016, Alg. 2) from cell `i` of a grid of `cols`
/// columns, within rows [row0, row1): each neighbour not reached yet (`open_label`) takes i's label
/// and is raised to its level onto the pit queue, or queued at its own; a neighbour of another
/// watershed (not `void_label`) calls `meet(label_i, label_n, spill elevation)`.
template <class Z, class Label, class Queue, class Meet>
inline void flood_neighbours(std::uint32_t i, int cols, int row0, int row1, Z& z, Label* label, Label open_label, Label void_label,
                             Queue& open, std::deque<std::uint32_t>& pit, Meet&& meet) {
  const int c = int(i % std::uint32_t(cols)), r = int(i / std::uint32_t(cols));
  const float zc = z[i];
  const Label lc = label[i];
  for (int k = 0; k < 8; ++k) {
    const int nc = c + dcol[k], nr = r + drow[k];
    if (nc < 0 || nr < row0 || nc >= cols || nr >= row1) continue;
    const std::size_t n = std::size_t(nr) * std::size_t(cols) + std::size_t(nc);
    const Label ln = label[n];
    if (ln == open_label) {
      label[n] = lc;
      if (z[n] <= zc) {
        z[n] = zc;
        pit.push_back(std::uint32_t(n));
      } else {
        open.push(flood_key(z[n], std::uint32_t(n)));
      }
    } else if (ln != lc && ln != void_label) {
      // Two watersheds meet. Both values are final (a cell is raised when it is reached), and
      // every adjacent pair passes here once its later cell is popped.
      meet(lc, ln, std::max(zc, z[n]));
    }
  }
}

}  // namespace terrapolis::hydro
