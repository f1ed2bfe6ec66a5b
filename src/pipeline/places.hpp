// Real places (GeoNames, a census) read onto a DEM's land, for calibration and realism figures.
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/raster.hpp"
#include "density/calibration.hpp"
#include "sites/sites.hpp"

namespace terrapolis::pipeline {

/// Places read from `path` (GeoJSON, GPKG or any OGR point layer; CSV with lon/lat or x/y
/// columns in WGS 84) with a numeric `population` (or `pop`) field, kept when they fall on a
/// land cell of `dem` with data, or within two cells of one (a coastal town on a sea cell
/// of a coarse grid is moved to the nearest land cell). `dropped` counts the others.
/// Throws bad_input naming `path` when it cannot be read or has no population field.
std::vector<density::Place> read_places(const std::string& path, const Dem& dem, const std::vector<std::uint8_t>& land, int& dropped);
/// The same on a grid read by windows: `land(c0, r0, cols, rows)` gives the window's land (1),
/// row-major; it is asked for the 5 x 5 cells around each place, clipped to the grid.
using LandWindow = std::function<std::vector<std::uint8_t>(int c0, int r0, int cols, int rows)>;
std::vector<density::Place> read_places(const std::string& path, const Georef& grid, int cols, int rows, const LandWindow& land, int& dropped);

/// The settlements that exist, for sites.existing: the places of `path` (the formats read_places
/// reads) with their populations (rounded to whole people), each on the cell holding it or, when
/// that cell is not buildable or is taken by a larger place, the nearest free buildable cell within
/// two cells; centres at cell centres, as generated sites. Places outside the grid are counted and
/// left out, places without people (population 0 or none) likewise.
struct ExistingPlaces {
  std::vector<sites::Site> sites;  ///< largest first, existing = true, name set
  int without_people = 0;
  std::vector<std::string> outside, moved;  ///< the names of the places left out off the DEM, moved to land
};

/// The run's and the command's warnings about a places file: those outside the DEM (left out) and
/// those moved to land, by name (the first ten, then how many more).
std::vector<std::string> existing_place_warnings(const ExistingPlaces& places);
/// Throws bad_input naming the file and the place when one lies farther than two cells from a free
/// buildable cell, or its population is negative; and when no place with people lies on the grid.
ExistingPlaces read_existing_places(const std::string& path, const sites::Land& land);

/// What of those checks needs no grid (the file, its fields, every population a number >= 0), for
/// a run to refuse a bad file before any stage starts.
void check_existing_places(const std::string& path, const Crs& crs);

}  // namespace terrapolis::pipeline
