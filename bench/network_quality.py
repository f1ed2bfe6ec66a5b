#!/usr/bin/env python3
"""Network quality of a run folder (terrapolis run): what real road networks look like.

Prints total road length (the network drawn once, sections.geojson), junctions, circuity (road
length over the geodesic distance of its ends) per link and between city pairs 10 km or more
apart through the network (Dijkstra on the sections; real regional networks: about 1.2-1.4,
Ballou, Rahardja & Sakai 2002, "Selected country circuity factors for road travel distance
estimation", Transportation Research A 36), the share of surface length above each class's grade
limit, the surface length on water (no bridge), and the road density the run states (run.json).
Usage: network_quality.py RUN_FOLDER   (coordinates in lon/lat: the SRTM and GEBCO tiles)
"""
import heapq
import json
import math
import os
import sys


def geod(a, b):  # haversine on the mean Earth radius
    p1, p2 = math.radians(a[1]), math.radians(b[1])
    dl = math.radians(b[0] - a[0])
    h = math.sin((p2 - p1) / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * 6371008.8 * math.asin(math.sqrt(h))


def quantile(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(p * len(v)))] if v else float('nan')


def load(folder, name):
    path = os.path.join(folder, name)
    return json.load(open(path))['features'] if os.path.exists(path) else []


def water_test(folder):
    """A test of whether the straight line between two lon/lat points crosses water (the sea: at or
    below 0 m or nodata in elevation.tif; the lakes of inland_water.tif), sampled every half cell;
    None without GDAL's Python bindings or the rasters."""
    try:
        from osgeo import gdal
    except ImportError:
        return None
    paths = [os.path.join(folder, f) for f in ('elevation.tif', 'inland_water.tif')]
    if not all(os.path.exists(p) for p in paths):
        return None
    ds = gdal.Open(paths[0])
    gt, band = ds.GetGeoTransform(), ds.GetRasterBand(1)
    z, nodata = band.ReadAsArray(), band.GetNoDataValue()
    lakes = gdal.Open(paths[1])  # kept open while its band is read (GDAL's bindings need the dataset)
    lake = lakes.GetRasterBand(1).ReadAsArray()
    rows, cols = z.shape

    def wet(lon, lat):
        c, r = int((lon - gt[0]) / gt[1]), int((lat - gt[3]) / gt[5])
        if not (0 <= r < rows and 0 <= c < cols):
            return True
        v = z[r, c]
        return lake[r, c] == 1 or v != v or (nodata is not None and v == nodata) or v <= 0

    def crosses(a, b):
        n = max(2, int(2 * max(abs(b[0] - a[0]) / abs(gt[1]), abs(b[1] - a[1]) / abs(gt[5]))))
        return any(wet(a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n) for k in range(1, n))
    return crosses


def main(folder):
    roads = load(folder, 'roads.geojson')
    sections = load(folder, 'sections.geojson')
    junctions = load(folder, 'junctions.geojson')
    land = [r for r in roads if r['properties']['router'] != 'ferry']
    key = lambda p: (round(p[0], 9), round(p[1], 9))
    # Per link.
    link = [r['properties']['length_m'] / d for r in land
            if (d := geod(r['geometry']['coordinates'][0], r['geometry']['coordinates'][-1])) > 0]
    # City pairs through the network: each city at the cell its roads start or end at.
    graph = {}
    for s in sections:
        c = s['geometry']['coordinates']
        a, b, w = key(c[0]), key(c[-1]), s['properties']['length_m']
        graph.setdefault(a, []).append((b, w))
        graph.setdefault(b, []).append((a, w))
    city = {}
    for r in land:
        c = r['geometry']['coordinates']
        city.setdefault(r['properties']['from'], key(c[0]))
        city.setdefault(r['properties']['to'], key(c[-1]))
    ids = sorted(i for i in city if city[i] in graph)
    over_water = water_test(folder)
    pair, land_pair, unreachable = [], [], 0
    for n, i in enumerate(ids):
        dist = {city[i]: 0.0}
        heap = [(0.0, city[i])]
        while heap:
            d, u = heapq.heappop(heap)
            if d > dist[u]:
                continue
            for v, w in graph[u]:
                if d + w < dist.get(v, math.inf):
                    dist[v] = d + w
                    heapq.heappush(heap, (d + w, v))
        for j in ids[n + 1:]:
            g = geod(city[i], city[j])
            if g < 1e4:
                continue
            if city[j] in dist:
                pair.append(dist[city[j]] / g)
                if over_water and not over_water(city[i], city[j]):
                    land_pair.append(dist[city[j]] / g)
            else:
                unreachable += 1
    # Grades and water, per class, on the surface (no bridge or tunnel).
    by_class = {}
    for r in land:
        p = r['properties']
        s = by_class.setdefault(p['class'], [0.0, 0.0, 0.0, p.get('grade_limit_pct')])
        s[0] += p['length_m'] - p['bridge_m'] - p['tunnel_m']
        s[1] += p.get('over_limit_m', 0)
        s[2] = max(s[2], p.get('longest_over_limit_m', 0))
    water_km = sum(r['properties'].get('water_m', 0) for r in land) / 1000
    km = sum(s['properties']['length_m'] for s in sections) / 1000
    print('  network: %.0f km (%d links, %.0f km summed per link), %d sections, %d junctions' %
          (km, len(roads), sum(r['properties']['length_m'] for r in roads) / 1000, len(sections), len(junctions)))
    print('  circuity per link: median %.2f p90 %.2f; city pairs >= 10 km: %d, median %.2f p90 %.2f (%d pairs not joined by road)' %
          (quantile(link, .5), quantile(link, .9), len(pair), quantile(pair, .5), quantile(pair, .9), unreachable))
    if over_water:
        print('  city pairs >= 10 km whose straight line stays on land (no sea or lake to go round): %d, median %.2f p90 %.2f' %
              (len(land_pair), quantile(land_pair, .5), quantile(land_pair, .9)))
    grades = ', '.join('%s %.1f %% over %s %% (longest %.0f m)' % (c, 100 * s[1] / s[0] if s[0] else 0, s[3], s[2])
                       for c, s in sorted(by_class.items()))
    print('  surface above the class grade limit: %s; on water without a structure: %.2f km' % (grades or 'no roads', water_km))
    # Road density as the run states it (run.json): against France's 0.73 km/km2 of national and
    # departmental roads and 2.0 km/km2 of all roads (Cour des comptes, ccomptes.fr/en/documents/59347).
    run = os.path.join(folder, 'run.json')
    figures = json.load(open(run))['summary'].get('roads', {}) if os.path.exists(run) else {}
    if 'network_km_per_km2' in figures:
        print('  road density: %.3f km per km2 of land (%.0f km2; France: 0.73 national and departmental, 2.0 all roads)' %
              (figures['network_km_per_km2'], figures['land_km2']))


if __name__ == '__main__':
    main(sys.argv[1])
