// SPDX-License-Identifier: MIT
#include "cli/generate_report.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/geodesy.hpp"
#include "hydro/hydro.hpp"
#include "generate/river_checks.hpp"

namespace terrapolis::cli {
namespace {

using json = nlohmann::ordered_json;

json rounded(double v, double unit = 1e-3) { return std::isfinite(v) ? json(std::round(v / unit) * unit) : json(nullptr); }
json optional_ratio(const std::optional<double>& v) { return v ? rounded(*v) : json(nullptr); }
std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

std::string skeleton_report(const generate::GeneratedTerrain& terrain, double cell_m, const std::string& method,
                            const Log& log, Progress& progress) {
  const generate::RiverRidgePlan& plan = terrain.plan;
  const Dem& dem = terrain.dem;
  hydro::HydroOptions options;
  options.sea_level = terrain.sea_level_m;
  options.with_hydrometry = false;
  options.with_streams = false;
  const hydro::HydroResult d8 = hydro::run_hydro(dem, options, progress);

  double river_m = 0;
  for (const auto& r : plan.rivers) river_m += generate::line_length_m(r.line, cell_m);
  const double threshold_m2 = terrain.channel_head_m2 ? *terrain.channel_head_m2 : generate::channel_head_threshold_m2(plan, d8.accumulation);
  const VectorLayer streams = hydro::extract_streams(d8.d8, d8.accumulation, cell_metrics(dem.georef(), dem.cols(), dem.rows()),
                                                     {threshold_m2 / 1e6}, progress);
  const auto order = generate::stream_order_raster(streams, dem.georef(), dem.cols(), dem.rows());
  const generate::D8Consistency consistency = generate::d8_consistency(plan, order, dem, cell_m, 2.0, terrain.sea_level_m);
  const generate::HortonRatios horton = generate::horton_ratios(plan, cell_m);
  const double density = generate::drainage_density(plan, dem, cell_m, terrain.sea_level_m);
  int top = 0;
  for (const auto& r : plan.rivers) top = std::max(top, r.strahler);

  log.info("generate: " + std::to_string(plan.rivers.size()) + " river reaches (" + fixed(river_m / 1000, 1) +
           " km, Strahler order up to " + std::to_string(top) + "), " + std::to_string(plan.ridges.size()) + " ridge lines");
  log.info("generate: " + fixed(100 * consistency.share(), 1) + " % of the river length within 2 cells of a D8 stream of the same or adjacent order" +
           " (D8 streams from " + fixed(threshold_m2 / 1e6, 3) + " km2); " + std::to_string(consistency.ending_in_pit) + " of " +
           std::to_string(consistency.mouths) + " mouths end in a pit");
  log.info("generate: Horton ratios Rb " + (horton.bifurcation ? fixed(*horton.bifurcation, 2) : std::string("n/a")) + ", Rl " +
           (horton.length ? fixed(*horton.length, 2) : std::string("n/a")) + " (real basins: Rb 3-5, Rl 1.5-3.5); drainage density " +
           fixed(density, 3) + " km/km2");

  json report;
  report["method"] = method;
  report["river_reaches"] = plan.rivers.size();
  report["ridge_lines"] = plan.ridges.size();
  report["river_length_km"] = rounded(river_m / 1000);
  report["max_strahler_order"] = top;
  report["d8_consistency"] = {{"share_within_2_cells", rounded(consistency.share(), 1e-4)},
                              {"d8_stream_threshold_km2", rounded(threshold_m2 / 1e6, 1e-6)},
                              {"mouths", consistency.mouths},
                              {"mouths_ending_in_pit", consistency.ending_in_pit}};
  json n = json::array(), l = json::array();
  for (std::size_t w = 0; w < horton.streams.size(); ++w) n.push_back(horton.streams[w]), l.push_back(rounded(horton.mean_length_m[w], 0.1));
  report["horton"] = {{"streams_by_order", n}, {"mean_length_m_by_order", l},
                      {"bifurcation_ratio", optional_ratio(horton.bifurcation)}, {"length_ratio", optional_ratio(horton.length)}};
  report["drainage_density_km_per_km2"] = rounded(density, 1e-4);
  if (!terrain.figures.empty()) {
    std::string line;
    json figures;
    for (const auto& [name, value] : terrain.figures) {
      figures[name] = rounded(value, 1e-4);
      line += (line.empty() ? "" : ", ") + name + " " + fixed(value, 3);
    }
    report["figures"] = figures;
    log.info("generate: " + line);
  }
  return report.dump(2) + "\n";
}

}  // namespace terrapolis::cli
