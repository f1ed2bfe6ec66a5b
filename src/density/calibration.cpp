// Presence/background calibration of the density model and its skill (Warton & Shepherd 2010).
// SPDX-License-Identifier: MIT
#include "density/calibration.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>

#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::density {
namespace {

struct RawPlace {
  std::string name;
  double population;
  double x, y;  // DEM CRS
};

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.push_back(cur), cur.clear();
    else if (c != '\r') cur += c;
  }
  out.push_back(cur);
  return out;
}

std::vector<RawPlace> read_csv(const std::string& path, const Crs& target) {
  std::ifstream in(path);
  if (!in) throw bad_input(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line)) throw bad_input(path + ": empty file");
  const auto header = split_csv_line(line);
  int ix = -1, iy = -1, ip = -1, in_ = -1;
  for (int k = 0; k < int(header.size()); ++k) {
    const std::string h = lower(header[std::size_t(k)]);
    if (h == "lon" || h == "longitude" || h == "x" || h == "lng") ix = k;
    if (h == "lat" || h == "latitude" || h == "y") iy = k;
    if (h == "population" || h == "pop") ip = k;
    if (h == "name") in_ = k;
  }
  if (ix < 0 || iy < 0) throw bad_input(path + ": no lon/lat (or x/y) columns");
  if (ip < 0) throw bad_input(path + ": no population column");
  const CrsTransform to_dem(wgs84(), target);
  std::vector<RawPlace> out;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const auto f = split_csv_line(line);
    try {
      const double lon = std::stod(f.at(std::size_t(ix))), lat = std::stod(f.at(std::size_t(iy))), pop = std::stod(f.at(std::size_t(ip)));
      const auto xy = to_dem(lon, lat);
      out.push_back({in_ >= 0 && in_ < int(f.size()) ? f[std::size_t(in_)] : "", pop, xy[0], xy[1]});
    } catch (const std::exception&) {
      throw bad_input(path + ": line " + std::to_string(n) + ": lon, lat and population must be numbers");
    }
  }
  return out;
}

std::vector<RawPlace> read_layer(const std::string& path, const Crs& target) {
  const VectorLayer layer = read_vector(path, target);
  if (!layer.features.empty() && layer.geometry != GeometryType::point) throw bad_input(path + ": places must be points");
  int ip = layer.field_index("population");
  if (ip < 0) ip = layer.field_index("pop");
  if (ip < 0) throw bad_input(path + ": no population field");
  const int in = layer.field_index("name");
  std::vector<RawPlace> out;
  for (std::size_t k = 0; k < layer.features.size(); ++k) {
    const Feature& f = layer.features[k];
    const FieldValue& v = f.values[std::size_t(ip)];
    double pop;
    if (std::holds_alternative<std::int64_t>(v)) pop = double(std::get<std::int64_t>(v));
    else if (std::holds_alternative<double>(v)) pop = std::get<double>(v);
    else if (std::holds_alternative<std::monostate>(v)) continue;  // no figure: not a reference
    else throw bad_input(path + ": feature " + std::to_string(k) + ": population is not a number");
    std::string name;
    if (in >= 0 && std::holds_alternative<std::string>(f.values[std::size_t(in)])) name = std::get<std::string>(f.values[std::size_t(in)]);
    out.push_back({name, pop, f.parts[0][0][0], f.parts[0][0][1]});
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> land_cells(const DensityResult& model) {
  if (model.altitude.size() == 0) throw processing_error("density: the terrain terms were not computed");
  std::vector<std::uint8_t> land(model.altitude.size());
  for (std::size_t i = 0; i < land.size(); ++i) land[i] = std::isnan(model.altitude[i]) ? 0 : 1;
  return land;
}

std::vector<Place> read_places(const std::string& path, const Dem& dem, const std::vector<std::uint8_t>& land, int& dropped) {
  const std::string ext = lower(std::filesystem::path(path).extension().string());
  if (!std::filesystem::exists(path)) throw bad_input(path + ": no such file");
  const std::vector<RawPlace> raw = ext == ".csv" ? read_csv(path, dem.georef().crs) : read_layer(path, dem.georef().crs);
  const GeoTransform& t = dem.georef().transform;
  const double det = t[1] * t[5] - t[2] * t[4];
  dropped = 0;
  std::vector<Place> places;
  for (const RawPlace& p : raw) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.population) || p.population < 0) {
      ++dropped;
      continue;
    }
    // Inverse geotransform: the cell holding the point.
    const double dx = p.x - t[0], dy = p.y - t[3];
    const int col = int(std::floor((t[5] * dx - t[2] * dy) / det)), row = int(std::floor((-t[4] * dx + t[1] * dy) / det));
    int best_c = -1, best_r = -1, best_d = 1 << 30;
    for (int r = row - 2; r <= row + 2; ++r)
      for (int c = col - 2; c <= col + 2; ++c) {
        if (!dem.inside(c, r) || !land[dem.index(c, r)]) continue;
        const int d = (c - col) * (c - col) + (r - row) * (r - row);
        if (d < best_d) best_d = d, best_c = c, best_r = r;
      }
    // A place outside the grid (the reference's bounding box is wider than the DEM) or far from land.
    if (best_c < 0 || !dem.inside(col, row)) {
      ++dropped;
      continue;
    }
    const auto xy = dem.georef().cell_centre(best_c, best_r);
    places.push_back({p.name, p.population, best_d == 0 ? p.x : xy[0], best_d == 0 ? p.y : xy[1], best_c, best_r});
  }
  std::stable_sort(places.begin(), places.end(), [](const Place& a, const Place& b) { return a.population > b.population; });
  return places;
}

