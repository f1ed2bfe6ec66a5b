#!/usr/bin/python3
"""Placement backtest scoring (bench/placement.sh, docs/benchmarks.md "Placement backtest").

Splits a region's real places into the given half (the largest, written as sites.existing) and the
hidden half, then scores a run that placed the rest: the share of hidden places with a new
(generated) settlement within 5 km and the median distance from a hidden place to the nearest new
settlement, against the same count of points drawn uniformly on the run's buildable land and drawn
in proportion to its density (100 draws each, fixed seed).

  placement.py split PLACES BUILDABLE.tif GIVEN.geojson HIDDEN.geojson   -> prints the people, given and hidden places
  placement.py score RUN HIDDEN.geojson                                   -> prints one JSON line
  placement.py self-test                                                  -> checks the scoring on a known case
"""
import json
import math
import random
import statistics
import sys

RADIUS_KM = 5.0
DRAWS = 100


def km(a, b):
    """Great-circle distance in km between (lon, lat) points (mean Earth radius; 0.5 % of an ellipsoid)."""
    lon1, lat1, lon2, lat2 = map(math.radians, (a[0], a[1], b[0], b[1]))
    h = math.sin((lat2 - lat1) / 2) ** 2 + math.cos(lat1) * math.cos(lat2) * math.sin((lon2 - lon1) / 2) ** 2
    return 2 * 6371.0088 * math.asin(math.sqrt(min(1.0, h)))


def unit_vectors(points):
    """(lon, lat) degrees as unit vectors, for nearest-point searches by chord length."""
    import numpy as np
    a = np.radians(np.asarray(points, dtype=float).reshape(-1, 2))
    return np.stack([np.cos(a[:, 1]) * np.cos(a[:, 0]), np.cos(a[:, 1]) * np.sin(a[:, 0]), np.sin(a[:, 1])], axis=1)


def scores(hidden, points):
    """(share of hidden places within RADIUS_KM of a point, median distance km); (0, inf) without points."""
    import numpy as np
    if len(points) == 0:
        return 0.0, math.inf
    h, p = unit_vectors(hidden), unit_vectors(points)
    nearest = np.empty(len(h))
    for start in range(0, len(h), 512):  # chords of the nearest point, 512 places at a time
        chunk = h[start:start + 512]
        nearest[start:start + 512] = np.sqrt(np.maximum(0.0, ((chunk[:, None, :] - p[None, :, :]) ** 2).sum(axis=2).min(axis=1)))
    dist_km = 2 * 6371.0088 * np.arcsin(np.minimum(1.0, nearest / 2))  # chord -> great-circle km
    return float((dist_km <= RADIUS_KM).mean()), float(np.median(dist_km))


def baselines(hidden, cells, weights, count, seed=1):
    """Mean share and median of medians over DRAWS draws of `count` cells, uniform and weighted."""
    rng = random.Random(seed)
    out = {}
    for name, w in (("uniform", None), ("density", weights)):
        shares, medians = [], []
        for _ in range(DRAWS):
            pick = rng.choices(cells, weights=w, k=count)
            s, m = scores(hidden, pick)
            shares.append(s)
            medians.append(m)
        out[name] = {"within_5km": round(statistics.mean(shares), 3), "median_km": round(statistics.median(medians), 2)}
    return out


def lonlat_points(path):
    """The points of a vector file as (lon, lat), and their properties."""
    from osgeo import ogr, osr
    ds = ogr.Open(path)
    layer = ds.GetLayer(0)
    wgs84 = osr.SpatialReference()
    wgs84.ImportFromEPSG(4326)
    wgs84.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    srs = layer.GetSpatialRef()
    to = None
    if srs is not None and not srs.IsSame(wgs84):
        srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        to = osr.CoordinateTransformation(srs, wgs84)
    out = []
    for f in layer:
        g = f.GetGeometryRef()
        x, y = g.GetX(), g.GetY()
        if to is not None:
            x, y, _ = to.TransformPoint(x, y)
        out.append(((x, y), f.items()))
    return out


def land_cells(run):
    """Centres (lon, lat) of the run's buildable cells and their density, every cell of a coarse
    lattice (at most about 200,000 of them)."""
    from osgeo import gdal, osr
    import numpy as np
    b = gdal.Open(f"{run}/buildable.tif")
    d = gdal.Open(f"{run}/density.tif")
    mask = b.ReadAsArray() == 1
    dens = d.ReadAsArray().astype(float)
    mask &= np.isfinite(dens)
    step = max(1, int(math.sqrt(mask.size / 200000)))
    t = b.GetGeoTransform()
    srs = osr.SpatialReference(wkt=b.GetProjection())
    srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    wgs84 = osr.SpatialReference()
    wgs84.ImportFromEPSG(4326)
    wgs84.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    to = None if srs.IsGeographic() else osr.CoordinateTransformation(srs, wgs84)
    cells, weights = [], []
    rows, cols = np.nonzero(mask[::step, ::step])
    for r, c in zip(rows * step, cols * step):
        x, y = t[0] + (c + 0.5) * t[1] + (r + 0.5) * t[2], t[3] + (c + 0.5) * t[4] + (r + 0.5) * t[5]
        if to is not None:
            x, y, _ = to.TransformPoint(x, y)
        cells.append((x, y))
        weights.append(max(0.0, dens[r, c]))
    return cells, weights


