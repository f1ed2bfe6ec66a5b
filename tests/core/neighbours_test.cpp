// The 8-neighbour order: opposite directions and unit steps.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include "core/neighbours.hpp"

using namespace terrapolis;

TEST(Neighbours, OppositeUndoesTheStep) {
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(dcol[k] + dcol[opposite(k)], 0);
    EXPECT_EQ(drow[k] + drow[opposite(k)], 0);
    EXPECT_EQ(is_diagonal(k), dcol[k] != 0 && drow[k] != 0);
  }
  EXPECT_EQ(dcol[0], 1);   // east first
  EXPECT_EQ(drow[2], 1);   // south is row + 1 (row 0 is north)
}
