// The determinism check of a seeded computation: the same bytes at 1 and 2 threads, other bytes for
// another seed (so the seed is read at all).
// SPDX-License-Identifier: MIT
#pragma once
#include <gtest/gtest.h>

#include <cstring>

namespace terrapolis::test {

/// `run(threads, seed)` returns the computed values (a std::vector of trivially copyable values).
template <class Run>
void expect_same_bytes_at_any_thread_count(Run&& run) {
  const auto one = run(1, 5), two = run(2, 5), other = run(2, 6);
  ASSERT_EQ(one.size(), two.size());
  EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(one[0])), 0);
  ASSERT_EQ(one.size(), other.size());
  EXPECT_NE(std::memcmp(one.data(), other.data(), one.size() * sizeof(one[0])), 0);
}

}  // namespace terrapolis::test
