// The spillover graph of Barnes 2016: watershed labels joined by their lowest spill elevation.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <vector>

namespace terrapolis::hydro {

/// An edge of the spillover graph: labels a and b meet, lowest at `spill` (the higher of the two
/// cells' filled elevations over every 8-adjacent pair of cells a, b).
struct SpillEdge {
  std::uint32_t a, b;
  float spill;
};

/// The water level of each of `nodes` labels: the Priority-Flood of the graph from label 0 (the
/// true outlets), level(v) = min over paths to 0 of the highest spill on the path; +inf for labels
/// not connected to 0. Consumes `edges`. Barnes 2016, "Parallel priority-flood depression filling
/// for trillion cell digital elevation models" (Environmental Modelling & Software 86), Alg. 3.
std::vector<float> spill_levels(std::uint32_t nodes, std::vector<SpillEdge>& edges);

/// Keeps one edge per pair of labels, the lowest (sorted by pair): a compact list for storing or sending.
void keep_lowest_edges(std::vector<SpillEdge>& edges);

}  // namespace terrapolis::hydro