def cell_of(path, lonlat):
    """(dataset, col, row) of the cell holding (lon, lat) in the raster at `path`, or None off the grid."""
    from osgeo import gdal, osr
    b = gdal.Open(path)
    t = b.GetGeoTransform()
    srs = osr.SpatialReference(wkt=b.GetProjection())
    srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    x, y = lonlat
    if not srs.IsGeographic():
        wgs84 = osr.SpatialReference()
        wgs84.ImportFromEPSG(4326)
        wgs84.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        x, y, _ = osr.CoordinateTransformation(wgs84, srs).TransformPoint(x, y)
    c, r = int(math.floor((x - t[0]) / t[1])), int(math.floor((y - t[3]) / t[5]))
    return (b, c, r) if 0 <= c < b.RasterXSize and 0 <= r < b.RasterYSize else None


def takeable(buildable, places):
    """The places sites.existing takes, as it takes them (src/pipeline/places.cpp): largest first,
    each on its cell or the nearest free buildable one within two cells; a place with none (on
    nodata, in a lake, or every cell near it held by a larger place) is left out."""
    from osgeo import gdal
    b = gdal.Open(buildable)
    grid = b.ReadAsArray() == 1
    rows, cols = grid.shape
    taken = set()
    out = []
    for f in sorted(places, key=lambda f: -f["properties"]["population"]):
        cell = cell_of(buildable, f["geometry"]["coordinates"])
        if cell is None:
            continue
        _, c0, r0 = cell
        free = [((c - c0) ** 2 + (r - r0) ** 2, r, c) for r in range(r0 - 2, r0 + 3) for c in range(c0 - 2, c0 + 3)
                if 0 <= r < rows and 0 <= c < cols and grid[r, c] and (c, r) not in taken]
        if free:
            best = min(free, key=lambda t: t[0])  # the first nearest in row order, as places.cpp scans
            taken.add((best[2], best[1]))
            out.append(f)
    return out


def split(places_path, buildable, given_path, hidden_path):
    """The places a run takes (takeable), the largest half given, the rest hidden."""
    places = [f for f in json.load(open(places_path))["features"] if (f["properties"].get("population") or 0) >= 1]
    places = takeable(buildable, places)
    places.sort(key=lambda f: -f["properties"]["population"])
    half = (len(places) + 1) // 2
    for path, part in ((given_path, places[:half]), (hidden_path, places[half:])):
        json.dump({"type": "FeatureCollection", "features": part}, open(path, "w"))
    print(sum(f["properties"]["population"] for f in places), len(places[:half]), len(places[half:]))


def score(run, hidden_path):
    hidden = [tuple(f["geometry"]["coordinates"][:2]) for f in json.load(open(hidden_path))["features"]]
    cities = lonlat_points(f"{run}/cities.geojson")
    new = [p for p, props in cities if not props.get("existing")]
    share, median = scores(hidden, new)
    cells, weights = land_cells(run)
    result = {"hidden": len(hidden), "new": len(new), "within_5km": round(share, 3), "median_km": round(median, 2)}
    result.update(baselines(hidden, cells, weights, len(new)) if new else {})
    print(json.dumps(result))


def self_test():
    """A synthetic region whose answers are known by hand."""
    hidden = [(0.0, 0.0), (0.1, 0.0), (1.0, 0.0)]
    # A point on each of the first two places, none near the third (0.9 degrees, about 100 km, away).
    share, median = scores(hidden, [(0.0, 0.0), (0.1, 0.0)])
    assert abs(share - 2 / 3) < 1e-12, share
    assert median < 1e-6, median
    # One point 0.04 degrees east of the first (4.45 km): within 5 km of it, 6.67 km from the second.
    share, median = scores(hidden, [(0.04, 0.0)])
    assert abs(share - 1 / 3) < 1e-12 and abs(median - 0.06 * 111.195) < 0.01, (share, median)
    # km(): one degree of longitude on the equator is 111.195 km on the mean sphere.
    assert abs(km((0, 0), (1, 0)) - 111.195) < 0.001
    # Baselines: land made of the hidden places' own cells scores them all; far land, none.
    b = baselines(hidden[:2], [(0.0, 0.0), (0.1, 0.0)], [1, 1], 2)
    assert b["uniform"]["within_5km"] >= 0.5 and b["density"]["median_km"] <= 11.2, b
    b = baselines(hidden, [(10.0, 10.0)], [1], 1)
    assert b["uniform"]["within_5km"] == 0 and b["density"]["within_5km"] == 0, b
    # Weighted draws follow the weights: all the weight on the first place's cell.
    b = baselines(hidden[:1], [(0.0, 0.0), (5.0, 5.0)], [1, 0], 1)
    assert b["density"]["within_5km"] == 1.0 and b["uniform"]["within_5km"] < 0.8, b
    print("placement scoring: ok")


if __name__ == "__main__":
    command = sys.argv[1]
    if command == "split":
        split(*sys.argv[2:6])
    elif command == "score":
        score(*sys.argv[2:4])
    elif command == "self-test":
        self_test()
    else:
        sys.exit(f"placement.py: unknown command {command}")
