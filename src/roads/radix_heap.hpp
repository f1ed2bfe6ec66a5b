// A radix heap: a priority queue for monotone non-negative double keys (Ahuja, Mehlhorn, Orlin & Tarjan 1990).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

namespace terrapolis::roads {

/// Min-queue of entries `T` with a public `double f` key >= 0, for searches whose keys never fall
/// below the last key popped (Dijkstra, A* with a consistent heuristic). A non-negative double
/// orders as its bit pattern, so an entry lives in the bucket of the highest bit where its key
/// differs from the last popped key; a pop empties the first non-empty bucket into lower ones. Each
/// entry moves at most 64 times, by sequential vector appends, where a binary heap of millions of
/// entries pays a cache miss per level. A key pushed below the last popped one (float rounding in
/// the caller's keys) is raised to it. Equal keys pop last in, first out: deterministic.
template <class T>
class RadixHeap {
 public:
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  /// No queued key is smaller (the last key popped; 0 before the first pop).
  double floor() const { return std::bit_cast<double>(last_); }
  void push(T e) {
    e.f += 0.0;  // -0 -> +0
    if (bits(e.f) < last_) e.f = floor();
    buckets_[bucket(bits(e.f))].push_back(e);
    ++size_;
  }
  /// Removes and returns an entry of the smallest key. Not on an empty heap.
  T pop() {
    if (buckets_[0].empty()) {
      std::size_t i = 1;
      while (buckets_[i].empty()) ++i;
      std::vector<T>& b = buckets_[i];
      std::uint64_t least = bits(b.front().f);
      for (const T& e : b) least = std::min(least, bits(e.f));
      last_ = least;
      for (const T& e : b) buckets_[bucket(bits(e.f))].push_back(e);  // every one lands below i
      b.clear();
    }
    T e = buckets_[0].back();
    buckets_[0].pop_back();
    --size_;
    return e;
  }
  /// Calls `rekey(entry)` on every entry (it may change the key, to any value >= 0) and restores
  /// the order; the floor becomes the smallest new key.
  template <class F>
  void rekey(F&& rekey) {
    std::vector<T> all;
    all.reserve(size_);
    for (std::vector<T>& b : buckets_) {
      for (T& e : b) {
        rekey(e);
        all.push_back(e);
      }
      b.clear();
    }
    last_ = ~std::uint64_t(0);
    for (const T& e : all) last_ = std::min(last_, bits(e.f));
    if (all.empty()) last_ = 0;
    size_ = 0;
    for (const T& e : all) push(e);
  }

 private:
  static std::uint64_t bits(double k) { return std::bit_cast<std::uint64_t>(k); }
  std::size_t bucket(std::uint64_t k) const { return k == last_ ? 0 : std::size_t(64 - std::countl_zero(k ^ last_)); }
  std::array<std::vector<T>, 65> buckets_;
  std::uint64_t last_ = 0;
  std::size_t size_ = 0;
};

}  // namespace terrapolis::roads
