// Road corridors: carriageway and earthworks zone, cut and fill by material, clearing, land take
// (Peytavie 2010 §4.4.3 for the road model, §2.3.4 for the angles of repose).
// SPDX-License-Identifier: MIT
#pragma once
#include <array>
#include <functional>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/polygon_area.hpp"
#include "core/raster.hpp"
#include "io/vector_io.hpp"
#include "roads/earthworks.hpp"
#include "roads/network_sections.hpp"
#include "roads/road_class.hpp"

namespace terrapolis::roads {

/// The design angle (deg) of cut and fill sides in a material. Sand, stones and earth: the lower
/// bound of Peytavie 2010 table 2.3 (angles of repose of dry, homogeneous material: sand 30-35,
/// stones 40-45, earth 25-40), so a side at that angle stands in any sample of the material.
/// Rock is not in the table: 63.4 deg (1 across for 2 up), a usual cutting in sound rock.
/// Throws bad_input for another name.
double repose_angle_deg(const std::string& material);

/// A road class's cross-section (full widths, m): the carriageway (the paved lanes and, on a
/// motorway, the central reserve) and the platform (carriageway and shoulders), levelled to the
/// deck; the side slopes start at its edge.
struct ClassWidths {
  double carriageway_m = 6, platform_m = 9;
};

struct CorridorOptions {
  /// Per class (motorway, national, departmental, local; a ferry link has no corridor). Orders of
  /// magnitude of the French profiles (ICTAAL 2000 for motorways: 2 x 2 lanes of 3.5 m, central
  /// reserve, shoulders; ARP 1994 for 2-lane roads: 7 m or 6 m of lanes and shoulders), not their tables.
  std::array<ClassWidths, 4> widths = {{{17, 25}, {7, 12}, {6, 9}, {5, 7}}};
  /// > 0: r for every road, the carriageway's and the platform's half-width (overrides `widths`), m.
  double half_width_m = 0;
  double side_angle_deg = 25;  ///< angle of the cut and fill sides where no map says otherwise (deg, 0-90 exclusive)
  /// Optional map of side angles (deg) on the DEM's grid, e.g. from a geology map; NaN or <= 0: side_angle_deg.
  Raster<float> side_angles_deg;
  /// Roads by windows with a map of side angles (CorridorWindows::side_angles): the map's
  /// shallowest angle within (0, 90) over the grid, which corridor_reach_m counts; 0: no map.
  double least_side_angle_deg = 0;
  double max_height_m = 50;   ///< deepest cut / highest fill (bounds the work area; beyond it a wall is needed), m
};

/// Land take, volumes and clearing of a section, a road or a run. The land take is the geodesic
/// area of the union of the earthworks zones (a section's, a road's sections', the run's roads'),
/// so ground two zones cover (a hairpin's bends, a junction, a trunk two roads share) counts once;
/// the clearing scales with it. Cut and fill add up the cross-sections (a road's are its sections',
/// a run's its roads': a trunk two roads share counts for each).
struct CorridorTotals {
  double land_take_ha = 0;   ///< the earthworks zone: platform and side slopes
  double cut_m3 = 0, fill_m3 = 0;
  double cleared_ha = 0;     ///< vegetation cleared: the zone's area times its mean cover (the layer clamped to 0-1)
};

/// One section of a road: the carriageway and, on surface sections, the earthworks zone (half-width
/// R on each side: where the side slopes from the platform's edge r meet the ground), each the union
/// of the quadrilaterals its cross-sections sweep between stations (valid polygons even where a
/// hairpin's inner side folds over itself), in the DEM's CRS. Bridges and tunnels have a
/// carriageway only (no earthworks under a deck, piers aside, nor above a tunnel) and take no
/// land; ferries have neither.
struct SectionCorridor {
  std::size_t road = 0, section = 0;
  std::string structure;
  double length_m = 0;
  double half_width_m = 0, carriageway_half_width_m = 0;  ///< r (the platform's) and the carriageway's, m
  std::vector<Polygon> carriageway, zone;
  double mean_half_width_m = 0, max_half_width_m = 0;  ///< R over the section's stations, both sides (surface sections)
  double walled_m = 0;  ///< length of sides that do not meet the ground within max_height_m (a wall is needed)
  CorridorTotals totals;
};

struct Corridors {
  std::vector<SectionCorridor> sections;
  std::vector<CorridorTotals> roads;  ///< per road, in the order given
  CorridorTotals run;
  std::vector<Polygon> land_take;  ///< the run's earthworks zones united (CRS of the DEM)
  bool vegetation = false;  ///< a vegetation layer was given (cleared_ha means something)
};

/// How far (m) from a road's axis its corridor reads the terrain: the widest half-platform and a side
/// rising max_height_m at side_angle_deg, or at least_side_angle_deg when that is shallower.
double corridor_reach_m(const CorridorOptions& options);

/// The earthworks options these corridor options imply for a road of class `road_class` (r: the
/// half-width override or the class's half platform; side slope = 1 / tan(angle), per cell when a
/// map is given; `slopes` holds the per-cell map and must outlive the result). Throws bad_input
/// for a width or an angle out of range.
EarthworkOptions earthwork_options(const CorridorOptions& options, Raster<float>& slopes,
                                   RoadClass road_class = RoadClass::departmental);

/// Corridors of `roads` (on the TerrainField's surface; its vegetation layer, when set, is the
/// one cleared). Each station of a surface section (the road's points) gets a cross-section on
/// both sides along the normal: levelled to the deck within r, then the side slope
/// |z' - deck| <= (d - r) / side_slope of earthworks() up to R where it meets the ground; cut and
/// fill are the cross-section's areas between ground and z' (m² per metre) times the station's
/// share of the road's length, so the figures do not depend on the DEM's resolution (the
/// levelled DEM of earthworks() gives the same volumes where its cells are small against R).
/// `classes`: each road's class (the widths), departmental for all when empty.
///
/// Roads on a grid larger than memory (a run by tiles): with `windows`, `terrain` is the grid's
/// frame (TerrainField::frame) and each road's corridor reads a window of the grid holding the
/// road's points and `margin_cells` around them, one road at a time. A margin of
/// window_margin_cells(0, corridor_reach_m(options), ...) holds every cell a cross-section reads, so
/// the corridors are the whole grid's; the roads' own windows had that margin, so a road's window
/// is no larger than the largest its search read. A map of side angles is read on the same window
/// (`side_angles`), the margin counting its shallowest angle (least_side_angle_deg).
struct CorridorWindows {
  ReadTerrainWindow read;
  int margin_cells = 0;
  bool vegetation = false;  ///< the windows carry a vegetation layer (Corridors::vegetation)
  /// The map of side angles (deg) on a window of the grid, as CorridorOptions::side_angles_deg holds
  /// it on the whole grid; empty: no map.
  using ReadAngles = std::function<Raster<float>(int col0, int row0, int cols, int rows)>;
  ReadAngles side_angles;
};
Corridors corridors(const TerrainField& terrain, const std::vector<const RoadGeometry*>& roads, const CorridorOptions& options,
                    const std::vector<RoadClass>& classes = {}, const CorridorWindows* windows = nullptr);

struct Road;
/// The corridors of routed roads, each at its class's widths (the roads and path commands, the run),
/// of their new parts only when roads were given (roads.existing): `existing` the given roads'
/// cells (NetworkResult::existing); a segment whose two ends lie on such cells has its earthworks
/// already and is left out, each road's other stretches get their corridors (sections numbered
/// along the road; a road's totals add up its stretches'). `windows`: as corridors().
Corridors road_corridors(const TerrainField& terrain, const std::vector<Road>& roads, const CorridorOptions& options,
                         const GivenCells& existing = {}, const CorridorWindows* windows = nullptr);

/// corridors.geojson: per section an "earthworks" polygon (surface sections) and a "carriageway"
/// polygon, with road, section, structure, part, length_m, area_ha (geodesic), half-widths,
/// cut_m3, fill_m3, cleared_ha (null without a vegetation layer), walled_m; then the run's
/// "land_take" polygons (the zones united; road and section null).
VectorLayer corridors_layer(const TerrainField& terrain, const Corridors& corridors);

/// Appends land_take_ha, cut_m3, fill_m3 and cleared_ha to the roads layer (one feature per road,
/// in the order the corridors were computed).
void add_corridor_fields(VectorLayer& roads_layer, const Corridors& corridors);

/// A QGIS 3 style (.qml) for corridors.geojson: the land take's dashed outline, earthworks zones in
/// ochre under the carriageways (road grey, bridge blue, tunnel dashed); its <renderer-v2> alone
/// for a run's project.
std::string corridors_qml();
std::string corridors_renderer();

/// "land take 12.30 ha, cut 4567 m³, fill 890 m³, vegetation cleared 1.20 ha, 0.05 s" for a
/// command's summary (`seconds`: the time the corridors took).
std::string corridor_summary(const Corridors& corridors, double seconds);

}  // namespace terrapolis::roads
