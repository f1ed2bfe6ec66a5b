// Erosion of a DEM for what-if studies: hydraulic (virtual pipes), thermal (angle of repose) and
// layered (loose material on bedrock: Peytavie's global and local erosion and granular deposits).
// SPDX-License-Identifier: MIT
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "core/geodesy.hpp"
#include "core/progress.hpp"
#include "core/raster.hpp"

namespace terrapolis::erode {

/// layered: Peytavie 2010 §2.3, a ground of bedrock under loose material; the rock weathers into
/// loose material (global erosion, §2.3.2), is broken off by a tool (local erosion, §2.3.3), and only
/// the loose material slides to its angle of repose (§2.3.4).
enum class Process { hydraulic, thermal, both, layered };

/// Virtual-pipe hydraulic erosion (Mei, Decaudin & Hu 2007, "Fast hydraulic erosion simulation and
/// visualization on GPU", Pacific Graphics): per iteration, rain, pipe fluxes, water and velocity,
/// dissolution and deposition against the capacity C = Kc sin(alpha) |v|, sediment transport,
/// evaporation.
struct HydraulicOptions {
  double rain_m = 0.01;          ///< water added to every cell per iteration, m (> 0)
  double capacity_s = 0.002;      ///< Kc: sediment height carried per (m/s of speed x sin of slope), s
  double dissolve = 0.3;         ///< Ks: share of the capacity deficit dissolved per iteration, [0, 1]
  double deposit = 0.3;          ///< Kd: share of the capacity excess deposited per iteration, [0, 1]
  double evaporation = 0.02;     ///< Ke: share of the water evaporated per iteration, [0, 1)
  double dt_s = 0.5;             ///< time step of the pipe model, s
  double min_slope = 0.02;       ///< sin(alpha) floor, so that water on flat cells still carries
};

/// Thermal erosion (Musgrave, Kolb & Mace 1989, "The synthesis and rendering of eroded fractal
/// terrains", SIGGRAPH) with Peytavie's stabilisation (Peytavie 2010, thesis §2.3.4): where the
/// slope to a lower neighbour exceeds tan(angle of repose), material moves downhill, shared among
/// the lower neighbours in proportion to their excess.
struct ThermalOptions {
  double angle_deg = 32.5;  ///< angle of repose, degrees in (0, 90); sand (Peytavie Tab. 2.3: 30-35)
  /// Per-cell angles (degrees) on the DEM's grid, overriding angle_deg where finite; nullptr: none.
  const Raster<float>* angles_deg = nullptr;
  /// Share of a cell's largest excess height moved per iteration, (0, 1]: Peytavie's constant a,
  /// below 1 so that the piles do not oscillate; 0.5 equalises two cells in one step.
  double rate = 0.5;
};

/// The two-layer ground of Peytavie 2010 §2.3 (his stack of materials per cell cut to two: bedrock,
/// which never slides, and one loose material on it, whose angle of repose is ThermalOptions').
/// The DEM is the surface, bedrock + loose thickness.
struct LayeredOptions {
  /// Loose thickness at the start, m >= 0 on the DEM's grid (NaN: none); nullptr: bare rock everywhere.
  const Raster<float>* loose_m = nullptr;
  /// Local erosion (§2.3.3): rock broken off into loose material before the first iteration, m >= 0
  /// per cell on the DEM's grid (the tool's region R is where it is > 0; NaN: none); nullptr: none.
  const Raster<float>* rockfall_m = nullptr;
  /// Global erosion (§2.3.2): S of eta <- eta - a(p) S(p) in soft rock, the share of a rock voxel that
  /// weathers per iteration where the rock is fully accessible (a = 1), [0, 1]; 0: no global erosion.
  double erodibility = 0.05;
  double voxel_m = 1;        ///< thickness of rock turned loose when a voxel's eta reaches 0, m (> 0)
  double radius_m = 200;     ///< radius of the sphere the accessibility a(p) is measured in, m (> 0)
  double strata_m = 0;       ///< thickness of the alternating soft and hard strata, m (>= 0); 0: one rock
  double hard_ratio = 0.2;   ///< S of the hard strata over S of the soft, [0, 1]
};

struct ErodeOptions {
  Process process = Process::both;
  int iterations = 100;  ///< >= 0; thermal alone (and layered without global erosion) stops once nothing moves
  HydraulicOptions hydraulic;
  ThermalOptions thermal;
  LayeredOptions layered;
};

/// Angle of repose of a material of Peytavie's Tab. 2.3 (dry, homogeneous), the middle of its range
/// in degrees: sand 30-35 -> 32.5, stones 40-45 -> 42.5, earth 25-40 -> 32.5, snow 40-80 -> 60.
/// Throws bad_input naming /erode/material for any other name.
double material_angle_deg(const std::string& material);

/// Refuses settings the schema's ranges cannot state, naming them by their scenario pointer.
void check_settings(const ErodeOptions& options);

/// What an erosion did. Volumes are m³ of the output's float heights against the input's (so
/// eroded = deposited + carried_out to float precision); carried_out is the sediment that left
/// the grid, its nodata or the mask with the water.
struct ErodeReport {
  int iterations = 0;  ///< iterations run
  double eroded_m3 = 0, deposited_m3 = 0, carried_out_m3 = 0;
  double max_lowering_m = 0, max_raising_m = 0;  ///< largest fall and rise of a cell, >= 0
  double water_out_m3 = 0;                       ///< rain that left the grid (hydraulic)
  double loosened_m3 = 0;  ///< rock turned into loose material by global and local erosion (layered), m³
  double seconds = 0, seconds_per_iteration = 0;
};

/// Erodes `dem` (metres, NaN nodata) with `options`; cell sizes from `metrics` (cell_metrics of the
/// DEM). `mask` (same grid, optional): only its non-zero cells change, the others are outside like
/// nodata (water and sediment reaching them leave). Nodata cells stay nodata. Deterministic: rows
/// run in parallel on double buffers, sums are reduced row by row in order. `loose` (optional):
/// receives the loose thickness at the end, m (layered; 0 for the other processes, NaN on nodata).
Dem erode(const Dem& dem, const CellMetrics& metrics, const ErodeOptions& options,
          const Raster<std::uint8_t>* mask, Progress& progress, ErodeReport* report = nullptr,
          Raster<float>* loose = nullptr);

}  // namespace terrapolis::erode
