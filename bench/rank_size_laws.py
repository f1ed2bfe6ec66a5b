#!/usr/bin/python3
"""Which size law predicts a region's settlements from its population (and land)? For every shared
region with GeoNames places (CC BY 4.0), the total P of its places of 1,000 or more is given to each
candidate law, which predicts the count of 1,000+ settlements and the largest; a law fitted across
regions is fitted on the other regions only (leave one region out). Prints the count of regions
within x1.5 of the real count and x2 of the real largest (the bars of bench/realism.sh).
With DEMS_DIR, also the laws that use the land area (cells above 0 m): Zipf with the count held to
the hexagons of sites.spacing_km the land holds (Christaller's 7 km, and 6 and 8 km around it), and
the region's people per km2 of land against the default sites.people_per_km2 = 60 and against the
median of the other regions.
Usage: bench/rank_size_laws.py [PLACES_DIR [DEMS_DIR]]"""
import json
import math
import statistics
import sys

PLACES = sys.argv[1] if len(sys.argv) > 1 else "../shared/reference/geonames"
REGIONS = ["N47E009", "N57E011", "demcompare_reduced_gironde_topobathy", "osmtransform_heidelberg_mannheim_srtm3",
           "pyflwdir_rhine_elv0", "spDataLarge_nz_elev", "terra_elev_luxembourg", "gebco2022_15s_la_palma",
           "gebco2022_15s_north_corsica_capcorse", "gebco2022_15s_tenerife_east"]
MIN = 1000

ref = {}
for r in REGIONS:
    sizes = sorted((f["properties"]["population"] for f in json.load(open(f"{PLACES}/{r}.geojson"))["features"]
                    if f["properties"]["population"] >= MIN), reverse=True)
    ref[r] = (sum(sizes), len(sizes), sizes[0])


def zipf_from_total(total, q, max_count=math.inf):
    """The rank-size law of sites.zipf_exponent q fitted to the total, at most max_count ranks (rank_size_populations)."""
    h, n = 0.0, 0
    while n < max_count and total * (n + 1) ** -q / (h + (n + 1) ** -q) >= MIN:
        h += (n + 1) ** -q
        n += 1
    return n, total / h if n else 0


def land_km2(path):
    """km2 of cells above 0 m with data (cell areas from the latitude on geographic grids)."""
    from osgeo import gdal, osr
    ds = gdal.Open(path)
    band, t = ds.GetRasterBand(1), ds.GetGeoTransform()
    z, nodata = band.ReadAsArray().astype(float), band.GetNoDataValue()
    geographic = osr.SpatialReference(wkt=ds.GetProjection()).IsGeographic()
    km2 = 0.0
    for row in range(ds.RasterYSize):
        lat = t[3] + t[5] * (row + 0.5)
        cell = abs(t[1] * t[5]) * (111320 * math.cos(math.radians(lat)) * 110574 if geographic else 1) / 1e6
        km2 += cell * sum(1 for v in z[row] if v == v and v != nodata and v > 0)
    return km2


def hexagons(km2, spacing_km):
    """Settlements of MIN people the land holds spacing_km apart on a hexagonal lattice (sites::settleable_count)."""
    return max(1, math.floor(km2 / (math.sqrt(3) / 2 * spacing_km ** 2 * MIN / 1000) + 1e-9))


def zipf_from_largest(total, largest):
    """A law P_k = largest k^-q down to MIN whose sizes add up to the total: q by bisection."""
    lo, hi = 0.05, 5.0
    for _ in range(60):
        q = (lo + hi) / 2
        n = int((largest / MIN) ** (1 / q))
        if sum(largest * k ** -q for k in range(1, n + 1)) > total:
            lo = q
        else:
            hi = q
    return int((largest / MIN) ** (1 / ((lo + hi) / 2))), largest


def loglog_fit(held_out, y):
    """ln y = a + b ln P by least squares over the other regions."""
    pts = [(math.log(ref[r][0]), math.log(y(r))) for r in REGIONS if r != held_out]
    mx, my = statistics.fmean(p[0] for p in pts), statistics.fmean(p[1] for p in pts)
    b = sum((x - mx) * (v - my) for x, v in pts) / sum((x - mx) ** 2 for x, _ in pts)
    return lambda total: math.exp(my + b * (math.log(total) - mx))


laws = {f"zipf q={q}": (lambda r, q=q: zipf_from_total(ref[r][0], q)) for q in (0.8, 0.9, 1.0, 1.1, 1.2)}
laws["largest = a P^b (held out), q from the total"] = lambda r: zipf_from_largest(ref[r][0], loglog_fit(r, lambda s: ref[s][2])(ref[r][0]))
files = {"N47E009": "N47E009.hgt", "N57E011": "N57E011.hgt", "gebco2022_15s_la_palma": "gebco2022_15s_la_palma.asc",
         "gebco2022_15s_north_corsica_capcorse": "gebco2022_15s_north_corsica_capcorse.asc",
         "gebco2022_15s_tenerife_east": "gebco2022_15s_tenerife_east.asc"}
land = {r: land_km2(f"{sys.argv[2]}/{files.get(r, r + '.tif')}") for r in REGIONS} if len(sys.argv) > 2 else {}
for spacing in (6, 7, 8) if land else ():
    laws[f"zipf q=1, at most land / hexagon({spacing} km)" + (" (the default)" if spacing == 7 else "")] = (
        lambda r, spacing=spacing: zipf_from_total(ref[r][0], 1.0, hexagons(land[r], spacing)))
print("| law | count within x1.5 | largest within x2 |")
print("|---|---|---|")
for name, law in laws.items():
    count = largest = 0
    for r in REGIONS:
        n, p1 = law(r)
        count += 1 / 1.5 <= n / ref[r][1] <= 1.5
        largest += 0.5 <= p1 / ref[r][2] <= 2
    print(f"| {name} | {count} | {largest} |")
print("\n| region | P (1,000+) | count | largest | largest / (1000 count) |")
print("|---|---|---|---|---|")
for r in REGIONS:
    total, n, p1 = ref[r]
    print(f"| {r} | {total} | {n} | {p1} | {p1 / (MIN * n):.2f} |")

if land:
    density = {r: ref[r][0] / land[r] for r in REGIONS}
    print("\n| region | people per km2 of land | x of 60 | x of the others' median |")
    print("|---|---|---|---|")
    within = {"60": 0, "median": 0}
    for r in REGIONS:
        median = statistics.median(density[s] for s in REGIONS if s != r)
        within["60"] += 1 / 3 <= 60 / density[r] <= 3
        within["median"] += 1 / 3 <= median / density[r] <= 3
        print(f"| {r} | {density[r]:.1f} | {60 / density[r]:.2f} | {median / density[r]:.2f} |")
    print(f"\ndefault total within x3 (of {len(REGIONS)}): 60 people/km2 {within['60']}, held-out median {within['median']}")
