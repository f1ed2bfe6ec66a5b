// Distance (in cells) from every cell to the nearest cell of a set, with which cell that is.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstddef>
#include <vector>

namespace terrapolis::generate {

/// Dijkstra over the 8 neighbours (steps 1 and sqrt 2) from the cells where `source` is set;
/// `nearest` gets the index of the source each cell was reached from. Deterministic.
void distance_to(const std::vector<char>& source, int cols, int rows, std::vector<double>& dist, std::vector<std::size_t>& nearest);

}  // namespace terrapolis::generate
