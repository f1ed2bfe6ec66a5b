// What every terrain generator of `terrapolis generate --method` takes and gives.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/progress.hpp"
#include "core/raster.hpp"
#include "generate/planar_basins.hpp"
#include "generate/river_fractal.hpp"
#include "generate/river_grammar.hpp"
#include "generate/river_ridge_plan.hpp"
#include "terrain/subdivision.hpp"

namespace terrapolis::generate {

struct GenerateRequest {
  Raster<float> grid;            ///< the empty grid (NaN), georeferenced; square cells of cell_m
  double cell_m = 30;
  std::uint64_t seed = 1;
  double relief_m = 1000;        ///< height of the highest crest above the outlets
  terrain::DmmcParams dmmc;      ///< the DMMC that fills between the skeleton's cells
  /// dmmc: which way each sketch cell extrapolates (grid's size, row-major; empty: the global rule)
  std::vector<terrain::ExtrapolationLabel> labels;
  std::vector<std::vector<GridPoint>> lines;  ///< user lines (flow: ridges), cell coordinates
  std::vector<GridPoint> points;               ///< user points (tectonic: mountain points)
  std::vector<std::vector<GridPoint>> polygons;  ///< user polygon rings (coast: the land; empty: a seeded island)
  CoastParams coast;             ///< coast: Génévaux et al.'s parameters (seed taken from `seed`)
  PlanarParams planar;           ///< planar: the planar-maps chapter's parameters (seed taken from `seed`)
  RiverFractalParams river;      ///< river: eq. 1.2-1.3 and the bed (top_down and relief taken from dmmc and relief_m)
  Progress* progress = nullptr;
};

struct GeneratedTerrain {
  Raster<float> dem;                  ///< metres, on the request's grid
  RiverRidgePlan plan;                ///< what the DEM was built from (empty for plain DMMC)
  std::optional<double> sea_level_m;  ///< cells at or below it are sea
  /// Upstream area (m²) at which the generator starts its rivers: the D8 stream threshold of the
  /// consistency check. None: the median D8 area at the generated channel heads.
  std::optional<double> channel_head_m2;
  std::vector<std::pair<std::string, double>> timings;  ///< seconds by phase, for logs only (never in files)
  std::vector<std::pair<std::string, double>> figures;  ///< the method's own figures (e.g. the paper's Tab. 2), for the report
};

}  // namespace terrapolis::generate
