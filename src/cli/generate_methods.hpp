// `terrapolis generate --method coast|planar`: options of the two skeleton generators and their runs.
// SPDX-License-Identifier: MIT
#pragma once
#include <CLI/CLI.hpp>

#include <string>

#include "cli/command.hpp"
#include "core/raster.hpp"
#include "io/vector_io.hpp"
#include "terrain/planar_basins.hpp"
#include "terrain/river_grammar.hpp"

namespace terrapolis::cli {

/// What a skeleton generator leaves for the command to write.
struct GeneratedRegion {
  VectorLayer skeleton;                                        ///< rivers and ridges in the grid's CRS
  std::vector<std::pair<std::string, std::string>> metadata;   ///< provenance and figures for the GeoTIFF
};

/// Génévaux et al.'s river networks from a coastline (--method coast).
struct CoastOptions {
  terrain::CoastParams params;
  std::string coast, grammar = "0.2,0.7,0.1";
  void add(CLI::App& app);
  /// Heights on `grid` (its CRS must be projected) and the skeleton; logs the paper's Tab. 1-2 figures.
  GeneratedRegion run(Raster<float>& grid, std::uint64_t seed, Context& context);
  std::array<double, 3> parse_triple_probabilities() const;
};

/// The planar-maps chapter's binary-tree basin (--method planar).
struct PlanarOptions {
  terrain::PlanarParams params;
  std::string tree;
  int nodes = 150;
  void add(CLI::App& app);
  GeneratedRegion run(Raster<float>& grid, std::uint64_t seed, Context& context);
};

}  // namespace terrapolis::cli
