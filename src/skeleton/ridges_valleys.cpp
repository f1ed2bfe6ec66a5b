// Ridge and valley skeleton (Belhadj 2007, §5.2.2 "La reconstruction à partir des contours").
// SPDX-License-Identifier: MIT
#include "skeleton/ridges_valleys.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/neighbours.hpp"

namespace terrapolis::skeleton {

Raster<float> form_index(const Dem& dem, const CellMetrics& metrics) {
  Raster<float> index = dem.like<float>(std::numeric_limits<float>::quiet_NaN());
  const int cols = dem.cols(), rows = dem.rows();
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& rr) {
    for (int r = rr.begin(); r < rr.end(); ++r)
      for (int c = 0; c < cols; ++c) {
        const float z = dem(c, r);
        if (std::isnan(z)) continue;
        // Footnote 14: the mean of V_i . (0,0,1), V_i the unit vector from neighbour i to the cell.
        double sum = 0;
        int pairs = 0;
        for (int k = 0; k < 4; ++k) {
          const int o = opposite(k);
          const int c1 = c + dcol[k], r1 = r + drow[k], c2 = c + dcol[o], r2 = r + drow[o];
          if (!dem.inside(c1, r1) || !dem.inside(c2, r2)) continue;
          const double dz1 = double(z) - dem(c1, r1), dz2 = double(z) - dem(c2, r2);
          if (std::isnan(dz1) || std::isnan(dz2)) continue;
          const double d1 = metrics.step_m(r, k), d2 = metrics.step_m(r, o);
          sum += dz1 / std::hypot(d1, dz1) + dz2 / std::hypot(d2, dz2);
          ++pairs;
        }
        if (pairs) index(c, r) = float(sum / (2 * pairs));
      }
  });
  return index;
}

namespace {

/// Circular distance between two neighbour directions, 0..4 (0: same heading, 4: opposite).
int turn(int a, int b) {
  const int d = std::abs(a - b) & 7;
  return std::min(d, 8 - d);
}

class Tracer {
 public:
  Tracer(const Dem& dem, const Raster<float>& index, double tolerance)
      : dem_(dem), index_(index), tolerance_(tolerance), stamp_(dem.size(), -1), owner_(dem.size(), -1) {}

  /// The next step (k of 0..7) from `cell` on line `line` of sign `sign` (+1 ridge, -1 valley), or -1;
  /// only directions at most `max_turn` eighths of a turn from `around` (any when `around` < 0).
  int next(std::size_t cell, int around, int max_turn, double sign, int line) const {
    const int cols = dem_.cols();
    const int c = int(cell % std::size_t(cols)), r = int(cell / std::size_t(cols));
    const double f = index_[cell];
    int best = -1;
    double best_value = 0;
    for (int k = 0; k < 8; ++k) {
      if (around >= 0 && turn(k, around) > max_turn) continue;
      const int nc = c + dcol[k], nr = r + drow[k];
      if (!dem_.inside(nc, nr)) continue;
      const std::size_t n = dem_.index(nc, nr);
      const double fn = index_[n];
      // The thesis's ±10 %: the neighbour's form index within tolerance of the previous cell's.
      if (!(sign * fn > 0) || std::abs(fn - f) > tolerance_ * std::abs(f) || stamp_[n] == line) continue;
      if (best < 0 || sign * fn > best_value) best = k, best_value = sign * fn;
    }
    return best;
  }

  /// Follows the path from `seed` both ways; the cells in path order.
  std::vector<std::size_t> trace(std::size_t seed, double sign, int line) {
    const int cols = dem_.cols();
    stamp_[seed] = line;
    auto walk = [&](int first) {
      std::vector<std::size_t> path;
      std::size_t cell = seed;
      for (int k = first; k >= 0;) {
        cell = dem_.index(int(cell % std::size_t(cols)) + dcol[k], int(cell / std::size_t(cols)) + drow[k]);
        path.push_back(cell);
        stamp_[cell] = line;
        if (owner_[cell] >= 0) break;  // joins an earlier line
        k = next(cell, k, 1, sign, line);
      }
      return path;
    };
    const int first = next(seed, -1, 4, sign, line);
    std::vector<std::size_t> forward = first >= 0 ? walk(first) : std::vector<std::size_t>{};
    // The other way: roughly opposite the first step, so the seed lies inside its line.
    const int second = first >= 0 ? next(seed, opposite(first), 1, sign, line) : -1;
    std::vector<std::size_t> backward = second >= 0 ? walk(second) : std::vector<std::size_t>{};
    std::vector<std::size_t> cells(backward.rbegin(), backward.rend());
    cells.push_back(seed);
    cells.insert(cells.end(), forward.begin(), forward.end());
    return cells;
  }

