// CRS descriptions and transformations (OGR/PROJ).
// SPDX-License-Identifier: MIT
#include "io/crs.hpp"

#include <cpl_error.h>
#include <ogr_spatialref.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <unistd.h>

#include "core/error.hpp"
#include "io/gdal_util.hpp"

namespace terrapolis {
namespace detail {

Crs describe(const OGRSpatialReference& srs_in) {
  OGRSpatialReference srs(srs_in);
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  Crs crs;
  char* wkt = nullptr;
  const char* options[] = {"FORMAT=WKT2_2019", nullptr};
  if (srs.exportToWkt(&wkt, options) == OGRERR_NONE && wkt) crs.wkt = wkt;
  CPLFree(wkt);
  if (const char* name = srs.GetName()) crs.name = name;
  crs.geographic = srs.IsGeographic();
  // An EPSG code is reported only when the CRS itself says so (or identifies as one with certainty).
  const char* auth = srs.IsProjected() ? srs.GetAuthorityName("PROJCS") : srs.GetAuthorityName("GEOGCS");
  const char* code = srs.IsProjected() ? srs.GetAuthorityCode("PROJCS") : srs.GetAuthorityCode("GEOGCS");
  if (!auth) { auth = srs.GetAuthorityName(nullptr); code = srs.GetAuthorityCode(nullptr); }
  if (auth && code && std::string(auth) == "EPSG") {
    crs.epsg = std::atoi(code);
  } else {
    // Files such as ESRI .prj carry no code; accept PROJ's identification only when it is certain.
    int count = 0;
    int* confidence = nullptr;
    OGRSpatialReferenceH* matches = srs.FindMatches(nullptr, &count, &confidence);
    if (count >= 1 && confidence[0] == 100) {
      const auto* m = OGRSpatialReference::FromHandle(matches[0]);
      const char* mauth = m->GetAuthorityName(nullptr);
      const char* mcode = m->GetAuthorityCode(nullptr);
      if (mauth && mcode && std::string(mauth) == "EPSG") crs.epsg = std::atoi(mcode);
    }
    OSRFreeSRSArray(matches);
    CPLFree(confidence);
  }
  if (!crs.geographic) crs.linear_unit_m = srs.GetLinearUnits(nullptr);
  OGRErr err = OGRERR_NONE;
  const double a = srs.GetSemiMajor(&err);
  if (err == OGRERR_NONE && a > 0) crs.ellipsoid.semi_major_m = a;
  const double invf = srs.GetInvFlattening(&err);
  if (err == OGRERR_NONE) crs.ellipsoid.inverse_flattening = invf;
  return crs;
}

OGRSpatialReference to_ogr(const Crs& crs) {
  OGRSpatialReference srs;
  if (srs.importFromWkt(crs.wkt.c_str()) != OGRERR_NONE) throw bad_input("invalid CRS definition: " + crs.name);
  srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return srs;
}

std::string last_gdal_error(const std::string& fallback) {
  const char* msg = CPLGetLastErrorMsg();
  std::string s = (msg && *msg) ? msg : fallback;
  for (char& c : s) if (c == '\n') c = ' ';
  return s;
}

std::string temporary_name(const std::string& path) { return path + ".tmp-" + std::to_string(::getpid()); }

void commit_file(const std::string& temporary, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    discard_file(temporary);
    throw write_failure(path, ec.value(), "");
  }
}

Error write_failure(const std::string& path, int error_number, const std::string& message) {
  const bool full = error_number == ENOSPC || message.find("No space left") != std::string::npos ||
                    message.find("Free disk space available") != std::string::npos;  // GTiff's own check
  std::string why = full ? "no space left on the device" : message;
  if (why.empty()) why = error_number ? std::strerror(error_number) : "write failed";
  return processing_error(path + ": cannot write output (" + why + ")");
}

void discard_file(const std::string& temporary) {
  std::error_code ec;
  std::filesystem::remove(temporary, ec);
}

void check_output(const std::string& path, bool overwrite) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(path, ec) && !overwrite) throw bad_input(path + ": output exists (use --overwrite to replace it)");
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir, ec)) throw bad_input(path + ": output folder " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0) throw bad_input(path + ": output folder " + dir.string() + " is not writable");
}

}  // namespace detail

Crs crs_from_user(const std::string& definition) {
  OGRSpatialReference srs;
  const OGRErr err = [&] {
    const detail::QuietGdal quiet;
    return srs.SetFromUserInput(definition.c_str());
  }();
  if (err != OGRERR_NONE) throw bad_input("unknown CRS '" + definition + "'");
  return detail::describe(srs);
}

