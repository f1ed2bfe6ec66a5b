// Discharge and river types of stream reaches (Génévaux et al. 2013, rivers paper §5.1-5.2).
// SPDX-License-Identifier: MIT
#pragma once
#include <optional>
#include <string>

#include "core/raster.hpp"
#include "io/raster_io.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::hydro {

/// Mean discharge (m³/s) of a river draining `area_km2`: the power law the paper takes from
/// Dunne and Leopold 1978, φ = 0.42 A^0.69 (§5.1, "Débit"). An empirical mean for temperate
/// basins, not a measurement: climate, soils and abstractions are outside it.
double paper_discharge_m3s(double area_km2);

/// The paper's four types (§5.2): B straight, E sinuous, D braided, and deltas.
enum class RiverType { B, E, D, delta };
const char* river_type_name(RiverType type);

/// Thresholds of the typing. The paper names the rules but gives no figures ("débit suffisamment
/// important", "en dessous d'une certaine distance géodésique"): the defaults are ours, the
/// slope and sinuosity bounds are Rosgen 1994's.
struct RiverTypeOptions {
  double e_max_slope = 0.02;           ///< E (and Rosgen's C, folded into it): slope below 2 %
  double e_min_sinuosity = 1.2;        ///< ... and sinuosity at least 1.2 (Rosgen's C/E bound)
  double braided_discharge_m3s = 10;   ///< D: φ at least this (10 m³/s: A ≈ 100 km²) ...
  double coast_distance_km = 10;       ///< ... and the reach ends within this river distance of a mouth
  double delta_discharge_m3s = 50;     ///< delta: a mouth reach with φ at least this (A ≈ 1,000 km²)
};

/// What decides a reach's type, computed from the DEM.
struct ReachMeasures {
  double discharge_m3s = 0;
  double slope = 0;                    ///< drop over length, from the conditioned DEM (m/m, >= 0)
  double sinuosity = 1;                ///< length along the cells over the geodesic chord (>= 1)
  double to_mouth_km = -1;             ///< river distance from the reach's end to a sea mouth, -1 if it reaches none
  bool mouth = false;                  ///< the reach flows into the sea
};

/// The paper's rules: delta only on a mouth reach at high discharge; D near a mouth at high
/// discharge; else E when gentle and sinuous; else B.
RiverType classify_reach(const ReachMeasures& m, const RiverTypeOptions& options);

/// Throws bad_input naming the command-line option of a threshold out of range.
void check(const RiverTypeOptions& options);

/// Adds `discharge_m3s`, `slope`, `sinuosity`, `to_mouth_km` (null when the river reaches no
/// sea) and `river_type` to every reach of `streams` (extract_streams's layer, on `filled`'s grid).
/// The sea is the cells at or below `sea_level`; without one there is no coast (no D, no delta).
void classify_streams(VectorLayer& streams, const Dem& filled, const std::optional<double>& sea_level, const RiverTypeOptions& options);
/// The same on a grid larger than memory (`grid`'s georeferencing, the filled tiles' mosaic read by
/// `filled`): each reach's ends, and a mouth's neighbours, read cell by cell through a CellSampler.
void classify_streams(VectorLayer& streams, const DemWindowReader& filled, const Georef& grid, const std::optional<double>& sea_level,
                      const RiverTypeOptions& options);

/// A QGIS 3 style (.qml) drawing a classified streams layer by `river_type`, width by discharge.
std::string river_types_qml();

}  // namespace terrapolis::hydro
