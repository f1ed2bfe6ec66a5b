// The network as a vector layer of line strings.
// SPDX-License-Identifier: MIT
#pragma once
#include <vector>

#include "io/vector_io.hpp"
#include "network/network.hpp"
#include "roads/road_network.hpp"

namespace terrapolis::network {

/// `network`: every candidate edge as a two-point LineString in `crs` (the sites' CRS), with
/// fields from, to (int, the sites' ids), kind (inter_urban | parent_child | all_sites), kept
/// (int 0/1), length_m (real, geodesic metres) and detour_ratio (real, null when no detour
/// under k x length was found). Field names are a contract with the roads stage.
VectorLayer network_layer(const SiteGraph& graph, const std::vector<sites::Site>& sites, const Crs& crs);

/// The kept edges of a network layer (as network_layer writes it) as links for the roads, each of
/// the class roads::link_class gives the hierarchy levels of its two cities (Points: id, class,
/// population; levels from the rank by population, see the code; all departmental without cities).
/// Throws bad_input naming the layer when a field is missing.
std::vector<roads::Link> road_links(const VectorLayer& network, const VectorLayer* cities);

}  // namespace terrapolis::network