  bool owned(std::size_t cell) const { return owner_[cell] >= 0; }
  bool stamped(std::size_t cell) const { return stamp_[cell] >= 0; }
  void own(const std::vector<std::size_t>& cells, int line) {
    for (std::size_t cell : cells)
      if (owner_[cell] < 0) owner_[cell] = line;
  }

 private:
  const Dem& dem_;
  const Raster<float>& index_;
  double tolerance_;
  std::vector<int> stamp_;  ///< the last line (attempt) that visited each cell, -1 never
  std::vector<int> owner_;  ///< the kept line each cell belongs to, -1 none
};

/// Neighbour direction from cell a to the 8-adjacent cell b.
int direction(std::size_t a, std::size_t b, int cols) {
  const int dc = int(b % std::size_t(cols)) - int(a % std::size_t(cols)), dr = int(b / std::size_t(cols)) - int(a / std::size_t(cols));
  for (int k = 0; k < 8; ++k)
    if (dcol[k] == dc && drow[k] == dr) return k;
  return -1;
}

}  // namespace

Skeleton extract_skeleton(const Dem& dem, const CellMetrics& metrics, const SkeletonOptions& options, Progress& progress) {
  Skeleton s;
  {
    ProgressStep step(progress, "form index");
    s.index = form_index(dem, metrics);
    step.update(1);
  }
  const int cols = dem.cols();
  // Seeds: the thesis uses "the positions with the largest absolute weights"; the seed_share most
  // positive cells start ridges and the most negative start valleys, strongest first.
  struct Seed {
    float strength;
    std::size_t cell;
  };
  std::vector<Seed> ridges, valleys;
  for (std::size_t i = 0; i < dem.size(); ++i) {
    if (std::isnan(dem[i])) continue;
    ++s.valid_cells;
    const float f = s.index[i];
    if (f > 0 && options.lines != Lines::valleys) ridges.push_back({f, i});
    if (f < 0 && options.lines != Lines::ridges) valleys.push_back({-f, i});
  }
  const auto stronger = [](const Seed& a, const Seed& b) { return a.strength != b.strength ? a.strength > b.strength : a.cell < b.cell; };
  const std::size_t quota = std::size_t(std::ceil(options.seed_share * double(s.valid_cells)));
  for (auto* seeds : {&ridges, &valleys}) {
    const std::size_t n = std::min(quota, seeds->size());
    std::partial_sort(seeds->begin(), seeds->begin() + std::ptrdiff_t(n), seeds->end(), stronger);
    seeds->resize(n);
  }
  std::vector<Seed> seeds;
  seeds.reserve(ridges.size() + valleys.size());
  std::merge(ridges.begin(), ridges.end(), valleys.begin(), valleys.end(), std::back_inserter(seeds), stronger);

  ProgressStep step(progress, "ridge and valley lines");
  Tracer tracer(dem, s.index, options.tolerance);
  s.kept = dem.like<float>(std::numeric_limits<float>::quiet_NaN());
  int attempt = 0;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    if ((i & 4095) == 0) step.update(double(i) / double(seeds.size()));
    const std::size_t seed = seeds[i].cell;
    if (tracer.stamped(seed)) continue;  // on a line already, or tried from another seed
    const double sign = s.index[seed] > 0 ? 1.0 : -1.0;
    std::vector<std::size_t> cells = tracer.trace(seed, sign, attempt++);
    if (int(cells.size()) < options.min_cells) continue;
    Line line;
    line.kind = sign > 0 ? Kind::ridge : Kind::valley;
    line.index = s.index[seed];
    float lo = dem[cells[0]], hi = lo;
    for (std::size_t j = 0; j < cells.size(); ++j) {
      lo = std::min(lo, dem[cells[j]]);
      hi = std::max(hi, dem[cells[j]]);
      if (j) line.length_m += metrics.step_m(int(cells[j - 1] / std::size_t(cols)), direction(cells[j - 1], cells[j], cols));
      if (kept_on_line(j, cells.size(), options.line_step)) s.kept[cells[j]] = dem[cells[j]];
    }
    line.relief_m = double(hi) - double(lo);
    tracer.own(cells, int(s.lines.size()));
    line.cells = std::move(cells);
    (line.kind == Kind::ridge ? s.ridges : s.valleys)++;
    s.lines.push_back(std::move(line));
  }
  for (std::size_t i = 0; i < s.kept.size(); ++i) s.line_cells += std::isnan(s.kept[i]) ? 0 : 1;
  // The lattice: line cells sit where a smooth surface through evenly spread cells errs most (1.2 to
  // 2.2 times its mean error, docs/skeleton.md), but alone they leave slopes, plateaus and edges
  // without a sample.
  for (int r = 0; r < dem.rows(); ++r)
    for (int c = 0; c < cols; ++c)
      if (on_lattice(c, r, options.lattice) && !std::isnan(dem(c, r))) {
        s.kept(c, r) = dem(c, r);
        ++s.lattice_cells;
      }
  for (std::size_t i = 0; i < s.kept.size(); ++i) s.kept_cells += std::isnan(s.kept[i]) ? 0 : 1;
  step.update(1);
  return s;
}

