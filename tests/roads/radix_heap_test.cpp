// The radix heap pops what a sorted list would, for monotone keys, and re-keys in place.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "roads/radix_heap.hpp"

using namespace terrapolis::roads;

namespace {
struct Item {
  double f;
  int id;
};
}  // namespace

TEST(RadixHeap, PopsKeysInOrderAgainstASortedList) {
  // A Dijkstra-like run: each pop pushes a few keys at or above it (some equal, some huge).
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> step(0, 50);
  for (int trial = 0; trial < 20; ++trial) {
    RadixHeap<Item> heap;
    std::vector<double> slow;  // the obvious queue: every key, smallest taken each time
    int id = 0;
    heap.push({0.0, id++});
    slow.push_back(0.0);
    double last = 0;
    while (!heap.empty()) {
      ASSERT_EQ(heap.size(), slow.size());
      const Item top = heap.pop();
      const auto it = std::min_element(slow.begin(), slow.end());
      ASSERT_EQ(top.f, *it) << trial;
      slow.erase(it);
      ASSERT_GE(top.f, last);
      last = top.f;
      EXPECT_EQ(heap.floor(), top.f);
      if (id < 3000)
        for (int k = int(rng() % 4); k-- > 0;) {
          const double f = rng() % 5 == 0 ? top.f : top.f + step(rng) * (rng() % 7 == 0 ? 1e6 : 1.0);
          heap.push({f, id++});
          slow.push_back(f);
        }
    }
    EXPECT_TRUE(slow.empty());
  }
}

TEST(RadixHeap, RaisesKeysBelowTheLastPopAndRekeys) {
  RadixHeap<Item> heap;
  heap.push({10.0, 0});
  heap.push({20.0, 1});
  EXPECT_EQ(heap.pop().id, 0);
  heap.push({10.0 - 1e-12, 2});  // rounding below the last pop: raised to it, popped first
  const Item raised = heap.pop();
  EXPECT_EQ(raised.id, 2);
  EXPECT_EQ(raised.f, 10.0);
  heap.push({30.0, 3});
  // Re-key: 1 -> 40, 3 -> 5 (below the old floor: the floor follows the new keys).
  heap.rekey([](Item& e) { e.f = e.id == 1 ? 40.0 : 5.0; });
  EXPECT_EQ(heap.floor(), 5.0);
  EXPECT_EQ(heap.pop().id, 3);
  EXPECT_EQ(heap.pop().id, 1);
  EXPECT_TRUE(heap.empty());
}