double auc(const std::vector<double>& presence, const std::vector<double>& weights, std::vector<double> background) {
  background.erase(std::remove_if(background.begin(), background.end(), [](double v) { return std::isnan(v); }), background.end());
  std::sort(background.begin(), background.end());
  double sum = 0, total = 0;
  for (std::size_t k = 0; k < presence.size(); ++k) {
    const double v = presence[k];
    if (std::isnan(v) || background.empty()) continue;
    const double w = weights.empty() ? 1.0 : weights[k];
    const auto lo = std::lower_bound(background.begin(), background.end(), v);
    const auto hi = std::upper_bound(lo, background.end(), v);
    sum += w * (double(lo - background.begin()) + 0.5 * double(hi - lo)) / double(background.size());
    total += w;
  }
  return total > 0 ? sum / total : NAN;
}

std::vector<double> fit_logistic(const std::vector<std::vector<double>>& x, const std::vector<double>& y, const std::vector<double>& w,
                                 double ridge) {
  const std::size_t n = x.size(), p = n ? x[0].size() + 1 : 1;
  std::vector<double> b(p, 0.0);
  const double total_w = std::accumulate(w.begin(), w.end(), 0.0);
  for (int iter = 0; iter < 100; ++iter) {
    std::vector<double> g(p, 0.0), h(p * p, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      double eta = b[0];
      for (std::size_t j = 1; j < p; ++j) eta += b[j] * x[i][j - 1];
      const double mu = 1 / (1 + std::exp(-eta)), v = w[i] * mu * (1 - mu), r = w[i] * (y[i] - mu);
      for (std::size_t j = 0; j < p; ++j) {
        const double xj = j ? x[i][j - 1] : 1.0;
        g[j] += r * xj;
        for (std::size_t k = 0; k <= j; ++k) h[j * p + k] += v * xj * (k ? x[i][k - 1] : 1.0);
      }
    }
    for (std::size_t j = 1; j < p; ++j) {
      g[j] -= ridge * total_w * b[j];
      h[j * p + j] += ridge * total_w;
    }
    for (std::size_t j = 0; j < p; ++j)
      for (std::size_t k = j + 1; k < p; ++k) h[j * p + k] = h[k * p + j];
    // Newton step: solve h d = g by Gaussian elimination with partial pivoting.
    std::vector<double> d = g;
    for (std::size_t c = 0; c < p; ++c) {
      std::size_t piv = c;
      for (std::size_t r = c + 1; r < p; ++r)
        if (std::abs(h[r * p + c]) > std::abs(h[piv * p + c])) piv = r;
      for (std::size_t k = 0; k < p; ++k) std::swap(h[c * p + k], h[piv * p + k]);
      std::swap(d[c], d[piv]);
      if (std::abs(h[c * p + c]) < 1e-300) throw processing_error("calibration: singular system (no variation in a term?)");
      for (std::size_t r = c + 1; r < p; ++r) {
        const double f = h[r * p + c] / h[c * p + c];
        for (std::size_t k = c; k < p; ++k) h[r * p + k] -= f * h[c * p + k];
        d[r] -= f * d[c];
      }
    }
    for (std::size_t c = p; c-- > 0;) {
      for (std::size_t k = c + 1; k < p; ++k) d[c] -= h[c * p + k] * d[k];
      d[c] /= h[c * p + c];
    }
    double step = 0;
    for (std::size_t j = 0; j < p; ++j) b[j] += d[j], step = std::max(step, std::abs(d[j]));
    if (step < 1e-9) break;
  }
  return b;
}

std::array<double, 8> terms_at(const DensityResult& m, std::size_t i) {
  return {m.coast[i], m.hydrometry[i], m.plateau[i], m.plain[i], m.altitude[i], m.slope[i], m.coast_near[i], m.river_near[i]};
}

std::array<double, 3> baselines_at(const DensityResult& m, std::size_t i) { return {-m.altitude[i], -m.slope[i], m.coast_near[i]}; }

double Skill::best_baseline() const { return *std::max_element(baseline_auc.begin(), baseline_auc.end()); }

Skill skill(const Raster<float>& density, const DensityResult& terms, const std::vector<Place>& places, const std::vector<std::uint8_t>& land) {
  std::vector<double> bg;
  std::array<std::vector<double>, 3> bg_base;
  for (std::size_t i = 0; i < land.size(); ++i) {
    if (!land[i]) continue;
    bg.push_back(density[i]);
    const auto b = baselines_at(terms, i);
    for (int k = 0; k < 3; ++k) bg_base[std::size_t(k)].push_back(b[std::size_t(k)]);
  }
  std::vector<double> pres, weights;
  std::array<std::vector<double>, 3> pres_base;
  for (const Place& p : places) {
    const std::size_t i = density.index(p.col, p.row);
    pres.push_back(density[i]);
    weights.push_back(p.population);
    const auto b = baselines_at(terms, i);
    for (int k = 0; k < 3; ++k) pres_base[std::size_t(k)].push_back(b[std::size_t(k)]);
  }
  Skill s;
  s.auc = auc(pres, {}, bg);
  s.weighted_auc = auc(pres, weights, bg);
  for (std::size_t k = 0; k < 3; ++k) {
    s.baseline_auc[k] = auc(pres_base[k], {}, bg_base[k]);
    s.baseline_weighted_auc[k] = auc(pres_base[k], weights, bg_base[k]);
  }
  return s;
}

}  // namespace terrapolis::density
