// Options shared by `fill`, `reconstruct` and `generate`: method, subdivision and noise parameters.
// SPDX-License-Identifier: MIT
#pragma once
#include <CLI/CLI.hpp>

#include <array>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "cli/command.hpp"
#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/raster_io.hpp"
#include "terrain/fill.hpp"

namespace terrapolis::cli {

struct TerrainOptions {
  std::string method = "thin-plate";
  std::string subdivision = "diamond-square";
  std::string bottom_up = "weighted";
  std::uint64_t seed = 1;
  double roughness_m = 0.0;
  double hurst = 0.5;
  double shape = 0.0, shape_up = 0.0;
  double tension = 0.0;
  bool no_low_pass = false;

  /// Declares the options; `with_method` for the commands that choose a method (fill, reconstruct).
  void add(CLI::App& app, bool with_method, double default_roughness_m) {
    roughness_m = default_roughness_m;
    if (with_method)
      app.add_option("--method", method, "dmmc | harmonic | thin-plate (default: thin-plate, the most accurate in our benchmark)")
          ->capture_default_str();
    app.add_option("--subdivision", subdivision, "Midpoint displacement scheme: triangle-edge | diamond-square")->capture_default_str();
    app.add_option("--seed", seed, "Seed of the position hash of the displacements")->capture_default_str();
    app.add_option("--roughness", roughness_m, "S of Belhadj eq. 1.1 in metres: size of the level-0 displacement (0: no noise)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    app.add_option("--hurst", hurst, "Hurst exponent H in (0,1]: displacements shrink by 2^(-2H) per level")
        ->capture_default_str()->check(CLI::Range(0.01, 1.0));
    app.add_option("--shape", shape, "I of Belhadj eq. 3.4: shapes the interpolation with distance (0: plain mean)")->capture_default_str();
    app.add_option("--shape-up", shape_up, "I_-1 of Belhadj eq. 3.5: shapes the bottom-up extrapolation (0: plain)")->capture_default_str();
    app.add_option("--bottom-up", bottom_up, "dmmc: bottom-up extrapolation: weighted (Belhadj Alg. 11, children weighted by distance) | "
                                             "mean (Alg. 10 as printed: plain mean of the children, noise s = roughness/65536 m per cell of distance)")
        ->capture_default_str()->check(CLI::IsMember({"weighted", "mean"}));
    app.add_option("--tension", tension, "thin-plate: tension in 1/cell^2 (0: pure thin plate; large: membrane)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    app.add_flag("--no-low-pass", no_low_pass, "dmmc: skip the 3x3 low-pass of Belhadj §5.2.1");
  }

  terrain::FillParams params() const {
    terrain::FillParams p;
    p.method = terrain::parse_fill_method("--method", method);
    terrain::MidpointParams& m = p.dmmc.top_down;
    if (subdivision == "triangle-edge") m.subdivision = terrain::Subdivision::triangle_edge;
    else if (subdivision == "diamond-square") m.subdivision = terrain::Subdivision::diamond_square;
    else throw bad_input("--subdivision: unknown scheme '" + subdivision + "' (expected triangle-edge or diamond-square)");
    m.seed = seed;
    m.scale_m = roughness_m;
    m.hurst = hurst;
    m.shape = shape;
    p.dmmc.bottom_up.shape = shape_up;
    if (bottom_up == "mean") {
      // Alg. 10 has no extrapolation shaping: I_-1 comes with Alg. 11 (§3.2.2).
      if (shape_up != 0.0) throw bad_input("--shape-up: needs --bottom-up weighted (Belhadj Alg. 10 has no extrapolation shaping)");
      p.dmmc.bottom_up.rule = terrain::BottomUpRule::mean;
      p.dmmc.bottom_up.noise_m_per_cell = terrain::thesis_noise_per_cell_m(roughness_m);
    }
    p.dmmc.low_pass = !no_low_pass;
    p.spline.tension = tension;
    return p;
  }

  /// Provenance written into the output's metadata.
  std::vector<std::pair<std::string, std::string>> metadata(bool with_method) const {
    std::vector<std::pair<std::string, std::string>> md;
    if (with_method) md.emplace_back("TERRAPOLIS_METHOD", method);
    if (!with_method || method == "dmmc") {
      md.emplace_back("TERRAPOLIS_SUBDIVISION", subdivision);
      md.emplace_back("TERRAPOLIS_SEED", std::to_string(seed));
      md.emplace_back("TERRAPOLIS_ROUGHNESS_M", std::to_string(roughness_m));
      md.emplace_back("TERRAPOLIS_HURST", std::to_string(hurst));
      // Only when not the default, so outputs made with the default keep their bytes.
      if (bottom_up != "weighted") md.emplace_back("TERRAPOLIS_BOTTOM_UP", bottom_up);
    }
    if (method == "thin-plate") md.emplace_back("TERRAPOLIS_TENSION", std::to_string(tension));
    return md;
  }
};

/// A new grid given on the command line: --size WxH --cell M [--crs EPSG:n --origin X,Y].
struct GridOptions {
  std::string size, crs, origin;
  double cell_m = 0;
  bool default_crs = false;  ///< crs and origin were chosen by the command, not given: errors name --size and --cell only

  /// `defaults`: what the command does without --crs and --origin, for their help.
  void add(CLI::App& app, bool required, const std::string& defaults = "an unreferenced grid with its corner at 0,0") {
    auto* s = app.add_option("--size", size, "Grid size in cells, WxH (e.g. 513x513)");
    auto* c = app.add_option("--cell", cell_m, "Cell size in metres")->check(CLI::PositiveNumber);
    if (required) { s->required(); c->required(); }
    app.add_option("--crs", crs, "Projected CRS of the grid, e.g. EPSG:32632 (default: " + defaults + ")");
    app.add_option("--origin", origin, "CRS coordinates X,Y of the grid's north-west corner (default: see --crs)");
  }
  bool given() const { return !size.empty(); }

  /// The grid; throws bad_input naming the option at fault.
  Raster<float> make() const {
    const auto x = size.find_first_of("xX");
    int cols = 0, rows = 0;
    try {
      if (x != std::string::npos) {
        std::size_t a = 0, b = 0;
        cols = std::stoi(size.substr(0, x), &a);
        rows = std::stoi(size.substr(x + 1), &b);
        if (a != x || b != size.size() - x - 1) cols = rows = 0;
      }
    } catch (const std::exception&) {
      cols = rows = 0;
    }
    if (cols < 2 || rows < 2 || double(cols) * rows > 4e8) throw bad_input("--size: expected WxH with 2 <= W, H (e.g. 513x513), got '" + size + "'");
    if (!(cell_m > 0)) throw bad_input("--cell: give the cell size in metres (> 0)");
    Georef georef;
    if (!crs.empty()) {
      georef.crs = crs_from_user(crs);
      if (georef.crs.geographic) throw bad_input("--crs: '" + crs + "' is geographic; give a projected CRS (cells are in metres)");
    }
    const auto o = origin.empty() ? std::array<double, 2>{0, 0} : parse_pair("--origin", origin);
    const double unit = georef.crs.linear_unit_m > 0 ? georef.crs.linear_unit_m : 1.0;
    georef.transform = {o[0], cell_m / unit, 0, o[1], 0, -cell_m / unit};
    RasterHeader header;
    header.cols = cols;
    header.rows = rows;
    header.georef = georef;
    char cell_text[32];
    std::snprintf(cell_text, sizeof(cell_text), "%g", cell_m);
    std::string what = "--size " + size + " --cell " + cell_text;
    if (!crs.empty() && !default_crs) what += " --crs " + crs;
    if (!origin.empty() && !default_crs) what += " --origin " + origin;
    check_grid_georeferencing(what, header);
    return Raster<float>(cols, rows, georef, std::numeric_limits<float>::quiet_NaN());
  }
};

}  // namespace terrapolis::cli
