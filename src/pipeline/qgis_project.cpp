// QGIS 3 .qml styles and .qgs project, written as XML text (QGIS reads both without any plugin).
// SPDX-License-Identifier: MIT
#include "pipeline/qgis_project.hpp"

#include "hydro/option_names.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/text_io.hpp"
#include "roads/corridor.hpp"
#include "roads/road_class.hpp"

namespace terrapolis::pipeline {
namespace {

struct Stop {
  double value;
  const char* color;
  std::string label;
};

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// A complete <spatialrefsys>: QGIS 3.22 rebuilds the CRS from <wkt> (an <authid> alone reads as an
/// invalid CRS unless <srsid>, QGIS's own database key, is also right; it is left out).
std::string spatialrefsys(const CrsDefinition& d) {
  std::ostringstream x;
  x << "<spatialrefsys><wkt>" << escape(d.wkt) << "</wkt><proj4>" << escape(d.proj4) << "</proj4>";
  if (d.epsg) x << "<srid>" << *d.epsg << "</srid><authid>EPSG:" << *d.epsg << "</authid>";
  x << "<description>" << escape(d.description) << "</description><projectionacronym>" << escape(d.projection_acronym)
    << "</projectionacronym><ellipsoidacronym>" << escape(d.ellipsoid_acronym) << "</ellipsoidacronym><geographicflag>"
    << (d.geographic ? "true" : "false") << "</geographicflag></spatialrefsys>";
  return x.str();
}

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

/// `clear_zero`: cells of value 0 drawn transparent (the density on water and unbuildable land,
/// so the terrain's sea shows through, as in the preview).
std::string pseudocolor(const std::vector<Stop>& stops, const char* type = "INTERPOLATED", double opacity = 1.0, bool clear_zero = false) {
  std::ostringstream x;
  x << "<pipe><rasterrenderer type=\"singlebandpseudocolor\" band=\"1\" opacity=\"" << num(opacity)
    << "\" alphaBand=\"-1\" classificationMin=\"" << num(stops.front().value) << "\" classificationMax=\"" << num(stops.back().value) << "\">";
  if (clear_zero)
    x << "<rasterTransparency><singleValuePixelList><pixelListEntry min=\"0\" max=\"0\" percentTransparent=\"100\"/>"
         "</singleValuePixelList></rasterTransparency>";
  x << "<rastershader><colorrampshader colorRampType=\"" << type << "\" classificationMode=\"1\" clip=\"0\">";
  for (const auto& s : stops)
    x << "<item alpha=\"255\" value=\"" << num(s.value) << "\" label=\"" << escape(s.label) << "\" color=\"" << s.color << "\"/>";
  x << "</colorrampshader></rastershader></rasterrenderer><brightnesscontrast brightness=\"0\" contrast=\"0\"/>"
       "<rasterresampler maxOversampling=\"2\"/></pipe>";
  return x.str();
}

std::string paletted(const std::vector<Stop>& entries, double opacity = 1.0) {
  std::ostringstream x;
  x << "<pipe><rasterrenderer type=\"paletted\" band=\"1\" opacity=\"" << num(opacity) << "\" alphaBand=\"-1\"><colorPalette>";
  for (const auto& e : entries)
    x << "<paletteEntry value=\"" << num(e.value) << "\" color=\"" << e.color << "\" alpha=\"" << (std::string(e.color) == "#000000" ? 0 : 255)
      << "\" label=\"" << escape(e.label) << "\"/>";
  x << "</colorPalette></rasterrenderer><brightnesscontrast brightness=\"0\" contrast=\"0\"/><rasterresampler maxOversampling=\"2\"/></pipe>";
  return x.str();
}

std::string gray(double lo, double hi) {
  return "<pipe><rasterrenderer type=\"singlebandgray\" grayBand=\"1\" gradient=\"BlackToWhite\" opacity=\"1\" alphaBand=\"-1\">"
         "<contrastEnhancement><minValue>" + num(lo) + "</minValue><maxValue>" + num(hi) +
         "</maxValue><algorithm>StretchToMinimumMaximum</algorithm></contrastEnhancement></rasterrenderer>"
         "<brightnesscontrast brightness=\"0\" contrast=\"0\"/><rasterresampler maxOversampling=\"2\"/></pipe>";
}

/// One QGIS symbol: a line, a marker or a fill, with a few properties.
std::string symbol(const std::string& name, const std::string& kind, const std::map<std::string, std::string>& props) {
  const std::string layer_class = kind == "line" ? "SimpleLine" : kind == "marker" ? "SimpleMarker" : "SimpleFill";
  std::ostringstream x;
  x << "<symbol name=\"" << name << "\" type=\"" << kind << "\" alpha=\"1\" clip_to_extent=\"1\" force_rhr=\"0\">"
    << "<layer class=\"" << layer_class << "\" enabled=\"1\" locked=\"0\" pass=\"0\">";
  for (const auto& [k, v] : props) x << "<prop k=\"" << k << "\" v=\"" << escape(v) << "\"/>";
  x << "</layer></symbol>";
  return x.str();
}

struct Category {
  std::string value, label, symbol_xml;
};

std::string categorized(const std::string& field, const std::vector<Category>& cats) {
  std::ostringstream x;
  x << "<renderer-v2 type=\"categorizedSymbol\" attr=\"" << escape(field) << "\" forceraster=\"0\" symbollevels=\"0\" enableorderby=\"0\"><categories>";
  for (std::size_t i = 0; i < cats.size(); ++i)
    x << "<category render=\"true\" symbol=\"" << i << "\" value=\"" << escape(cats[i].value) << "\" label=\"" << escape(cats[i].label) << "\"/>";
  x << "</categories><symbols>";
  for (const auto& c : cats) x << c.symbol_xml;
  x << "</symbols></renderer-v2>";
  return x.str();
}

std::string single(const std::string& symbol_xml) {
  return "<renderer-v2 type=\"singleSymbol\" forceraster=\"0\" symbollevels=\"0\" enableorderby=\"0\"><symbols>" + symbol_xml +
         "</symbols></renderer-v2>";
}

std::string line(const std::string& name, const std::string& color, double width_mm, const std::string& style = "solid") {
  return symbol(name, "line", {{"line_color", color}, {"line_width", num(width_mm)}, {"line_width_unit", "MM"},
                               {"line_style", style}, {"capstyle", "round"}, {"joinstyle", "round"}});
}

std::string marker(const std::string& name, const std::string& color, double size_mm) {
  return symbol(name, "marker", {{"color", color}, {"name", "circle"}, {"size", num(size_mm)}, {"size_unit", "MM"},
                                 {"outline_color", "35,35,35,255"}, {"outline_width", "0.2"}});
}

std::string fill(const std::string& name, const std::string& color, const std::string& outline) {
  return symbol(name, "fill", {{"color", color}, {"style", "solid"}, {"outline_color", outline}, {"outline_width", "0.3"}});
}

/// Rank of a layer in drawing order (lower draws first, at the bottom).
int draw_rank(Style s) {
  switch (s) {
    case Style::hillshade: return 0;
    case Style::elevation: return 1;
    case Style::flow_direction: case Style::accumulation: case Style::unit_ramp: return 2;
    case Style::mask: case Style::water: return 3;
    case Style::density: case Style::access_minutes: return 4;
    case Style::city_extents: case Style::access_catchments: return 5;
    case Style::streams: return 6;
    case Style::network: return 7;
    case Style::corridors: return 8;
    case Style::existing_roads: return 8;
    case Style::road_sections: return 8;
    case Style::roads: return 9;
    case Style::sections: return 10;
    case Style::junctions: return 11;
    case Style::cities: return 12;
  }
  return 5;
}

std::string layer_id(const OutputFile& o) {
  std::string id = o.name;
  std::replace(id.begin(), id.end(), '.', '_');
  return id;
}

std::string stem(const std::string& name) { return name.substr(0, name.find_last_of('.')); }

}  // namespace

std::string qgis_style_body(const OutputFile& o, const RunState& state) {
  switch (o.style) {
    case Style::elevation: {
      const double lo = state.summary["terrain"]["min_m"].get<double>(), hi = state.summary["terrain"]["max_m"].get<double>();
      // Cells at or below the sea level are water (water.sea_level_m; SRTM seas are exactly 0 m): blue.
      const double sea = state.scenario.resolved["water"]["sea_level_m"].get<double>();
      std::vector<Stop> stops;
      if (lo < sea) stops.push_back({lo, "#08306b", num(lo) + " m"});
      if (lo <= sea) stops.push_back({std::min(sea, hi), "#9ecae1", "sea level"});
      const double base = lo <= sea ? std::min(sea, hi) + 1e-3 : lo, top = std::max(hi, base + 1);
      stops.push_back({base, "#1a9641", num(lo <= sea ? std::min(sea, hi) : lo) + " m"});
      stops.push_back({base + 0.25 * (top - base), "#a6d96a", ""});
      stops.push_back({base + 0.5 * (top - base), "#ffffbf", ""});
      stops.push_back({base + 0.75 * (top - base), "#c08040", ""});
      stops.push_back({top, "#ffffff", num(top) + " m"});
      return pseudocolor(stops, "INTERPOLATED", 0.55);
    }
    case Style::hillshade: return gray(1, 255);
    case Style::unit_ramp:
      return pseudocolor({{0, "#440154", "0"}, {0.25, "#3b528b", ""}, {0.5, "#21918c", ""}, {0.75, "#5ec962", ""}, {1, "#fde725", "1"}});
    case Style::density:
      return pseudocolor({{0, "#ffffb2", "0 (empty)"}, {0.25, "#fecc5c", ""}, {0.5, "#fd8d3c", ""}, {0.75, "#f03b20", ""}, {1, "#bd0026", "1 (most attractive)"}},
                         "INTERPOLATED", 0.7, true);
    case Style::mask: return paletted({{0, "#000000", "not buildable"}, {1, "#4daf4a", "buildable"}}, 0.4);
    case Style::water: return paletted({{0, "#000000", "land"}, {1, "#2171b5", "inland water"}}, 0.8);
    case Style::flow_direction:
    {
      // The codes of the run's convention (hydro.d8_codes), one colour per direction.
      const hydro::D8Codes codes = hydro::kD8Codes.at(state.scenario.resolved["hydro"]["d8_codes"].get<std::string>());
      const char* colours[8] = {"#e41a1c", "#377eb8", "#4daf4a", "#984ea3", "#ff7f00", "#ffff33", "#a65628", "#f781bf"};
      const char* names[8] = {"E", "SE", "S", "SW", "W", "NW", "N", "NE"};
      std::vector<Stop> entries;
      for (int k = 0; k < 8; ++k) entries.push_back({double(hydro::d8_code(k, codes)), colours[k], names[k]});
      return paletted(entries);
    }
    case Style::accumulation:
      // accumulation.tif of a run is in km2 (the hydro stage writes km2).
      return pseudocolor({{0, "#f7fbff", "0"}, {0.1, "#c6dbef", ""}, {1, "#6baed6", "1 km2"}, {10, "#2171b5", ""}, {100, "#08306b", "100 km2"}});
    case Style::streams: {
      std::vector<Category> cats;
      const char* blues[] = {"#9ecae1", "#6baed6", "#4292c6", "#2171b5", "#08519c", "#08306b", "#08306b", "#08306b"};
      for (int order = 1; order <= 8; ++order)
        cats.push_back({std::to_string(order), "order " + std::to_string(order), line(std::to_string(order - 1), blues[order - 1], 0.2 + 0.25 * order)});
      cats.push_back({"", "order 9 and more", line("8", blues[7], 2.5)});  // "" = every other value
      return categorized("strahler", cats);
    }
    case Style::cities: {
      std::vector<Category> cats;
      const char* colors[] = {"#67000d", "#a50f15", "#cb181d", "#ef3b2c", "#fb6a4a", "#fc9272"};
      for (int c = 0; c < 6; ++c)
        cats.push_back({std::to_string(c), "class " + std::to_string(c), marker(std::to_string(c), colors[c], 4.5 - 0.6 * c)});
      cats.push_back({"", "smaller classes", marker("6", "#fcbba1", 1.2)});  // "" = every other value
      return categorized("class", cats);
    }
    case Style::city_extents: return single(fill("0", "239,59,44,60", "165,15,21,255"));
    case Style::network:
      return categorized("kept", {{"1", "kept link", line("0", "#252525", 0.5)}, {"0", "removed candidate", line("1", "#bdbdbd", 0.2, "dash")}});
    case Style::roads:
    case Style::sections: {
      std::vector<Category> cats;
      for (const roads::RoadClassStyle& s : roads::kRoadClasses)
        cats.push_back({std::string(s.name), std::string(s.label),
                        line(std::to_string(cats.size()), std::string(s.colour), s.width_mm, s.dashed ? "dash" : "solid")});
      return categorized("class", cats);
    }
    case Style::road_sections:
      return categorized("structure", {{"road", "road", line("0", "#636363", 0.4)},
                                       {"bridge", "bridge", line("1", "#1f78b4", 1.4)},
                                       {"tunnel", "tunnel", line("2", "#8c510a", 1.0, "dash")},
                                       {"ferry", "ferry", line("3", "#a6cee3", 0.6, "dot")}});
    case Style::junctions: return single(marker("0", "#252525", 1.6));
    case Style::existing_roads: {  // under the new roads: dark grey, as wide as the class
      std::vector<Category> cats;
      for (const roads::RoadClassStyle& s : roads::kRoadClasses)
        if (s.road_class != roads::RoadClass::maritime) {
          std::string label = "existing ";
          label += s.label;
          cats.push_back({std::string(s.name), label, line(std::to_string(cats.size()), "#525252", s.width_mm + 0.4)});
        }
      return categorized("class", cats);
    }
    case Style::corridors: return roads::corridors_renderer();
    case Style::access_catchments: return single(fill("0", "0,0,0,0", "37,37,37,255"));  // outlines over the travel times
    case Style::access_minutes:
      return pseudocolor({{15, "#1a9850", "15 min or less"}, {30, "#91cf60", "15-30 min"}, {60, "#fee08b", "30-60 min"},
                          {120, "#fc8d59", "1-2 h"}, {1e9, "#d73027", "over 2 h"}},
                         "DISCRETE", 0.7);
  }
  return "";
}

std::string qgis_style(const OutputFile& output, const RunState& state) {
  return "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n<qgis version=\"3.22.16\" styleCategories=\"AllStyleCategories\">" +
         qgis_style_body(output, state) + "<blendMode>0</blendMode></qgis>\n";
}

void write_geopackage(const RunState& state, const std::string& path) {
  // Read back from the run's GeoJSON files, so a rerun that reuses saved stages (--from) writes the
  // same GeoPackage as the run that saved them.
  std::vector<VectorLayer> layers;
  std::vector<LayerStyle> styles;
  for (const OutputFile& o : state.outputs) {
    if (o.raster) continue;
    layers.push_back(read_vector((state.folder / o.name).string(), state.grid.georef.crs));
    layers.back().name = stem(o.name);
    styles.push_back({stem(o.name), qgis_style(o, state), o.description});
  }
  std::vector<const VectorLayer*> pointers;
  for (const VectorLayer& l : layers) pointers.push_back(&l);
  write_vectors(path, pointers, styles, true);
}

void write_qgis_styles_and_project(const RunState& state) {
  const std::string srs = spatialrefsys(crs_definition(state.grid.georef.crs));
  const std::string srs_lonlat = spatialrefsys(crs_definition(wgs84()));

  std::vector<const OutputFile*> layers;
  for (const auto& o : state.outputs) layers.push_back(&o);
  std::stable_sort(layers.begin(), layers.end(), [](auto* a, auto* b) { return draw_rank(a->style) > draw_rank(b->style); });

  std::ostringstream tree, project_layers, order;
  std::map<std::string, std::vector<const OutputFile*>> by_stage;
  std::vector<std::string> stage_order;
  for (auto* o : layers) {
    if (!by_stage.count(o->stage)) stage_order.push_back(o->stage);
    by_stage[o->stage].push_back(o);
  }
  for (const auto& stage : stage_order) {
    tree << "<layer-tree-group name=\"" << escape(stage) << "\" checked=\"Qt::Checked\" expanded=\"1\"><customproperties/>";
    for (auto* o : by_stage[stage]) {
      // Only the most useful layers are shown at first; the rest are one click away.
      const bool visible = o->style != Style::elevation && o->style != Style::flow_direction && o->style != Style::accumulation &&
                           o->style != Style::unit_ramp && o->style != Style::mask && o->style != Style::network &&
                           o->style != Style::access_minutes;
      tree << "<layer-tree-layer id=\"" << layer_id(*o) << "\" name=\"" << escape(stem(o->name)) << "\" source=\"./" << o->name
           << "\" providerKey=\"" << (o->raster ? "gdal" : "ogr") << "\" checked=\"" << (visible ? "Qt::Checked" : "Qt::Unchecked")
           << "\" expanded=\"0\"><customproperties/></layer-tree-layer>";
    }
    tree << "</layer-tree-group>";
  }
  for (auto* o : layers) {
    const std::string body = qgis_style_body(*o, state);
    write_text_file((state.folder / (stem(o->name) + ".qml")).string(), qgis_style(*o, state), true);
    project_layers << "<maplayer type=\"" << (o->raster ? "raster" : "vector") << "\""
                   << (o->raster ? "" : " geometry=\"\"") << "><id>" << layer_id(*o) << "</id><datasource>./" << o->name
                   << "</datasource><layername>" << escape(stem(o->name)) << "</layername><srs>" << (o->raster ? srs : srs_lonlat)
                   << "</srs><abstract>" << escape(o->description) << "</abstract><provider>" << (o->raster ? "gdal" : "ogr")
                   << "</provider>" << body << "<blendMode>0</blendMode></maplayer>";
    order << "<item>" << layer_id(*o) << "</item>";
  }
  std::ostringstream out;
  out << "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
      << "<qgis projectname=\"Terrapolis run\" version=\"3.22.16\"><title>Terrapolis run</title>"
      << "<projectCrs>" << srs << "</projectCrs>"
      << "<layer-tree-group><customproperties/>" << tree.str() << "<custom-order enabled=\"0\">" << order.str() << "</custom-order></layer-tree-group>"
      << "<projectlayers>" << project_layers.str() << "</projectlayers>"
      // QGIS reads <projectCrs> only when SpatialRefSys/ProjectionsEnabled is set.
      << "<properties><Paths><Absolute type=\"bool\">false</Absolute></Paths>"
      << "<SpatialRefSys><ProjectionsEnabled type=\"int\">1</ProjectionsEnabled></SpatialRefSys></properties></qgis>\n";
  write_text_file((state.folder / "project.qgs").string(), out.str(), true);
}

}  // namespace terrapolis::pipeline
