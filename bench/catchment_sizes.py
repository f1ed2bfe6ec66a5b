#!/usr/bin/python3
"""Which size model suits regions it was not tuned on? Scored after the fact on the runs
bench/realism.sh keeps (its 4th argument), without rerunning Terrapolis: for each run, the people
of the density model (spread over buildable land in proportion to density x cell area) go to the
nearest settlement centre (catchments), and candidate size models are scored with the realism bars
(count of 1,000+ within x1.5 of the reference, largest within x2, rank-size exponent within 0.25)
on the region runs, plus the default run's largest on the bundled DEM (run_default).
Models: the fixed rank-size law as run; pure catchments (sizes proportional to M^gamma, Bettencourt
2007's agglomeration exponent gamma); the rank-size law over the same settlements with its exponent
read from the catchments of 1,000 or more (sites.sizes = catchment); the density-mass law (issue 30:
sizes proportional to the density mass within R = 5 or 10 km of each centre, to the power gamma,
overlaps counted for each); the default run also with the settled share of the people
(sites.urban_share). Scores only: no parameter is fitted here.
Usage: bench/catchment_sizes.py KEPT_DIR  (the runs realism.sh kept, made with sites.sizes = rank_size)"""
import glob
import json
import sys

import numpy as np
from osgeo import gdal, osr
from scipy.spatial import cKDTree


def exponent(sizes):
    """q of ln P = c - q ln(k - 1/2) (Gabaix & Ibragimov 2011), as the run's realism figures."""
    s = sorted(sizes, reverse=True)
    return None if len(s) < 3 else float(-np.polyfit(np.log(np.arange(len(s)) + 0.5), np.log(s), 1)[0])


def catchments(run):
    """Shares of the density mass nearest to each settlement of `run`, and the run's summary."""
    s = json.load(open(f"{run}/run.json"))["summary"]
    d, b = gdal.Open(f"{run}/density.tif"), gdal.Open(f"{run}/buildable.tif")
    dens = d.GetRasterBand(1).ReadAsArray().astype(float)
    ok = (b.GetRasterBand(1).ReadAsArray() == 1) & np.isfinite(dens)
    t = d.GetGeoTransform()
    srs = osr.SpatialReference(wkt=d.GetProjection())
    r, c = np.nonzero(ok)
    x, y = t[0] + (c + 0.5) * t[1], t[3] + (r + 0.5) * t[5]
    geo = srs.IsGeographic()
    w = dens[r, c] * np.abs(t[1] * t[5]) * (111320 * np.cos(np.radians(y)) * 110574 if geo else 1)
    wgs = osr.SpatialReference()
    wgs.ImportFromEPSG(4326)
    for ref in (wgs, srs):
        ref.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    to_grid = osr.CoordinateTransformation(wgs, srs)
    cities = json.load(open(f"{run}/cities.geojson"))["features"]
    pts = np.array([to_grid.TransformPoint(*f["geometry"]["coordinates"][:2])[:2] for f in cities])
    lat0 = np.radians(np.mean(y))
    metric = (lambda a, b: np.c_[a * 111320 * np.cos(lat0), b * 110574]) if geo else (lambda a, b: np.c_[a, b])
    _, nearest = cKDTree(metric(pts[:, 0], pts[:, 1])).query(metric(x, y))
    masses = {"catchment": np.bincount(nearest, weights=w, minlength=len(pts)) / w.sum()}
    cells = cKDTree(metric(x, y))
    for r_km in (5, 10):  # the density-mass law: the people within r_km of each centre
        within = cells.query_ball_point(metric(pts[:, 0], pts[:, 1]), r_km * 1000.0)
        masses[f"{r_km} km"] = np.array([w[i].sum() for i in within]) / w.sum()
    return masses, s, [f["properties"]["population"] for f in cities]


def law_from_catchments(shares, settled, m=1000):
    """sites.sizes = catchment: the law over as many settlements, q from the catchments of m or more."""
    q = exponent([p for p in settled * shares if p >= m]) or 1.0
    k = np.arange(1, len(shares) + 1, dtype=float)
    return settled * k ** -q / np.sum(k ** -q)


runs = {p.split("/run_")[-1]: catchments(p) for p in sorted(glob.glob(f"{sys.argv[1]}/run_*"))}
models = {"rank-size law as run (q = 1)": ("catchment", lambda M, T, pops: np.array(pops, float))}
for g in (0.8, 1.0, 1.2, 1.4):
    models[f"catchments, M^{g}"] = ("catchment", lambda M, T, pops, g=g: T * M ** g / np.sum(M ** g))
models["law, q from the catchments (sites.sizes = catchment)"] = ("catchment", lambda M, T, pops: law_from_catchments(M, T))
for r_km in (5, 10):
    for g in (1.0, 1.5, 2.0):
        models[f"density mass within {r_km} km, M^{g}"] = (f"{r_km} km", lambda M, T, pops, g=g: T * M ** g / np.sum(M ** g))
    models[f"law, q from the masses within {r_km} km"] = (f"{r_km} km", lambda M, T, pops: law_from_catchments(M, T))
print("| model | count within x1.5 | largest within x2 | exponent within 0.25 | default run: largest / 5,552 (urban_share 1, 0.55) |")
print("|---|---|---|---|---|")
for label, (mass, model) in models.items():
    bars = [0, 0, 0]
    default = []
    for name, (masses, s, pops) in runs.items():
        M = masses[mass]
        ref = s["realism"]
        for share in ((1.0, 0.55) if name == "default" else (1.0,)):
            sizes = sorted((p for p in model(M, share * s["sites"]["target_population"], pops) if p >= 1000), reverse=True)
            if name == "default" and label.startswith("rank-size") and share != 1:
                continue  # the run's own sizes exist for its own total only
            largest = (sizes[0] if sizes else 0) / ref["largest"]["reference"]
            if name == "default":
                default.append(f"x{largest:.2f}")
                continue
            q = exponent(sizes)
            bars[0] += 1 / 1.5 <= len(sizes) / ref["count"]["reference"] <= 1.5
            bars[1] += 0.5 <= largest <= 2
            bars[2] += q is not None and abs(q - ref["rank_size_exponent"]["reference"]) <= 0.25
    print(f"| {label} | {bars[0]} | {bars[1]} | {bars[2]} | {', '.join(default)} |")
