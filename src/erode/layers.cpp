// Rock turned into loose material on a two-layer ground (Peytavie 2010, thesis §2.3): global
// erosion by the accessibility of the rock (§2.3.2) and local erosion by a tool (§2.3.3).
// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "erode/domain.hpp"

namespace terrapolis::erode {

GlobalErosion::GlobalErosion(Domain& domain, const LayeredOptions& options)
    : d_(domain), o_(options), eta_(domain.height.size(), 1.0) {  // eta = 1: an intact voxel
  const CellMetrics& m = *d_.metrics;
  const double narrowest = *std::min_element(m.width_m.begin(), m.width_m.end());
  const double shortest = *std::min_element(m.height_m.begin(), m.height_m.end());
  reach_c_ = int(std::floor(o_.radius_m / narrowest));
  reach_r_ = int(std::floor(o_.radius_m / shortest));
  const int reach = std::max(reach_c_, reach_r_);
  if (reach > max_reach)
    throw bad_input("/erode/radius_m: the sphere spans " + std::to_string(reach) + " cells on this grid, at most " + std::to_string(max_reach));
}

std::vector<GlobalErosion::Chord> GlobalErosion::sphere(int r) const {
  const CellMetrics& m = *d_.metrics;
  const double radius = o_.radius_m;
  std::vector<Chord> chords;
  for (int dr = -reach_r_; dr <= reach_r_; ++dr) {
    const int rr = r + dr;
    if (rr < 0 || rr >= d_.rows) continue;
    double dy = 0;  // north-south distance, the row steps between r and rr added up
    for (int b = std::min(r, rr) + 1; b <= std::max(r, rr); ++b) dy += m.height_m[std::size_t(b)];
    // East-west: the mean of the two rows' widths (the rows differ by a few cells at most).
    const double width = 0.5 * (m.width_m[std::size_t(r)] + m.width_m[std::size_t(rr)]);
    for (int dc = -reach_c_; dc <= reach_c_; ++dc) {
      const double d2 = dc * width * dc * width + dy * dy;
      if (d2 >= radius * radius) continue;
      const double half = std::sqrt(radius * radius - d2);
      chords.push_back({dc, dr, half, 2 * half * m.area_m2[std::size_t(rr)]});
    }
  }
  return chords;
}

// Beardall et al. 2007, "Goblins by spheroidal weathering" (Peytavie's BFO+07): the accessibility of a point is the share of a sphere
// around it that is air. On a grid, each column within the radius cuts a vertical chord of the
// sphere, [z - half, z + half], of which the part above the column's surface is air; the chords
// are weighted by their volume (2 half x area). Flat ground: 1/2; a peak or an edge: more; a
// hollow: less. Columns without data (nodata, beyond the border) are left out of both sums.
double GlobalErosion::accessibility(int c, int r, const std::vector<Chord>& chords) const {
  const double z = d_.height[d_.index(c, r)];
  double air = 0, all = 0;
  for (const Chord& k : chords) {
    if (!d_.on_grid(c + k.dc, r + k.dr)) continue;
    const double h = d_.height[d_.index(c + k.dc, r + k.dr)];
    if (std::isnan(h)) continue;
    air += std::clamp((z + k.half_m - h) / (2 * k.half_m), 0.0, 1.0) * k.weight_m4;
    all += k.weight_m4;
  }
  return all > 0 ? air / all : 0.5;
}

// Peytavie's stratification S(p), "la granularité et la dureté de la roche", here as the regular
// strata of his sea cliffs: a 1-D stack of soft and hard beds strata_m thick, the hard ones
// hard_ratio times as erodible; the bed containing height 0 is soft.
double GlobalErosion::strength(double z) const {
  if (o_.strata_m <= 0) return o_.erodibility;
  const long long bed = (long long)std::floor(z / o_.strata_m);
  return (bed & 1) ? o_.erodibility * o_.hard_ratio : o_.erodibility;
}

// Peytavie: "seules les couches de roches voisines d'une couche d'air sont converties en voxel": the
// rock of a cell touches the air when no loose material covers it. (Not on its sides: between two
// columns of a height field there is a step at every slope, not a rock face, and counting it would
// let rock weather under any scree on a slope steeper than the scree is thick. A real face is steeper
// than the angle of repose, so its scree slides off and it is bare anyway.)
bool GlobalErosion::exposed(std::size_t i) const { return d_.loose[i] <= stable_m; }

double GlobalErosion::weather(int r) {
  const std::vector<Chord> chords = sphere(r);
  const double area = d_.metrics->area_m2[std::size_t(r)];
  double loosened = 0;
  for (int c = 0; c < d_.cols; ++c) {
    const std::size_t i = d_.index(c, r);
    if (!d_.in[i] || !exposed(i)) continue;
    const double voxel_middle = d_.height[i] - d_.loose[i] - 0.5 * o_.voxel_m;
    eta_[i] -= accessibility(c, r, chords) * strength(voxel_middle);  // Peytavie: eta~ = eta - a(p) S(p)
    if (eta_[i] > 0) continue;
    // "Lorsque eta = 0 le voxel de roche est transformé en sédiment": it stays on its cell as loose
    // material (the surface does not move) for the stabilisation to carry; the next voxel is intact.
    d_.loose[i] += o_.voxel_m;
    eta_[i] = 1;
    loosened += o_.voxel_m * area;
  }
  return loosened;
}

double GlobalErosion::step() {
  // Heights are only read here; each row writes only its own cells' eta and loose thickness.
  return rows_sum(d_.rows, [&](int r) { return weather(r); });
}

double break_off(Domain& domain, const Raster<float>& rockfall_m) {
  check_grid("/erode/rockfall", rockfall_m, domain);
  double volume = 0;
  for (int r = 0; r < domain.rows; ++r) {
    double row = 0;
    for (int c = 0; c < domain.cols; ++c) {
      const std::size_t i = domain.index(c, r);
      if (!domain.in[i] || std::isnan(rockfall_m[i])) continue;
      const double t = checked_thickness("/erode/rockfall", rockfall_m[i]);
      domain.loose[i] += t;  // the rock in the tool's region R turned into loose material, in place
      row += t;
    }
    volume += row * domain.metrics->area_m2[std::size_t(r)];
  }
  return volume;
}

}  // namespace terrapolis::erode