VectorLayer lines_layer(const Skeleton& skeleton, Kind kind) {
  VectorLayer layer;
  layer.name = kind == Kind::ridge ? "ridges" : "valleys";
  layer.geometry = GeometryType::line_string;
  const Georef& georef = skeleton.kept.georef();
  layer.crs = georef.crs;
  layer.fields = {{"id", FieldType::integer},       {"kind", FieldType::string},     {"cells", FieldType::integer},
                  {"length_m", FieldType::real},    {"relief_m", FieldType::real},   {"form_index", FieldType::real}};
  const std::size_t cols = std::size_t(skeleton.kept.cols());
  std::int64_t id = 0;
  for (const Line& line : skeleton.lines) {
    if (line.kind != kind) continue;
    Feature f;
    f.parts.emplace_back();
    for (std::size_t cell : line.cells) f.parts[0].push_back(georef.cell_centre(double(cell % cols), double(cell / cols)));
    f.values = {++id, std::string(layer.name == "ridges" ? "ridge" : "valley"), std::int64_t(line.cells.size()), line.length_m, line.relief_m,
                double(line.index)};
    layer.features.push_back(std::move(f));
  }
  return layer;
}

std::string lines_qml(Kind kind) {
  const std::string colour = kind == Kind::ridge ? "#8c510a" : "#2166ac";
  return "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n<qgis version=\"3.22.16\" styleCategories=\"AllStyleCategories\">"
         "<renderer-v2 type=\"singleSymbol\" enableorderby=\"0\" forceraster=\"0\" symbollevels=\"0\"><symbols>"
         "<symbol type=\"line\" name=\"0\" alpha=\"1\"><layer class=\"SimpleLine\" enabled=\"1\"><Option type=\"Map\">"
         "<Option type=\"QString\" name=\"line_color\" value=\"" + colour + "\"/>"
         "<Option type=\"QString\" name=\"line_width\" value=\"0.3\"/><Option type=\"QString\" name=\"line_width_unit\" value=\"MM\"/>"
         "<Option type=\"QString\" name=\"capstyle\" value=\"round\"/><Option type=\"QString\" name=\"joinstyle\" value=\"round\"/>"
         "</Option><data_defined_properties><Option type=\"Map\"><Option type=\"QString\" name=\"name\" value=\"\"/>"
         "<Option type=\"Map\" name=\"properties\"><Option type=\"Map\" name=\"outlineWidth\">"
         "<Option type=\"bool\" name=\"active\" value=\"true\"/>"
         "<Option type=\"QString\" name=\"expression\" value=\"0.15 + 0.12 * ln(1 + &quot;relief_m&quot;)\"/>"
         "<Option type=\"int\" name=\"type\" value=\"3\"/></Option></Option>"
         "<Option type=\"QString\" name=\"type\" value=\"collection\"/></Option></data_defined_properties></layer></symbol>"
         "</symbols></renderer-v2></qgis>\n";
}

}  // namespace terrapolis::skeleton