Crs wgs84() { return crs_from_user("EPSG:4326"); }

namespace {

/// The value of "+key=" in a PROJ string, or "".
std::string proj_parameter(const std::string& proj4, const std::string& key) {
  const std::string token = "+" + key + "=";
  const auto at = proj4.find(token);
  if (at == std::string::npos) return "";
  const auto start = at + token.size();
  return proj4.substr(start, proj4.find(' ', start) - start);
}

}  // namespace

CrsDefinition crs_definition(const Crs& crs) {
  // With an EPSG code, the official definition (its AUTHORITY node): QGIS then identifies the code
  // rather than matching the file's WKT to another CRS (OGC:CRS84 for an ESRI .prj of WGS 84).
  OGRSpatialReference srs = detail::to_ogr(crs);
  if (crs.epsg) {
    OGRSpatialReference official;
    CPLErrorReset();
    if (official.importFromEPSG(*crs.epsg) == OGRERR_NONE) srs = official;
  }
  CrsDefinition d;
  d.description = crs.name;
  d.epsg = crs.epsg;
  d.geographic = crs.geographic;
  CPLErrorReset();
  char* text = nullptr;
  const char* wkt1[] = {"FORMAT=WKT1_GDAL", nullptr};
  d.wkt = srs.exportToWkt(&text, wkt1) == OGRERR_NONE && text ? text : crs.wkt;
  CPLFree(text);
  text = nullptr;
  if (srs.exportToProj4(&text) == OGRERR_NONE && text) d.proj4 = text;
  CPLFree(text);
  while (!d.proj4.empty() && d.proj4.back() == ' ') d.proj4.pop_back();
  d.projection_acronym = proj_parameter(d.proj4, "proj");
  const char* ellipsoid_auth = srs.GetAuthorityName("SPHEROID");
  const char* ellipsoid_code = srs.GetAuthorityCode("SPHEROID");
  if (ellipsoid_auth && ellipsoid_code) d.ellipsoid_acronym = std::string(ellipsoid_auth) + ":" + ellipsoid_code;
  else d.ellipsoid_acronym = proj_parameter(d.proj4, "ellps");
  if (d.ellipsoid_acronym.empty())  // a datum named by PROJ (+datum=NAD83) hides its ellipsoid: its name then
    if (const char* name = srs.GetAttrValue("SPHEROID")) d.ellipsoid_acronym = name;
  return d;
}

struct CrsTransform::Impl {
  OGRCoordinateTransformation* ct = nullptr;
  ~Impl() { if (ct) OGRCoordinateTransformation::DestroyCT(ct); }
};

CrsTransform::CrsTransform(const Crs& from, const Crs& to) : impl_(std::make_unique<Impl>()) {
  const OGRSpatialReference a = detail::to_ogr(from), b = detail::to_ogr(to);
  impl_->ct = OGRCreateCoordinateTransformation(&a, &b);
  if (!impl_->ct) throw bad_input("no transformation from " + from.name + " to " + to.name);
}
CrsTransform::~CrsTransform() = default;
CrsTransform::CrsTransform(CrsTransform&&) noexcept = default;
CrsTransform& CrsTransform::operator=(CrsTransform&&) noexcept = default;

std::array<double, 2> CrsTransform::operator()(double x, double y) const {
  double px = x, py = y;
  if (!impl_->ct->Transform(1, &px, &py)) return {std::nan(""), std::nan("")};
  return {px, py};
}

GridLocator::GridLocator(const Georef& georef)
    : georef_(georef), to_lonlat_(georef.crs, wgs84()), from_lonlat_(wgs84(), georef.crs) {}

std::array<double, 2> GridLocator::pixel_to_crs(double col, double row) const {
  const auto& t = georef_.transform;
  return {t[0] + col * t[1] + row * t[2], t[3] + col * t[4] + row * t[5]};
}

std::array<double, 2> GridLocator::crs_to_pixel(double x, double y) const {
  const auto& t = georef_.transform;
  const double det = t[1] * t[5] - t[2] * t[4];
  if (det == 0.0) throw bad_input("singular geotransform");
  const double dx = x - t[0], dy = y - t[3];
  return {(t[5] * dx - t[2] * dy) / det, (-t[4] * dx + t[1] * dy) / det};
}

std::array<double, 2> GridLocator::cell_lonlat(int col, int row) const {
  const auto p = pixel_to_crs(col + 0.5, row + 0.5);
  return crs_to_lonlat(p[0], p[1]);
}

}  // namespace terrapolis
