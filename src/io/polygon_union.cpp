// Unions of polygons through OGR's GEOS bindings (the only source that includes ogr_geometry.h for them).
// SPDX-License-Identifier: MIT
#include "io/polygon_union.hpp"

#include <ogr_geometry.h>

#include <memory>

#include "core/error.hpp"
#include "io/gdal_util.hpp"

namespace terrapolis {
namespace {

void add_polygons(const OGRGeometry& g, std::vector<Polygon>& out) {
  const OGRwkbGeometryType type = wkbFlatten(g.getGeometryType());
  if (type == wkbPolygon) {
    const OGRPolygon& p = *g.toPolygon();
    Polygon polygon;
    for (const OGRLinearRing* ring : p) {
      Ring r;
      for (int i = 0; i + 1 < ring->getNumPoints(); ++i) r.push_back({ring->getX(i), ring->getY(i)});  // OGR closes its rings
      if (r.size() >= 3) polygon.rings.push_back(std::move(r));
    }
    if (!polygon.rings.empty()) out.push_back(std::move(polygon));
  } else if (type == wkbMultiPolygon || type == wkbGeometryCollection) {
    for (const OGRGeometry* part : *g.toGeometryCollection()) add_polygons(*part, out);
  }  // lines and points: a union of polygons has none of area
}

/// The polygons of `g` (a polygon, or the polygons of a collection) appended to `out`, copied.
void add_polygons(const OGRGeometry& g, OGRMultiPolygon& out) {
  const OGRwkbGeometryType type = wkbFlatten(g.getGeometryType());
  if (type == wkbPolygon) {
    out.addGeometry(&g);
  } else if (type == wkbMultiPolygon || type == wkbGeometryCollection) {
    for (const OGRGeometry* part : *g.toGeometryCollection()) add_polygons(*part, out);
  }
}

}  // namespace

std::vector<Polygon> polygon_union(const std::vector<Polygon>& polygons) {
  if (!OGRGeometryFactory::haveGEOS())
    throw processing_error("polygon union: this GDAL was built without GEOS (install a GDAL with GEOS, e.g. Debian's libgdal)");
  OGRMultiPolygon all;
  for (const Polygon& p : polygons) {
    auto polygon = std::make_unique<OGRPolygon>();
    for (const Ring& r : p.rings) {
      auto ring = std::make_unique<OGRLinearRing>();
      for (const auto& v : r) ring->addPoint(v[0], v[1]);
      ring->closeRings();
      polygon->addRingDirectly(ring.release());
    }
    all.addGeometryDirectly(polygon.release());
  }
  std::vector<Polygon> out;
  if (all.IsEmpty()) return out;
  const detail::QuietGdal quiet;  // GEOS's complaint about an invalid piece: repaired below
  std::unique_ptr<OGRGeometry> united(all.UnionCascaded());
  if (!united) {
    // GEOS refuses a union with an invalid piece (a ring that touches or crosses itself, e.g. a
    // swept quadrilateral folded at the scale of rounding): each invalid one made valid (GEOS's
    // MakeValid keeps every part of its area), then united again.
    OGRMultiPolygon valid;
    for (const OGRGeometry* g : all) {
      if (g->IsValid()) {
        valid.addGeometry(g);
      } else if (const std::unique_ptr<OGRGeometry> repaired(g->MakeValid()); repaired) {
        add_polygons(*repaired, valid);
      }
    }
    united.reset(valid.UnionCascaded());
  }
  if (!united) throw processing_error("polygon union: GEOS could not unite the polygons");
  add_polygons(*united, out);
  return out;
}

}  // namespace terrapolis
