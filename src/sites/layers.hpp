// The sites as vector layers: cities (points), city extents (geodesic circles), and back.
// SPDX-License-Identifier: MIT
#pragma once
#include <string>
#include <vector>

#include "io/vector_io.hpp"
#include "sites/sites.hpp"

namespace terrapolis::sites {

/// `cities` points in `crs` (the DEM's) with fields id (int), radius_m (real), class (int,
/// 0 = largest radius), population (int), density (real), parent (int, null for roots),
/// depth (int) and seed (int, the placement's seed). Field names are a contract with the roads stage.
VectorLayer cities_layer(const SitesResult& result, const Crs& crs);

/// `city_extents`: each disc as a geodesic circle of `vertices` points (WGS 84), fields id, radius_m, class, depth, seed.
VectorLayer city_extents_layer(const SitesResult& result, const Crs& crs, int vertices = 72);

/// Sites from a cities layer (a planner's own or `cities_layer`'s): points with radius_m
/// (metres, > 0); optional id (unique integers, default the feature's position) and parent
/// (an id, null or absent for roots), population (people, default 0). Parents become indices into the returned list.
/// Throws bad_input naming `path` for a missing field, a bad value or an unknown parent.
std::vector<Site> sites_from_layer(const VectorLayer& layer, const std::string& path);

/// Puts sites read back from a layer on the cell centres of the grid they were placed on (`georef`,
/// `cols` x `rows`): GeoJSON keeps 7 decimals of lon/lat, and the network's Delaunay triangulation of
/// grid-aligned, often co-circular points must see the positions the sites stage computed. Rotated
/// grids keep the positions as read.
void snap_to_cells(std::vector<Site>& sites, const Georef& georef, int cols, int rows);

}  // namespace terrapolis::sites
