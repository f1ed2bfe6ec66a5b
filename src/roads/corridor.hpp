// Road corridors: carriageway and earthworks zone, cut and fill by material, clearing, land take
// (Peytavie 2010 §4.4.3 for the road model, §2.3.4 for the angles of repose).
// SPDX-License-Identifier: MIT
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/raster.hpp"
#include "io/vector_io.hpp"
#include "roads/earthworks.hpp"

namespace terrapolis::roads {

/// The design angle (deg) of cut and fill sides in a material. Sand, stones and earth: the lower
/// bound of Peytavie 2010 table 2.3 (angles of repose of dry, homogeneous material: sand 30-35,
/// stones 40-45, earth 25-40), so a side at that angle stands in any sample of the material.
/// Rock is not in the table: 63.4 deg (1 across for 2 up), a usual cutting in sound rock.
/// Throws bad_input for another name.
double repose_angle_deg(const std::string& material);

struct CorridorOptions {
  double half_width_m = 4;    ///< r: half the carriageway (m)
  double side_angle_deg = 25;  ///< angle of the cut and fill sides where no map says otherwise (deg, 0-90 exclusive)
  /// Optional map of side angles (deg) on the DEM's grid, e.g. from a geology map; NaN or <= 0: side_angle_deg.
  Raster<float> side_angles_deg;
  double max_height_m = 50;   ///< deepest cut / highest fill (bounds the work area; beyond it a wall is needed), m
};

/// Land take, volumes and clearing of a section, a road or a run. A road's figures are the sum of
/// its sections', a run's the sum of its roads' (where two roads' corridors overlap, near a shared
/// junction, the overlap counts for each).
struct CorridorTotals {
  double land_take_ha = 0;   ///< the earthworks zone: carriageway and side slopes (geodesic polygon area)
  double cut_m3 = 0, fill_m3 = 0;
  double cleared_ha = 0;     ///< vegetation cleared: the zone's area times its mean cover (the layer clamped to 0-1)
};

/// One section of a road: the carriageway (half-width r) and, on surface sections, the earthworks
/// zone (half-width R on each side: where the side slopes meet the ground), rings in grid
/// coordinates. Bridges and tunnels have a carriageway only (no earthworks under a deck, piers
/// aside, nor above a tunnel) and take no land.
struct SectionCorridor {
  std::size_t road = 0, section = 0;
  std::string structure;
  double length_m = 0;
  std::vector<GridPoint> carriageway, zone;
  double mean_half_width_m = 0, max_half_width_m = 0;  ///< R over the section's stations, both sides (surface sections)
  double walled_m = 0;  ///< length of sides that do not meet the ground within max_height_m (a wall is needed)
  CorridorTotals totals;
};

struct Corridors {
  std::vector<SectionCorridor> sections;
  std::vector<CorridorTotals> roads;  ///< per road, in the order given
  CorridorTotals run;
  bool vegetation = false;  ///< a vegetation layer was given (cleared_ha means something)
  double half_width_m = 0;  ///< r
};

/// The earthworks options these corridor options imply (side slope = 1 / tan(angle), per cell
/// when a map is given; `slopes` holds the per-cell map and must outlive the result). Throws
/// bad_input for a half-width or an angle out of range.
EarthworkOptions earthwork_options(const CorridorOptions& options, Raster<float>& slopes);

/// Corridors of `roads` (on the TerrainField's surface; its vegetation layer, when set, is the
/// one cleared). Each station of a surface section (the road's points) gets a cross-section on
/// both sides along the normal: levelled to the deck within r, then the side slope
/// |z' - deck| <= (d - r) / side_slope of earthworks() up to R where it meets the ground; cut and
/// fill are the cross-section's areas between ground and z' (m² per metre) times the station's
/// share of the road's length, so the figures do not depend on the DEM's resolution (the
/// levelled DEM of earthworks() gives the same volumes where its cells are small against R).
Corridors corridors(const TerrainField& terrain, const std::vector<const RoadGeometry*>& roads, const CorridorOptions& options);

/// corridors.geojson: per section an "earthworks" polygon (surface sections) and a "carriageway"
/// polygon, with road, section, structure, part, length_m, area_ha (geodesic), half-widths,
/// cut_m3, fill_m3, cleared_ha (null without a vegetation layer), walled_m.
VectorLayer corridors_layer(const TerrainField& terrain, const Corridors& corridors);

/// Appends land_take_ha, cut_m3, fill_m3 and cleared_ha to the roads layer (one feature per road,
/// in the order the corridors were computed).
void add_corridor_fields(VectorLayer& roads_layer, const Corridors& corridors);

/// A QGIS 3 style (.qml) for corridors.geojson: earthworks zones in ochre under the carriageways
/// (road grey, bridge blue, tunnel dashed).
std::string corridors_qml();

/// "land take 12.30 ha, cut 4567 m³, fill 890 m³, vegetation cleared 1.20 ha, 0.05 s" for a
/// command's summary (`seconds`: the time the corridors took).
std::string corridor_summary(const Corridors& corridors, double seconds);

}  // namespace terrapolis::roads
