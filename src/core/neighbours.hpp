// The 8-neighbour order used everywhere: drawn once, here.
// SPDX-License-Identifier: MIT
#pragma once
#include <array>

namespace terrapolis {

//   5 6 7        row - 1  (north)
//   4 . 0        row
//   3 2 1        row + 1  (south)
// Index k starts east and turns clockwise on the map (row 0 is north), so k+4 mod 8 is the opposite.
inline constexpr std::array<int, 8> dcol = {1, 1, 0, -1, -1, -1, 0, 1};
inline constexpr std::array<int, 8> drow = {0, 1, 1, 1, 0, -1, -1, -1};
inline constexpr int opposite(int k) { return (k + 4) & 7; }
inline constexpr bool is_diagonal(int k) { return (k & 1) != 0; }

}  // namespace terrapolis
