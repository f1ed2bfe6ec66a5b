// SPDX-License-Identifier: MIT
#include "pipeline/descriptions.hpp"

#include <cstdio>
#include <stdexcept>

#include "hydro/flow_directions.hpp"
#include "pipeline/stage_options.hpp"

namespace terrapolis::pipeline {

DescriptionTerms description_terms(const Scenario& scenario) {
  const auto& h = scenario.resolved["hydro"];
  DescriptionTerms t;
  t.fill = h["fill"].get<std::string>();
  t.flow = h["flow"].get<std::string>();
  t.hydrometry = h["hydrometry"].get<std::string>();
  t.d8_codes = hydro::describe(d8_codes(scenario));
  return t;
}

std::string describe_output(const std::string& file, const DescriptionTerms& t) {
  // terrain
  if (file == "elevation.tif") return "Elevation (m), as read from the input DEM";
  if (file == "hillshade.tif") return "Hillshade (Horn 1981), light from 315 deg at 45 deg";
  // hydro
  if (file == "filled.tif") return "Conditioned elevation (m), " + t.fill + " depression handling";
  if (file == "flowdir.tif") return "D8 flow direction, " + t.d8_codes;
  if (file == "accumulation.tif")
    return "Upstream " + (t.accumulation_unit == "cells" ? std::string("cell count") : "area (" + t.accumulation_unit + ")") + ", " + t.flow +
           " routing" + (t.weighted ? ", weighted" : "");
  if (file == "hydrometry.tif") return "Hydrometry in [0,1] (" + t.hydrometry + ")";
  if (file == "basins.tif") return "Drainage basin: 1 + rank of its outlet cell in row-major order (0: nodata)";
  if (file == "streams.geojson") return "Stream reaches with Strahler order, upstream area (km2), length (m)";
  if (file == "inland_water.tif") return "Inland water (1): lakes the DEM flattens, water.water_mask and water.reservoirs";
  // density (Belhadj 2007 §4.2)
  if (file == "coast.tif") return "Coast: share of water between r_min and r_max around the cell, over its maximum on land (0..1; 0 on water)";
  if (file == "plateau.tif")
    return "Plateau: share of rough ground between plateau_min and plateau_max altitudes in the ring r_min..r_max, over its maximum on land (0..1)";
  if (file == "plain.tif") return "Plain: 1 - standard deviation of altitude within r_min / maximum variation, clamped (0..1; 0 on water)";
  if (file == "buildable.tif") return "Buildable: 1 habitable, 0 uninhabitable (water, too high, too steep, river bed, excluded), 255 no data";
  if (file == "density.tif") return "Human population density model (MNDPH, Belhadj 2007 4.2): weighted characteristics, 0..1, 0 where uninhabitable";
  // sites, network
  if (file == "cities.geojson") return "City centres with radius, class, population, parent and depth";
  if (file == "city_extents.geojson") return "City discs (geodesic circles)";
  if (file == "network.geojson") return "Candidate links between cities (kept = in the simplified network)";
  // roads
  if (file == "roads.geojson") return "One road per link with class, router, length, cost, grades, structures and its sections";
  if (file == "sections.geojson") return "The network drawn once: each section with the roads using it and their highest class";
  if (file == "junctions.geojson") return "Where three or more sections meet, with their classes";
  if (file == "road_sections.geojson") return "Road, bridge, tunnel and ferry sections";
  if (file == "existing_roads.geojson") return "The given roads (roads.existing) as read: through the cells they cross, with their class";
  if (file == "corridors.geojson") return "Per section of the new roads the carriageway and earthworks zone (cut, fill), and the land take united";
  if (file == "earthworks.tif") return "Terrain after cut-and-fill along the roads (m)";
  // access
  if (file.starts_with("access_minutes") && file.ends_with(".tif")) {  // access_minutes_10000.tif: to the settlements of 10,000+
    const std::string level = file == "access_minutes.tif" ? "" : file.substr(15, file.size() - 19);
    return "Travel time to " + (level.empty() ? std::string("the nearest settlement") : "a settlement of " + level + " people or more") +
           ", minutes (on foot off the roads, by road on them)";
  }
  if (file == "access_nearest.tif") return "Id of the settlement nearest in time (cities.geojson), -1 where none is reached";
  if (file == "access_catchments.geojson") return "Catchment of each settlement (the land nearest to it in time): its people, area (km2) and mean time (minutes)";
  // lake
  if (file == "depth.tif") {
    char level[32];
    std::snprintf(level, sizeof level, "%.2f", t.lake_level_m);
    return "Water depth (m) of a lake at " + std::string(level) + " m";
  }
  throw std::out_of_range("no description of " + file);
}

}  // namespace terrapolis::pipeline
