// Real places (GeoNames, a census) read onto a DEM's land, for calibration and realism figures.
// SPDX-License-Identifier: MIT
#include "pipeline/places.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/error.hpp"
#include "io/crs.hpp"
#include "io/vector_io.hpp"

namespace terrapolis::pipeline {
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

std::vector<RawPlace> read_point_layer(const std::string& path, const Crs& target) {
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

std::vector<RawPlace> read_raw(const std::string& path, const Crs& crs) {
  if (!std::filesystem::exists(path)) throw bad_input(path + ": no such file");
  return lower(std::filesystem::path(path).extension().string()) == ".csv" ? read_csv(path, crs) : read_point_layer(path, crs);
}

/// The cell holding CRS point (x, y) (inverse geotransform).
std::array<int, 2> cell_of(const Georef& g, double x, double y) {
  const GeoTransform& t = g.transform;
  const double det = t[1] * t[5] - t[2] * t[4], dx = x - t[0], dy = y - t[3];
  return {int(std::floor((t[5] * dx - t[2] * dy) / det)), int(std::floor((-t[4] * dx + t[1] * dy) / det))};
}

}  // namespace

void check_existing_places(const std::string& path, const Crs& crs) {
  const std::vector<RawPlace> raw = read_raw(path, crs);
  for (std::size_t k = 0; k < raw.size(); ++k)
    if (!std::isfinite(raw[k].population) || raw[k].population < 0)
      throw bad_input(path + ": " + (raw[k].name.empty() ? "place " + std::to_string(k + 1) : raw[k].name) +
                      ": the population must be a number of people >= 0");
  if (raw.empty()) throw bad_input(path + ": holds no place");
}

ExistingPlaces read_existing_places(const std::string& path, const sites::Land& land) {
  ExistingPlaces out;
  std::set<std::pair<int, int>> taken;  // (col, row)
  const auto inside = [&](int c, int r) { return c >= 0 && r >= 0 && c < land.cols() && r < land.rows(); };
  std::vector<RawPlace> raw = read_raw(path, land.georef().crs);
  // The largest first: where two places share a cell, the larger keeps it.
  std::stable_sort(raw.begin(), raw.end(), [](const RawPlace& a, const RawPlace& b) { return a.population > b.population; });
  for (std::size_t k = 0; k < raw.size(); ++k) {
    const RawPlace& p = raw[k];
    const std::string name = p.name.empty() ? "place " + std::to_string(k + 1) : p.name;
    if (!std::isfinite(p.population) || p.population < 0)
      throw bad_input(path + ": " + name + ": the population must be a number of people >= 0");
    if (p.population < 1) {
      ++out.without_people;
      continue;
    }
    const auto [col, row] = std::isfinite(p.x) && std::isfinite(p.y) ? cell_of(land.georef(), p.x, p.y) : std::array<int, 2>{-1, -1};
    if (!inside(col, row)) {
      out.outside.push_back(name);
      continue;
    }
    // Its cell, or the nearest free buildable one within two cells (a coastal town on a sea cell of
    // a coarse grid, a second place in the same cell).
    int best_c = -1, best_r = -1, best_d = 1 << 30;
    const int c0 = std::max(0, col - 2), r0 = std::max(0, row - 2);
    const sites::LandView near = land.window(c0, r0, std::min(land.cols(), col + 3) - c0, std::min(land.rows(), row + 3) - r0);
    for (int r = row - 2; r <= row + 2; ++r)
      for (int c = col - 2; c <= col + 2; ++c) {
        if (!inside(c, r) || near.buildable[near.at(c, r)] != 1 || taken.count({c, r})) continue;
        const int d = (c - col) * (c - col) + (r - row) * (r - row);
        if (d < best_d) best_d = d, best_c = c, best_r = r;
      }
    if (best_c < 0)
      throw bad_input(path + ": " + name + ": lies on water, nodata or unbuildable land with no free buildable cell within two cells; move it or leave it out");
    if (best_d > 0) out.moved.push_back(name);
    taken.insert({best_c, best_r});
    sites::Site s;
    s.col = best_c, s.row = best_r;
    const auto xy = land.georef().cell_centre(best_c, best_r);
    s.x = xy[0], s.y = xy[1];
    s.population = std::int64_t(std::llround(p.population));
    s.existing = true;
    s.name = p.name;
    out.sites.push_back(std::move(s));
  }
  if (out.sites.empty()) throw bad_input(path + ": no place with people lies on the DEM");
  return out;
}

std::vector<std::string> existing_place_warnings(const ExistingPlaces& places) {
  const auto listed = [](const std::vector<std::string>& names) {
    std::string list;
    for (std::size_t k = 0; k < std::min<std::size_t>(10, names.size()); ++k) list += (k ? ", " : "") + names[k];
    if (names.size() > 10) list += " and " + std::to_string(names.size() - 10) + " more";
    return list;
  };
  const auto count = [](std::size_t n) { return std::to_string(n) + (n == 1 ? " place " : " places "); };
  std::vector<std::string> out;
  if (!places.outside.empty())
    out.push_back("sites.existing: " + count(places.outside.size()) + "outside the DEM left out: " + listed(places.outside));
  if (!places.moved.empty())
    out.push_back("sites.existing: " + count(places.moved.size()) + "on water or unbuildable land moved to the nearest free buildable cell: " +
                  listed(places.moved));
  return out;
}

std::vector<density::Place> read_places(const std::string& path, const Dem& dem, const std::vector<std::uint8_t>& land, int& dropped) {
  return read_places(path, dem.georef(), dem.cols(), dem.rows(), [&](int c0, int r0, int cols, int rows) {
    std::vector<std::uint8_t> window(std::size_t(cols) * std::size_t(rows));
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) window[std::size_t(r) * std::size_t(cols) + std::size_t(c)] = land[dem.index(c0 + c, r0 + r)];
    return window;
  }, dropped);
}

