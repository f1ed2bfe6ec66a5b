// The erosion run: the domain (and its loose layer), the iterations of each process, and what they moved.
// SPDX-License-Identifier: MIT
#include "erode/erosion.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "core/error.hpp"
#include "erode/domain.hpp"

namespace terrapolis::erode {

double material_angle_deg(const std::string& material) {
  // Peytavie 2010, Tab. 2.3 (dry, homogeneous materials): the middle of each range.
  if (material == "sand") return 32.5;    // 30-35
  if (material == "stones") return 42.5;  // 40-45
  if (material == "earth") return 32.5;   // 25-40
  if (material == "snow") return 60.0;    // 40-80
  throw bad_input("/erode/material: unknown material '" + material + "' (sand, stones, earth, snow)");
}

void check_settings(const ErodeOptions& o) {
  if (o.iterations < 0) throw bad_input("/erode/iterations: must be >= 0");
  const HydraulicOptions& h = o.hydraulic;
  if (!(h.rain_m > 0) || !(h.dt_s > 0) || !(h.capacity_s >= 0)) throw bad_input("/erode: rain, dt and capacity must be > 0");
  if (!(h.dissolve >= 0 && h.dissolve <= 1) || !(h.deposit >= 0 && h.deposit <= 1) || !(h.evaporation >= 0 && h.evaporation < 1))
    throw bad_input("/erode: dissolve and deposit must lie in [0, 1], evaporation in [0, 1)");
  if (!(o.thermal.angle_deg > 0 && o.thermal.angle_deg < 90)) throw bad_input("/erode/angle_deg: must lie in (0, 90) degrees");
  if (!(o.thermal.rate > 0 && o.thermal.rate <= 1)) throw bad_input("/erode: the thermal rate must lie in (0, 1]");
  const LayeredOptions& l = o.layered;
  if (!(l.erodibility >= 0 && l.erodibility <= 1)) throw bad_input("/erode/erodibility: must lie in [0, 1]");
  if (!(l.voxel_m > 0) || !(l.radius_m > 0)) throw bad_input("/erode: voxel_m and radius_m must be > 0");
  if (!(l.strata_m >= 0) || !(l.hard_ratio >= 0 && l.hard_ratio <= 1)) throw bad_input("/erode: strata_m must be >= 0, hard_ratio in [0, 1]");
}

namespace {

Domain make_domain(const Dem& dem, const CellMetrics& metrics, const Raster<std::uint8_t>* mask) {
  if (mask && (mask->cols() != dem.cols() || mask->rows() != dem.rows())) throw bad_input("/erode/mask: not on the DEM's grid");
  Domain d;
  d.cols = dem.cols();
  d.rows = dem.rows();
  d.metrics = &metrics;
  d.height.assign(dem.values().begin(), dem.values().end());
  d.in.resize(dem.size());
  for (std::size_t i = 0; i < dem.size(); ++i) d.in[i] = !std::isnan(dem[i]) && (!mask || (*mask)[i] != 0);
  return d;
}

/// The loose layer of a layered ground: the given thickness on the cells with data (outside the mask
/// it stays as given), 0 elsewhere.
void add_loose_layer(Domain& d, const Raster<float>* loose_m) {
  d.loose.assign(d.height.size(), 0.0);
  if (!loose_m) return;
  check_grid("/erode/loose", *loose_m, d);
  for (std::size_t i = 0; i < d.loose.size(); ++i)
    if (!std::isnan(d.height[i]) && !std::isnan((*loose_m)[i])) d.loose[i] = checked_thickness("/erode/loose", (*loose_m)[i]);
}

/// The processes of one run over a domain, each present when the options ask for it.
struct Processes {
  std::optional<Hydraulic> water;
  std::optional<Thermal> slide;
  std::optional<GlobalErosion> weathering;
  double loosened_m3 = 0;

  Processes(Domain& domain, const ErodeOptions& o) {
    if (o.process == Process::layered) {
      add_loose_layer(domain, o.layered.loose_m);
      if (o.layered.rockfall_m) loosened_m3 = break_off(domain, *o.layered.rockfall_m);
      if (o.layered.erodibility > 0) weathering.emplace(domain, o.layered);
    }
    if (o.process == Process::hydraulic || o.process == Process::both) water.emplace(domain, o.hydraulic);
    if (o.process != Process::hydraulic) slide.emplace(domain, o.thermal);  // after the loose layer is laid
  }
  /// One iteration; false once nothing can change any more (only slides left, and none moved).
  bool step() {
    if (water) water->step();
    if (weathering) loosened_m3 += weathering->step();
    const double moved = slide ? slide->step() : 0.0;
    return water || weathering || moved > 0;
  }
};

/// The loose thickness at the end, m (0 without a loose layer, NaN on nodata; a film of rounding
/// below 0 left by a cell that sent all it held shows as 0).
Raster<float> loose_thickness(const Dem& dem, const Domain& domain) {
  Raster<float> loose = dem.like<float>(0);
  for (std::size_t i = 0; i < loose.size(); ++i)
    if (std::isnan(dem[i])) loose[i] = NAN;
    else if (!domain.loose.empty()) loose[i] = float(std::max(0.0, domain.loose[i]));
  return loose;
}

/// The report's volumes from the float output against the float input (one pass, in cell order).
void measure(const Dem& before, const Dem& after, const CellMetrics& metrics, ErodeReport& report) {
  for (int r = 0; r < before.rows(); ++r) {
    const double area = metrics.area_m2[std::size_t(r)];
    for (int c = 0; c < before.cols(); ++c) {
      const double change = double(after(c, r)) - double(before(c, r));
      if (std::isnan(change)) continue;  // nodata
      if (change < 0) report.eroded_m3 -= change * area, report.max_lowering_m = std::max(report.max_lowering_m, -change);
      if (change > 0) report.deposited_m3 += change * area, report.max_raising_m = std::max(report.max_raising_m, change);
    }
  }
}

}  // namespace

Dem erode(const Dem& dem, const CellMetrics& metrics, const ErodeOptions& options, const Raster<std::uint8_t>* mask,
          Progress& progress, ErodeReport* report, Raster<float>* loose) {
  check_settings(options);
  const auto start = std::chrono::steady_clock::now();
  Domain domain = make_domain(dem, metrics, mask);
  Processes run(domain, options);
  int done = 0;
  {
    ProgressStep step(progress, "erode");
    bool changing = true;
    while (changing && done < options.iterations) {
      changing = run.step();  // stable: further iterations would change nothing
      ++done;
      step.update(double(done) / options.iterations);
    }
  }
  if (run.water) run.water->settle();
  Dem out = dem;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (domain.in[i]) out[i] = float(domain.height[i]);
  if (loose) *loose = loose_thickness(dem, domain);
  if (report) {
    report->iterations = done;
    measure(dem, out, metrics, *report);
    report->carried_out_m3 = run.water ? run.water->sediment_out_m3 : 0.0;
    report->water_out_m3 = run.water ? run.water->water_out_m3 : 0.0;
    report->loosened_m3 = run.loosened_m3;
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    report->seconds_per_iteration = done > 0 ? report->seconds / done : 0.0;
  }
  return out;
}

}  // namespace terrapolis::erode