std::vector<density::Place> read_places(const std::string& path, const Georef& grid, int cols, int rows, const LandWindow& land, int& dropped) {
  const std::vector<RawPlace> raw = read_raw(path, grid.crs);
  dropped = 0;
  std::vector<density::Place> places;
  for (const RawPlace& p : raw) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.population) || p.population < 0) {
      ++dropped;
      continue;
    }
    const auto [col, row] = cell_of(grid, p.x, p.y);
    // A place outside the grid (the reference's bounding box is wider than the DEM) or far from land.
    if (col < 0 || row < 0 || col >= cols || row >= rows) {
      ++dropped;
      continue;
    }
    const int c0 = std::max(0, col - 2), r0 = std::max(0, row - 2), c1 = std::min(cols, col + 3), r1 = std::min(rows, row + 3);
    const std::vector<std::uint8_t> near = land(c0, r0, c1 - c0, r1 - r0);
    int best_c = -1, best_r = -1, best_d = 1 << 30;
    for (int r = r0; r < r1; ++r)
      for (int c = c0; c < c1; ++c) {
        if (!near[std::size_t(r - r0) * std::size_t(c1 - c0) + std::size_t(c - c0)]) continue;
        const int d = (c - col) * (c - col) + (r - row) * (r - row);
        if (d < best_d) best_d = d, best_c = c, best_r = r;
      }
    if (best_c < 0) {
      ++dropped;
      continue;
    }
    const auto xy = grid.cell_centre(best_c, best_r);
    places.push_back({p.name, p.population, best_d == 0 ? p.x : xy[0], best_d == 0 ? p.y : xy[1], best_c, best_r});
  }
  std::stable_sort(places.begin(), places.end(), [](const density::Place& a, const density::Place& b) { return a.population > b.population; });
  return places;
}

}  // namespace terrapolis::pipeline
